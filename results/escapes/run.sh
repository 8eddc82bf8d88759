#!/usr/bin/env bash
# The escape study (issue 18, point 5): every trap and the paper's task x the escape planners,
# a time limit of 30 s per leg (iteration and check budgets lifted), every solved plan executed.
# Usage: results/escapes/run.sh SEEDS [PROBLEM...]   e.g.  results/escapes/run.sh 0-4
# Resumable: rerun with the same or more seeds and finished trials are skipped.
# The escape planners' attempt caps (max_escapes, max_replans: sized for check budgets) are
# lifted, so that every planner may use its whole 30 s (the hybrids' escapes keep their
# check slices and try again; gradient.clearance+rrtconnect, which ends the leg when its one
# RRT-Connect escape fails, gives that escape the rest of the leg).
set -euo pipefail
seeds=${1:?seeds, e.g. 0-4}; shift || true
problems=${*:-armz_deep_a armz_deep_b armz_deep_e armz_inspection_direct armz_inspection armz_pocket armz_window armz_cavity armz_thin_wall}
planners=gradient,gradient.clearance,gradient.clearance+detour,gradient.clearance+random_detour,gradient.clearance+rrtconnect,gradient.follow_leader,gradient.follow_leader+detour,gradient.follow_leader+random,gradient+rrtconnect,gradient.multistart,ompl.rrtconnect,ompl.kpiece1,ompl.prm,ompl.rrtstar
py=${PYTHON:-.venv/bin/python}
for p in $problems; do
  "$py" -m plannerlab compare "$p" --planners "$planners" --seeds "$seeds" \
    --time-limit 30 --max-iterations 100000000 --max-checks 1000000000 \
    --set gradient+rrtconnect:max_escapes=100000 --set gradient.multistart:max_escapes=100000 \
    --set gradient.clearance+rrtconnect:max_escapes=100000 --set gradient.clearance+rrtconnect:escape_checks=1000000000 \
    --set gradient.clearance+random_detour:max_escapes=100000 \
    --set gradient.follow_leader+random:max_replans=100000 \
    --execute --jobs "${JOBS:-2}" --out results/escapes --name "$p" --columns planner,solved,time
done

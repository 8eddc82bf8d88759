#!/usr/bin/env bash
# The escape study (issue 18, point 5; rerun for issue 26, item 3): every trap and the paper's
# task x the escape planners, a time limit of 30 s per leg (iteration and check budgets
# lifted), every solved plan executed.
# Usage: results/escapes/run.sh SEEDS [PROBLEM...]   e.g.  results/escapes/run.sh 0-19
#        PLANNERS=native.rrtconnect,native.rrtconnect+leader results/escapes/run.sh 0-19 armz_deep_a
# Resumable, and can be run in pieces: rerun with the same or more seeds (or other problems,
# or a subset of planners through PLANNERS) and finished trials are skipped (the store
# results/escapes/<problem>/trials.jsonl keeps one record per planner x seed).
# Deterministic planners (the registry's uses_rng = False: their seeds are one run) are run
# on the first seed of SEEDS only; report.py marks them "(one run)".
# The escape planners' attempt caps (max_escapes, max_replans: sized for check budgets) are
# lifted, so that every planner may use its whole 30 s (the hybrids' escapes keep their
# check slices and try again; gradient.clearance+rrtconnect, which ends the leg when its one
# RRT-Connect escape fails, gives that escape the rest of the leg).
set -euo pipefail
seeds=${1:?seeds, e.g. 0-19}; shift || true
problems=${*:-armz_deep_a armz_deep_b armz_deep_e armz_inspection_direct armz_inspection armz_pocket armz_window armz_cavity armz_thin_wall}
all=gradient,gradient.clearance,gradient.clearance+detour,gradient.clearance+random_detour,gradient.clearance+rrtconnect,gradient.follow_leader,gradient.follow_leader+detour,gradient.follow_leader+random,gradient+rrtconnect,gradient.multistart,ompl.rrtconnect,ompl.kpiece1,ompl.prm,ompl.rrtstar,native.rrtconnect,native.rrtconnect+leader
planners=${PLANNERS:-$all}
py=${PYTHON:-.venv/bin/python}
# split the planners into deterministic ones (one seed) and the others (every seed)
read -r det rnd < <("$py" - "$planners" <<'PY'
import sys
from plannerlab.planners import get_entry
names = [n for n in sys.argv[1].split(",") if n]
det = [n for n in names if not get_entry(n).uses_rng]
rnd = [n for n in names if get_entry(n).uses_rng]
print(",".join(det) or "-", ",".join(rnd) or "-")
PY
)
first=${seeds%%[-,]*}
# the lifted caps, each passed only with its planner (compare refuses a --set for a planner
# it does not run)
caps=(gradient+rrtconnect:max_escapes=100000 gradient.multistart:max_escapes=100000
  gradient.clearance+rrtconnect:max_escapes=100000 gradient.clearance+rrtconnect:escape_checks=1000000000
  gradient.clearance+random_detour:max_escapes=100000 gradient.follow_leader+random:max_replans=100000)
for p in $problems; do
  for pair in "$det:$first" "$rnd:$seeds"; do
    names=${pair%%:*}; s=${pair#*:}
    [ "$names" = "-" ] && continue
    sets=()
    for c in "${caps[@]}"; do
      case ",$names," in *",${c%%:*},"*) sets+=(--set "$c") ;; esac
    done
    "$py" -m plannerlab compare "$p" --planners "$names" --seeds "$s" \
      --time-limit 30 --max-iterations 100000000 --max-checks 1000000000 "${sets[@]}" \
      --execute --jobs "${JOBS:-2}" --out "${OUT:-results/escapes}" --name "$p" --columns planner,solved,time
  done
done

#!/usr/bin/env bash
# One entry point for set-up and the two jobs. Creates .venv (Python 3.11+) if it is
# missing or if pyproject.toml changed since it was made, then runs the job.
#   ./do main    the main job: planners compared on the Arm-Z paper's problem (a few
#                minutes; results/runs/main/, a rerun resumes and only prints the table)
#   ./do test    the test suite (what CI runs)
#   ./do bench   the speed benchmarks (bench/)
#   ./do jupyter Jupyter Lab on notebooks/compare.ipynb (installs jupyterlab into .venv once)
set -euo pipefail
cd "$(dirname "$0")"
PY=${PYTHON:-python3}
VENV=.venv
stamp="$VENV/.installed-$(cat pyproject.toml constraints.txt | sha1sum | cut -c1-12)"
if [ ! -x "$VENV/bin/python" ] || [ ! -f "$stamp" ]; then
  echo "setting up $VENV (once; a few minutes on a fresh machine)" >&2
  "$PY" -m venv "$VENV"
  "$VENV/bin/python" -m pip install --quiet --upgrade pip
  # pinned versions (constraints.txt): the goldens of tests/ depend on them
  "$VENV/bin/python" -m pip install --quiet -c constraints.txt -e ".[test]"
  rm -f "$VENV"/.installed-*
  touch "$stamp"
fi
export MPLBACKEND=Agg
job=${1:-main}
shift || true
case "$job" in
  main)
    # the paper's whole experiment: enter, A-E, leave; each trial stops at its first
    # failed leg, solved legs are executed in PyBullet
    exec "$VENV/bin/plannerlab" compare armz_inspection \
      --planners gradient.clearance+detour,gradient.clearance+random_detour,gradient.clearance,gradient \
      --seeds 0-1 --max-checks 100000 --execute --jobs 2 --out results/runs --name main "$@" ;;
  test)
    exec "$VENV/bin/python" -m pytest -q "$@" ;;
  bench)
    for b in bench/*.py; do "$VENV/bin/python" "$b" "$@"; done ;;
  jupyter)
    # the [jupyter] extra of pyproject.toml (jupyterlab, nbconvert, ipykernel), once
    if [ ! -x "$VENV/bin/jupyter-lab" ]; then
      echo "installing Jupyter Lab into $VENV (once)" >&2
      "$VENV/bin/python" -m pip install --quiet -c constraints.txt -e ".[test,jupyter]"
    fi
    if [ "$#" -eq 0 ]; then set -- notebooks/compare.ipynb; fi
    exec "$VENV/bin/jupyter" lab "$@" ;;
  *)
    echo "usage: ./do main|test|bench|jupyter [args]" >&2; exit 2 ;;
esac

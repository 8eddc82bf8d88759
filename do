#!/usr/bin/env bash
# One entry point for set-up and the two jobs. Creates .venv (Python 3.11+) if it is
# missing or if pyproject.toml changed since it was made, then runs the job.
#   ./do main    the main job: the paper's gradient method against the clearance family,
#                OMPL, compiled sampling, follow-the-leader and trajectory optimisation on
#                the Arm-Z paper's task,
#                executed (a few minutes; results/runs/main/, a rerun resumes and only
#                prints the table), ending with which planner escaped which local minimum
#   ./do test    the test suite (what CI runs), in two processes
#   ./do bench   the speed benchmarks (bench/)
#   ./do jupyter Jupyter Lab on notebooks/compare.ipynb (installs jupyterlab into .venv once)
set -euo pipefail
cd "$(dirname "$0")"
PY=${PYTHON:-python3}
VENV=.venv
job=${1:-main}
shift || true
# the package and its engines; the test suite's tools ([test]: pytest, ray, selenium,
# mypy, ...) only for ./do test, so that ./do main on a fresh clone installs half as much
hash=$(cat pyproject.toml constraints.txt | sha1sum | cut -c1-12)
extras=""
if [ "$job" = test ]; then extras="[test]"; fi
stamp="$VENV/.installed-$hash${extras:+-test}"
if [ ! -x "$VENV/bin/python" ] || { [ ! -f "$stamp" ] && [ ! -f "$VENV/.installed-$hash-test" ]; }; then
  echo "setting up $VENV (once; a few minutes on a fresh machine)" >&2
  "$PY" -m venv "$VENV"
  # pip's scratch space on the venv's own disk, not /tmp (stop 44's CI died with "No space
  # left on device" in /tmp while pip built the editable wheel; /tmp may be a small tmpfs)
  export TMPDIR="$PWD/$VENV/.pip-tmp"
  mkdir -p "$TMPDIR"
  "$VENV/bin/python" -m pip install --quiet --no-cache-dir --upgrade pip
  # pinned versions (constraints.txt): the goldens of tests/ depend on them
  "$VENV/bin/python" -m pip install --quiet --no-cache-dir -c constraints.txt -e ".$extras"
  rm -rf "$TMPDIR"
  unset TMPDIR
  rm -f "$VENV"/.installed-*
  touch "$stamp"
fi
export MPLBACKEND=Agg
case "$job" in
  main)
    # the mission (issue 36, item 5): on the Arm-Z paper's task (enter, A-E, leave) the
    # paper's gradient method against the best of the clearance family, OMPL, compiled
    # sampling, follow-the-leader and trajectory optimisation (trajopt.leader: the
    # leader-guided sampler's path optimised whole), with the same budget of collision checks per leg for
    # every planner (iterations lifted, a time limit only as a guard), solved legs executed
    # in PyBullet; one table, then which planner escaped which local minimum. First the
    # compiled kernels are loaded: a fresh clone compiles them (the core, then the clearance
    # descent's and the compiled samplers' side by side), so no two trials compile the same
    # kernels at once. The trials run in the order given, two at a time.
    echo "loading the compiled kernels (a fresh clone compiles them once: a few minutes)" >&2
    warm() { "$VENV/bin/python" -c "from plannerlab.run.preload import warm; warm('$1')"; }
    warm core
    warm clearance & clearance=$!
    warm native & native=$!
    wait "$clearance"
    wait "$native"
    exec "$VENV/bin/plannerlab" compare armz_inspection \
      --planners gradient,gradient.clearance+detour,ompl.rrtconnect,ompl.kpiece1,native.rrtconnect,gradient.follow_leader,native.rrtconnect+leader,trajopt.leader \
      --seeds 0 --max-checks 300000 --max-iterations 1000000000 --time-limit 60 \
      --execute --jobs 2 --minima --out results/runs --name main "$@" ;;
  test)
    # two test processes (pytest-xdist; PLANNERLAB_TEST_JOBS=0: in this process alone),
    # each taking the next test when it is free (worksteal: a few tests take a minute);
    # on a fresh clone they share numba's cache, so a kernel one compiles the other loads
    # (the 15 slowest tests are listed at the end: the suite aims at 10 minutes)
    exec "$VENV/bin/python" -m pytest -q -n "${PLANNERLAB_TEST_JOBS:-2}" --dist worksteal --durations=15 "$@" ;;
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

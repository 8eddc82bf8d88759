"""The state test in vector lanes (``collision/lanes.py``) against the one-state test
(``chain_valid._state_ok``), in one run: µs of CPU time per state on the MotionBenchMaker
Panda (``problems/urdf/panda/bookshelf_small_0001.toml``) and the 23-joint Arm-Z in the
paper's room (``armz_inspection``), each with its problem's margin.

    PYTHONPATH=. .venv/bin/python bench/lanes_bench.py [--states 20000] [--repeats 5]

Rows (the least of ``--repeats`` repetitions, the roads interleaved):

* ``one state, uniform``: a compiled loop calling the one-state test per state;
* ``lanes, uniform``: the same states, ``lanes.W`` at a time, every lane's verdict;
* ``one state, edges`` / ``lanes, edges``: states along short random edges (``W``
  neighbours 0.1 rad apart in all, as an edge's grid gives them), the lanes stopping at
  the first lane that collides (an edge's test);
* ``lanes, edges, k filled``: groups holding only k states (an edge's coarse states are
  few): the cost per group against k one-state tests, which sets ``lanes.LANES_MIN``.

Every lane's verdict is checked against the one-state test's before timing.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.chain_valid import _state_ok
from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.lanes import W, lanes_check, lanes_views, valid_states_lanes
from plannerlab.collision.model_old import views
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import parse_problem

PANDA = "problems/urdf/panda/bookshelf_small_0001.toml"


@njit(cache=True, nogil=True)
def _one_by_one(Q, m, out):
    V, S = views(m)
    for s in range(Q.shape[0]):
        out[s] = _state_ok(Q[s], V, S)
    return out


@njit(cache=True, nogil=True)
def _edges(Q, m, k_filled):
    """Groups of W consecutive rows, the first ``k_filled`` lanes alive, stopping at the
    first collision: the number of groups all valid."""
    V, SL = lanes_views(m)
    dof = Q.shape[1]
    QL = np.empty((dof, W))
    alive = np.empty(W, dtype=np.bool_)
    n = 0
    for s0 in range(0, Q.shape[0] - W + 1, W):
        for k in range(W):
            for i in range(dof):
                QL[i, k] = Q[s0 + k, i]
            alive[k] = k < k_filled
        n += lanes_check(QL, V, SL, alive, True)
    return n


def _timed(fn: Callable[[], Any]) -> float:
    t = time.process_time()
    fn()
    return time.process_time() - t


def _bench(name: str, problem: Any, n: int, repeats: int) -> None:
    robot = problem.robot
    m = problem_checker(problem).model
    rng = np.random.default_rng(0)
    Q = rng.uniform(robot.lower, robot.upper, (n, robot.dof))
    starts = rng.uniform(robot.lower, robot.upper, (n // W, robot.dof))
    dirs = rng.normal(size=(n // W, robot.dof))
    dirs *= 0.1 / np.linalg.norm(dirs, axis=1, keepdims=True)
    E = (starts[:, None, :] + (np.arange(W) / W)[None, :, None] * dirs[:, None, :]).reshape(
        -1, robot.dof
    )
    E = np.ascontiguousarray(np.clip(E, robot.lower, robot.upper))
    out = np.empty(n, dtype=np.bool_)
    one = _one_by_one(Q, m, out).copy()
    assert np.array_equal(valid_states_lanes(Q, m, out), one), "lanes and one-state differ"
    e_one = _one_by_one(E, m, np.empty(len(E), dtype=np.bool_))
    assert _edges(E, m, W) == int(e_one.reshape(-1, W).all(axis=1).sum())
    roads: dict[str, tuple[Callable[[], Any], int]] = {
        "one state, uniform": (lambda: _one_by_one(Q, m, out), n),
        "lanes, uniform": (lambda: valid_states_lanes(Q, m, out), n),
        "one state, edges": (lambda: _one_by_one(E, m, np.empty(len(E), dtype=np.bool_)), len(E)),
        f"lanes, edges ({W} filled)": (lambda: _edges(E, m, W), len(E)),
    }
    for k in (1, 2, 4, 6):
        roads[f"lanes, edges, {k} filled (per state)"] = (
            (lambda k=k: _edges(E, m, k)),
            len(E) // W * k,
        )
    times: dict[str, list[float]] = {k: [] for k in roads}
    for _ in range(repeats):
        for key, (fn, _cnt) in roads.items():
            times[key].append(_timed(fn))
    print(
        f"\n{name}: {robot.dof} joints; {n} uniform states ({one.mean():.3f} valid), "
        f"{len(E)} edge states ({e_one.mean():.3f} valid); lanes W = {W}"
    )
    base = min(times["one state, uniform"]) / n
    print(f"  {'road':42s} {'us/state':>9s} {'one-state/road':>15s}")
    for key, (_, cnt) in roads.items():
        t = min(times[key]) / cnt
        ref = base if "uniform" in key else min(times["one state, edges"]) / len(E)
        print(f"  {key:42s} {t * 1e6:9.3f} {ref / t:15.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()}")
    _bench("Panda, MotionBenchMaker bookshelf_small_0001", parse_problem(PANDA), args.states,
           args.repeats)  # fmt: skip
    _bench("Arm-Z, armz_inspection", load_problem("armz_inspection"), args.states, args.repeats)
    print(f"\nload average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()

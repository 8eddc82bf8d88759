"""The state test (issue 32): ns of CPU time per state, in one run, against baselines
measured in the same run, with the machine's load.

    PYTHONPATH=. .venv/bin/python bench/state_test_bench.py [--states 200000] [--repeats 5]

Problems: the MotionBenchMaker Panda (``problems/urdf/panda/bookshelf_small_0001.toml``,
its spheres and margin), the 23-joint Arm-Z in the paper's room (``armz_inspection``) and
the IRb-6 (``irb6_case1``). States uniform in the joint box (seeded).

Rows per problem (the least CPU time of ``--repeats`` repetitions, the roads interleaved):

* ``lanes, batch``: the state test as every batch query runs it (``queries.states``:
  eight states a call in float32 lanes, hits and close calls confirmed in float64);
* ``lanes, one state a call``: the same test on one state at a time from compiled code
  (``state_test.valid_one``: lane 0 only, as a planner's sample is tested);
* ``one-state road (compiled)``: the same states one at a time by the one-state road
  (``one_state.valid_each``: one state's capsules eight to a vector; what the native
  planners' shim and ``pl.checker(problem).valid(q)`` run);
* ``float64 alone``: the float64 test of every state with no filter
  (``state_test.exact_batch``: what the lanes save);
* ``from Python, one state``: ``CollisionChecker.is_valid(q)`` per state (the batch road
  on one state, the call's overhead included; on ``--python-states`` states);
* ``public valid(q)``: ``pl.checker(problem).valid(q)`` per state (the one-state road and
  the public call's checks of its input; on ``--python-states`` states);
* ``python-fcl``: the FCL reference, ``CollisionChecker(backend="fcl").valid_batch`` (on
  ``--fcl-states`` states), the baseline of the ratios.

Every road's verdicts are compared with the float64 verdicts before timing (a mismatch
stops the bench). Edges: on short random edges from free states (``--edges``) the state
tests the certified edges make (``edge_check``, the re-check's grid proved by stretches)
against the grid's states, both giving the same verdicts.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.edges import edge_check
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.one_lanes import checker_tables
from plannerlab.collision.one_state import valid_each
from plannerlab.collision.public import Checker
from plannerlab.collision.queries import EACH, open_packed, states
from plannerlab.collision.state_test import exact_batch, set_plain, valid_one
from plannerlab.problem.catalog import load_problem

PROBLEMS = ("problems/urdf/panda/bookshelf_small_0001.toml", "armz_inspection", "irb6_case1")


@njit(cache=True, nogil=True)
def _one_by_one(P, Q, out):
    m, Z = open_packed(P)
    set_plain(Z)
    for s in range(Q.shape[0]):
        out[s] = valid_one(m, Z, Q[s])
    return out


@njit(cache=True, nogil=True)
def _edges(P, A, B, joint_step, out):
    """Certified edges A[i] -> B[i]: out[i] = (status, tests, grid states)."""
    m, Z = open_packed(P)
    for i in range(A.shape[0]):
        status, tests, n = edge_check(m, Z, A[i], B[i], joint_step, 1 << 40)
        out[i, 0], out[i, 1], out[i, 2] = status, tests, n
    return out


def _cpu(fn: Callable[[], Any]) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def bench_problem(name: str, n: int, repeats: int, n_py: int, n_fcl: int, n_edges: int) -> None:
    problem = load_problem(name)
    checker = problem_checker(problem)
    robot = problem.robot
    P = checker.packed_model
    rng = np.random.default_rng(0)
    Q = rng.uniform(robot.lower, robot.upper, (n, robot.dof))
    truth = exact_batch(checker.model, Q, np.empty(n, dtype=np.bool_))
    out = np.empty(n, dtype=np.bool_)
    # verdicts first (and every kernel compiled or loaded before timing)
    states(P, Q, out, EACH)
    assert np.array_equal(out, truth), "lanes, batch: verdicts differ from float64's"
    _one_by_one(P, Q, out)
    assert np.array_equal(out, truth), "lanes, one state: verdicts differ from float64's"
    T = checker_tables(checker)
    valid_each(P, T, Q, out)
    assert np.array_equal(out, truth), "one-state road: verdicts differ from float64's"
    public = Checker(problem, checker)
    assert [public.valid(q) for q in Q[:n_py]] == truth[:n_py].tolist()
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=problem.safety_margin_m)
    fcl_v = fcl.valid_batch(Q[:n_fcl])
    mismatch = int(np.count_nonzero(fcl_v != truth[:n_fcl]))
    py = np.array([checker.is_valid(q) for q in Q[:n_py]])
    assert np.array_equal(py, truth[:n_py])

    roads: dict[str, tuple[Callable[[], Any], int]] = {
        "lanes, batch": (lambda: states(P, Q, out, EACH), n),
        "lanes, one state a call": (lambda: _one_by_one(P, Q, out), n),
        "one-state road (compiled)": (lambda: valid_each(P, T, Q, out), n),
        "float64 alone": (lambda: exact_batch(checker.model, Q, out), n),
        "from Python, one state": (lambda: [checker.is_valid(q) for q in Q[:n_py]], n_py),
        "public valid(q)": (lambda: [public.valid(q) for q in Q[:n_py]], n_py),
        "python-fcl": (lambda: fcl.valid_batch(Q[:n_fcl]), n_fcl),
    }
    best = {k: np.inf for k in roads}
    for _ in range(repeats):
        for k, (fn, _count) in roads.items():
            best[k] = min(best[k], _cpu(fn))
    ns = {k: best[k] / roads[k][1] * 1e9 for k in roads}
    print(
        f"\n## {problem.name} ({robot.dof} joints, margin {problem.safety_margin_m * 1e3:.0f} "
        f"mm): {truth.mean():.1%} of {n} uniform states free; FCL disagrees on {mismatch} "
        f"of {n_fcl} (the core's float64 verdicts are the reference here)"
    )
    print("\n| road | ns/state (CPU) | × faster than python-fcl |\n|---|---:|---:|")
    for k in roads:
        print(f"| {k} | {ns[k]:,.0f} | {ns['python-fcl'] / ns[k]:,.1f} |")
    # edges: short random motions from free states
    free = Q[truth][: n_edges * 2]
    A = free[:n_edges]
    B = np.clip(
        A + rng.normal(0.0, 0.3, A.shape), robot.lower, robot.upper
    )  # a planner's extension, about 0.3 rad a joint
    res = _edges(P, A, B, problem.joint_step / 4.0, np.empty((len(A), 3), dtype=np.int64))
    grid_free = np.array(
        [checker.check_path(np.array([a, b]), problem.joint_step / 4.0, mode="grid").valid
         for a, b in zip(A, B, strict=True)]
    )  # fmt: skip
    assert np.array_equal(res[:, 0] == 0, grid_free), "certified edges differ from the grid"
    fr = res[:, 0] == 0
    print(
        f"\nEdges (re-check grid, joint_step/4): {len(A)} random motions from free states, "
        f"{fr.sum()} free; on the free ones the certified check tested "
        f"{res[fr, 1].sum():,} states where the grid has {res[fr, 2].sum():,} "
        f"({res[fr, 2].sum() / max(1, res[fr, 1].sum()):.1f}× fewer); the same verdicts"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=200_000)
    ap.add_argument("--python-states", type=int, default=20_000)
    ap.add_argument("--fcl-states", type=int, default=5_000)
    ap.add_argument("--edges", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--problems", default=",".join(PROBLEMS))
    a = ap.parse_args()
    load0 = os.getloadavg()
    print(
        f"# state test: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"load average {load0[0]:.2f} at the start"
    )
    for name in a.problems.split(","):
        bench_problem(name, a.states, a.repeats, a.python_states, a.fcl_states, a.edges)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()

"""The compiled robot–scene model (``collision/model.py``) against the road the collision
core takes today and against FCL, in one run: µs per state on the MotionBenchMaker Panda
(``problems/urdf/panda/bookshelf_small_0001.toml``) and the 23-joint Arm-Z in the paper's
room (``armz_inspection``), each with its problem's margin.

    PYTHONPATH=. .venv/bin/python bench/model_bench.py [--states 4000] [--repeats 7]

Rows (µs of CPU time per state, the least of ``--repeats`` repetitions and the median beside it; the
roads interleaved in each repetition so that other load counts alike):

* ``model, batched``: ``valid_states(Q, m, out)``, one compiled call for the batch;
* ``model, one state in compiled code``: a compiled loop calling ``state_ok(q, V, S)``
  once per state (what a compiled planner pays per sample, its views made once);
* ``model, one state from Python``: ``chain_state_valid(q, P, M, idat)``, a Python call;
* ``core road, batched`` / ``one state``: ``CollisionChecker.valid_batch`` /
  ``is_valid`` (the checker every planner uses: Arm-Z on its own compiled kinematics,
  URDF chains on the fused chain check);
* ``numpy kinematics + core kernels``: the robot's own ``link_segments`` and the core's
  generic kernels, the road IRb-6 and the continuum chain took before they gave their
  chain (``--all`` adds them);
* ``FCL, batched`` / ``one state``: the independent reference (fewer states: it is slow).

The ratio column is the model's batched figure over each row's. ``--ik`` adds the compiled
IK's cost per valid goal state on the Panda's tip goals against the numeric IK's.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.chain_valid import chain_state_valid
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.kernels import valid_batch
from plannerlab.collision.model_old import state_ok, valid_states, views
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import parse_problem

PANDA = "problems/urdf/panda/bookshelf_small_0001.toml"


@njit(cache=True, nogil=True)
def _one_by_one(Q, m):
    """Each state through ``state_ok`` on its own (a compiled planner's sample check)."""
    V, S = views(m)
    n = 0
    for s in range(Q.shape[0]):
        n += state_ok(Q[s], V, S)
    return n


def _timed(fn: Callable[[], Any], n_states: int) -> float:
    """µs of this process's CPU time per state (wall time on a shared machine counts the
    other jobs: the CPU time does not, though they still share the caches)."""
    t = time.process_time()
    fn()
    return (time.process_time() - t) / n_states * 1e6


def _bench(name: str, problem: Any, n_states: int, repeats: int) -> None:
    robot = problem.robot
    margin = float(problem.safety_margin_m)
    checker = problem_checker(problem)
    m = checker.model
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=margin)
    rng = np.random.default_rng(0)
    Q = rng.uniform(robot.lower, robot.upper, (n_states, robot.dof))
    out = np.empty(n_states, dtype=np.bool_)
    Qf = Q[: max(n_states // 10, 50)]
    valid_states(Q[:2], m, out[:2])  # compile / load once
    _one_by_one(Q[:2], m)
    v_model = valid_states(Q, m, out).copy()
    v_fcl = fcl.valid_batch(Qf)
    assert np.array_equal(v_model, checker.valid_batch(Q)), "model and core differ"
    differ = int(np.sum(v_model[: len(Qf)] != v_fcl))
    args = (m.P, m.M, m.idat)
    geo = checker._core._geo  # the core's arrays for its generic kernels
    roads: dict[str, tuple[Callable[[], Any], int]] = {
        "model, batched": (lambda: valid_states(Q, m, out), n_states),
        "model, one state in compiled code": (lambda: _one_by_one(Q, m), n_states),
        "model, one state from Python": (
            lambda: [chain_state_valid(q, *args) for q in Q],
            n_states,
        ),
        "core road, batched": (lambda: checker.valid_batch(Q), n_states),
        "numpy kinematics + core kernels, batched": (
            lambda: valid_batch(
                np.ascontiguousarray(robot.link_segments(Q)), *geo, np.empty(n_states, bool)
            ),
            n_states,
        ),
        "core road, one state": (lambda: [checker.is_valid(q) for q in Q], n_states),
        "FCL, batched": (lambda: fcl.valid_batch(Qf), len(Qf)),
        "FCL, one state": (lambda: [fcl.is_valid(q) for q in Qf], len(Qf)),
    }
    times: dict[str, list[float]] = {k: [] for k in roads}
    for _ in range(repeats):
        for k, (fn, n) in roads.items():
            times[k].append(_timed(fn, n))
    print(
        f"\n{name}: {robot.dof} joints, {len(robot.link_radii_m)} capsules, "
        f"{len(problem.scene.obstacles)} obstacles, margin {margin} m; {n_states} uniform "
        f"states, {v_model.mean():.3f} valid; {differ} of {len(Qf)} verdicts differ from FCL"
    )
    base = min(times["model, batched"])
    print(f"  {'road':42s} {'min us':>9s} {'median':>9s} {'model/road':>11s}")
    for k, t in times.items():
        print(f"  {k:42s} {min(t):9.3f} {float(np.median(t)):9.3f} {base / min(t):11.3f}")


def _bench_ik(repeats: int) -> None:
    from plannerlab.collision.chain_ik import descent_for_robot
    from plannerlab.problem.goals import GoalRegion
    from plannerlab.problem.ik import sample_goal_state

    problem = parse_problem(PANDA)
    checker = problem_checker(problem)
    robot = problem.robot
    # the tip pose of the problem's goal state, as a position + normal goal
    p, n = robot.tip(problem.goal(0).q_rad)
    goal = GoalRegion("tip", p, n, 0.01, 10.0)
    print(f"\nPanda goal states for {goal.name} ({goal.pos_tol_m} m, {goal.angle_tol_deg} deg)")
    sample_goal_state(  # compile
        robot, goal, checker, np.random.default_rng(0), attempts=1, descent=descent_for_robot(robot)
    )
    for compiled in (True, False):
        times = []
        got = 0
        for seed in range(repeats):
            rng = np.random.default_rng(seed)
            t = time.process_time()
            q = sample_goal_state(
                robot,
                goal,
                checker,
                rng,
                seeds=[problem.q_start],
                descent=descent_for_robot(robot) if compiled else None,
            )
            times.append((time.process_time() - t) * 1e3)
            got += q is not None
        road = "compiled descent" if compiled else "numpy descent"
        print(
            f"  IK, {road:17s} median {np.median(times):8.2f} ms, max {max(times):8.2f} ms "
            f"per call (CPU; {got} of {repeats} calls found a valid goal state)"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=4000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--ik", action="store_true", help="also the Panda's goal-state IK")
    ap.add_argument("--all", action="store_true", help="also irb6_case1, continuum_case1")
    a = ap.parse_args()
    print(f"load average at start: {os.getloadavg()}")
    panda = parse_problem(PANDA)
    _bench("Panda, MotionBenchMaker bookshelf_small_0001", panda, a.states, a.repeats)
    _bench("Arm-Z, armz_inspection", load_problem("armz_inspection"), a.states, a.repeats)
    if a.all:
        for name in ("irb6_case1", "continuum_case1"):
            _bench(name, load_problem(name), a.states, a.repeats)
    if a.ik:
        _bench_ik(20)
    print(f"\nload average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()

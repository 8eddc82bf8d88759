"""The path's quality a comparison reports: the smallest clearance along the whole path is
the minimum over every state of the final re-check's grid (python-fcl's distances on the
true geometry are the reference), in pieces or in one call, and a solved leg carries it
with its roughness and its goal's tolerances."""

from __future__ import annotations

import numpy as np
import pytest

import plannerlab.run.pipeline as pipeline
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.problem.catalog import load_problem
from plannerlab.robots.paths import roughness


def _path(problem, offsets: list[float]) -> np.ndarray:
    """The start, then states a few hundredths of a radian away (inside the limits)."""
    q0 = np.asarray(problem.q_start, dtype=float)
    rows = [q0]
    for k, off in enumerate(offsets):
        q = q0.copy()
        q[k % len(q0)] += off
        rows.append(np.clip(q, problem.robot.lower, problem.robot.upper))
    return np.array(rows)


@pytest.mark.parametrize("name", ["armz_pocket", "irb6_pick_table"])
def test_the_clearance_along_the_path_is_the_minimum_over_the_re_check_grid(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    problem = load_problem(name)
    checker = problem_checker(problem)
    path = _path(problem, [0.04, -0.03, 0.05])
    step = problem.joint_step / 4.0
    states, _ = checker.densify(path, step)
    assert 20 < len(states) < 2000
    reference = CollisionChecker(problem.robot, problem.scene, backend="fcl")
    expected = min(reference.clearance(q) for q in states)
    checks = checker.checks
    got = pipeline.path_clearance_m(checker, path, step)
    assert checker.checks == checks  # a measurement, not planning: no checks counted
    assert got == pytest.approx(expected, abs=1e-6)
    # the grid's states between the waypoints count: never above the waypoints' minimum
    assert got <= min(reference.clearance(q) for q in path) + 1e-9
    # a long path is measured in pieces of whole edges: the same minimum
    monkeypatch.setattr(pipeline, "CLEARANCE_CHUNK", 7)
    assert pipeline.path_clearance_m(checker, path, step) == got


def test_a_solved_leg_carries_its_path_quality_and_tolerances() -> None:
    problem = load_problem("irb6_pick_table")
    budget = problem.budget.replace(max_collision_checks=200_000)
    plan = pipeline.solve_legs(problem, "ompl.rrtconnect", 0, legs=[0], budget=budget)
    (leg,) = plan.legs
    assert leg.solved, leg.reason
    goal = problem.goal(0)
    assert (leg.pos_tol_m, leg.angle_tol_deg) == (goal.pos_tol_m, goal.angle_tol_deg)
    assert leg.roughness_rad2 == roughness(leg.path, problem.robot.continuous)
    checker = problem_checker(problem)
    assert leg.path_clearance_m == pipeline.path_clearance_m(
        checker, leg.path, problem.joint_step / 4.0
    )
    assert 0.0 < leg.path_clearance_m

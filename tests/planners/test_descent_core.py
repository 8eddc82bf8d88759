"""The compiled clearance descent (``backend = "compiled"``) against the numpy one: the
same field, step and hold at single states, and the same path on fixed problems."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from plannerlab.errors import PlannerlabError
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.goals import JointGoal
from plannerlab.problem.load import Budget, parse_problem
from plannerlab.robots.base import joint_difference


def _models(problem, **overrides):
    numpy_model = make_planner("gradient.clearance", {"backend": "numpy", **overrides}).model(
        problem
    )
    compiled = make_planner("gradient.clearance", {"backend": "compiled", **overrides}).model(
        problem
    )
    assert type(numpy_model).__name__ == "NumpyModel"
    assert type(compiled).__name__ == "CompiledStep"
    return numpy_model, compiled


@pytest.mark.parametrize("direction", ["gauss_newton", "gradient"])
def test_compiled_field_step_and_hold_equal_numpy_at_states_near_walls(direction):
    """States drawn round the start of the pocket (walls and self pairs close): F, f, the
    tip errors, the clearance cost and gradient, every distance below the margin, the step
    and the hold's projection agree to rounding. The clearance floor is raised to 0.1 m
    (the hold acts on pairs closer than 0.11 m) so that the hold has pairs to hold."""
    problem = load_problem("armz_pocket")
    numpy_model, compiled = _models(problem, direction=direction, clearance_floor_m=0.1)
    goal = problem.goal(0)
    rng = np.random.default_rng(7)
    margin = 0.3
    held = 0
    for _ in range(25):
        q = problem.q_start + rng.normal(0.0, 0.5, problem.robot.dof)
        a, b = numpy_model.point(goal, q), compiled.point(goal, q)
        for name in ("F", "f", "pos_err_m", "ang_err_deg", "cost"):
            assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-10, abs=1e-12)
        np.testing.assert_allclose(b.gradient, a.gradient, rtol=1e-9, atol=1e-10)
        near = a.distances_m < margin
        np.testing.assert_allclose(b.distances_m[near], a.distances_m[near], atol=1e-12)
        assert np.all(b.distances_m[~near] >= margin)
        np.testing.assert_allclose(b.direction, a.direction, rtol=1e-8, atol=1e-10)
        # the hold projects a step that closes the nearest pairs (up the clearance cost)
        step = a.gradient if a.cost > 0 else a.direction
        h_a, h_b = numpy_model.hold(goal, q, step), compiled.hold(goal, q, step)
        held += int(not np.allclose(h_a, step))
        # the hold solves G A⁻¹ Gᵀ λ = … regularised by only 1e-9 (sphere rows of one link
        # pair are nearly dependent): rounding grows by up to ~1e7 there
        np.testing.assert_allclose(h_b, h_a, rtol=1e-5, atol=1e-6 * np.abs(h_a).max())
    assert held > 0  # some states were within the clearance floor: the hold was exercised


@pytest.mark.parametrize(
    ("problem_name", "leg", "status"),
    [
        ("armz_inspection", 0, Status.SOLVED),  # approach, descent, settle
        ("armz_inspection", 3, Status.LOCAL_MINIMUM),  # holds along walls, then a stall
    ],
)
def test_compiled_descent_takes_the_numpy_descents_path(problem_name, leg, status):
    """Same iterates: the whole path of a leg to 1e-9 rad, on an iteration budget."""
    problem = load_problem(problem_name)
    budget = Budget(max_iterations=1000)
    paths = {}
    for backend in ("numpy", "compiled"):
        planner = make_planner("gradient.clearance", {"backend": backend})
        r = planner.solve(problem, leg, budget, np.random.default_rng(0))
        assert r.status is status
        paths[backend] = (r.path, r.iterations, r.collision_checks)
    (p_np, it_np, c_np), (p_c, it_c, c_c) = paths["numpy"], paths["compiled"]
    assert (it_c, c_c) == (it_np, c_np)
    assert p_c.shape == p_np.shape and len(p_c) > 100
    np.testing.assert_allclose(p_c, p_np, rtol=0.0, atol=1e-9)


def _joint_goal_variant():
    """``armz_inspection_v00`` with its witness states as goal states (0.01 rad)."""
    from conftest import ROOT

    problem = parse_problem(ROOT / "problems" / "variants" / "armz_inspection_v00.toml")
    W = np.array(problem.extras["witness"]["goal_states_rad"], dtype=float)
    goals = tuple(
        JointGoal.at(problem.robot, g.name, w, 0.01) for g, w in zip(problem.goals, W, strict=True)
    )
    return dataclasses.replace(problem, goals=goals), W


@pytest.mark.parametrize("direction", ["gauss_newton", "gradient"])
def test_compiled_step_towards_a_goal_state_equals_numpy(direction):
    """A goal state: f = r1 |q − q_goal|, F = |(q − q_goal) / tol|² + w · cost, the
    joint error and the step (joint residual plus clearance) agree to rounding, at states
    drawn round the window where walls are close. Gauss-Newton heads almost straight for
    the goal state (not for its tip pose); steepest descent is −∇F."""
    problem, W = _joint_goal_variant()
    numpy_model, compiled = _models(problem, direction=direction)
    goal = problem.goal(1)
    rng = np.random.default_rng(3)
    close = 0
    for _ in range(25):
        q = W[0] + rng.normal(0.0, 0.05, problem.robot.dof)
        a, b = numpy_model.point(goal, q), compiled.point(goal, q)
        dq = joint_difference(q, goal.q_rad, goal.continuous)
        assert a.f == pytest.approx(float(np.linalg.norm(dq)), rel=1e-12)
        # accepted on the sum of squares the Gauss-Newton step models
        e_sq = float(np.sum((dq / goal.tol_rad) ** 2))
        assert a.F == pytest.approx(e_sq + 0.2 * a.cost, rel=1e-12)
        for name in ("F", "f", "joint_err", "cost"):
            assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-10, abs=1e-12)
        assert b.joint_err == pytest.approx(float(np.max(np.abs(dq))), rel=1e-12)
        np.testing.assert_allclose(b.direction, a.direction, rtol=1e-8, atol=1e-10)
        if direction == "gauss_newton":
            # the joint residual (in tolerances) outweighs the clearance: nearly straight
            cos = float(-dq @ a.direction) / (np.linalg.norm(dq) * np.linalg.norm(a.direction))
            assert cos > 0.9
        else:  # −∇F: a short step along it lowers F
            step = 1e-6 * a.direction / np.linalg.norm(a.direction)
            assert numpy_model.point(goal, q + step).F < a.F
        close += int(a.cost > 0)
    assert close == 25  # the clearance term was in every step


@pytest.mark.parametrize(
    ("planner", "leg", "status"),
    [
        ("gradient.clearance", 0, Status.LOCAL_MINIMUM),  # through the window, stalls
        ("gradient.clearance+detour", 4, Status.SOLVED),  # stalls, retracts, solves
    ],
)
def test_compiled_descent_to_a_goal_state_takes_the_numpy_path(planner, leg, status):
    """Same iterates towards a goal state: the whole path to 1e-9 rad."""
    problem, W = _joint_goal_variant()
    q0 = problem.q_start if leg == 0 else W[leg - 1]
    paths = {}
    for backend in ("numpy", "compiled"):
        r = make_planner(planner, {"backend": backend}).solve(
            problem, leg, Budget(max_iterations=3000), np.random.default_rng(0), q_start=q0
        )
        assert r.status is status, r.reason
        paths[backend] = (r.path, r.iterations, r.collision_checks)
    (p_np, it_np, c_np), (p_c, it_c, c_c) = paths["numpy"], paths["compiled"]
    assert (it_c, c_c) == (it_np, c_np)
    assert p_c.shape == p_np.shape and len(p_c) > 100
    np.testing.assert_allclose(p_c, p_np, rtol=0.0, atol=1e-9)


def test_backend_setting_is_checked():
    with pytest.raises(PlannerlabError, match="backend setting"):
        make_planner("gradient.clearance", {"backend": "cuda"})


def test_robots_other_than_armz_descend_in_numpy_and_say_so():
    problem = load_problem("irb6_case1")
    r = make_planner("gradient.clearance").solve(
        problem, 0, Budget(max_iterations=5), np.random.default_rng(0)
    )
    assert r.extra["descent_backend"] == "numpy"
    arm = load_problem("armz_pocket")
    r = make_planner("gradient.clearance").solve(
        arm, 0, Budget(max_iterations=5), np.random.default_rng(0)
    )
    assert r.extra["descent_backend"] == "compiled"

"""The paper's gradient method: objective, stall detection, fixed-seed regressions."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import assert_golden_path, colliding_state, path_fingerprint, small_armz_problem

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError, UnknownNameError
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.planners.objective import Objective
from plannerlab.problem.catalog import load_problem


def test_objective_is_the_papers_formula(small_problem):
    p = small_problem
    f = Objective(p.robot, p.goal(0), CollisionChecker(p.robot, p.scene))
    q = p.q_start
    tip, n = p.robot.tip(q)
    expected = np.linalg.norm(tip - p.goal(0).p_world_m) + (1 - n @ p.goal(0).n_world) ** 2
    assert f(q) == pytest.approx(expected)
    assert f(colliding_state(p)) > 1e4  # A(S) ~ five orders above f


def test_analytic_gradient_matches_approx_fprime(small_problem):
    from scipy.optimize import approx_fprime

    p = small_problem
    f = Objective(p.robot, p.goal(0))
    for q in np.random.default_rng(4).uniform(-np.pi, np.pi, (5, p.robot.dof)):
        np.testing.assert_allclose(f.smooth_gradient(q), approx_fprime(q, f, 1e-7), atol=1e-5)


def test_gradient_solves_a_free_problem_and_stays_in_budget(small_problem):
    r = make_planner("gradient").solve(
        small_problem, 0, small_problem.budget, np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED
    assert small_problem.goal(0).contains(small_problem.robot, r.path[-1])
    assert r.pos_err_m <= 0.1 and 5 < r.iterations <= 500
    np.testing.assert_array_equal(r.path[0], small_problem.q_start)
    assert len(r.trace) == r.iterations + 1 and r.trace[-1] < r.trace[0]
    cut = make_planner("gradient").solve(
        small_problem, 0, small_problem.budget.replace(max_iterations=3), np.random.default_rng(0)
    )
    assert cut.status is Status.BUDGET_EXHAUSTED and cut.iterations == 3


def test_unknown_setting_and_bad_value_are_refused():
    with pytest.raises(UnknownNameError, match="did you mean 'gamma'"):
        make_planner("gradient", {"gama": "0.1"})
    with pytest.raises(PlannerlabError, match="finite_difference"):
        make_planner("gradient", {"gradient": "magic"})


def test_settings_are_frozen_and_not_changed_by_solve(small_problem):
    planner = make_planner("gradient.analytic", {"gamma": "0.04"})
    before = dataclasses.asdict(planner.settings)
    planner.solve(small_problem, 0, small_problem.budget, np.random.default_rng(0))
    assert dataclasses.asdict(planner.settings) == before and planner.settings.gamma == 0.04
    with pytest.raises(dataclasses.FrozenInstanceError):
        planner.settings.gamma = 1.0


def test_closed_loop_mode_refuses_to_run_without_a_simulator(small_problem):
    with pytest.raises(PlannerlabError, match="stepper"):
        make_planner("gradient.closed_loop").solve(
            small_problem, 0, small_problem.budget, np.random.default_rng(0)
        )


def test_start_in_collision_is_reported_not_raised():
    p = small_armz_problem()
    q = colliding_state(p)
    r = make_planner("gradient").solve(p, 0, p.budget, np.random.default_rng(0), q_start=q)
    assert r.status is Status.INVALID_START and "wall" in r.reason


# ---------------------------------------------------------------- fixed-seed regressions
def test_pocket_stalls_at_the_pinned_iteration_and_path():
    """Golden values (seed 0; the method ignores its generator): the stall iteration and a
    digest of the path. A change here is a change of the paper's method."""
    problem = load_problem("armz_pocket")
    a = make_planner("gradient").solve(problem, 0, problem.budget, np.random.default_rng(0))
    assert a.status is Status.LOCAL_MINIMUM
    assert (a.iterations, a.extra["stall_iteration"], len(a.path)) == (61, 61, 62)
    assert_golden_path("gradient/armz_pocket", path_fingerprint(a.path))
    assert a.local_minima == 1
    # the stall is real: far from the goal, and f flat over the stall window
    assert a.pos_err_m > 1.0
    window = a.settings["stall_window"]
    assert a.trace[-window:].min() > a.trace.min() - a.settings["stall_min_decrease"]
    # and it is not the goal's fault: the witness path reaches the goal collision-free
    checker = CollisionChecker(problem.robot, problem.scene)
    witness = np.array(problem.extras["witness"]["path_rad"])
    assert checker.check_path(witness, problem.joint_step / 4).valid
    assert problem.goal(0).contains(problem.robot, witness[-1])


def test_analytic_variant_follows_the_faithful_one_on_the_pocket():
    problem = load_problem("armz_pocket")
    fd = make_planner("gradient").solve(problem, 0, problem.budget, np.random.default_rng(0))
    an = make_planner("gradient.analytic").solve(
        problem, 0, problem.budget, np.random.default_rng(0)
    )
    assert fd.iterations == an.iterations
    np.testing.assert_allclose(fd.path[-1], an.path[-1], atol=1e-4)
    assert an.collision_checks < fd.collision_checks  # no dof+1 checks per gradient


def test_inspection_leg_stalls_at_the_pinned_iteration_and_path():
    """Golden values on the paper's entry leg (150-iteration budget, seed 0)."""
    problem = load_problem("armz_inspection")
    budget = problem.budget.replace(max_iterations=150)
    r = make_planner("gradient").solve(problem, 0, budget, np.random.default_rng(0))
    assert (r.status, r.iterations, len(r.path)) == (Status.LOCAL_MINIMUM, 73, 74)
    assert_golden_path("gradient/armz_inspection/enter", path_fingerprint(r.path))


def test_descent_keeps_bounded_joints_inside_their_limits():
    problem = load_problem("irb6_pick_table")
    r = make_planner("gradient.analytic").solve(
        problem, 0, problem.budget.replace(max_iterations=300), np.random.default_rng(0)
    )
    robot = problem.robot
    bounded = ~robot.continuous
    assert len(r.path) > 5
    assert np.all(r.path[:, bounded] >= robot.lower[bounded] - 1e-12)
    assert np.all(r.path[:, bounded] <= robot.upper[bounded] + 1e-12)

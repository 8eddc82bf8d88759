"""The gradient method with a clearance term (``gradient.clearance*``): its field and
gradient, and the paper's whole experiment done on fixed seeds with check budgets."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.planners.clearance import ClearanceField
from plannerlab.problem.catalog import load_problem
from plannerlab.run.pipeline import leg_rng, solve_legs


def test_clearance_gradient_is_the_derivative_of_the_cost():
    problem = load_problem("armz_inspection")
    field = ClearanceField(problem.robot, problem.scene, influence_m=1.0)
    rng = np.random.default_rng(3)
    q = problem.q_start + rng.normal(0.0, 0.4, problem.robot.dof)
    c = field(q)
    assert c.close_pairs > 0
    h = 1e-6
    fd = np.array(
        [
            (field(q + h * e).cost - field(q - h * e).cost) / (2 * h)
            for e in np.eye(problem.robot.dof)
        ]
    )
    np.testing.assert_allclose(c.gradient, fd, atol=1e-6, rtol=1e-4)


def test_clearance_field_distance_matches_fcl_within_the_sphere_cover():
    problem = load_problem("armz_inspection")
    field = ClearanceField(problem.robot, problem.scene, influence_m=1.0)
    checker = CollisionChecker(problem.robot, problem.scene)
    rng = np.random.default_rng(4)
    for _ in range(5):
        q = problem.q_start + rng.normal(0.0, 0.5, problem.robot.dof)
        d_fcl = checker.clearance(q)
        d_field = field(q).min_distance_m
        # spheres under-cover the capsule by < 2 % of its radius: never below FCL's
        assert d_fcl - 1e-6 <= d_field <= d_fcl + 0.02 * 0.75


def test_bad_settings_are_refused():
    with pytest.raises(PlannerlabError, match="escape"):
        make_planner("gradient.clearance", {"escape": "teleport"})
    with pytest.raises(PlannerlabError, match="direction"):
        make_planner("gradient.clearance", {"direction": "sideways"})


@pytest.mark.parametrize("seed", [0, 1])
def test_the_papers_task_is_done_by_the_clearance_descent_with_detours(seed):
    """All seven legs (enter, A-E, leave) within 100 000 checks per leg, every path
    valid at a quarter of joint_step, and only the leave leg needs an escape, which
    starts at the stall."""
    problem = load_problem("armz_inspection")
    budget = problem.budget.replace(max_collision_checks=100_000, time_limit_s=None)
    plan = solve_legs(
        problem, "gradient.clearance+detour", seed, budget=budget, stop_on_failure=True
    )
    assert [r.goal for r in plan.legs] == ["enter", "A", "B", "C", "D", "E", "leave"]
    checker = CollisionChecker(problem.robot, problem.scene)
    for r in plan.legs:
        assert r.status is Status.SOLVED, f"{r.goal}: {r.reason}"
        assert r.collision_checks <= 100_000
        assert checker.check_path(r.path, problem.joint_step / 4).valid, r.goal
        for e in r.extra["escapes"]:
            assert e["start_from_stall_rad"] == 0.0
            assert e["start_from_leg_start_rad"] > 0.5
    assert sum(r.escapes for r in plan.legs) >= 1
    if seed == 0:
        # without the detour the same descent stalls on the leave leg, under the ceiling
        r = make_planner("gradient.clearance").solve(
            problem, 6, budget, np.random.default_rng(0), q_start=plan.legs[5].path[-1]
        )
        assert r.status is Status.LOCAL_MINIMUM
        assert r.extra["descent_rad"][0] > 0.5


def test_the_random_detour_draws_its_sub_goals_from_the_seed():
    """On armz_thin_wall the clearance descent stalls once. The random detour escapes on
    every seed tried, with sub-goals drawn from the leg's generator: the same seed gives
    the same path, another seed another path; the detour gives one path whatever the seed."""
    problem = load_problem("armz_thin_wall")
    budget = problem.budget.replace(max_collision_checks=20_000, time_limit_s=None)
    checker = CollisionChecker(problem.robot, problem.scene)

    def solve(name: str, seed: int):
        return make_planner(name).solve(problem, 0, budget, leg_rng(seed, 0))

    drawn = [solve("gradient.clearance+random_detour", s) for s in (0, 1, 0)]
    for r in drawn:
        assert r.status is Status.SOLVED, r.reason
        assert (r.local_minima, r.escapes) == (1, 1)
        assert r.extra["escapes"][0]["kind"] == "random_detour"
        assert checker.check_path(r.path, problem.joint_step / 4).valid
    assert np.array_equal(drawn[0].path, drawn[2].path)
    assert not np.array_equal(drawn[0].path, drawn[1].path)
    fixed = [solve("gradient.clearance+detour", s) for s in (0, 1)]
    assert fixed[0].solved and np.array_equal(fixed[0].path, fixed[1].path)


def test_random_retract_depths_step_forward_within_the_body():
    planner = make_planner("gradient.clearance+random_detour", {"retract_step": 2})
    assert planner._retract_depths(23, None) == list(range(2, 23, 2))
    seen = set()
    for seed in range(20):
        depths = planner._retract_depths(23, np.random.default_rng(seed))
        steps = np.diff([0, *depths])
        assert depths and depths[-1] < 23 and np.all((steps >= 1) & (steps <= 4))
        seen.add(tuple(depths))
    assert len(seen) > 1
    with pytest.raises(PlannerlabError, match="retract_jitter_m"):
        make_planner("gradient.clearance+random_detour", {"retract_jitter_m": -1.0})

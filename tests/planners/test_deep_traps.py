"""Deep traps (docs/traps.md, "Deep traps"): the paper's room, one leg from rest straight
to an inspection point. The faithful descent travels at least 2 rad before it stalls,
the straight joint-space line collides, a stored witness path shows a way exists, and
the planners that extend the method escape from the stall itself."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_witness_solves

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.robots.paths import interpolate_edge, path_length

DEEP = ("armz_deep_a", "armz_deep_b", "armz_deep_e")


@pytest.fixture(scope="module", params=DEEP)
def deep(request):
    return load_problem(request.param)


def test_witness_is_collision_free_from_the_start_into_the_goal(deep):
    assert_witness_solves(deep)


def test_the_straight_line_to_the_witness_end_collides(deep):
    witness = np.array(deep.extras["witness"]["path_rad"], dtype=float)
    line = interpolate_edge(deep.q_start, witness[-1], deep.joint_step / 4, deep.robot.continuous)
    assert CollisionChecker(deep.robot, deep.scene).first_invalid(line) is not None


def test_faithful_gradient_travels_two_radians_then_stalls(deep):
    r = make_planner("gradient").solve(deep, 0, deep.budget, np.random.default_rng(0))
    assert r.status is Status.LOCAL_MINIMUM, r.reason
    assert path_length(r.path, deep.robot.continuous) >= 2.0
    assert r.pos_err_m > 2 * deep.goal(0).pos_tol_m


def test_faithful_gradient_still_stalls_on_the_roof_entering_the_room():
    """The published baseline (results/armz_inspection.md): 73 iterations, 6.45 m."""
    problem = load_problem("armz_inspection")
    r = make_planner("gradient").solve(problem, 0, problem.budget, np.random.default_rng(0))
    assert r.status is Status.LOCAL_MINIMUM
    assert r.iterations == 73
    assert r.pos_err_m == pytest.approx(6.45, abs=0.01)


def test_detour_starts_its_escape_at_the_stall_on_deep_e():
    """The clearance descent goes 7 rad into the room before it stalls; the detour starts
    there (on this trap it does not find the way within the budget: results/comparison.md)."""
    problem = load_problem("armz_deep_e")
    budget = problem.budget.replace(max_collision_checks=3_000, time_limit_s=None)
    r = make_planner("gradient.clearance+detour").solve(
        problem, 0, budget, np.random.default_rng(0)
    )
    assert r.local_minima >= 1
    first = r.extra["escapes"][0]
    assert first["start_from_stall_rad"] == 0.0
    assert first["descent_before_stall_rad"] >= 2.0
    assert 1.0 < first["start_from_leg_start_rad"] <= first["descent_before_stall_rad"] + 1e-9


def test_gradient_rrtconnect_starts_its_escape_at_the_stall_not_the_start():
    problem = load_problem("armz_deep_e")
    budget = problem.budget.replace(max_collision_checks=3_000, time_limit_s=None)
    r = make_planner("gradient+rrtconnect", {"escape_checks": 1_000, "max_escapes": 1}).solve(
        problem, 0, budget, np.random.default_rng(0)
    )
    assert r.local_minima >= 1
    first = r.extra["escapes"][0]
    assert first["start_from_stall_rad"] == 0.0
    # the escape starts where the descent ended: as far from the start as the descent went
    assert 1.0 < first["start_from_leg_start_rad"] <= first["descent_before_stall_rad"] + 1e-9
    assert first["descent_before_stall_rad"] >= 2.0


@pytest.mark.parametrize("name", ["armz_deep_a", "armz_deep_b"])
def test_detour_enters_a_deep_trap_by_the_tips_route_when_no_retract_does(name):
    """Entering the room straight from rest, every retract's descent falls back in front
    of the roof; the detour's last resort, the tip's route through the window (followed
    as follow-the-leader does), gets in. Without it the same leg stalls."""
    problem = load_problem(name)
    budget = problem.budget.replace(
        max_collision_checks=60_000, time_limit_s=None, max_iterations=100_000_000
    )
    r = make_planner("gradient.clearance+detour").solve(
        problem, 0, budget, np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    first = r.extra["escapes"][0]
    assert first["how"].startswith("no retract led in") and "the tip's route" in first["how"]
    assert first["start_from_stall_rad"] == 0.0  # the route starts at the stall
    assert problem.goal(0).contains(problem.robot, r.path[-1])
    checker = CollisionChecker(problem.robot, problem.scene, margin_m=problem.safety_margin_m)
    assert checker.check_path(r.path, problem.joint_step).valid
    off = make_planner("gradient.clearance+detour", {"route_escape": False}).solve(
        problem, 0, budget, np.random.default_rng(0)
    )
    assert off.status is Status.LOCAL_MINIMUM

"""``native.rrtconnect+leader`` (planners/native/leader.py) and follow-the-leader's
reverse plan (planners/follow_leader/): golden values on fixed seeds with check budgets
(no clock), seeds that differ, and leaving a room from its far wall."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.errors import PlannerlabError
from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget
from plannerlab.record.leg import Status

CHECKS = Budget(max_iterations=None, max_collision_checks=200_000, time_limit_s=None)


def _solve(problem_name: str, seed: int):
    problem = load_problem(problem_name)
    planner = make_planner("native.rrtconnect+leader")
    return problem, planner.solve(problem, 0, CHECKS, np.random.default_rng(seed))


def test_golden_values_on_the_window_trap():
    """Seed 0, 200 000 checks: the forward leader reaches the goal (its 303 body states,
    thinned to 39, seed the start tree, and its end is the goal tree's root: the trees
    are joined before any sample), the path is shortcut and re-checked."""
    problem, r = _solve("armz_window", 0)
    assert r.status is Status.SOLVED, r.reason
    assert r.collision_checks == 52_683  # 92 100 before the certified edges (issue 32)
    assert r.iterations == 302
    assert r.extra["path_length_rad"] == pytest.approx(5.814842593, abs=1e-6)
    assert r.extra["leader"]["forward"]["status"] == "solved"
    assert r.extra["leader"]["forward"]["states"] == 39
    assert r.extra["nodes"] == [39, 1]
    checker = problem_checker(problem)
    assert checker.check_path(r.path, problem.joint_step / 4).valid
    assert bool(problem.goal(0).contains(problem.robot, r.path[-1]))


def test_same_seed_same_run_other_seed_other_run():
    _, a = _solve("armz_window", 0)
    _, b = _solve("armz_window", 0)
    _, c = _solve("armz_window", 1)
    assert a.collision_checks == b.collision_checks
    np.testing.assert_array_equal(a.path, b.path)
    assert c.status is Status.SOLVED
    assert c.collision_checks == 38_374  # 58 558 before the certified edges
    assert c.extra["path_length_rad"] == pytest.approx(2.682099129, abs=1e-6)


def test_bad_settings_are_refused_by_name():
    with pytest.raises(PlannerlabError, match="guide_stride"):
        make_planner("native.rrtconnect+leader", {"guide_stride": 0})
    with pytest.raises(PlannerlabError, match="guide_bias"):
        make_planner("native.rrtconnect+leader", {"guide_bias": 2.0})


def test_leaving_from_the_far_wall_retracts_along_the_body():
    """``armz_inspection_v21`` (far_rtl: the task ends at B in the far corner away from
    the window): leaving from B's witness, follow-the-leader's forward tracking stalls at
    sub-goal 2 (the leader's path leads the tip back through the window its own body
    fills); with the retract (the body slid back out along its own curve until the tip
    sees the goal's approach point, then the leader) it is solved within 3 000 iterations
    and 20 000 checks, and the path is valid at a quarter of joint_step."""
    problem = load_problem(PROBLEMS / "variants" / "armz_inspection_v21.toml")
    q_b = np.array(problem.extras["witness"]["goal_states_rad"][-2])
    leave = problem.legs - 1
    budget = Budget(max_iterations=3_000, max_collision_checks=20_000, time_limit_s=None)
    forward_only = make_planner("gradient.follow_leader", {"retract": False})
    r0 = forward_only.solve(problem, leave, budget, np.random.default_rng(0), q_start=q_b)
    assert r0.status is Status.LOCAL_MINIMUM
    assert "tracking stalled at sub-goal 2" in r0.reason
    r = make_planner("gradient.follow_leader").solve(
        problem, leave, budget, np.random.default_rng(0), q_start=q_b
    )
    assert r.status is Status.SOLVED, r.reason
    assert r.reason.startswith("slid 9.07 m back along the body to face 12")
    assert r.extra["leader"][0]["attempt"] == "retract"
    np.testing.assert_allclose(r.path[0], q_b)
    assert bool(problem.goal(leave).contains(problem.robot, r.path[-1]))
    assert problem_checker(problem).check_path(r.path, problem.joint_step / 4).valid


def test_golden_values_of_a_search_from_backward_branches():
    """``forward = false`` on armz_window, seed 0, 300 000 checks: four IK goal states
    root the goal tree, two of them grow a backward branch into the start's tip pose,
    and the compiled RRT-Connect joins the start to them in 7 iterations."""
    problem = load_problem("armz_window")
    planner = make_planner("native.rrtconnect+leader", {"forward": False})
    budget = Budget(max_iterations=None, max_collision_checks=300_000, time_limit_s=None)
    r = planner.solve(problem, 0, budget, np.random.default_rng(0))
    assert r.status is Status.SOLVED, r.reason
    assert r.extra["search_iterations"] == 7
    assert r.iterations == 2_106
    assert r.collision_checks == 127_701  # 174 982 before the certified edges
    assert r.extra["path_length_rad"] == pytest.approx(9.255477345, abs=1e-6)
    assert [b["status"] for b in r.extra["leader"]["backward"]] == ["solved", "solved"]
    assert problem_checker(problem).check_path(r.path, problem.joint_step / 4).valid

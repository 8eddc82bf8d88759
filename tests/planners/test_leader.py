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
    assert r.collision_checks == 49_837  # 92 100 before the certified edges (issue 32)
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
    assert c.collision_checks == 36_087  # 58 558 before the certified edges
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
    # 174 982 before the certified edges; 127 701 with the trees in turn (the same path:
    # the balanced search grows the smaller goal tree once more before they join)
    assert r.collision_checks == 120_921
    assert r.extra["path_length_rad"] == pytest.approx(9.255477345, abs=1e-6)
    assert [b["status"] for b in r.extra["leader"]["backward"]] == ["solved", "solved"]
    assert problem_checker(problem).check_path(r.path, problem.joint_step / 4).valid


def _ceiling_hole(problem, x_m, y_m):
    """``problem`` with its room's ceiling cut around a hole ``x_m`` × ``y_m`` (lo, hi)
    [m]: a room with a second opening."""
    import dataclasses

    from plannerlab.problem.scene import Box, Scene

    scene = problem.scene
    c = next(o for o in scene.obstacles if o.name == "room_ceiling")
    cx, cy, cz = c.T_world_obstacle[:3, 3]
    sx, sy, sz = c.size_m
    x0, x1, y0, y1 = cx - sx / 2, cx + sx / 2, cy - sy / 2, cy + sy / 2

    def box(name, lo, hi):
        T = np.eye(4)
        T[:3, 3] = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, cz]
        return Box(name, T, np.array([hi[0] - lo[0], hi[1] - lo[1], sz]))

    cut = (
        box("ceiling_left", (x0, y0), (x_m[0], y1)),
        box("ceiling_right", (x_m[1], y0), (x1, y1)),
        box("ceiling_near", (x_m[0], y0), (x_m[1], y_m[0])),
        box("ceiling_far", (x_m[0], y_m[1]), (x_m[1], y1)),
    )
    kept = tuple(o for o in scene.obstacles if o.name != "room_ceiling")
    return dataclasses.replace(problem, scene=Scene(kept + cut, scene.meshes), name="two_openings")


@pytest.fixture(scope="module")
def two_openings():
    """``armz_inspection_v21``'s room (one window, in the near wall; the task ends at B in
    the far corner) with a 2.6 m square hole cut in the ceiling above B's corner, and B's
    witness state: the body threaded through the near window, its tip in the far corner."""
    base = load_problem(PROBLEMS / "variants" / "armz_inspection_v21.toml")
    problem = _ceiling_hole(base, (-7.8, -5.2), (7.6, 10.2))
    q_b = np.array(problem.extras["witness"]["goal_states_rad"][-2])
    return problem, q_b


def _exit(points_m, y_wall_m, z_ceiling_m):
    """Where a polyline from inside the room first leaves it: ("ceiling", point) when it
    first rises above the ceiling's underside ``z_ceiling_m``, ("near wall", point) when
    it first passes the near wall's room side ``y_wall_m`` (None: it does neither)."""
    pts = np.asarray(points_m)
    s = np.linspace(0.0, 1.0, 50)[:, None]
    dense = np.vstack([a + s * (b - a) for a, b in zip(pts[:-1], pts[1:], strict=True)])
    out = np.flatnonzero((dense[:, 1] < y_wall_m) | (dense[:, 2] > z_ceiling_m))
    if not len(out):
        return None
    p = dense[out[0]]
    return ("ceiling" if p[2] > z_ceiling_m else "near wall"), p


def test_leaving_a_two_opening_room_the_leader_takes_the_body_s_own_opening(two_openings):
    """In the constructed two-opening room the leader's shortest way out for the tip runs
    up through the ceiling hole, while the body fills the near window; routed by the
    body's opening (its pivot face) it leaves by the near window, and the retract's test
    of sight (``sees_through``) tells the two ways apart."""
    from plannerlab.planners.clearance.slide import sees, sees_through
    from plannerlab.planners.context import PlanningContext
    from plannerlab.planners.follow_leader.moves import body_opening, leaves_from_inside

    problem, q_b = two_openings
    leave = problem.legs - 1
    planner = make_planner("native.rrtconnect+leader")
    fl = planner.leader.for_robot(problem.robot)
    ctx = PlanningContext.for_planner(planner, problem, leave, CHECKS, q_start=q_b)
    window = next(o for o in problem.scene.obstacles if o.name == "wall_near_below")
    y_wall = float(window.T_world_obstacle[1, 3] + window.size_m[1] / 2)  # its room side
    ceiling = next(o for o in problem.scene.obstacles if o.name == "ceiling_left")
    z_ceiling = float(ceiling.T_world_obstacle[2, 3] - ceiling.size_m[2] / 2)

    plain = fl.leader_path(problem, leave, q_b, None)
    way, _ = _exit(plain.points_m, y_wall, z_ceiling)
    assert way == "ceiling"  # the tip's shortest way out: the hole, not the body's window

    assert leaves_from_inside(fl, ctx, q_b, plain)
    opening = body_opening(fl, ctx, q_b)
    faces = problem.robot.fk(q_b)[:, :3, 3]
    assert opening is not None and any(np.allclose(opening, f) for f in faces)
    routed = fl.leader_path(problem, leave, q_b, None, via_m=opening)
    way, crossed = _exit(routed.points_m, y_wall, z_ceiling)
    assert way == "near wall"
    # through the window: between wall_near_below's top and wall_near_above's bottom
    top = next(o for o in problem.scene.obstacles if o.name == "wall_near_above")
    z_lo = window.T_world_obstacle[2, 3] + window.size_m[2] / 2
    z_hi = top.T_world_obstacle[2, 3] - top.size_m[2] / 2
    assert z_lo < crossed[2] < z_hi

    # below the hole, on a line of sight from the approach point through the hole's
    # centre, the approach point is in sight, but not by the body's opening; below the
    # window, on the line through its centre, it is (a clearance of 0.3 m: these
    # oblique lines do not fit the leader's 0.81 m through the openings)
    goal = problem.goal(leave)
    approach = goal.p_world_m - fl.settings.approach_m * goal.n_world
    hole = np.array([-6.5, 8.9, z_ceiling])
    window_centre = np.array([window.T_world_obstacle[0, 3], y_wall, (z_lo + z_hi) / 2])
    under_hole = hole + 0.15 * (hole - approach)
    by_window = window_centre + 0.15 * (window_centre - approach)
    for p in (under_hole, by_window):
        assert sees(problem.scene, p, approach, 0.3)
    assert not sees_through(problem.scene, under_hole, opening, approach, 0.3)
    assert sees_through(problem.scene, by_window, opening, approach, 0.3)


def test_leaving_a_two_opening_room_succeeds_on_a_check_budget(two_openings):
    """Seed 0, 1 000 000 checks (no clock): from B's witness in the two-opening room the
    body slides back out along its own curve until its tip sees the approach point by its
    own opening, the leader from there gets it into the goal region, and the path is valid
    at a quarter of joint_step. (Main's code at 6653204 solves it too, its slide ending
    at 9.07 m where the tip sees the approach point by any opening: at the leader's
    0.81 m clearance no point of this body inside the room sees it through the hole, so
    the room shows the leader's other way out, not v49's early end of the slide.)"""
    problem, q_b = two_openings
    leave = problem.legs - 1
    budget = Budget(max_iterations=None, max_collision_checks=1_000_000, time_limit_s=None)
    planner = make_planner("native.rrtconnect+leader")
    r = planner.solve(problem, leave, budget, np.random.default_rng(0), q_start=q_b)
    assert r.status is Status.SOLVED, r.reason
    log = r.extra["leader"]
    assert log["retract_first"]
    assert log["retract"]["reason"] == "slid 9.31 m back along the body to face 12 in 1710 steps"
    assert log["after_retract"]["status"] == "solved"
    assert r.iterations == 1_999
    # the count within 20 checks of its golden, not to the check: the certified stretches
    # of this 7-leg path compare distances with growths that tie to the last bit on some
    # stretches, and LLVM's code for one CPU model rounds them otherwise than for another
    # (190 090 where the golden was pinned, znver4; 190 094 on znver5, the same search,
    # iterations and path)
    assert abs(r.collision_checks - 190_090) <= 20, r.collision_checks
    np.testing.assert_allclose(r.path[0], q_b)
    assert bool(problem.goal(leave).contains(problem.robot, r.path[-1]))
    assert problem_checker(problem).check_path(r.path, problem.joint_step / 4).valid

"""The slide (planners/clearance/slide.py): leaving a room from its far wall, the body drawn
back out along its own curve, every face inside at once; used by the clearance descent's
detour, follow-the-leader's retract and the leader-guided sampler. Budgets in checks and
iterations, no clock."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.planners import make_planner
from plannerlab.planners.clearance.settings import robot_size
from plannerlab.planners.clearance.slide import (
    deep_inside,
    openness,
    pivot_face,
    sees,
    sight_clearance_m,
    slide_out,
)
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.follow_leader import moves
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget
from plannerlab.record.leg import Status

BUDGET = Budget(max_iterations=20_000, max_collision_checks=40_000, time_limit_s=None)


@pytest.fixture(scope="module")
def v29():
    """``armz_inspection_v29`` (far_rtl, 30 modules, the room x1.25): the task ends at B
    in the far corner away from the window; leaving from B's witness."""
    problem = load_problem(PROBLEMS / "variants" / "armz_inspection_v29.toml")
    q_b = np.array(problem.extras["witness"]["goal_states_rad"][-2])
    return problem, q_b


def _context(problem, q, name="gradient.clearance+detour"):
    planner = make_planner(name).for_robot(problem.robot)
    return PlanningContext.for_planner(planner, problem, problem.legs - 1, BUDGET, q_start=q)


def _target(problem):
    goal = problem.goal(problem.legs - 1)
    link = robot_size(problem.robot).pitch_m
    clearance = sight_clearance_m(problem.robot, problem.safety_margin_m, link)
    return goal.p_world_m - 2.5 * goal.n_world, clearance, link


def _inside(problem, q) -> int:
    """Faces beyond the near wall's inner face (inside the room)."""
    walls = [o for o in problem.scene.obstacles if o.name.startswith("wall_near")]
    y0 = max(float(o.T_world_obstacle[1, 3] + o.size_m[1] / 2) for o in walls)
    return int(np.sum(problem.robot.fk(q)[:, 1, 3] > y0))


def test_the_body_slides_out_along_its_own_curve(v29):
    """From B the tip does not see the leave goal's approach point; the first 14 faces
    (from the base) that do end at face 15 (the pivot), and 16 of its 31 frames are in the
    room. The slide draws the inside part back 10.7 m along the body until the tip sees
    it: every state collision-free, joint steps at most half the problem's joint_step,
    and at most two frames (the tip module's) left in the room; the path is valid at a
    quarter of joint_step."""
    problem, q_b = v29
    target, clearance, link = _target(problem)
    faces = problem.robot.fk(q_b)[:, :3, 3]
    assert not sees(problem.scene, faces[-1], target, clearance)
    assert pivot_face(problem.scene, faces, target, clearance) == 15
    assert _inside(problem, q_b) == 16
    ctx = _context(problem, q_b)
    sl = slide_out(
        ctx,
        q_b,
        target,
        clearance,
        clearance_floor_m=0.03,
        max_step_rad=problem.joint_step / 2,
        link_m=link,
    )
    assert sl.status is Status.SOLVED, sl.reason
    assert sl.pivot == 15
    assert sl.slid_m == pytest.approx(10.74, abs=0.05)
    end = sl.states[-1]
    assert sees(problem.scene, problem.robot.fk(end)[-1, :3, 3], target, clearance)
    assert _inside(problem, end) <= 2
    steps = np.abs(np.diff(np.array(sl.states), axis=0))
    steps = np.minimum(steps, 2 * np.pi - steps)
    assert steps.max() <= problem.joint_step / 2 + 1e-9
    checker = problem_checker(problem)
    assert checker.check_path(np.array(sl.states), problem.joint_step / 4).valid


def test_the_tip_alone_coils_the_body_inside(v29):
    """The retract that came before the slide (the tip alone drawn back face by face,
    the body left to the clearance descent) gets the tip to face 16 and no further: the
    body coils in the room (14 faces still inside) and the tip does not see the
    approach point."""
    problem, q_b = v29
    fl = make_planner("gradient.follow_leader").for_robot(problem.robot)
    ctx = _context(problem, q_b, "gradient.follow_leader")
    tr = moves._retract_tip(fl, ctx, q_b)
    target, clearance, _ = _target(problem)
    end = tr.states[-1]
    assert tr.reason.startswith("retracted to face 16")
    assert _inside(problem, end) >= 12
    assert not sees(problem.scene, problem.robot.fk(end)[-1, :3, 3], target, clearance)


def test_deep_inside_is_a_third_of_the_body_beyond_the_pivot_and_the_tip_enclosed(v29):
    """From B: 15 of 30 faces beyond the pivot, the tip's rays (a third of the body long)
    open in 1 of 26 directions, the approach point's in all. The traps' straight column
    is not deep inside: on armz_thin_wall a quarter of it lies beyond the pivot; on
    armz_deep_e more than half does, but its tip is in the open and the approach point
    inside the room."""
    problem, q_b = v29
    target, clearance, _ = _target(problem)

    def deep(problem, q, target):
        faces = problem.robot.fk(q)[:, :3, 3]
        reach = float(np.sum(np.linalg.norm(np.diff(faces, axis=0), axis=1)))
        return deep_inside(problem.scene, faces, target, clearance, reach / 3)

    faces = problem.robot.fk(q_b)[:, :3, 3]
    assert openness(problem.scene, faces[-1], clearance / 2, 7.0) < 0.1
    assert openness(problem.scene, target, clearance / 2, 7.0) == 1.0
    assert deep(problem, q_b, target)
    for name, pivot in (("armz_thin_wall", 18), ("armz_deep_e", 11)):
        trap = load_problem(name)
        goal = trap.goal(0)
        tgt = goal.p_world_m - 2.5 * goal.n_world
        column = trap.robot.fk(trap.q_start)[:, :3, 3]
        assert pivot_face(trap.scene, column, tgt, clearance) == pivot, name
        assert not deep(trap, trap.q_start, tgt), name


def test_no_slide_where_the_tip_sees_the_target(v29):
    problem, _ = v29
    target, clearance, link = _target(problem)
    q = problem.q_start  # the rest pose: its tip is in the leave goal
    sl = slide_out(
        _context(problem, q),
        q,
        target,
        clearance,
        clearance_floor_m=0.03,
        max_step_rad=0.01,
        link_m=link,
    )
    assert sl.status is Status.LOCAL_MINIMUM
    assert sl.reason == "no slide: the tip sees the target"
    assert len(sl.states) == 1


@pytest.mark.parametrize("name", ["gradient.clearance+detour", "gradient.follow_leader"])
def test_the_gradient_families_leave_from_the_far_corner(v29, name):
    """Both leave from B within 20 000 iterations and 40 000 checks (before the slide both
    failed there: the descent stalled at iteration 8 and no retract of its detour got
    out; follow-the-leader's tracking stalled at the window): by the slide first, and the
    path is valid at a quarter of joint_step and ends in the goal region."""
    problem, q_b = v29
    leave = problem.legs - 1
    r = make_planner(name).solve(problem, leave, BUDGET, np.random.default_rng(0), q_start=q_b)
    assert r.status is Status.SOLVED, r.reason
    assert "slid" in r.reason or "slide" in r.reason
    assert r.collision_checks <= 40_000
    assert bool(problem.goal(leave).contains(problem.robot, r.path[-1]))
    assert problem_checker(problem).check_path(r.path, problem.joint_step / 4).valid

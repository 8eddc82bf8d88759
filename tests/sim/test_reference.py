"""The executor's reference: how far it may stray from the plan, and the dense re-check.

The retimed reference (:mod:`plannerlab.sim.retime`) is a shape-preserving PCHIP through
the plan's waypoints with corner knots, so it stays within ``Trajectory.bound_m`` of the
plan; the natural cubic spline it replaced rang round every corner. The execution
re-checks the reference at every physics step with the plan's margin
(:mod:`plannerlab.sim.execute`); before, it thinned the reference to one state per joint
step joined by straight lines, which missed the spline bulging between them.

Real PyBullet (inverse dynamics for TOPP-RA, the execution), real collision checks.
"""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.collision.reach import joint_reach_m
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Problem
from plannerlab.problem.scene import Box, Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.sim import execute
from plannerlab.sim.measure import geometry_deviation_m
from plannerlab.sim.retime import PCHIP_BOUND, Trajectory, corner_knots, retime
from plannerlab.sim.world import SimWorld

DT_S = 1.0 / 240.0


def zigzag(robot: ArmZ, amplitude_rad: float, corners: int = 8) -> np.ndarray:
    """A path that turns at every waypoint (as a gradient descent's does): joint 0 turns
    steadily while the others zig-zag (fixed seed)."""
    rng = np.random.default_rng(2)
    q0 = np.full(robot.dof, np.pi) + rng.uniform(-0.3, 0.3, robot.dof)
    ahead = np.zeros(robot.dof)
    ahead[0] = 0.04
    zig = rng.uniform(-1.0, 1.0, robot.dof)
    zig[0] = 0.0
    zig *= amplitude_rad / np.max(np.abs(zig))
    return np.array([q0 + k * ahead + (k % 2) * zig for k in range(corners)])


def reference(robot: ArmZ, path: np.ndarray, **kw) -> tuple[Trajectory, np.ndarray, np.ndarray]:
    """The retimed reference at every physics step (as the executor samples it) and the
    plan's state at the same path parameter."""
    with SimWorld(robot, Scene()) as world:
        traj = retime(
            path,
            velocity_limit=world.max_velocity,
            effort_limit=world.max_force,
            inverse_dynamics=world.inverse_dynamics,
            knot_step=0.0125,
            reach_m=joint_reach_m(robot),
            **kw,
        )
    t = np.arange(1, int(np.ceil(traj.duration_s / DT_S - 1e-9)) + 1) * DT_S
    return traj, traj.sample(t)[0], traj.plan_states(t)


def test_corner_knots_keep_every_waypoint_and_short_intervals_round_them() -> None:
    robot = ArmZ(n_modules=8)
    reach = joint_reach_m(robot)
    path = zigzag(robot, 0.1)
    knots = corner_knots(path, 0.0125, reach, 0.02)
    for q in path:  # every waypoint is a knot
        assert np.min(np.max(np.abs(knots - q), axis=1)) < 1e-12
    span_m = np.abs(np.diff(knots, axis=0)) @ reach
    at_waypoint = np.array(
        [np.min(np.max(np.abs(path - k), axis=1)) < 1e-12 for k in knots], dtype=bool
    )
    touching = at_waypoint[:-1] | at_waypoint[1:]
    assert np.all(span_m[touching] <= 0.02 + 1e-12)
    assert np.all(np.max(np.abs(np.diff(knots, axis=0)), axis=1) <= 0.0125 + 1e-12)


@pytest.mark.parametrize("amplitude_rad", [0.02, 0.1, 0.3])
def test_pchip_reference_stays_within_its_bound_of_the_plan(amplitude_rad: float) -> None:
    """At every physics step the reference's geometry is within ``bound_m`` (0.385 x the
    corner distance) of the plan's at the same path parameter; the spline's was not
    bounded and strays further."""
    robot = ArmZ(n_modules=8)
    path = zigzag(robot, amplitude_rad)
    traj, q_ref, q_plan = reference(robot, path, corner_m=0.02)
    assert traj.interpolant == "pchip"
    assert traj.bound_m == pytest.approx(PCHIP_BOUND * 0.02)
    dev = geometry_deviation_m(robot, q_plan, q_ref)
    assert 0.0 < np.max(dev) <= traj.bound_m
    np.testing.assert_allclose(q_ref[-1], path[-1], atol=1e-9)  # ends on the goal state
    _, s_ref, s_plan = reference(robot, path, interpolant="spline")
    assert np.max(geometry_deviation_m(robot, s_plan, s_ref)) > 2 * np.max(dev)


def test_dense_recheck_catches_the_spline_grazing_a_wall_the_plan_clears() -> None:
    """A constructed plan (12-module arm, a zig-zag) beside a wall placed so that the plan
    keeps the 2-mm margin (2.12 mm) while the old natural-spline reference bulges beyond
    the plan's extreme towards the wall, between the states the old thinned re-check kept
    (one per joint step, joined by straight lines). The dense re-check (every physics
    step, the executor's since 7c7e4de) refuses that reference; the thinned one passed
    it. The PCHIP reference keeps the margin and stays within its bound of the plan."""
    robot = ArmZ(n_modules=12)
    path = zigzag(robot, 0.2)
    margin_m = 0.002
    # the wall's face: the plane n·p = 3.8101 m (n found by searching directions in which
    # the spline's support exceeds the plan's and the thinned reference's)
    n = np.array([0.07, -0.93, 0.36])
    n /= np.linalg.norm(n)
    x = np.cross(n, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, np.cross(n, x), n], axis=1)
    T[:3, 3] = n * (3.8101 + 0.5)
    scene = Scene((Box("wall", T, np.array([20.0, 20.0, 1.0])),))
    checker = CollisionChecker(robot, scene, margin_m=margin_m)
    exact = CollisionChecker(robot, scene)
    step = 0.0125

    assert checker.check_path(path, step).valid  # the plan keeps the margin
    _, spline, _ = reference(robot, path, interpolant="spline")
    thin = [0]  # the old re-check's states: one per joint step
    for i in range(1, len(spline)):
        if np.max(np.abs(spline[i] - spline[thin[-1]])) >= step:
            thin.append(i)
    thin.append(len(spline) - 1)
    assert checker.check_path(spline[thin], step).valid  # missed
    assert not checker.check_path(spline, step).valid  # caught
    assert min(exact.clearance(q) for q in spline) < margin_m

    # through the executor: the verdict with the old interpolant and the new one
    goal = GoalRegion("g", *robot.tip(path[-1]), pos_tol_m=0.05, angle_tol_deg=3.0)
    problem = Problem(
        "reference_test",
        robot,
        scene,
        np.full(robot.dof, np.pi),
        (goal,),
        joint_step=4 * step,
        safety_margin_m=margin_m,
    )
    old = execute(problem, path, leg=0, interpolant="spline")
    assert old.path_valid and old.trajectory_valid is False and not old.success
    new = execute(problem, path, leg=0)
    assert new.path_valid and new.trajectory_valid and new.success
    assert 0.0 < new.reference_deviation_m <= PCHIP_BOUND * 0.02
    assert old.reference_deviation_m > 5 * new.reference_deviation_m  # 1.27 / 0.096 mm
    # the arm tracks its reference (measured 0 mm): the deviation from the plan is the
    # reference's own
    assert new.max_deviation_m == pytest.approx(new.reference_deviation_m, abs=1e-4)
    # PyBullet's smallest clearance (sampled to 1 mm, measured 2.13 mm): the margin kept
    assert new.min_clearance_m > margin_m - 1e-3

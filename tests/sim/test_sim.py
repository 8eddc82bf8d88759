"""PyBullet execution: URDF kinematics, position control under gravity, contacts, records.

Every test runs the real PyBullet (DIRECT mode); nothing is mocked. Small arms
(8-18 modules) unless the full 24-module arm is the point.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Problem
from plannerlab.problem.scene import Box, Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix, trans
from plannerlab.sim import Execution, SimWorld, execute, execute_legs


def static_gravity_torques_nm(robot: ArmZ, q: np.ndarray) -> np.ndarray:
    """Gravity torque about each joint axis at rest (dof,) [N·m]: module masses at the
    chord midpoints (the URDF's inertial origins)."""
    F = robot.fk(q)
    origins, axes = F[1:-1, :3, 3], F[1:-1, :3, 2]
    com = 0.5 * (F[1:-1, :3, 3] + F[2:, :3, 3])  # module i+1 for joint i
    weight = np.array([0.0, 0.0, -9.81 * robot.module_mass_kg])
    return np.array(
        [axes[i] @ np.cross(com[i:] - origins[i], weight).sum(axis=0) for i in range(robot.dof)]
    )


def make_problem(
    robot: ArmZ, scene: Scene, q_goal: np.ndarray, *, joint_step: float = 0.05
) -> Problem:
    p, n = robot.tip(q_goal)
    goal = GoalRegion("g", p, n, pos_tol_m=0.05, angle_tol_deg=3.0)
    return Problem(
        "sim_test", robot, scene, np.full(robot.dof, np.pi), (goal,), joint_step=joint_step
    )


WALL = Scene((Box("wall", trans(0.0, -2.1, 5.0), np.array([6.0, 1.0, 4.0])),))


# ---------------------------------------------------------------------- kinematics
def test_urdf_link_frames_match_fk_24_modules_tilted_base() -> None:
    T = pose_matrix([1.0, 2.0, 3.0], [0.3, -0.2, 0.5])
    robot = ArmZ(n_modules=24, T_world_base=T)
    rng = np.random.default_rng(7)
    with SimWorld(robot) as world:
        for _ in range(20):
            q = rng.uniform(-3 * np.pi, 3 * np.pi, robot.dof)  # unwrapped on purpose
            world.reset(q)
            np.testing.assert_array_equal(world.state(), q)
            F_sim, F_fk = world.link_frames(), robot.fk(q)
            assert F_sim.shape == F_fk.shape == (robot.dof + 2, 4, 4)
            assert np.max(np.linalg.norm(F_sim[:, :3, 3] - F_fk[:, :3, 3], axis=1)) <= 1e-6
            # rotation error angle of R_fk^T R_sim
            R_rel = np.einsum("fji,fjk->fik", F_fk[:, :3, :3], F_sim[:, :3, :3])
            cos = np.clip((np.trace(R_rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
            assert np.max(np.arccos(cos)) <= 1e-6


def test_self_contacts_match_fcl_pairs_for_a_closed_ring() -> None:
    """All θ = 0 curls an 18-module arm into a ring that closes on itself: PyBullet reports
    exactly FCL's colliding pairs (the root URDF link ``base`` named ``module_0``)."""
    robot = ArmZ(n_modules=18)
    q = np.zeros(robot.dof)
    fcl_pairs = set(CollisionChecker(robot, Scene()).colliding_pairs(q))
    assert fcl_pairs and ("module_0", "module_16") in fcl_pairs
    with SimWorld(robot) as world:
        world.reset(q)
        contacts = world.contacts()
    assert all(c.other_is_link for c in contacts)
    assert {(c.link_name, c.other_name) for c in contacts} == fcl_pairs


# ---------------------------------------------------------------------- control
def test_straight_column_holds_exactly_because_gravity_has_no_torque() -> None:
    """The 24-module straight column (all θ = π) holds under gravity with 100 N·m motors:
    every joint axis and centre of mass lies in one vertical plane, so gravity has no
    torque about any joint and the column stays within 1e-2 rad (in fact exactly)."""
    robot = ArmZ(n_modules=24)
    q = np.full(robot.dof, np.pi)
    assert np.max(np.abs(static_gravity_torques_nm(robot, q))) < 1e-9
    with SimWorld(robot) as world:
        world.reset(q)
        q_reached = world.move_towards(q, 240)
    assert np.max(np.abs(q_reached - q)) <= 1e-2


def test_bent_24_module_pose_under_the_torque_limit_holds() -> None:
    robot = ArmZ(n_modules=24)
    q = np.pi + np.random.default_rng(0).uniform(-0.5, 0.5, robot.dof)
    assert np.max(np.abs(static_gravity_torques_nm(robot, q))) < robot.joint_torque_limit_nm
    with SimWorld(robot) as world:
        world.reset(q)
        q_reached = world.move_towards(q, 240)
    assert np.max(np.abs(q_reached - q)) <= 1e-2


def test_pose_needing_more_than_100_nm_sags_under_gravity() -> None:
    """The honest limit: alternating θ = π, π − 0.6 needs > 100 N·m at some joint, and
    the paper's motors cannot hold it."""
    robot = ArmZ(n_modules=24)
    q = np.where(np.arange(robot.dof) % 2, np.pi, np.pi - 0.6)
    assert np.max(np.abs(static_gravity_torques_nm(robot, q))) > robot.joint_torque_limit_nm
    with SimWorld(robot) as world:
        world.reset(q)
        q_reached = world.move_towards(q, 240)
    assert np.max(np.abs(q_reached - q)) > 1e-2
    with SimWorld(robot, gravity_mps2=(0.0, 0.0, 0.0)) as world:  # the same pose, no gravity
        world.reset(q)
        q_reached = world.move_towards(q, 240)
    assert np.max(np.abs(q_reached - q)) <= 1e-6


def test_position_control_reaches_a_nearby_target() -> None:
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q_target = q0 + np.random.default_rng(1).uniform(-0.1, 0.1, robot.dof)
    with SimWorld(robot) as world:
        world.reset(q0)
        q_reached = world.move_towards(q_target, 240)
        assert world.steps_taken == 240
        assert world.sim_time_s == pytest.approx(1.0)
    assert np.max(np.abs(q_reached - q_target)) <= 1e-3


def test_continuous_joints_take_the_short_way_round() -> None:
    """From π − 0.05 to the target −π + 0.05 (0.1 rad away across the wrap): the motor
    goes up to π + 0.05 (raw, unwrapped), not 6.18 rad the long way down."""
    robot = ArmZ(n_modules=6)
    with SimWorld(robot) as world:
        world.reset(np.full(robot.dof, np.pi - 0.05))
        q_reached = world.move_towards(np.full(robot.dof, -np.pi + 0.05), 240)
    np.testing.assert_allclose(q_reached, np.pi + 0.05, atol=1e-3)


# ---------------------------------------------------------------------- execution
def test_running_into_a_wall_is_reported_by_the_recheck_and_the_simulator() -> None:
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0.copy()
    q1[0] = 0.0  # swings the arm's top over to y ≈ -2 m, into the wall's face at y = -1.6
    problem = make_problem(robot, WALL, q1)
    ex = execute(problem, np.stack([q0, q1]), leg=0)
    assert not ex.path_valid
    assert ex.recheck_first_invalid_edge == 0
    assert ("module_7", "wall") in ex.recheck_pairs
    assert ex.contacts
    hit = {(c.link_name, c.other_name, c.other_is_link) for c in ex.contacts}
    assert ("module_7", "wall", False) in hit
    wall_hit = next(c for c in ex.contacts if c.other_name == "wall")
    assert wall_hit.max_depth_m > 0.0
    assert wall_hit.p_world_m[1] == pytest.approx(-1.6, abs=0.01)  # on the wall's face
    assert 0.0 < wall_hit.first_time_s < ex.sim_time_s
    assert ex.goal_reached is False  # the wall stops the arm
    assert not ex.success
    assert "module_7 x wall" in ex.reason
    # the simulated clearance says the same in metres: the arm is pressed into the wall
    assert ex.min_clearance_m < 0.0 and not ex.clear
    assert ex.min_clearance_pair is not None and ex.min_clearance_pair[1] == "wall"
    assert "simulated clearance" in ex.reason


def test_short_free_path_executes_without_contact_and_tracks() -> None:
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0 + np.random.default_rng(2).uniform(-0.3, 0.3, robot.dof)
    problem = make_problem(robot, WALL, q1)  # the wall is there but out of the way
    ex = execute(problem, np.stack([q0, q1]), leg="g", timing="waypoints")
    assert ex.timing == "waypoints" and ex.trajectory_valid is None
    assert ex.path_valid and ex.recheck_pairs == ()
    assert ex.recheck_joint_step == pytest.approx(problem.joint_step / 4)
    assert ex.contacts == ()
    assert ex.max_track_err_rad < 0.02
    assert ex.max_tip_track_err_m < 0.05
    assert ex.final_track_err_rad < 1e-3
    assert ex.final_pos_err_m < 1e-3 and ex.final_angle_err_deg < 0.1
    assert ex.goal_reached and ex.success
    # judged where the arm should have arrived: the end of each waypoint's window
    assert ex.max_deviation_m < ex.max_deviation_limit_m == 0.01
    assert ex.min_clearance_m > 0.0
    M = len(ex.q_cmd_rad)
    assert ex.q_actual_rad.shape == (M, robot.dof) and ex.t_s.shape == (M,)
    assert ex.sim_time_s == pytest.approx((M * ex.steps_per_waypoint + ex.settle_steps) / 240)
    assert not ex.carried_over and ex.start_offset_rad == 0.0


def test_execute_legs_carries_the_state_over() -> None:
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0 + 0.2
    q2 = q0 - 0.1
    problem = make_problem(robot, Scene(), q1)
    first, second = execute_legs(problem, [np.stack([q0, q1]), np.stack([q1, q2])])
    assert first.leg == 0 and not first.carried_over
    assert second.leg is None and second.carried_over  # the problem has one goal only
    np.testing.assert_array_equal(second.q_start_rad, first.q_final_rad)
    assert second.start_offset_rad == pytest.approx(
        np.max(np.abs(first.q_final_rad - q1)), abs=1e-12
    )
    assert first.success and second.success


def test_execution_json_round_trip() -> None:
    robot = ArmZ(n_modules=6)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0.copy()
    q1[0] = 0.0
    # This wall overlaps the arm from the start, so the first record has contacts.
    scene = Scene((Box("wall", trans(0.0, -1.3, 3.0), np.array([4.0, 1.0, 2.0])),))
    problem = make_problem(robot, scene, q1)
    with_contacts = execute(problem, np.stack([q0, q1]), settle_steps=24, leg=0)
    without_leg = execute(
        problem, np.stack([q0, q0 + 0.1]), settle_steps=24, gravity_mps2=(0.0, 0.0, 0.0)
    )
    assert with_contacts.contacts and not with_contacts.path_valid
    assert without_leg.leg is None and np.isnan(without_leg.final_pos_err_m)
    for ex in (with_contacts, without_leg):
        text = json.dumps(ex.to_dict(), allow_nan=False)  # strictly JSON: NaN -> null
        back = Execution.from_dict(json.loads(text))
        assert back.to_dict() == ex.to_dict()
        assert back.contacts == ex.contacts
        assert back.recheck_pairs == ex.recheck_pairs
        np.testing.assert_array_equal(back.q_actual_rad, ex.q_actual_rad)
        assert back.success == ex.success and back.reason == ex.reason
        assert back.goal_reached == ex.goal_reached
    assert np.isnan(back.final_pos_err_m) and back.goal_reached is None
    assert back.gravity_mps2 == (0.0, 0.0, 0.0) and with_contacts.gravity_mps2 == (0, 0, -9.81)


def test_a_path_the_arm_cannot_follow_is_not_executed_cleanly() -> None:
    """The verdict includes following the commanded motion: the arm reaches the goal after
    settling, but lagged far behind the commanded path on the way, so the execution is
    not clean; the deviation is in metres (the joint error is reported, not judged)."""
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0 + 0.5
    problem = make_problem(robot, Scene(), q1)
    kw = dict(
        leg=0,
        timing="waypoints",
        steps_per_waypoint=1,
        settle_steps=2400,
        gravity_mps2=(0.0, 0.0, 0.0),
    )
    fast = execute(problem, np.stack([q0, q1]), **kw)
    assert fast.path_valid and not fast.contacts and fast.goal_reached
    assert fast.max_deviation_limit_m == problem.simulation.max_deviation_m == 0.01
    assert fast.max_deviation_m > 0.1  # metres behind, not millimetres
    assert fast.max_track_err_rad > 0.05  # reported, not judged
    assert not fast.followed and not fast.success
    assert "strayed" in fast.reason and "max_deviation_m" in fast.reason
    # the limit is the problem's: a looser one accepts the same motion
    loose = execute(problem, np.stack([q0, q1]), max_deviation_m=100.0, **kw)
    assert loose.max_deviation_limit_m == 100.0 and loose.followed and loose.success
    back = Execution.from_dict(json.loads(json.dumps(fast.to_dict())))
    assert back.max_deviation_m == fast.max_deviation_m and not back.success


def test_records_made_before_the_deviation_keep_their_verdict() -> None:
    """An execution record without the metre fields (a trial store written before them)
    loads, with NaN deviation and clearance, and is judged as it was: by its joint
    tracking limit."""
    robot = ArmZ(n_modules=6)
    q0 = np.full(robot.dof, np.pi)
    problem = make_problem(robot, Scene(), q0 + 0.1)
    ex = execute(problem, np.stack([q0, q0 + 0.1]), settle_steps=24, leg=0)
    old = ex.to_dict(include_log=False)
    for key in (
        "deviation_m",
        "max_deviation_m",
        "max_deviation_time_s",
        "max_deviation_limit_m",
        "min_clearance_m",
        "min_clearance_time_s",
        "min_clearance_pair",
        "clearance_samples",
        "solver",
    ):
        old.pop(key, None)
    old["t_s"], old["q_cmd_rad"], old["q_actual_rad"] = [0.1], [q0.tolist()], [q0.tolist()]
    old["track_err_rad"], old["tip_track_err_m"] = [0.04], [0.0]
    back = Execution.from_dict(old)
    assert np.isnan(back.max_deviation_m) and np.isnan(back.min_clearance_m)
    assert back.followed and back.clear and back.success  # 0.04 rad <= 0.05 rad
    old["track_err_rad"] = [0.06]
    assert not Execution.from_dict(old).success


def test_geometry_deviation_of_a_turned_joint_by_hand() -> None:
    """Joint 0 turned by δ: the capsules beyond it turn about the joint's axis. An axis
    end point at distance ρ from that axis moves by the chord 2 ρ sin(δ/2), the unit
    capsule axis by 2 ρ_u sin(δ/2), so the bound is max(ρ_a, ρ_b) chords + r · that."""
    from plannerlab.sim.measure import geometry_deviation_m

    robot = ArmZ(n_modules=3)
    q0 = np.array([np.pi - 0.4, np.pi + 0.3])
    delta = 0.05
    q1 = q0 + np.array([delta, 0.0])
    F = robot.fk(q0)
    o, z = F[1, :3, 3], F[1, :3, 2]  # joint 0 turns about z of frame 1

    def off_axis(v: np.ndarray) -> float:
        return float(np.linalg.norm(v - (v @ z) * z))

    chord = 2.0 * np.sin(delta / 2.0)
    expected = 0.0
    for a, b in robot.link_segments(q0)[1:]:  # module 0 and its capsule do not move
        u = (b - a) / np.linalg.norm(b - a)
        ends = max(off_axis(a - o), off_axis(b - o)) * chord
        expected = max(expected, ends + robot.collision_radius_m * off_axis(u) * chord)
    got = geometry_deviation_m(robot, q0, q1)
    assert got.shape == (1,)
    assert got[0] == pytest.approx(expected, rel=1e-9)
    assert expected > 0.01  # the far module swings by centimetres
    # pairs row by row, and a state with itself deviates by nothing
    both = geometry_deviation_m(robot, np.stack([q0, q0]), np.stack([q1, q0]))
    np.testing.assert_allclose(both, [expected, 0.0], rtol=1e-9, atol=1e-12)


def test_simulated_clearance_to_a_known_wall() -> None:
    """The straight column (all θ = π): a tall wall whose face (a plane y = const) is
    0.2 m beyond the capsules' surface, i.e. 0.2 m + r beyond the largest y of the moving
    capsules' axis end points, is at a clearance of 0.2 m by PyBullet's closest points."""
    from plannerlab.sim.measure import sampled_clearance

    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    seg = robot.link_segments(q0)[1:]  # module 0 is fixed: never checked against the scene
    face = float(np.max(seg[..., 1])) + robot.collision_radius_m + 0.2
    scene = Scene((Box("wall", trans(0.0, face + 0.5, 3.0), np.array([4.0, 1.0, 12.0])),))
    with SimWorld(robot, scene) as probe:
        got = sampled_clearance(robot, probe, q0[None, :])
    assert got.clearance_m == pytest.approx(0.2, abs=1e-3)
    assert got.pair is not None and got.pair[1] == "wall" and not got.self_pair
    assert got.samples == 1


def test_sampled_clearance_finds_the_smallest_within_its_resolution() -> None:
    """A swing past a wall, 2 000 states: the sampled smallest clearance is within the
    documented tolerance of the one found by querying every state, with far fewer
    queries."""
    from plannerlab.sim.measure import sampled_clearance

    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0.copy()
    q1[0] += 0.6
    q1[2] -= 0.6
    states = q0 + np.linspace(0.0, 1.0, 2000)[:, None] * (q1 - q0)
    # a tall wall (a plane y = const facing +y) that the swing passes at 5 cm
    lowest = float(np.min(robot.link_segments(states)[:, 1:, :, 1]))
    face = lowest - robot.collision_radius_m - 0.05
    scene = Scene((Box("wall", trans(0.0, face - 0.5, 3.0), np.array([12.0, 1.0, 12.0])),))
    with SimWorld(robot, scene) as probe:
        got = sampled_clearance(robot, probe, states, resolution_m=1e-3)
        every = []
        for q in states:
            probe.set_state(q)
            near, _, pairs = probe.link_distances(1.0)
            every.append(min(near.min(), pairs.min()))
    true_min = float(np.min(every))
    assert true_min == pytest.approx(0.05, abs=1e-4)  # it does pass close
    assert true_min - 1e-9 <= got.clearance_m <= true_min + max(1e-3, true_min / 8.0)
    assert got.samples < len(states) / 5


def test_retimed_small_execution_follows_within_a_millimetre_and_keeps_clear() -> None:
    """The executor's defaults (TOPP-RA on a fine grid, the direct constraint solver): a
    short motion of the 8-module arm beside a wall is followed to well under the 1 cm
    limit, and the simulated clearance matches the planned one (FCL) along the path."""
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0 + np.random.default_rng(2).uniform(-0.3, 0.3, robot.dof)
    problem = make_problem(robot, WALL, q1)
    ex = execute(problem, np.stack([q0, q1]), leg=0)
    assert ex.timing == "toppra" and ex.solver == "dantzig" and ex.success
    assert ex.max_deviation_m < 1e-3
    assert len(ex.deviation_m) == len(ex.t_s) and np.max(ex.deviation_m) <= ex.max_deviation_m
    checker = CollisionChecker(robot, WALL)
    planned = min(checker.clearance(q) for q in q0 + np.linspace(0, 1, 200)[:, None] * (q1 - q0))
    assert ex.min_clearance_m == pytest.approx(planned, abs=max(2e-3, planned / 8.0))
    assert ex.clearance_samples >= 2


def test_problem_file_sets_the_tracking_limit(tmp_path) -> None:
    from conftest import TINY_PROBLEM_TOML, write_problem

    from plannerlab.errors import ProblemError
    from plannerlab.problem.load import parse_problem

    assert (
        parse_problem(write_problem(tmp_path, TINY_PROBLEM_TOML)).simulation.max_deviation_m == 0.01
    )
    path = write_problem(tmp_path, TINY_PROBLEM_TOML + "[simulation]\nmax_deviation_m = 0.002\n")
    assert parse_problem(path).simulation.max_deviation_m == 0.002

    path = write_problem(tmp_path, TINY_PROBLEM_TOML + "[simulation]\nmax_track_err_rad = 0.02\n")
    assert parse_problem(path).simulation.max_track_err_rad == 0.02
    path = write_problem(tmp_path, TINY_PROBLEM_TOML + "[simulation]\nmax_track_err_rad = -1\n")
    with pytest.raises(ProblemError, match=r"simulation\.max_track_err_rad"):
        parse_problem(path)


def test_retimed_execution_follows_the_path_within_its_limits() -> None:
    """toppra timing: a trajectory of the path under the URDF's velocity limits and half
    its torque limits, tracked by position+velocity targets every physics step."""
    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    q1 = q0 + np.random.default_rng(2).uniform(-0.3, 0.3, robot.dof)
    q2 = q1.copy()
    q2[0] += 1.5  # one long edge: a joint jump the controller must not be handed as is
    problem = make_problem(robot, Scene(), q2)
    path = np.stack([q0, q1, q2])
    ex = execute(problem, path, leg="g")
    assert ex.timing == "toppra" and ex.trajectory_valid and ex.path_valid
    assert ex.contacts == () and ex.goal_reached and ex.success
    assert ex.max_track_err_rad < 0.005  # measured 3e-4 rad on the 24-module arm
    assert ex.spline_dev < ex.recheck_joint_step
    assert 0.0 < ex.duration_s < ex.sim_time_s
    n = int(np.ceil(ex.duration_s * 240 - 1e-9))
    assert ex.sim_time_s == pytest.approx((n + ex.settle_steps) / 240)
    np.testing.assert_allclose(ex.q_cmd_rad[-1], q2, atol=1e-9)  # ends on the path's end
    # the waypoints' timing of the same path takes far longer to run
    slow = execute(problem, path, leg="g", timing="waypoints")
    assert slow.success and slow.duration_s > 2 * ex.duration_s
    back = Execution.from_dict(json.loads(json.dumps(ex.to_dict())))
    assert back.timing == "toppra" and back.duration_s == ex.duration_s and back.success


def test_retime_respects_velocity_and_torque_limits() -> None:
    from plannerlab.sim.retime import retime

    robot = ArmZ(n_modules=8)
    q0 = np.full(robot.dof, np.pi)
    corner = q0 + np.where(np.arange(robot.dof) % 2, 0.0, 0.8)
    path = np.stack([q0, corner, q0 + 0.8])
    with SimWorld(robot, Scene(), gravity_mps2=(0.0, 0.0, 0.0)) as world:
        v_max = np.full(robot.dof, 0.5)
        traj = retime(
            path,
            velocity_limit=v_max,
            effort_limit=world.max_force,
            inverse_dynamics=world.inverse_dynamics,
            knot_step=0.01,
            torque_fraction=0.5,
        )
        t = np.linspace(0.0, traj.duration_s, 400)
        q, qd = traj.sample(t)
        np.testing.assert_allclose(q[0], path[0], atol=1e-9)
        np.testing.assert_allclose(q[-1], path[-1], atol=1e-9)
        assert np.max(np.abs(qd[[0, -1]])) < 1e-6  # from rest to rest
        assert np.max(np.abs(qd)) <= 0.5 * (1 + 1e-2)  # slightly above between grid points
        # the corner is a knot: the trajectory passes through it
        assert np.min(np.max(np.abs(q - path[1]), axis=1)) < 0.01
        # TOPP-RA holds half the 100 N·m limit at its grid points (4 per knot interval);
        # with the knots alone as the grid the spline, bending round the corner between
        # two knots, overshot that budget (0.74 x the limit here), with 4 it keeps it
        qdd = np.gradient(qd, t, axis=0)
        tau = np.array(
            [world.inverse_dynamics(a, b, c) for a, b, c in zip(q, qd, qdd, strict=True)]
        )
        assert np.max(np.abs(tau)) < 0.55 * 100.0
        assert np.percentile(np.max(np.abs(tau), axis=1), 50) < 0.5 * 100.0
        assert np.max(np.abs(tau)) > 0.4 * 100.0  # and the torque is what sets the pace
        coarse = retime(
            path,
            velocity_limit=v_max,
            effort_limit=world.max_force,
            inverse_dynamics=world.inverse_dynamics,
            knot_step=0.01,
            torque_fraction=0.5,
            grid_per_knot=1,
        )
        q, qd = coarse.sample(t := np.linspace(0.0, coarse.duration_s, 400))
        qdd = np.gradient(qd, t, axis=0)
        tau = np.array(
            [world.inverse_dynamics(a, b, c) for a, b, c in zip(q, qd, qdd, strict=True)]
        )
        assert np.max(np.abs(tau)) > 0.65 * 100.0


def test_retiming_that_is_infeasible_falls_back_to_waypoints_and_says_so() -> None:
    """Under gravity, a pose needing more than half the torque limit to hold has no
    trajectory within the torque budget; the path is executed along densified waypoints
    and the reason says why."""
    robot = ArmZ(n_modules=24)
    q0 = np.full(robot.dof, np.pi)
    q1 = np.where(np.arange(robot.dof) % 2, np.pi, np.pi - 0.6)  # > 100 N·m to hold
    problem = make_problem(robot, Scene(), q1)
    ex = execute(problem, np.stack([q0, q1]), settle_steps=24, steps_per_waypoint=2)
    assert ex.timing == "waypoints"
    assert "not retimed" in ex.reason and "to hold against gravity" in ex.reason

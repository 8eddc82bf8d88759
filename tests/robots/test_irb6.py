"""IRb-6 on LP-1: forward kinematics, URDF, analytic IK (all cases), goal sampling."""

from __future__ import annotations

import math
import os
import tempfile

import numpy as np
import pybullet
import pytest

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Robot, pose_matrix
from plannerlab.robots.irb6.goals import sample_irb6_goal
from plannerlab.robots.irb6.ik import (
    flange_target,
    format_ik_answer,
    pose_from_approach,
    solve_ik,
    solve_with_lambda0,
)
from plannerlab.robots.irb6.model import IRb6
from plannerlab.robots.irb6.wrist import wrist_annulus_m, wrist_radius_intervals_m

# Hand-worked numbers for the default robot (λ1 = 0.700, l2 = 0.455, l3 = 0.670, λ5 = 0.095).
# At the wrist height h_w = λ1 + l2·cos 40° = 0.700 + 0.455·0.766044 = 1.048550 m the slice of
# the wrist workspace is bounded by θ2 = ±40° with θ3 = 0 (θ3 = 25° would need |θ2| = 81.7°,
# θ3 = −40° needs cos θ2 > 1, aligned arms need |θ2| = 72°):
#   l2·sin 40° = 0.455·0.642788 = 0.292468
#   r_w,min = l3 − 0.292468 = 0.377532,  r_w,max = l3 + 0.292468 = 0.962468
H_W = 1.048550221619135
R_W_MIN = 0.37753163759262465
R_W_MAX = 0.9624683624073754
TAN20 = math.tan(math.radians(20.0))  # 0.363970


@pytest.fixture(scope="module")
def robot() -> IRb6:
    return IRb6()


def _pose_error(robot: IRb6, q: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    Tq = robot.fk_station(q)[5]
    return float(np.linalg.norm(Tq[:3, 3] - T[:3, 3])), float(np.abs(Tq[:3, :3] - T[:3, :3]).max())


# ----------------------------------------------------------------------------- model
def test_protocol_and_parameters(robot: IRb6) -> None:
    assert isinstance(robot, Robot)
    assert robot.dof == 6 and len(robot.joint_names) == 6
    assert robot.lower.shape == robot.upper.shape == (6,)
    assert not robot.continuous.any()
    assert len(robot.link_names) == len(robot.link_radii_m) == 5
    assert robot.fixed_links == frozenset({0})
    assert all(i < j for i, j in robot.excluded_pairs)
    assert np.isclose(robot.upper[0], 0.851) and np.isclose(robot.upper[1], math.radians(170))
    # the paper's wedge: azimuths [0°, 20°] (from +x_s towards −z_s) are dead
    w0, w1 = robot.dead_wedge_azimuth_rad
    assert np.isclose(w0, 0.0) and np.isclose(w1, math.radians(20))
    with pytest.raises(PlannerlabError):
        IRb6(lower_arm_m=-1.0)
    with pytest.raises(PlannerlabError):
        IRb6(dead_wedge_side="left")
    with pytest.raises(PlannerlabError):
        IRb6(T_world_base=np.diag([2.0, 1.0, 1.0, 1.0]))


def test_zero_pose(robot: IRb6) -> None:
    # lower arm vertical, upper arm and approach horizontal: wrist at height λ1 + l2 and
    # distance l3 from the column, flange λ5 further out along the azimuth −170°.
    p, c = robot.tip(np.zeros(6))
    u = np.array([math.cos(math.radians(-170)), 0.0, -math.sin(math.radians(-170))])
    assert np.allclose(p, (0.670 + 0.095) * u + [0.0, 1.155, 0.0], atol=1e-12)
    assert np.allclose(c, u, atol=1e-12)


def test_batched_fk_equals_looped_fk() -> None:
    robot = IRb6(T_world_base=pose_matrix([0.2, -0.1, 0.3], [0.1, -0.2, 0.4]))
    Q = np.random.default_rng(3).uniform(robot.lower, robot.upper, size=(50, 6))
    F = robot.fk(Q)
    S = robot.link_segments(Q)
    assert F.shape == (50, 6, 4, 4) and S.shape == (50, 5, 2, 3)
    for k, q in enumerate(Q):
        assert np.allclose(F[k], robot.fk(q), atol=1e-14)
        assert np.allclose(S[k], robot.link_segments(q), atol=1e-14)
    p, n = robot.tip(Q)
    assert np.allclose(p, F[:, 5, :3, 3]) and np.allclose(n, F[:, 5, :3, 2])
    # capsules: column along the axis, arms of the nominal lengths
    lengths = np.linalg.norm(S[:, :, 1] - S[:, :, 0], axis=-1)
    assert np.allclose(lengths[:, 1:], [0.700, 0.455, 0.670, 0.095])


def test_jacobian_matches_finite_differences() -> None:
    robot = IRb6(T_world_base=pose_matrix([0.5, 0.0, -0.2], [0.3, 0.1, -0.7]))
    rng = np.random.default_rng(4)
    h = 1e-6
    for _ in range(20):
        q = rng.uniform(robot.lower, robot.upper)
        Jp, Jn = robot.tip_jacobian(q)
        for j in range(6):
            dq = np.zeros(6)
            dq[j] = h
            (pp, np_), (pm, nm) = robot.tip(q + dq), robot.tip(q - dq)
            assert np.allclose(Jp[:, j], (pp - pm) / (2 * h), atol=1e-8)
            assert np.allclose(Jn[:, j], (np_ - nm) / (2 * h), atol=1e-8)


def test_urdf_in_pybullet_matches_fk() -> None:
    robot = IRb6(T_world_base=pose_matrix([0.3, -0.2, 0.5], [0.1, 0.2, 0.3]))
    T = robot.T_world_base
    # quaternion (x, y, z, w) of the base rotation, via PyBullet's own rpy convention
    rpy_quat = pybullet.getQuaternionFromEuler([0.1, 0.2, 0.3])
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "irb6.urdf")
            with open(path, "w", encoding="utf-8") as f:
                f.write(robot.urdf())
            body = pybullet.loadURDF(
                path, T[:3, 3].tolist(), rpy_quat, useFixedBase=True, physicsClientId=cid
            )
        n = pybullet.getNumJoints(body, physicsClientId=cid)
        infos = [pybullet.getJointInfo(body, i, physicsClientId=cid) for i in range(n)]
        assert tuple(info[1].decode() for info in infos) == robot.joint_names
        link_index = {info[12].decode(): i for i, info in enumerate(infos)}
        rng = np.random.default_rng(5)
        for _ in range(25):
            q = rng.uniform(robot.lower, robot.upper)
            j = robot.urdf_joint_positions(q)
            assert np.allclose(robot.q_from_urdf_joint_positions(j), q, atol=1e-15)
            for i, value in enumerate(j):
                pybullet.resetJointState(body, i, float(value), physicsClientId=cid)
            frames = robot.fk(q)
            for k, name in enumerate(robot.link_frame_names):
                state = pybullet.getLinkState(
                    body, link_index[name], computeForwardKinematics=True, physicsClientId=cid
                )
                R = np.array(pybullet.getMatrixFromQuaternion(state[5])).reshape(3, 3)
                assert np.abs(np.array(state[4]) - frames[k, :3, 3]).max() <= 1e-6
                assert np.abs(R - frames[k, :3, :3]).max() <= 1e-6
    finally:
        pybullet.disconnect(physicsClientId=cid)


# ----------------------------------------------------------------------------- workspace
def test_wrist_annulus_hand_worked_and_brute_force(robot: IRb6) -> None:
    assert np.allclose(wrist_annulus_m(robot, H_W), (R_W_MIN, R_W_MAX), atol=1e-12)
    assert wrist_annulus_m(robot, 3.0) is None
    # brute force: θ2 on a fine grid, θ3 solved from the height
    l1, l2, l3 = robot.shoulder_height_m, robot.lower_arm_m, robot.upper_arm_m
    t2 = np.linspace(*robot.theta2_range_rad, 40001)
    for h in (0.625, 0.70, 0.80, 1.0, 1.2, 1.40):
        s = (h - l1 - l2 * np.cos(t2)) / l3
        ok = np.abs(s) <= 1.0
        t3 = np.arcsin(s[ok])
        keep = (t3 >= robot.theta3_range_rad[0]) & (t3 <= robot.theta3_range_rad[1])
        r = l2 * np.sin(t2[ok][keep]) + l3 * np.cos(t3[keep])
        iv = wrist_radius_intervals_m(robot, h)
        assert all(any(lo - 1e-9 <= x <= hi + 1e-9 for lo, hi in iv) for x in r)
        for lo, hi in iv:  # every interval end is attained
            assert np.abs(r - lo).min() < 1e-4 and np.abs(r - hi).min() < 1e-4
    # near the lowest wrist height (0.6179 m, θ2 = ±40°, θ3 = −40°) the slice splits
    assert len(wrist_radius_intervals_m(robot, 0.625)) == 2


# ----------------------------------------------------------------------------- IK
def test_round_trip_on_random_reachable_poses(robot: IRb6) -> None:
    rng = np.random.default_rng(6)
    Q = rng.uniform(robot.lower, robot.upper, size=(1200, 6))
    F = robot.fk_station(Q)[:, 5]
    for q, T in zip(Q, F, strict=True):
        answer = solve_ik(robot, T)
        assert answer.case == "unambiguous" and answer.ok, answer.reason
        assert any(np.abs(s - q).max() < 1e-7 for s in answer.solutions)
        for s in answer.solutions:
            assert np.all(s >= robot.lower) and np.all(s <= robot.upper)
            pos_err, rot_err = _pose_error(robot, s, T)
            assert pos_err <= 1e-9 and rot_err <= 1e-9


def test_pose_inputs_and_tool_transform(robot: IRb6) -> None:
    q = np.array([0.4, 0.3, 0.2, -0.1, 0.5, 1.0])
    T = robot.fk_station(q)[5]
    # (p, c, roll) form: for a non-vertical approach the roll is θ5
    answer = solve_ik(robot, (T[:3, 3], T[:3, 2], q[5]))
    assert any(np.allclose(s, q, atol=1e-9) for s in answer.solutions)
    # X = T · E  ⇒  flange_target(X, E) = T
    E = pose_matrix([0.0, 0.0, 0.12], [0.0, 0.3, 0.0])
    assert np.allclose(flange_target(T @ E, E), T, atol=1e-12)
    rows = format_ik_answer(answer)
    assert rows[0] == ("case", "unambiguous") and any(r[0] == "solution 1" for r in rows)


def test_bad_input_raises(robot: IRb6) -> None:
    with pytest.raises(PlannerlabError, match="finite"):
        solve_ik(robot, ((np.nan, 1.0, 0.4), (1.0, 0.0, 0.0), 0.0))
    with pytest.raises(PlannerlabError, match="zero"):
        solve_ik(robot, ((0.5, 1.0, 0.4), (0.0, 0.0, 0.0), 0.0))
    with pytest.raises(PlannerlabError, match="rigid"):
        solve_ik(robot, np.diag([1.0, 2.0, 1.0, 1.0]))
    with pytest.raises(PlannerlabError):
        solve_ik(robot, np.full((4, 4), np.nan))
    with pytest.raises(PlannerlabError):
        solve_with_lambda0(robot, np.eye(4), math.inf)


def test_ambiguous_1_hand_worked(robot: IRb6) -> None:
    # c = +z_s (horizontal, along the track), d = (0, h_w, 1.2): wrist height h_w.
    # k_rw = |λ5·c_z| = 0.095, k_rz = 0;  paper r_max = r_w,max + λ5 = 1.057468
    # R_wew = r_w,min + k_rw = 0.472532,  R_zew = r_max − k_rz = 1.057468
    # c_z > 0: [d_z − R_zew, d_z − R_wew] = [0.142532, 0.727468] (inside the track)
    # midpoint 0.435000
    answer = solve_ik(robot, ((0.0, H_W, 1.2), (0.0, 0.0, 1.0), 0.3))
    assert answer.case == "ambiguous_1"
    assert np.isclose(answer.inner_radius_m, 0.47253163759262465, atol=1e-9)
    assert np.isclose(answer.outer_radius_m, 1.0574683624073754, atol=1e-9)
    assert np.allclose(answer.lambda0_intervals_m, [(0.14253163759262444, 0.7274683624073753)])
    assert len(answer.solutions) == 1 and np.isclose(answer.solutions[0][0], 0.435)

    # c = −z_s, d_z = 0.2: [d_z + R_wew, d_z + R_zew] = [0.672532, 1.257468]
    # clipped to the track: [0.672532, 0.851], midpoint 0.761766
    answer = solve_ik(robot, ((0.0, H_W, 0.2), (0.0, 0.0, -1.0), 0.0))
    assert np.allclose(answer.lambda0_intervals_m, [(0.6725316375926247, 0.851)])
    assert np.isclose(answer.solutions[0][0], 0.7617658187963123)

    # c tilted 30° down: c = (0, −sin 30°, cos 30°), wrist height d_y − λ5·c_y = d_y + 0.0475
    # k_rw = 0.095·cos 30° = 0.082272, k_rz = 0.012728
    # R_wew = 0.377532 + 0.082272 = 0.459804,  R_zew = 1.057468 − 0.012728 = 1.044741
    # d_z = 1.1: [0.055259, 0.640196], midpoint 0.347728
    c = np.array([0.0, -0.5, math.sqrt(3) / 2])
    T = pose_from_approach(np.array([0.0, H_W - 0.0475, 1.1]), c, 0.7)
    answer = solve_ik(robot, T)
    assert np.isclose(answer.inner_radius_m, 0.4598040509521463, atol=1e-9)
    assert np.isclose(answer.outer_radius_m, 1.0447407757668972, atol=1e-9)
    assert np.allclose(answer.lambda0_intervals_m, [(0.05525922423310292, 0.6401959490478537)])
    assert np.isclose(answer.solutions[0][0], 0.3477275866404783)
    # every λ0 of the interval reaches the pose; just outside it does not
    for lam in np.linspace(0.0553, 0.6401, 7):
        sols = solve_with_lambda0(robot, T, lam).solutions
        assert sols and all(max(_pose_error(robot, s, T)) <= 1e-9 for s in sols)
    assert not solve_with_lambda0(robot, T, 0.66).ok


def test_ambiguous_2_hand_worked(robot: IRb6) -> None:
    # vertical approach c = −y_s, flange λ5 below the wrist: d_y = h_w − 0.095.
    # R_wew = r_w,min = 0.377532, R_zew = r_max − λ5 = r_w,max = 0.962468.
    # d = (0.3, ·, 0.4):
    #   A = 0.4 ± √(0.962468² − 0.3²) = 0.4 ± 0.914519 = [−0.514519, 1.314519]
    #   B = 0.4 ± √(0.377532² − 0.3²) = 0.4 ± 0.229195 = [0.170805, 0.629195]
    #   C = [0.4, 0.4 + 0.3·tan 20°] = [0.4, 0.509191]  (inside B)
    #   D = [−0.514519, 0.170805] ∪ [0.629195, 1.314519]
    #   E = [0, 0.170805] ∪ [0.629195, 0.851]; midpoints 0.085403, 0.740097
    p = np.array([0.3, H_W - 0.095, 0.4])
    answer = solve_ik(robot, (p, (0.0, -1.0, 0.0), 0.4))
    assert answer.case == "ambiguous_2"
    assert np.isclose(answer.inner_radius_m, R_W_MIN) and np.isclose(answer.outer_radius_m, R_W_MAX)
    assert np.allclose(
        answer.lambda0_intervals_m, [(0.0, 0.17080545952538734), (0.6291945404746127, 0.851)]
    )
    assert np.allclose([s[0] for s in answer.solutions], [0.08540272976269367, 0.7400972702373063])
    for s in answer.solutions:
        assert max(_pose_error(robot, s, pose_from_approach(p, (0, -1, 0), 0.4))) <= 1e-9

    # d = (0.5, ·, 0.3): |d_x| ≥ R_wew so no B
    #   A = 0.3 ± √(0.962468² − 0.5²) = 0.3 ± 0.822402 = [−0.522402, 1.122402]
    #   C = [0.3, 0.3 + 0.5·tan 20°] = [0.3, 0.481985]
    #   E = [0, 0.3] ∪ [0.481985, 0.851]; midpoints 0.15, 0.666493
    T = pose_from_approach(np.array([0.5, H_W - 0.095, 0.3]), np.array([0.0, -1.0, 0.0]), 0.0)
    answer = solve_ik(robot, T)
    assert np.allclose(answer.lambda0_intervals_m, [(0.0, 0.3), (0.3 + 0.5 * TAN20, 0.851)])
    assert np.allclose([s[0] for s in answer.solutions], [0.15, 0.6664925585665505])
    # a λ0 inside C puts the arm in the dead wedge
    assert solve_with_lambda0(robot, T, 0.4).reason_code == "dead_wedge"
    # the wedge on the other side: C = [0.3 − 0.181985, 0.3] = [0.118015, 0.3]
    #   E = [0, 0.118015] ∪ [0.3, 0.851]; midpoints 0.059007, 0.5755
    other = IRb6(dead_wedge_side="+z")
    answer = solve_ik(other, T)
    assert np.allclose(answer.lambda0_intervals_m, [(0.0, 0.3 - 0.5 * TAN20), (0.3, 0.851)])
    assert np.allclose([s[0] for s in answer.solutions], [(0.3 - 0.5 * TAN20) / 2, 0.5755])

    # c = +y_s with d_x = 0 is the paper's case 1 with c_z = 0: both intervals
    #   [d_z − R_zew, d_z − R_wew] ∪ [d_z + R_wew, d_z + R_zew], d_z = 0.45, wrist at h_w →
    #   [−0.512468, 0.072468] ∪ [0.827532, 1.412468] → E = [0, 0.072468] ∪ [0.827532, 0.851]
    answer = solve_ik(robot, ((0.0, H_W + 0.095, 0.45), (0.0, 1.0, 0.0), 0.0))
    assert answer.case == "ambiguous_2"
    assert np.allclose(answer.lambda0_intervals_m, [(0.0, 0.072468), (0.827532, 0.851)], atol=1e-6)
    assert len(answer.solutions) == 2


def test_theta5_continuity_across_range_end(robot: IRb6) -> None:
    p = np.array([0.6, 1.0, 0.3])
    c = np.array([0.8, -0.2, 0.3])
    # at roll = 180° both θ5 = ±180° give the same orientation
    both = solve_ik(robot, (p, c, math.pi))
    assert sorted(round(s[5], 9) for s in both.solutions) == [-round(math.pi, 9), round(math.pi, 9)]
    for start, end in ((2.8, math.pi), (-2.8, -math.pi)):
        theta5 = start
        for roll in np.linspace(start, end, 9):
            answer = solve_ik(robot, (p, c, roll), previous_theta5_rad=theta5)
            assert len(answer.solutions) == 1
            assert abs(answer.solutions[0][5] - theta5) < 0.1
            theta5 = answer.solutions[0][5]
        assert np.isclose(theta5, end, atol=1e-9)


def test_every_unreachable_reason(robot: IRb6) -> None:
    q = np.array([0.5, 0.3, 0.1, 0.0, 0.2, 0.0])
    T = robot.fk_station(q)[5]
    T[2, 3] += 1.0  # λ0 = d_z − d_x·c_z/c_x moves with d_z: 1.5 m
    answer = solve_ik(robot, T)
    assert answer.reason_code == "outside_track" and "track" in answer.reason

    answer = solve_ik(robot, ((2.0, 1.0, 0.4), (1.0, 0.0, 0.0), 0.0))
    assert answer.reason_code == "outside_annulus" and "annulus" in answer.reason

    q_wedge = np.array([0.4, math.radians(175.0), 0.1, 0.0, 0.2, 0.0])  # θ1 past 170°
    answer = solve_ik(robot, robot.fk_station(q_wedge)[5])
    assert answer.reason_code == "dead_wedge" and "wedge" in answer.reason

    # approach pointing back at the column: θ4 = 180°
    answer = solve_ik(robot, ((-0.8, 1.0, 0.4), (1.0, 0.0, 0.0), 0.0))
    assert answer.reason_code == "joint_limit" and "θ4" in answer.reason

    # c_x = 0, d_x ≠ 0: the approach plane never holds the column axis
    answer = solve_ik(robot, ((0.5, 1.0, 0.4), (0.0, 0.0, 1.0), 0.0))
    assert answer.reason_code == "no_arm_plane"

    # a λ0 off the unambiguous value
    answer = solve_with_lambda0(robot, robot.fk_station(q)[5], 0.7)
    assert answer.reason_code == "no_arm_plane"
    assert solve_with_lambda0(robot, robot.fk_station(q)[5], 0.9).reason_code == "outside_track"


# ----------------------------------------------------------------------------- goals
def test_goal_sampling(robot: IRb6) -> None:
    rng = np.random.default_rng(7)
    # vertical approach, zero tolerances: λ0 is drawn over E = [0, 0.1708] ∪ [0.6292, 0.851]
    p = np.array([0.3, H_W - 0.095, 0.4])
    c = np.array([0.0, -1.0, 0.0])
    lams = []
    for _ in range(30):
        q = sample_irb6_goal(robot, p, c, 0.0, 0.0, rng)
        assert q is not None and np.all(q >= robot.lower) and np.all(q <= robot.upper)
        tp, tc = robot.tip(q)
        assert np.linalg.norm(tp - p) < 1e-9 and np.allclose(tc, c, atol=1e-9)
        lams.append(q[0])
    lams = np.array(lams)
    assert np.all((lams <= 0.1709) | (lams >= 0.6291))
    assert (lams < 0.2).any() and (lams > 0.6).any()

    # with tolerances, world frame with a moved base
    moved = IRb6(T_world_base=pose_matrix([1.0, 0.0, 2.0], [0.0, 0.0, 0.5]))
    q0 = np.array([0.3, 0.5, 0.2, -0.2, -0.4, 0.0])
    p_w, c_w = moved.tip(q0)
    for _ in range(10):
        q = sample_irb6_goal(moved, p_w, c_w, 0.01, 5.0, rng)
        assert q is not None
        tp, tc = moved.tip(q)
        assert np.linalg.norm(tp - p_w) <= 0.01 + 1e-9
        assert math.degrees(math.acos(min(1.0, float(tc @ c_w)))) <= 5.0 + 1e-6

    # same seed, same goal
    a = sample_irb6_goal(robot, p, c, 0.01, 3.0, np.random.default_rng(11))
    b = sample_irb6_goal(robot, p, c, 0.01, 3.0, np.random.default_rng(11))
    assert a is not None and np.array_equal(a, b)
    # unreachable region
    far = sample_irb6_goal(robot, np.array([5.0, 1.0, 0.4]), c, 0.01, 3.0, rng, max_attempts=8)
    assert far is None
    with pytest.raises(PlannerlabError):
        sample_irb6_goal(robot, p, c, -1.0, 3.0, rng)

"""Arm-Z kinematics: the paper's shapes, batched = looped, Jacobians vs finite differences."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix

ROBOT = ArmZ()
angles = arrays(np.float64, ROBOT.dof, elements=st.floats(-np.pi, np.pi))


def test_all_pi_is_the_straight_column_of_the_papers_reach():
    q = np.full(ROBOT.dof, np.pi)
    p, n = ROBOT.tip(q)
    reach = ROBOT.delta_z_m / 2 + ROBOT.dof * ROBOT.chord_m  # 0.35 + 23 * 0.716
    assert np.isclose(p[2], reach, atol=1e-9)
    assert abs(reach - (0.35 + 23 * 0.716)) < 0.01
    # The paper's δy/δz is tan(ζ/2) to 4 digits only, so the column leans by ~1e-5 rad.
    np.testing.assert_allclose(p[:2], [0.0, ROBOT.delta_y_m], atol=1e-5)
    # faces alternate ±ζ/2 about the chord: after 23 joints the top face leans by ζ/2
    assert np.isclose(np.degrees(np.arccos(n[2])), 11.25, atol=1e-3)
    origins = ROBOT.fk(q)[1:, :3, 3]
    np.testing.assert_allclose(
        origins[:, :2], np.tile([0.0, ROBOT.delta_y_m], (ROBOT.dof + 1, 1)), atol=1e-5
    )


def test_all_zero_closes_a_ring_after_16_modules():
    F = ROBOT.fk(np.zeros(ROBOT.dof))
    np.testing.assert_allclose(np.linalg.inv(F[1]) @ F[17], np.eye(4), atol=1e-9)
    # and not before: 15 modules leave a gap of one chord
    gap = np.linalg.norm(F[16, :3, 3] - F[1, :3, 3])
    assert np.isclose(gap, ROBOT.chord_m, atol=1e-9)


def test_alternating_zero_pi_is_a_staircase_not_straight():
    q = np.where(np.arange(ROBOT.dof) % 2 == 0, 0.0, np.pi)
    p, _ = ROBOT.tip(q)
    assert abs(p[1] - ROBOT.delta_y_m) > 3.0  # it walks sideways, step by step
    assert p[2] < ROBOT.tip(np.full(ROBOT.dof, np.pi))[0][2] - 0.5


def test_module_chord_and_symmetry():
    assert np.isclose(ROBOT.chord_m, np.hypot(0.1397, 0.7023))
    assert np.isclose(-ROBOT.delta_y_m / ROBOT.delta_z_m, np.tan(ROBOT.zeta_rad / 2), rtol=1e-3)
    seg = ROBOT.link_segments(np.random.default_rng(0).uniform(-np.pi, np.pi, ROBOT.dof))
    lengths = np.linalg.norm(seg[1:, 1] - seg[1:, 0], axis=1)
    np.testing.assert_allclose(lengths, ROBOT.chord_m, atol=1e-12)


def test_batched_fk_equals_one_at_a_time():
    Q = np.random.default_rng(1).uniform(-np.pi, np.pi, (7, ROBOT.dof))
    batch = ROBOT.fk(Q)
    assert batch.shape == (7, ROBOT.dof + 2, 4, 4)
    for k in range(7):
        np.testing.assert_allclose(batch[k], ROBOT.fk(Q[k]), atol=1e-12)
    p, n = ROBOT.tip(Q)
    assert p.shape == (7, 3) and n.shape == (7, 3)


def test_base_pose_moves_everything_rigidly():
    T = pose_matrix([1.0, -2.0, 0.5], np.deg2rad([10.0, -20.0, 30.0]))
    moved = ArmZ(T_world_base=T)
    q = np.random.default_rng(2).uniform(-np.pi, np.pi, ROBOT.dof)
    np.testing.assert_allclose(moved.fk(q), T @ ROBOT.fk(q), atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(angles)
def test_tip_jacobians_match_finite_differences(q):
    J_p, J_n = ROBOT.tip_jacobian(q)
    h = 1e-6
    for i in range(ROBOT.dof):
        dq = np.zeros(ROBOT.dof)
        dq[i] = h
        p1, n1 = ROBOT.tip(q + dq)
        p0, n0 = ROBOT.tip(q - dq)
        np.testing.assert_allclose(J_p[:, i], (p1 - p0) / (2 * h), atol=1e-6)
        np.testing.assert_allclose(J_n[:, i], (n1 - n0) / (2 * h), atol=1e-6)


@settings(max_examples=30, deadline=None)
@given(angles)
def test_tip_normal_is_unit_and_frames_are_rotations(q):
    F = ROBOT.fk(q)
    R = F[:, :3, :3]
    np.testing.assert_allclose(
        R @ np.swapaxes(R, 1, 2), np.tile(np.eye(3), (len(F), 1, 1)), atol=1e-9
    )
    assert np.isclose(np.linalg.norm(ROBOT.tip(q)[1]), 1.0)


def test_excluded_pairs_are_the_chain_neighbours():
    pairs = ROBOT.excluded_pairs
    assert (0, 4) in pairs and (0, 5) not in pairs and (10, 14) in pairs
    assert all(j - i < 5 for i, j in pairs)


def test_urdf_names_every_joint_and_frame():
    text = ROBOT.urdf()
    assert text.count('type="continuous"') == ROBOT.dof
    for name in ROBOT.joint_names + ROBOT.link_frame_names:
        assert f'name="{name}"' in text
    assert 'mass value="1.0"' in text and 'effort="100.0"' in text
    assert 'ixx="0.25"' in text and 'izz="0.5"' in text


@settings(max_examples=30, deadline=None)
@given(angles)
def test_tip_and_jacobian_is_tip_and_tip_jacobian_bit_for_bit(q):
    """One forward kinematics for both (what the numeric IK calls each step): the very
    numbers of ``tip`` and of the Jacobian made with ``np.cross``."""
    p, n, J_p, J_n = ROBOT.tip_and_jacobian(q)
    p_ref, n_ref = ROBOT.tip(q)
    F = ROBOT.fk(q)
    z, o = F[1:-1, :3, 2], F[1:-1, :3, 3]
    assert np.array_equal(p, p_ref) and np.array_equal(n, n_ref)
    assert np.array_equal(J_p, np.cross(z, F[-1, :3, 3] - o).T)
    assert np.array_equal(J_n, np.cross(z, F[-1, :3, 2]).T)
    J_p2, J_n2 = ROBOT.tip_jacobian(q)
    assert np.array_equal(J_p2, J_p) and np.array_equal(J_n2, J_n)

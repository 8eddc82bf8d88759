"""Joint-space path measures (``robots/paths.py``): the roughness planners are compared on."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.robots.paths import roughness

FREE = np.zeros(3, dtype=bool)


def test_a_straight_path_has_no_roughness_however_it_is_cut():
    a, b = np.array([0.0, 1.0, -1.0]), np.array([2.0, -1.0, 0.5])
    two = np.vstack([a, b])
    many = a + np.linspace(0.0, 1.0, 17)[:, None] * (b - a)
    uneven = a + np.array([0.0, 0.01, 0.02, 0.5, 0.99, 1.0])[:, None] * (b - a)
    for path in (two, many, uneven):
        assert roughness(path, FREE) == pytest.approx(0.0, abs=1e-12)


def test_one_right_angle_turn_costs_its_square_wherever_the_waypoints_are():
    # an L: 1 rad along x, then 1 rad along y; resampled, the corner falls inside one
    # sample interval or on a sample: the turning angles sum to pi/2 either way, and
    # their squares to (pi/2)^2 when it falls on a sample (199 intervals of 2/199 rad:
    # the corner at arc length 1 is a sample only for an odd count of intervals)
    L = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    assert roughness(L, FREE, n_samples=3) == pytest.approx((np.pi / 2) ** 2)
    r = roughness(L, FREE)
    assert 2 * (np.pi / 4) ** 2 - 1e-9 <= r <= (np.pi / 2) ** 2 + 1e-9
    # the same L cut into more waypoints has the same roughness
    dense = np.vstack([np.linspace(L[0], L[1], 9), np.linspace(L[1], L[2], 5)[1:]])
    assert roughness(dense, FREE) == pytest.approx(r, rel=1e-9)


def test_doubling_back_costs_pi_squared():
    path = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert roughness(path, FREE, n_samples=3) == pytest.approx(np.pi**2)


def test_a_wrapping_joint_goes_the_short_way_round():
    wrap = np.array([True, False, False])
    # 3.0 -> -3.0 is a step of 2 pi - 6 = 0.28 rad forward, then on to -2.9: straight on
    path = np.array([[3.0, 0.0, 0.0], [-3.0, 0.0, 0.0], [-2.9, 0.0, 0.0]])
    assert roughness(path, wrap) == pytest.approx(0.0, abs=1e-12)
    assert roughness(path, FREE) > 1.0  # unwrapped it doubles back


def test_repeated_and_single_states_have_none():
    assert roughness(np.zeros((1, 3)), FREE) == 0.0
    assert roughness(np.zeros((4, 3)), FREE) == 0.0
    with pytest.raises(ValueError, match="at least 3"):
        roughness(np.zeros((2, 3)), FREE, n_samples=2)

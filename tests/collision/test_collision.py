"""The FCL checker against geometry worked out by hand."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix

ROBOT = ArmZ()
COLUMN = np.full(ROBOT.dof, np.pi)
R = ROBOT.collision_radius_m
Y_AXIS = ROBOT.delta_y_m  # the straight column stands on the line x = 0, y = δy


def wall_at(x_face_m: float) -> Box:
    """A wall whose near face is the plane x = x_face_m, 20 m tall."""
    return Box("wall", pose_matrix([x_face_m + 0.25, 0.0, 10.0], [0, 0, 0]), [0.5, 6.0, 20.0])


@pytest.mark.parametrize("gap_m", [0.1, 0.5, 2.0])
def test_column_beside_a_wall_has_clearance_gap_minus_radius(gap_m):
    checker = CollisionChecker(ROBOT, Scene((wall_at(R + gap_m),)))
    assert checker.is_valid(COLUMN)
    assert checker.clearance(COLUMN, include_self=False) == pytest.approx(gap_m, abs=1e-5)


def test_column_into_a_wall_names_every_module_in_it():
    checker = CollisionChecker(ROBOT, Scene((wall_at(R - 0.05),)))
    assert not checker.is_valid(COLUMN)
    pairs = checker.colliding_pairs(COLUMN)
    # the fixed base module is exempt; every moving module lies 0.05 m into the wall
    assert {a for a, _ in pairs} == {f"module_{i}" for i in range(1, 24)}
    assert {b for _, b in pairs} == {"wall"}
    assert checker.clearance(COLUMN, include_self=False) == pytest.approx(-0.05, abs=1e-4)


def test_sphere_and_cylinder_at_known_distances():
    z = 8.0
    sphere = Sphere("ball", pose_matrix([0.0, Y_AXIS + R + 0.3 + 1.0, z], [0, 0, 0]), 1.0)
    checker = CollisionChecker(ROBOT, Scene((sphere,)))
    assert checker.clearance(COLUMN, include_self=False) == pytest.approx(0.3, abs=1e-5)
    # a horizontal cylinder across the column's axis at its top cuts it
    bar = Cylinder("bar", pose_matrix([0.0, Y_AXIS, 12.0], [0, np.pi / 2, 0]), 0.2, 6.0)
    checker = CollisionChecker(ROBOT, Scene((bar,)))
    assert ("module_16", "bar") in checker.colliding_pairs(COLUMN)


def test_the_ring_collides_with_itself_where_it_closes():
    checker = CollisionChecker(ROBOT, Scene())
    q = np.zeros(ROBOT.dof)
    assert not checker.is_valid(q)
    pairs = checker.colliding_pairs(q)
    assert ("module_1", "module_17") in pairs  # module 17 lies on module 1
    assert all(int(b.split("_")[1]) - int(a.split("_")[1]) >= 5 for a, b in pairs)


def test_straight_column_does_not_collide_with_itself():
    assert CollisionChecker(ROBOT, Scene()).is_valid(COLUMN)


def test_batch_equals_one_at_a_time_and_counts_checks():
    scene = Scene((wall_at(2.0), Sphere("s", pose_matrix([-3, 2, 6], [0, 0, 0]), 1.5)))
    checker = CollisionChecker(ROBOT, scene)
    Q = np.random.default_rng(3).uniform(-np.pi, np.pi, (60, ROBOT.dof))
    batch = checker.valid_batch(Q)
    assert checker.checks == 60
    single = np.array([checker.is_valid(q) for q in Q])
    assert checker.checks == 120
    np.testing.assert_array_equal(batch, single)
    assert 0 < batch.sum() < 60  # both kinds occur


def test_path_check_finds_the_first_bad_edge():
    checker = CollisionChecker(ROBOT, Scene((wall_at(1.2),)))
    tilt = COLUMN.copy()
    tilt[0] = np.pi - 0.5  # the base joint swings the whole column towards +x
    away = COLUMN.copy()
    away[0] = np.pi + 0.5
    # towards +x or -x? find which swing hits the wall
    hits = [not checker.is_valid(q) for q in (tilt, away)]
    assert sum(hits) == 1
    bad = tilt if hits[0] else away
    good = away if hits[0] else tilt
    ok = checker.check_path(np.array([COLUMN, good, COLUMN]), 0.02)
    assert ok.valid and ok.states_checked > 3
    res = checker.check_path(np.array([COLUMN, good, COLUMN, bad]), 0.02)
    assert not res.valid and res.first_invalid_edge == 2
    assert all(b == "wall" for _, b in res.pairs)


def test_continuous_joints_are_interpolated_the_short_way():
    checker = CollisionChecker(ROBOT, Scene())
    a = COLUMN.copy()
    b = COLUMN.copy()
    b[3] = -np.pi + 0.1  # 0.1 rad from pi across the wrap
    res = checker.check_path(np.array([a, b]), 0.02)
    assert res.states_checked == 6  # 0.1 / 0.02 = 5 intervals, not 6.18 / 0.02

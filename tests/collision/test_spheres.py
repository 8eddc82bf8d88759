"""The clearance field's compiled geometry (``collision/spheres.py``) on the compiled
robot–scene model's kinematics, for every robot family with a chain and a tip: link axes
and the tip equal the robot's own kinematics, gradients through the chain (a coupling,
sliding joints, folded axes) equal finite differences of them; and the model a checker
builds gives the same chain as the robot's chain packed alone."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.spheres import (
    frames,
    kin,
    link_ends,
    model_sphere_chain,
    pair_spheres,
    point_gradient,
    sphere_chain,
    tip_jacobians,
    tip_pose,
)
from plannerlab.problem.catalog import load_problem

PROBLEMS = [
    "armz_pocket",  # 23 turning joints about z
    "irb6_case1",  # a sliding joint, axes not z, a coupling
    "continuum_case1",  # a sliding joint along x, then turns
    "problems/urdf/panda/bookshelf_small_0001.toml",  # a URDF chain
]


def _states(robot, k: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo = np.maximum(robot.lower, -np.pi)
    hi = np.minimum(robot.upper, np.pi)
    return lo + rng.uniform(0.05, 0.95, (k, robot.dof)) * (hi - lo)


@pytest.fixture(scope="module", params=PROBLEMS)
def robot(request):
    return load_problem(request.param).robot


def _checker_model(robot):
    """The compiled model a checker of the robot (no obstacles) builds."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene

    return CollisionChecker(robot, Scene(()), "core").model


@pytest.mark.parametrize("source", ["chain_alone", "checker_model"])
def test_link_axes_and_tip_are_the_robots(robot, source):
    """On the robot's chain packed alone and on a checker's compiled model alike."""
    if source == "chain_alone":
        ch = sphere_chain(robot)
    else:
        ch = model_sphere_chain(_checker_model(robot), robot)
    for q in _states(robot, 10, 0):
        Bf = frames(q, ch)
        a, b = link_ends(Bf, ch)
        seg = robot.link_segments(q)
        np.testing.assert_allclose(a, seg[:, 0], atol=1e-12)
        np.testing.assert_allclose(b, seg[:, 1], atol=1e-12)
        p, n = tip_pose(Bf, ch)
        p_ref, n_ref = robot.tip(q)
        np.testing.assert_allclose(p, p_ref, atol=1e-12)
        np.testing.assert_allclose(n, n_ref, atol=1e-12)


def test_gradients_through_the_chain_are_the_derivatives(robot):
    """n · ∂p/∂q of a point on each link (its axis' midpoint) and the tip's Jacobians
    against central differences of the robot's own kinematics, on a checker's model."""
    ch = model_sphere_chain(_checker_model(robot), robot)
    kn = kin(ch)
    rng = np.random.default_rng(1)
    h = 1e-6
    for q in _states(robot, 3, 2):
        Bf = frames(q, ch)
        a, b = link_ends(Bf, ch)
        mid = (a + b) / 2.0
        n = rng.normal(size=(len(mid), 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        E = np.eye(robot.dof) * h
        seg_p = robot.link_segments(q[None] + E)
        seg_m = robot.link_segments(q[None] - E)
        d_mid = ((seg_p[..., 0, :] + seg_p[..., 1, :]) - (seg_m[..., 0, :] + seg_m[..., 1, :])) / (
            4.0 * h
        )  # (dof, L, 3)
        for l in range(len(mid)):
            out = np.zeros(robot.dof)
            point_gradient(Bf, kn, kn[3][l], mid[l], (n[l][0], n[l][1], n[l][2]), 1.0, out)
            np.testing.assert_allclose(out, d_mid[:, l] @ n[l], atol=1e-6)
        p, nt = tip_pose(Bf, ch)
        Jp, Jn = tip_jacobians(Bf, ch, p, nt, robot.dof)
        tp, tn = robot.tip(q[None] + E)
        tm, tnm = robot.tip(q[None] - E)
        np.testing.assert_allclose(Jp, ((tp - tm) / (2 * h)).T, atol=1e-6)
        np.testing.assert_allclose(Jn, ((tn - tnm) / (2 * h)).T, atol=1e-6)


def test_a_chain_whose_capsules_are_not_its_links_is_refused():
    robot = load_problem("armz_pocket").robot

    class Split:
        """Arm-Z with one link more than its chain has capsules."""

        def __getattr__(self, name):
            return getattr(robot, name)

        @property
        def link_radii_m(self):
            return np.append(robot.link_radii_m, 0.1)

    with pytest.raises(ValueError, match="one capsule per link"):
        sphere_chain(Split())


def test_a_checker_model_of_another_chain_is_refused_by_name():
    """A checker's model of a six-module Arm-Z given with a
    24-module one is refused, naming the robot and both counts."""
    from plannerlab.robots.armz.model import ArmZ

    short, long = ArmZ(n_modules=6), ArmZ(n_modules=24)
    with pytest.raises(ValueError, match=r"'armz'.*6 capsules for 24 links"):
        model_sphere_chain(_checker_model(short), long)


def test_pair_bookkeeping_is_the_pairs_own():
    """:func:`pair_spheres` on a small field, against the bookkeeping written out: scene
    pairs obstacle by obstacle, then the self pairs; each self pair's link pair; the
    links' first and last spheres (a link without spheres: −1)."""
    link = np.array([0, 0, 1, 1, 1, 3])  # link 2 holds no sphere
    scene_idx = np.array([2, 3, 4, 5])
    self_a = np.array([0, 0, 1, 2, 4])
    self_b = np.array([5, 2, 3, 5, 5])
    a, b, lp_of_row, lp_links, ends = pair_spheres(scene_idx, 2, self_a, self_b, link)
    np.testing.assert_array_equal(a, [2, 3, 4, 5, 2, 3, 4, 5, 0, 0, 1, 2, 4])
    np.testing.assert_array_equal(b, [-1] * 8 + [5, 2, 3, 5, 5])
    np.testing.assert_array_equal(lp_links, [[0, 1], [0, 3], [1, 3]])
    np.testing.assert_array_equal(lp_of_row, [1, 0, 0, 2, 2])
    np.testing.assert_array_equal(ends, [[0, 1], [2, 4], [-1, -1], [5, 5]])

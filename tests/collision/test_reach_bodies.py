"""The metric edge bound per rigid body (``collision/reach.py``, issue 35): it holds (never
below the fastest point of any capsule, measured on an independent forward kinematics of
the robot's chain at random states, by small joint steps) for every robot family, and on
a mesh robot with finer covers it is within a small factor of that fastest point, where
the capsules' chain sum alone is many times it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.reach import (
    body_reach_bounds,
    capsule_reach_bounds,
    joint_reach_m,
    reach_bounds,
)
from plannerlab.problem.load import parse_problem
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.continuum.model import ContinuumChain
from plannerlab.robots.irb6.model import IRb6
from plannerlab.robots.urdf.model import UrdfChain

DATA = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"
PANDA = PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml"


def _rot(u: np.ndarray, a: float) -> np.ndarray:
    """Rotation by a about unit u (Rodrigues)."""
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def body_frames(robot, q: np.ndarray) -> np.ndarray:
    """Every body's world frame (m + 1, 4, 4) from ``chain_data()`` in plain numpy (not
    the compiled kinematics): body 0 at ``T_world_base``, joint i moves body i + 1."""
    data = robot.chain_data()
    parent, pre, axes, prismatic = data[0], data[1], data[2], data[3]
    v = q if len(data) == 7 or data[7] is None else np.asarray(data[7]) @ q
    F = [np.asarray(robot.T_world_base, dtype=float)]
    for i in range(len(parent)):
        M = np.eye(4)
        u = np.asarray(axes[i], dtype=float) / np.linalg.norm(axes[i])
        if prismatic[i]:
            M[:3, 3] = u * v[i]
        else:
            M[:3, :3] = _rot(u, v[i])
        F.append(F[int(parent[i])] @ np.asarray(pre[i], dtype=float) @ M)
    return np.array(F)


def fastest_points(robot, Q: np.ndarray, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Per state joint and capsule, over the states Q, by central differences of each
    body's frame (m per rad or per m): the fastest end of the capsule's axis, and the
    fastest point of the capsule. The capsule at q + Δ lies within (the ends' largest
    displacement) of the capsule at q (it is its axis grown by its radius), which is what
    a margin and a certified stretch need; a point ``x + r n`` of it (x on the axis, n a
    unit vector) moves at ``v(x) + r ω × n``, whose largest norm over n is
    ``sqrt(|v∥|² + (|v⊥| + r |ω|)²)`` (parts along and across ω), over x at an end of the
    axis (the norm is convex in x): more when the capsule spins about its own axis, which
    moves none of its shape."""
    data = robot.chain_data()
    body, cap_a, cap_b = np.asarray(data[4]), np.asarray(data[5]), np.asarray(data[6])
    radii = np.asarray(robot.link_radii_m, dtype=float)
    out = np.zeros((robot.dof, len(radii)))
    out_ends = np.zeros((robot.dof, len(radii)))
    for q in Q:
        F0 = body_frames(robot, q)
        seg = robot.link_segments(q)
        ends = np.stack(
            [
                np.einsum("lij,lj->li", F0[body, :3, :3], cap_a) + F0[body, :3, 3],
                np.einsum("lij,lj->li", F0[body, :3, :3], cap_b) + F0[body, :3, 3],
            ],
            axis=1,
        )
        assert np.abs(ends - seg).max() < 1e-9  # the numpy kinematics is the robot's
        for j in range(robot.dof):
            e = np.zeros(robot.dof)
            e[j] = h
            Fp, Fm = body_frames(robot, q + e), body_frames(robot, q - e)
            dR = (Fp[:, :3, :3] - Fm[:, :3, :3]) / (2 * h) @ np.transpose(F0[:, :3, :3], (0, 2, 1))
            omega = np.stack([dR[:, 2, 1], dR[:, 0, 2], dR[:, 1, 0]], axis=1)[body]  # (L, 3)
            w = np.linalg.norm(omega, axis=1)
            u = omega / np.maximum(w, 1e-300)[:, None]
            for x in (cap_a, cap_b):
                pp = np.einsum("lij,lj->li", Fp[body, :3, :3], x) + Fp[body, :3, 3]
                pm = np.einsum("lij,lj->li", Fm[body, :3, :3], x) + Fm[body, :3, 3]
                v = (pp - pm) / (2 * h)
                along = np.einsum("li,li->l", v, u) * (w > 1e-12)
                across = np.sqrt(np.maximum(np.sum(v * v, axis=1) - along**2, 0.0))
                speed = np.sqrt(along**2 + (across + radii * w) ** 2)
                out[j] = np.maximum(out[j], speed)
                out_ends[j] = np.maximum(out_ends[j], np.linalg.norm(v, axis=1))
    return out_ends, out


def mesh_arm(tmp: Path, fine: int) -> UrdfChain:
    return UrdfChain(
        DATA / "mesh_arm.urdf",
        "tool",
        mesh_paths=(DATA / "pkgroot",),
        cover_excess_m=0.02,
        cover_cache_dir=tmp / "covers",
        self_cover_max_primitives=fine,
    )


@pytest.fixture(scope="module")
def covers(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One cover cache for the mesh arm's tests (its finer covers take a while)."""
    return tmp_path_factory.mktemp("reach_covers")


ROBOTS = {
    "armz": lambda tmp: ArmZ(
        n_modules=24, T_world_base=pose_matrix([1.0, -2.0, 0.5], [0.1, -0.2, 0.3])
    ),
    "irb6": lambda tmp: IRb6(T_world_base=pose_matrix([0.3, -0.2, 0.1], [0.0, 0.0, 0.7])),
    "continuum_chain": lambda tmp: ContinuumChain(
        n_links=30, T_world_base=pose_matrix([0.2, 0.1, 0.0], [0.0, 0.0, 40.0])
    ),
    "panda_spheres": lambda tmp: parse_problem(PANDA).robot,
    "mesh_arm_finer_covers": lambda tmp: mesh_arm(tmp, 16),
}


def _states(robot, n: int, seed: int) -> np.ndarray:
    cont = np.asarray(robot.continuous, dtype=bool)
    lo = np.where(cont, -np.pi, robot.lower)
    hi = np.where(cont, np.pi, robot.upper)
    return np.random.default_rng(seed).uniform(lo, hi, (n, robot.dof))


@pytest.mark.parametrize("which", sorted(ROBOTS))
def test_the_bound_holds_on_every_family(which: str, covers: Path) -> None:
    robot = ROBOTS[which](covers)
    ends, points = fastest_points(robot, _states(robot, 25, 4))
    reach, W, _ = reach_bounds(robot)
    tol = 1e-6 * (1.0 + points)
    assert np.all(W >= ends - tol), np.argwhere(W < ends - tol)[:5]
    assert np.all(reach >= ends.max(axis=1) - tol.max(axis=1))
    assert np.array_equal(reach, joint_reach_m(robot))
    # both bounds hold on their own, and the bound used is the smaller; the bodies' holds
    # every point, a capsule spinning about its own axis included
    by_body = body_reach_bounds(robot)
    assert by_body is not None
    caps = capsule_reach_bounds(robot)
    rigid = caps[2]  # the capsules' bound holds where the joint moves its links rigidly
    for r, w, rows in ((*by_body, np.ones(robot.dof, bool)), (*caps[:2], rigid)):
        assert np.all(w[rows] >= ends[rows] - tol[rows])
        assert np.all(r[rows] >= ends[rows].max(axis=1) - tol[rows].max(axis=1))
    assert np.all(by_body[1] >= points - tol), np.argwhere(by_body[1] < points - tol)[:5]
    assert np.array_equal(W[rigid], np.minimum(by_body[1], caps[1])[rigid])
    assert np.array_equal(W[~rigid], by_body[1][~rigid])


def test_the_capsules_bound_alone_fails_irb6s_coupled_joints() -> None:
    """Why the bodies' bound alone is used where a joint moves its links non-rigidly:
    IRb-6's third joint (an absolute angle) turns its link and the next about two axes;
    the capsules' bound, one rotation fitted to both, is below the speed seen."""
    robot = IRb6()
    ends, _ = fastest_points(robot, _states(robot, 25, 4))
    W, rigid = capsule_reach_bounds(robot)[1:]
    assert not rigid[2] and np.any(W[2] < 0.9 * ends[2])
    assert np.all(reach_bounds(robot)[1][2] >= ends[2] - 1e-6)


def test_the_bound_is_tight_on_a_mesh_robot_with_finer_covers(covers: Path) -> None:
    """Within 1.5x the fastest point seen per joint; the capsules' chain sum alone (the
    bound before, which sums a mesh link of many capsules as that many links) is more than
    5x it on some joint."""
    robot = mesh_arm(covers, 16)
    assert len(robot.self_only_links) > 10  # finer covers: many capsules a link
    seen = fastest_points(robot, _states(robot, 40, 9))[1].max(axis=1)
    reach = joint_reach_m(robot)
    assert np.all(reach <= 1.5 * seen), reach / seen
    assert np.max(capsule_reach_bounds(robot)[0] / seen) > 5.0


def test_a_robot_without_a_chain_keeps_the_capsules_bound() -> None:
    class NoChain:
        def __init__(self) -> None:
            self.inner = ArmZ(n_modules=6)

        def __getattr__(self, name: str):
            if name == "chain_data":
                raise AttributeError(name)
            return getattr(self.inner, name)

    robot = NoChain()
    assert body_reach_bounds(robot) is None  # type: ignore[arg-type]
    assert np.array_equal(reach_bounds(robot)[1], capsule_reach_bounds(robot)[1])  # type: ignore[arg-type]

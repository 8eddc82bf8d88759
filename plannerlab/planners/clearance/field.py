"""A smooth clearance field: signed distances of the robot's links to the scene and to
each other, with their gradient in joint space.

Each link capsule (axis segment ``a → b``, radius ``r``) is represented by ``k`` spheres of
radius ``r`` centred at ``p = a + t (b − a)`` for evenly spaced ``t`` in [0, 1], spaced at
most ``0.4 r`` apart (so the spheres under-cover the capsule by less than 2 % of r).

**Bounded.** A thin link (a 1-mm radius) would need thousands of spheres at that spacing,
and the pairs grow as their square: the spheres are at most :data:`MAX_SPHERES` in all,
so the spacing of the links whose ``0.4 r`` would pass that grows, every link alike,
to ``max(0.4 r, spacing)`` with one spacing for the whole robot (the field then
under-covers those links a little more; it only steers, the checker decides). The pair
lists are built with numpy, and a ``stop()`` the builder is given (the leg's time limit)
is asked between the links: building a field counts against the solve's time.
Obstacles are exact (boxes, cylinders, spheres: signed point distances), so the field is
a close, slightly optimistic estimate of the checker's distances; validity is always
decided by the collision checker, the field only steers. The pairs are the checker's
(fixed links never against the scene, the robot's ``excluded_pairs`` never against each
other).

The gradient of a distance ``d`` w.r.t. q is ``n · J_p`` with ``n`` the unit direction that
increases ``d`` when the sphere centre moves along it and ``J_p`` the Jacobian of the centre,
``(1 − t) J_a + t J_b`` from the Jacobians of the segment end points. For an Arm-Z those
are analytic (joint ``j`` turns about the z axis of frame ``j``); for any other robot they
come from one batched forward kinematics of ``dof + 1`` states (finite differences).

Only numpy here; no collision library.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere, touch_mask
from plannerlab.robots.base import Array, Robot

#: the most spheres a field holds (its self pairs grow as the square: 5e5 at most, some
#: 25 MB and tens of milliseconds per state evaluated in numpy; Arm-Z holds 95, the
#: continuum chain of continuum_case3 680)
MAX_SPHERES = 1000


class SetupStopped(PlannerlabError):
    """A planner's set-up (a field, a grid) stopped because its ``stop()`` said so (the
    solve's time limit was reached while it was being built)."""


def sphere_counts(lengths_m: Array, radii_m: Array, max_spheres: int = MAX_SPHERES) -> Array:
    """Spheres per link: ``max(2, ceil(length / spacing) + 1)`` with the spacing ``0.4 r``,
    or, when those would be more than ``max_spheres`` in all, ``max(0.4 r, h)`` with the
    smallest common ``h`` that keeps them within it (bisection on h)."""
    lengths = np.asarray(lengths_m, dtype=float)
    radii = np.asarray(radii_m, dtype=float)
    if max_spheres < 2 * len(lengths):
        raise PlannerlabError(
            f"clearance field: {len(lengths)} links need at least {2 * len(lengths)} "
            f"spheres, more than the cap of {max_spheres}"
        )

    def counts(h: float) -> Array:
        spacing = np.maximum(0.4 * radii, h)
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.where(spacing > 0, np.ceil(lengths / np.where(spacing > 0, spacing, 1.0)), 0.0)
        return np.maximum(2, k.astype(np.int64) + 1)

    n = counts(0.0)
    if int(n.sum()) <= max_spheres:
        return n
    lo, hi = 0.0, float(lengths.max())  # at hi every link has 2 spheres
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if int(counts(mid).sum()) <= max_spheres:
            hi = mid
        else:
            lo = mid
    return counts(hi)


@dataclass(frozen=True)
class Clearance:
    """The field at one state.

    Attributes:
        cost: ``Σ (margin − d)² / margin`` over the sphere pairs closer than the margin.
        gradient: (dof,) ∇cost.
        min_distance_m: the smallest sphere-pair distance (≈ the smallest link distance) [m].
        close_pairs: how many sphere pairs are inside the margin.
        distances_m: (m,) every sphere pair's distance, in a fixed order [m].
    """

    cost: float
    gradient: Array
    min_distance_m: float
    close_pairs: int
    distances_m: Array


def _box_distance(p: Array, R: Array, c: Array, half: Array) -> tuple[Array, Array]:
    """Signed distance of points p (m, 3) to a box and its outward unit gradient (m, 3)."""
    local = (p - c) @ R  # (m, 3) in the box frame
    q = np.abs(local) - half
    out = np.maximum(q, 0.0)
    out_norm = np.linalg.norm(out, axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    d = out_norm + inside
    sign = np.where(local >= 0, 1.0, -1.0)
    g_out = sign * out / np.where(out_norm > 1e-12, out_norm, 1.0)[:, None]
    k = np.argmax(q, axis=1)
    g_in = np.zeros_like(local)
    g_in[np.arange(len(p)), k] = sign[np.arange(len(p)), k]
    g_local = np.where((out_norm > 1e-12)[:, None], g_out, g_in)
    return d, g_local @ R.T


def _cylinder_distance(
    p: Array, R: Array, c: Array, radius: float, half_len: float
) -> tuple[Array, Array]:
    local = (p - c) @ R
    rho = np.hypot(local[:, 0], local[:, 1])
    radial_dir = np.zeros_like(local)
    safe = np.where(rho > 1e-12, rho, 1.0)
    radial_dir[:, 0] = np.where(rho > 1e-12, local[:, 0] / safe, 1.0)
    radial_dir[:, 1] = np.where(rho > 1e-12, local[:, 1] / safe, 0.0)
    axial_dir = np.zeros_like(local)
    axial_dir[:, 2] = np.where(local[:, 2] >= 0, 1.0, -1.0)
    q = np.stack([rho - radius, np.abs(local[:, 2]) - half_len], axis=1)
    out = np.maximum(q, 0.0)
    out_norm = np.linalg.norm(out, axis=1)
    d = out_norm + np.minimum(q.max(axis=1), 0.0)
    w = out / np.where(out_norm > 1e-12, out_norm, 1.0)[:, None]
    g_out = w[:, :1] * radial_dir + w[:, 1:] * axial_dir
    g_in = np.where((q[:, 0] >= q[:, 1])[:, None], radial_dir, axial_dir)
    g_local = np.where((out_norm > 1e-12)[:, None], g_out, g_in)
    return d, g_local @ R.T


class ClearanceField:
    """Clearance cost and gradient for one robot in one scene (see the module docstring).

    Args:
        robot: the robot (``link_segments``, ``link_radii_m``, ``fixed_links``,
            ``excluded_pairs``; Arm-Z frames for analytic Jacobians).
        scene: the obstacles.
        influence_m: pairs farther apart than this cost nothing.
        include_self: also link against link.
        max_spheres: the most spheres in all (see the module docstring).
        stop: asked between the links while the pairs are built; True raises
            :class:`SetupStopped` (None: never).
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        influence_m: float,
        include_self: bool = True,
        *,
        max_spheres: int = MAX_SPHERES,
        stop: Callable[[], bool] | None = None,
    ):
        if not influence_m > 0:
            raise ValueError(f"influence_m must be > 0, got {influence_m}")
        self.robot = robot
        self.scene = scene
        self.influence_m = float(influence_m)
        radii = np.asarray(robot.link_radii_m, dtype=float)
        L = len(radii)
        q_ref = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
        seg = robot.link_segments(q_ref)
        lengths = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)
        counts = np.asarray(sphere_counts(lengths, radii, max_spheres), dtype=np.int64)
        #: each link's length [m] at the reference state (the capsule's, rigid on its body)
        self._lengths = np.asarray(lengths, dtype=float)
        starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self._link = np.repeat(np.arange(L), counts)
        # np.linspace(0, 1, k) per link, to the bit: i · (1 / (k − 1)), the last exactly 1
        rank = np.arange(int(starts[-1])) - starts[self._link]
        self._t = rank * (1.0 / (counts - 1).astype(float))[self._link]
        self._t[starts[1:] - 1] = 1.0
        self._r = radii[self._link]
        fixed = np.zeros(L, dtype=bool)
        fixed[[i for i in robot.fixed_links if 0 <= i < L]] = True
        # a mesh robot's finer covers judge self-collision only, its first covers the
        # scene only (robots.urdf.model: "Self-collision at the meshes' accuracy")
        self_only = np.zeros(L, dtype=bool)
        self_only[[i for i in getattr(robot, "self_only_links", ()) if 0 <= i < L]] = True
        scene_only = np.zeros(L, dtype=bool)
        scene_only[[i for i in getattr(robot, "scene_only_links", ()) if 0 <= i < L]] = True
        self._scene_spheres = np.flatnonzero(~(fixed | self_only)[self._link])
        # the link pairs checked against each other: not the same link, not excluded,
        # not both fixed, not a first cover that a finer one replaces
        allowed = ~np.eye(L, dtype=bool) & ~(fixed[:, None] & fixed[None, :])
        allowed &= ~scene_only[:, None] & ~scene_only[None, :]
        for i, j in robot.excluded_pairs:
            allowed[i, j] = allowed[j, i] = False
        self._self_a = np.zeros(0, dtype=int)
        self._self_b = np.zeros(0, dtype=int)
        if include_self:
            if stop is not None and stop():
                raise SetupStopped(f"the clearance field of {L} links stopped: time is up")
            # the sphere pairs a < b of different, allowed links, in order (a first): one
            # mask over the sphere pairs (at most MAX_SPHERES², 1 MB)
            ok = allowed[self._link[:, None], self._link[None, :]]
            ok &= self._link[:, None] < self._link[None, :]
            a, b = np.nonzero(ok)
            self._self_a, self._self_b = a.astype(int), b.astype(int)
        self._n_links = L
        self._analytic = getattr(robot, "kind", "") == "armz"
        #: (L, n) the declared contacts (an obstacle's touch_links): never measured
        self._touch = touch_mask(robot, scene)

    # ------------------------------------------------------------------ geometry
    def _centres_and_jacobians(self, q: Array) -> tuple[Array, Array]:
        """Sphere centres (s, 3) and their Jacobians (s, 3, dof)."""
        robot = self.robot
        t = self._t[:, None]
        if self._analytic:
            F = robot.fk(q)  # (dof + 2, 4, 4); link i runs from frame i to frame i + 1
            o = F[:, :3, 3]
            a, b = o[self._link], o[self._link + 1]
            p = a + t * (b - a)
            z = F[1:-1, :3, 2]  # joint j (1-based) turns about frame j's z
            oj = F[1:-1, :3, 3]
            # centre on link i moves with joints 1..i
            J = np.cross(z[None, :, :], p[:, None, :] - oj[None, :, :])  # (s, dof, 3)
            dof = robot.dof
            mask = np.arange(1, dof + 1)[None, :] <= self._link[:, None]
            J = J * mask[:, :, None]
            return p, np.transpose(J, (0, 2, 1))
        h = 1e-6
        Q = np.repeat(np.asarray(q, dtype=float)[None, :], robot.dof + 1, axis=0)
        Q[1:] += h * np.eye(robot.dof)
        seg = robot.link_segments(Q)  # (dof + 1, L, 2, 3)
        P = seg[:, self._link, 0] + t[None] * (seg[:, self._link, 1] - seg[:, self._link, 0])
        J = (P[1:] - P[0][None]) / h  # (dof, s, 3)
        return P[0], np.transpose(J, (1, 2, 0))

    def distances(self, q: Array) -> tuple[Array, Array, Array, Array]:
        """Every sphere pair: distance d (m,), direction n (m, 3), spheres a and b (b = −1:
        an obstacle)."""
        p, _ = self._centres_and_jacobians(q)
        return self._pairs(p)

    def _pairs(self, p: Array) -> tuple[Array, Array, Array, Array]:
        ds, ns, sa, sb = [], [], [], []
        idx = self._scene_spheres
        ps = p[idx]
        for k, o in enumerate(self.scene.obstacles):
            T = o.T_world_obstacle
            R, c = T[:3, :3], T[:3, 3]
            if isinstance(o, Box):
                d, n = _box_distance(ps, R, c, np.asarray(o.size_m) / 2.0)
            elif isinstance(o, Cylinder):
                d, n = _cylinder_distance(ps, R, c, float(o.radius_m), float(o.length_m) / 2.0)
            elif isinstance(o, Sphere):
                diff = ps - c
                nd = np.linalg.norm(diff, axis=1)
                d = nd - float(o.radius_m)
                n = diff / np.where(nd > 1e-12, nd, 1.0)[:, None]
            else:  # pragma: no cover - scene types are closed
                raise TypeError(f"unknown obstacle {o!r}")
            # a declared contact (its link among the obstacle's touch_links): no pair
            ds.append(np.where(self._touch[self._link[idx], k], np.inf, d - self._r[idx]))
            ns.append(n)
            sa.append(idx)
            sb.append(np.full(len(idx), -1))
        if len(self._self_a):
            diff = p[self._self_a] - p[self._self_b]
            nd = np.linalg.norm(diff, axis=1)
            ds.append(nd - self._r[self._self_a] - self._r[self._self_b])
            ns.append(diff / np.where(nd > 1e-12, nd, 1.0)[:, None])
            sa.append(self._self_a)
            sb.append(self._self_b)
        if not ds:
            z = np.zeros(0)
            return z, np.zeros((0, 3)), z.astype(int), z.astype(int)
        return np.concatenate(ds), np.concatenate(ns), np.concatenate(sa), np.concatenate(sb)

    def __call__(self, q: Array) -> Clearance:
        """Cost and gradient at q (dof,)."""
        q = np.asarray(q, dtype=float)
        p, J = self._centres_and_jacobians(q)
        d, n, a, b = self._pairs(p)
        m = self.influence_m
        close = d < m
        min_d = float(d.min()) if len(d) else np.inf
        if not close.any():
            return Clearance(0.0, np.zeros(self.robot.dof), min_d, 0, d)
        all_d = d
        d, n, a, b = d[close], n[close], a[close], b[close]
        gap = m - d
        cost = float(np.sum(gap**2) / m)
        # d(cost)/dd = −2 gap / m; dd/dq = n · (J_a − J_b)
        w = (-2.0 * gap / m)[:, None] * n  # (c, 3)
        grad = np.einsum("ck,ckj->j", w, J[a])
        is_self = b >= 0
        if is_self.any():
            grad -= np.einsum("ck,ckj->j", w[is_self], J[b[is_self]])
        return Clearance(cost, grad, min_d, int(close.sum()), all_d)

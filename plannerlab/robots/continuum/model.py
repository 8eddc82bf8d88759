"""Planar continuum robot: constant-curvature sections and a rigid-link chain model.

Source: ``003_d410ec97f064abf9.txt`` (digest in ``docs/papers.md`` §3).

Two parts live here:

1. **Section math** (planar, 3x3 homogeneous frames). A constant-curvature section of arc
   length ``L`` and signed bend angle ``θ`` starts at a section base frame whose **y axis is
   the initial tangent** and whose x axis is the tangent turned by -90° (to the right,
   seen from +z). The paper's tip transform is::

       T_tip(a) = T_base · T_bend(aθ/2) · T_tr(H(a)) · T_bend(aθ/2),
       H(a)     = a · L · sinc(aθ/2)         (sinc(x) = sin(x)/x, sinc(0) = 1)

   ``H(1)`` is the chord, ``a ∈ (0, 1]`` walks along the arc (a = 1 is the tip, a > 1
   extends the arc along its own circle: the paper's push). ``H(a) = H·sin(aθ/2)/sin(θ/2)``
   of the paper is the same number; the sinc form stays exact as θ → 0.

   **Sign convention.** The inverse is ``θ = 2·atan2(X, Y)`` for a point (X, Y) in the
   section base frame (``docs/papers.md``: the sign of the bend is the sign of X), so
   **θ > 0 bends toward +X, i.e. clockwise seen from +z**, and ``T_bend(φ)`` is a rotation
   about z by **-φ**. The curvature ``κ = θ/L`` carries the same sign (right-positive).
   Valid for |θ| < 2π (the arc length to a point straight behind the base is infinite).

2. **ContinuumChain**: the robot as a joint-vector robot for planners, FCL and PyBullet.
   ``n_links`` rigid links of length ``ℓ = length_m / n_links`` behind a prismatic
   insertion joint, in the world x-y plane. ``q = (d, θ_1 … θ_n)``:

   * ``d`` [m] ∈ [0, length_m] is the length pushed out of the base port. The first joint
     (the proximal end of the robot) sits at ``base + (d - length_m)·x_base``, so the
     part of the robot that is not inserted lies straight behind the port along -x_base
     (keep that half-line free of obstacles in scenes). The base frame's **x axis is the
     insertion direction** (a problem file's ``base_rpy_deg = [0, 0, 90]`` points it
     along world +y).
   * ``θ_i`` [rad] is the relative angle of link i about +z (counter-clockwise positive,
     the usual revolute convention). Note the opposite sign of the section's θ:
     a right-bending section (θ > 0) becomes negative joint angles.

   Frames returned by :meth:`ContinuumChain.fk` (``F = n_links + 2``): ``0`` the carriage
   (frame of the first joint, x along the insertion direction), ``i`` (1..n) link i (origin
   at joint i, x along the link), ``n + 1`` the tip (end of the last link, same
   orientation). Tip normal = tip tangent = x axis of the tip frame.

Only numpy is used (see ``docs/architecture.md``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.robots.base import Array, pose_matrix, rot_z, urdf_origin

# --------------------------------------------------------------------------- section math


def sinc(x_rad: Array | float) -> Array:
    """Unnormalised sinc ``sin(x)/x`` with ``sinc(0) = 1`` (numpy's is ``sin(πx)/(πx)``)."""
    return np.sinc(np.asarray(x_rad, dtype=float) / np.pi)


def planar_frame(p_xy_m: Array, tangent_xy: Array) -> Array:
    """Section base frame (3, 3): y axis along ``tangent_xy``, x axis to its right, origin p.

    Args:
        p_xy_m: (2,) origin [m].
        tangent_xy: (2,) tangent direction (normalised here).
    """
    t = np.asarray(tangent_xy, dtype=float)
    t = t / np.linalg.norm(t)
    T = np.eye(3)
    T[:2, 0] = (t[1], -t[0])  # x = t turned by -90°: right of the tangent
    T[:2, 1] = t
    T[:2, 2] = np.asarray(p_xy_m, dtype=float)
    return T


def T_bend(phi_rad: Array | float) -> Array:
    """Bend rotation (..., 3, 3): about z by **-φ**, turning the y axis toward +x."""
    phi = np.asarray(phi_rad, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    T = np.zeros(phi.shape + (3, 3))
    T[..., 0, 0] = c
    T[..., 0, 1] = s
    T[..., 1, 0] = -s
    T[..., 1, 1] = c
    T[..., 2, 2] = 1.0
    return T


def T_tr(h_m: Array | float) -> Array:
    """Translation along y by ``h`` (..., 3, 3)."""
    h = np.asarray(h_m, dtype=float)
    T = np.zeros(h.shape + (3, 3))
    T[..., 0, 0] = T[..., 1, 1] = T[..., 2, 2] = 1.0
    T[..., 1, 2] = h
    return T


def chord_length(
    theta_rad: Array | float, length_m: Array | float, a: Array | float = 1.0
) -> Array:
    """``H(a) = a·L·sinc(aθ/2)`` [m]: distance from the base to the arc point at a."""
    a = np.asarray(a, dtype=float)
    return a * np.asarray(length_m, dtype=float) * sinc(a * np.asarray(theta_rad) / 2.0)


def section_tip(T_base: Array, theta_rad: float, length_m: float, a: Array | float = 1.0) -> Array:
    """Eq. (1): frame at arc fraction ``a`` (..., 3, 3), vectorised over ``a``.

    Args:
        T_base: (3, 3) section base frame (y = tangent).
        theta_rad: signed bend angle θ of the whole section [rad] (θ > 0 bends toward +x).
        length_m: arc length L [m].
        a: arc fraction(s); 1 is the tip, > 1 extends the arc along its circle.
    """
    a = np.asarray(a, dtype=float)
    half = T_bend(a * theta_rad / 2.0)
    return T_base @ half @ T_tr(chord_length(theta_rad, length_m, a)) @ half


def arc_points_local(theta_rad: Array | float, length_m: Array | float, a: Array | float) -> Array:
    """Points of arcs in their section frames (..., 2) = H(a)·(sin(aθ/2), cos(aθ/2)).

    ``theta_rad``, ``length_m`` and ``a`` broadcast against each other (e.g. θ (K, 1),
    L (K, 1), a (S,) gives (K, S, 2)).
    """
    half = np.asarray(a, dtype=float) * np.asarray(theta_rad, dtype=float) / 2.0
    h = chord_length(theta_rad, length_m, a)
    return np.stack([h * np.sin(half), h * np.cos(half)], axis=-1)


def arc_points(T_base: Array, theta_rad: float, length_m: float, a: Array | float) -> Array:
    """Points of one arc in the frame ``T_base`` is expressed in: (..., 2) for a (...)."""
    local = arc_points_local(theta_rad, length_m, a)
    return local @ T_base[:2, :2].T + T_base[:2, 2]


def section_ik(p_local_m: Array) -> tuple[Array, Array]:
    """Inverse kinematics of a section: bend angle and arc length reaching a point.

    Args:
        p_local_m: (..., 2) target (X, Y) in the section base frame (Y = initial tangent).

    Returns:
        ``theta_rad`` = 2·atan2(X, Y) ∈ (-2π, 2π] and ``length_m`` = |p|·(θ/2)/sin(θ/2)
        (= |p| as θ → 0; inf for a point straight behind the base), both of shape (...).
    """
    p = np.asarray(p_local_m, dtype=float)
    theta = 2.0 * np.arctan2(p[..., 0], p[..., 1])
    chord = np.hypot(p[..., 0], p[..., 1])
    s = sinc(theta / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        length = np.where(s > 0.0, chord / np.where(s > 0.0, s, 1.0), np.inf)
    return theta, length


def tangent_after(tangent_xy: Array, theta_rad: Array | float) -> Array:
    """Tangent (..., 2) after turning by the signed bend θ (θ > 0 turns clockwise)."""
    t = np.asarray(tangent_xy, dtype=float)
    c, s = np.cos(theta_rad), np.sin(theta_rad)
    c = np.asarray(c)[..., None]
    s = np.asarray(s)[..., None]
    right = np.stack([t[..., 1], -t[..., 0]], axis=-1)
    return c * t + s * right


def turning_at(s_m: Array, arcs: Sequence[tuple[float, float]]) -> Array:
    """Accumulated signed bend ``Φ(s) = ∫_0^s κ`` [rad] along a chain of arcs.

    Args:
        s_m: arc-length positions (...) [m]; clamped to [0, Σ L].
        arcs: ``(θ_k, L_k)`` per arc from the base (section convention, right-positive).
    """
    th = np.array([a[0] for a in arcs], dtype=float)
    ln = np.array([a[1] for a in arcs], dtype=float)
    s_breaks = np.concatenate([[0.0], np.cumsum(ln)])
    phi_breaks = np.concatenate([[0.0], np.cumsum(th)])
    return np.interp(np.asarray(s_m, dtype=float), s_breaks, phi_breaks)


# --------------------------------------------------------------------------- chain robot


@dataclass(frozen=True, eq=False)
class ContinuumChain:
    """Planar chain of short rigid links behind a prismatic insertion joint.

    Args:
        n_links: number of rigid links (revolute joints about z).
        length_m: total robot length [m] (sum of the link lengths).
        link_radius_m: capsule radius of every link [m].
        max_joint_rad: symmetric bound of every relative link angle [rad].
        T_world_base: (4, 4) base port pose; x = insertion direction, z must be world +z.
        link_mass_kg: mass of each link for PyBullet.
    """

    n_links: int = 40
    length_m: float = 0.5
    link_radius_m: float = 0.002
    max_joint_rad: float = float(np.pi / 2)
    T_world_base: Array = field(default_factory=lambda: np.eye(4))
    link_mass_kg: float = 0.01

    kind: str = field(default="continuum_chain", init=False)

    def __post_init__(self) -> None:
        if self.n_links < 1:
            raise ValueError(f"n_links must be >= 1, got {self.n_links}")
        if not self.length_m > 0:
            raise ValueError(f"length_m must be > 0, got {self.length_m}")
        if not self.link_radius_m > 0:
            raise ValueError(f"link_radius_m must be > 0, got {self.link_radius_m}")
        T = np.array(self.T_world_base, dtype=float)
        if T.shape != (4, 4):
            raise ValueError(f"T_world_base must be (4, 4), got {T.shape}")
        if not np.allclose(T[:3, 2], (0.0, 0.0, 1.0), atol=1e-9):
            raise ValueError(
                "T_world_base must keep z along world +z (a planar robot: roll = pitch = 0), "
                f"got z axis {T[:3, 2].tolist()}"
            )
        T.setflags(write=False)
        object.__setattr__(self, "T_world_base", T)

    # ------------------------------------------------------------------ description
    @property
    def link_length_m(self) -> float:
        """Length ℓ of one rigid link [m]."""
        return self.length_m / self.n_links

    @property
    def dof(self) -> int:
        return self.n_links + 1

    @property
    def joint_names(self) -> tuple[str, ...]:
        return ("insertion",) + tuple(f"joint_{i}" for i in range(1, self.n_links + 1))

    @property
    def link_names(self) -> tuple[str, ...]:
        return tuple(f"link_{i}" for i in range(1, self.n_links + 1))

    @property
    def link_frame_names(self) -> tuple[str, ...]:
        return ("carriage",) + self.link_names + ("tip",)

    @property
    def lower(self) -> Array:
        return np.concatenate([[0.0], np.full(self.n_links, -self.max_joint_rad)])

    @property
    def upper(self) -> Array:
        return np.concatenate([[self.length_m], np.full(self.n_links, self.max_joint_rad)])

    @property
    def continuous(self) -> np.ndarray:
        return np.zeros(self.dof, dtype=bool)

    @property
    def link_radii_m(self) -> Array:
        return np.full(self.n_links, self.link_radius_m)

    @property
    def fixed_links(self) -> frozenset[int]:
        return frozenset()

    @property
    def excluded_pairs(self) -> frozenset[tuple[int, int]]:
        """Neighbours always touch; links within ``⌈2r/ℓ⌉ + 1`` of each other are excluded.

        Two capsules k links apart can only touch through a fold sharper than the joint
        bounds allow unless they overlap already at the joint, which happens when
        ``2r`` is comparable to ``ℓ``.
        """
        within = int(np.ceil(2.0 * self.link_radius_m / self.link_length_m)) + 1
        n = self.n_links
        return frozenset((i, j) for i in range(n) for j in range(i + 1, min(n, i + within + 1)))

    @property
    def base_yaw_rad(self) -> float:
        """Yaw of the insertion direction in the world [rad]."""
        return float(np.arctan2(self.T_world_base[1, 0], self.T_world_base[0, 0]))

    # ------------------------------------------------------------------ kinematics
    def _as_batch(self, q: Array) -> tuple[Array, bool]:
        q = np.asarray(q, dtype=float)
        single = q.ndim == 1
        Q = q[None, :] if single else q
        if Q.ndim != 2 or Q.shape[-1] != self.dof:
            raise ValueError(f"q must have shape ({self.dof},) or (k, {self.dof}), got {q.shape}")
        return Q, single

    def _origins_headings(self, Q: Array) -> tuple[Array, Array]:
        """Frame origins (k, n + 2, 3) and world headings (k, n + 2) [rad]."""
        k = Q.shape[0]
        yaw0 = self.base_yaw_rad
        x0 = self.T_world_base[:3, 0]
        psi_links = yaw0 + np.cumsum(Q[:, 1:], axis=1)  # (k, n)
        p_car = self.T_world_base[:3, 3] + (Q[:, :1] - self.length_m) * x0  # (k, 3)
        steps = np.zeros((k, self.n_links, 3))
        steps[..., 0] = self.link_length_m * np.cos(psi_links)
        steps[..., 1] = self.link_length_m * np.sin(psi_links)
        origins = np.empty((k, self.n_links + 2, 3))
        origins[:, 0] = p_car
        origins[:, 1] = p_car
        origins[:, 2:] = p_car[:, None, :] + np.cumsum(steps, axis=1)
        headings = np.empty((k, self.n_links + 2))
        headings[:, 0] = yaw0
        headings[:, 1:-1] = psi_links
        headings[:, -1] = psi_links[:, -1]
        return origins, headings

    def fk(self, q: Array) -> Array:
        """Frames in the world: (F, 4, 4) for q (dof,), (k, F, 4, 4) for (k, dof).

        Vectorised over the batch (cumulative sums along the chain, no Python loop).
        """
        Q, single = self._as_batch(q)
        origins, psi = self._origins_headings(Q)
        T = rot_z(psi)
        T[..., :3, 3] = origins
        return T[0] if single else T

    def tip(self, q: Array) -> tuple[Array, Array]:
        """Tip position ``p_world`` [m] and tip tangent ``n_world`` (3,) each, or (k, 3)."""
        Q, single = self._as_batch(q)
        origins, psi = self._origins_headings(Q)
        p = origins[:, -1]
        n = np.stack([np.cos(psi[:, -1]), np.sin(psi[:, -1]), np.zeros(len(Q))], axis=-1)
        return (p[0], n[0]) if single else (p, n)

    def tip_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Analytic ``dp/dq`` and ``dn/dq`` (3, dof) at one q.

        ``dp/dd = x_base``; joint i turns about +z through its origin ``o_i``:
        ``dp/dθ_i = z × (p − o_i)``, ``dn/dθ_i = z × n``.
        """
        Q, _ = self._as_batch(np.asarray(q, dtype=float).reshape(self.dof))
        origins, psi = self._origins_headings(Q)
        p = origins[0, -1]
        o = origins[0, 1:-1]  # (n, 3) joint origins
        n = np.array([np.cos(psi[0, -1]), np.sin(psi[0, -1]), 0.0])
        J_p = np.zeros((3, self.dof))
        J_n = np.zeros((3, self.dof))
        J_p[:, 0] = self.T_world_base[:3, 0]
        J_p[0, 1:] = -(p[1] - o[:, 1])
        J_p[1, 1:] = p[0] - o[:, 0]
        J_n[0, 1:] = -n[1]
        J_n[1, 1:] = n[0]
        return J_p, J_n

    def chain_data(self) -> tuple[Any, ...]:
        """The robot as a serial chain for the compiled robot-scene model
        (:mod:`plannerlab.collision.chain`): per joint its parent body (dof,), the fixed
        transform parent body -> joint frame (dof, 4, 4), its unit axis (dof, 3), whether
        it slides (dof,); per capsule its body (n,) and end points in that body's frame.

        Body 0 is the port (``T_world_base``); the insertion slides body 1 (the carriage,
        :meth:`fk`'s frame 0) along x from ``-length_m``; joint ``i`` turns body ``i + 1``
        (link ``i``) about z, ``ℓ`` along the previous link's x (at the carriage for the
        first); link ``i``'s capsule runs from its origin to ``(ℓ, 0, 0)``."""
        n, ell = self.n_links, self.link_length_m
        dof = self.dof
        parent = np.arange(dof, dtype=np.int64)
        pre = np.tile(np.eye(4), (dof, 1, 1))
        pre[0, 0, 3] = -self.length_m
        pre[2:, 0, 3] = ell
        axes = np.tile([0.0, 0.0, 1.0], (dof, 1))
        axes[0] = (1.0, 0.0, 0.0)
        prismatic = np.zeros(dof, dtype=bool)
        prismatic[0] = True
        cap_body = np.arange(2, n + 2, dtype=np.int64)
        cap_a = np.zeros((n, 3))
        cap_b = np.zeros((n, 3))
        cap_b[:, 0] = ell
        return parent, pre, axes, prismatic, cap_body, cap_a, cap_b

    def tip_data(self) -> tuple[int, Array, Array]:
        """The tip in :meth:`chain_data`'s terms: the last link's body, the link's end
        ``(ℓ, 0, 0)`` and its tangent (x) in that body's frame."""
        return self.n_links + 1, np.array([self.link_length_m, 0.0, 0.0]), np.array([1.0, 0, 0])

    def link_segments(self, q: Array) -> Array:
        """Capsule axes (n, 2, 3) or (k, n, 2, 3): link i from joint i to joint i + 1."""
        Q, single = self._as_batch(q)
        origins, _ = self._origins_headings(Q)
        seg = np.stack([origins[:, 1:-1], origins[:, 2:]], axis=-2)
        return seg[0] if single else seg

    # ------------------------------------------------------------------ arcs -> joints
    def q_from_arcs(
        self, arcs: Sequence[tuple[float, float]], insertion_m: float | None = None
    ) -> Array:
        """Joint vector (dof,) approximating a chain of constant-curvature arcs.

        Args:
            arcs: ``(θ_k, L_k)`` per arc, from the base port along the insertion
                direction, in the section convention (θ > 0 bends clockwise seen from +z,
                i.e. toward the base's -y). An empty sequence is the straight robot.
            insertion_m: length pushed out; default ``Σ L_k`` (the shape's length). The rest
                of the robot stays straight behind the port (the leftover length).

        Each joint's relative angle is the curvature integrated over the cell centred on
        the joint, ``[u_i − ℓ/2, u_i + ℓ/2]`` (half of the link before and half of link i),
        with the opposite sign (joints are counter-clockwise positive). This makes every
        link's heading the arc's heading at the link's midpoint, so the links are (nearly)
        chords of the arcs and the joints lie on the curve up to O(κ²ℓ³); integrating over
        the link itself instead would shift the polygon sideways by ~ℓ/2 · total bend.
        Joint bounds are not enforced here (compare with :attr:`lower`, :attr:`upper`).
        """
        arcs = [(float(t), float(L)) for t, L in arcs]
        total = sum(L for _, L in arcs)
        d = total if insertion_m is None else float(insertion_m)
        if d > self.length_m * (1.0 + 1e-9) or d < 0.0:
            raise ValueError(f"insertion {d} m outside [0, {self.length_m}] m")
        if not arcs:
            arcs = [(0.0, 1.0)]
        ell = self.link_length_m
        u_mid = (np.arange(self.n_links) + 0.5) * ell  # link midpoints along the robot
        s_mid = u_mid - (self.length_m - d)  # arc length out of the port
        phi = turning_at(np.clip(s_mid, 0.0, None), arcs)  # right-positive turning
        psi_rel = -phi  # counter-clockwise heading relative to the base
        q = np.empty(self.dof)
        q[0] = min(d, self.length_m)
        q[1:] = np.diff(np.concatenate([[0.0], psi_rel]))
        return q

    def q_from_arcs_batch(self, theta_rad: Array, length_m: Array) -> Array:
        """:meth:`q_from_arcs` for many shapes at once (insertion = each shape's length).

        Args:
            theta_rad, length_m: (N, K) bend and length of the K arcs of N shapes (an arc
                of length 0 is allowed and adds nothing).

        Returns:
            (N, dof) joint vectors, equal to ``q_from_arcs(list(zip(θ_n, L_n)))`` per row.
        """
        th = np.atleast_2d(np.asarray(theta_rad, dtype=float))
        ln = np.atleast_2d(np.asarray(length_m, dtype=float))
        if th.shape != ln.shape:
            raise ValueError(f"theta_rad {th.shape} and length_m {ln.shape} differ in shape")
        d = ln.sum(axis=1)  # (N,)
        if np.any(d > self.length_m * (1.0 + 1e-9)) or np.any(d < 0.0) or np.any(ln < 0.0):
            raise ValueError(f"insertions {d.min()}..{d.max()} m outside [0, {self.length_m}] m")
        ell = self.link_length_m
        u_mid = (np.arange(self.n_links) + 0.5) * ell
        s_mid = np.clip(u_mid[None, :] - (self.length_m - d)[:, None], 0.0, None)  # (N, n)
        starts = np.cumsum(ln, axis=1) - ln  # (N, K)
        rel = s_mid[:, :, None] - starts[:, None, :]  # (N, n, K)
        safe = np.where(ln > 0.0, ln, 1.0)[:, None, :]
        frac = np.where(ln[:, None, :] > 0.0, np.clip(rel / safe, 0.0, 1.0), 0.0)
        phi = np.einsum("nik,nk->ni", frac, th)  # right-positive turning at the midpoints
        q = np.empty((len(th), self.dof))
        q[:, 0] = np.minimum(d, self.length_m)
        q[:, 1:] = np.diff(-phi, axis=1, prepend=0.0)
        return q

    # ------------------------------------------------------------------ URDF
    def urdf(self) -> str:
        """URDF of the chain in its base frame (load it at ``T_world_base``, fixed base).

        ``base`` (the port) → prismatic ``insertion`` along x, origin at (-length_m, 0, 0)
        → ``carriage`` → revolute ``joint_1`` about z → ``link_1`` → … → ``link_n`` → fixed
        ``tip_joint`` at (ℓ, 0, 0) → ``tip``. Each link carries a capsule of radius
        ``link_radius_m`` along its x axis.
        """
        ell = self.link_length_m
        r = self.link_radius_m
        m = self.link_mass_kg
        ix = m * r * r / 2.0
        iy = m * (3 * r * r + ell * ell) / 12.0
        body_T = pose_matrix([ell / 2.0, 0.0, 0.0], [0.0, np.pi / 2.0, 0.0])
        body = urdf_origin(body_T)

        def link(name: str, with_body: bool) -> str:
            if not with_body:
                return (
                    f'  <link name="{name}">\n'
                    f'    <inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="{m!r}"/>'
                    f'<inertia ixx="1e-8" ixy="0" ixz="0" iyy="1e-8" iyz="0" izz="1e-8"/>'
                    f"</inertial>\n  </link>\n"
                )
            return (
                f'  <link name="{name}">\n'
                f'    <inertial>{body}<mass value="{m!r}"/>'
                f'<inertia ixx="{ix!r}" ixy="0" ixz="0" iyy="{iy!r}" iyz="0" izz="{iy!r}"/>'
                f"</inertial>\n"
                f'    <visual>{body}<geometry><cylinder radius="{r!r}" length="{ell!r}"/>'
                f"</geometry></visual>\n"
                f'    <collision>{body}<geometry><capsule radius="{r!r}" length="{ell!r}"/>'
                f"</geometry></collision>\n"
                f"  </link>\n"
            )

        def joint(
            name: str,
            kind: str,
            parent: str,
            child: str,
            x_m: float,
            axis: str,
            limits: tuple[float, float] | None,
        ) -> str:
            lim = ""
            if limits is not None:
                lim = (
                    f'<limit lower="{limits[0]!r}" upper="{limits[1]!r}" effort="100" '
                    f'velocity="10"/>'
                )
            ax = f'<axis xyz="{axis}"/>' if axis else ""
            return (
                f'  <joint name="{name}" type="{kind}">\n'
                f'    <parent link="{parent}"/><child link="{child}"/>\n'
                f'    <origin xyz="{x_m!r} 0 0" rpy="0 0 0"/>{ax}{lim}\n'
                f"  </joint>\n"
            )

        parts = ['<?xml version="1.0"?>\n<robot name="continuum_chain">\n']
        parts.append(link("base", False))
        parts.append(link("carriage", False))
        parts.append(
            joint(
                "insertion",
                "prismatic",
                "base",
                "carriage",
                -self.length_m,
                "1 0 0",
                (0.0, self.length_m),
            )
        )
        parent = "carriage"
        for i, name in enumerate(self.link_names, start=1):
            parts.append(link(name, True))
            parts.append(
                joint(
                    f"joint_{i}",
                    "revolute",
                    parent,
                    name,
                    0.0 if i == 1 else ell,
                    "0 0 1",
                    (-self.max_joint_rad, self.max_joint_rad),
                )
            )
            parent = name
        parts.append(link("tip", False))
        parts.append(joint("tip_joint", "fixed", parent, "tip", ell, "", None))
        parts.append("</robot>\n")
        return "".join(parts)


__all__ = [
    "ContinuumChain",
    "T_bend",
    "T_tr",
    "arc_points",
    "arc_points_local",
    "chord_length",
    "planar_frame",
    "section_ik",
    "section_tip",
    "sinc",
    "tangent_after",
    "turning_at",
]

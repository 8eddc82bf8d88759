"""Arm-Z: a hyper-redundant chain of identical one-DOF modules.

Source: ``000_a8ed938e94518caf.txt`` (the Arm-Z paper; digest in ``docs/papers.md`` §1).

Each module twists by θ_i about the axis normal to its bottom face. From the frame of one
face to the next::

    H_i = RotZ(θ_i) · Trans(0, δy, δz) · RotX(ζ)

The base module is fixed and anchored at ζ/2: the first joint's frame is
``Trans(0, δy, δz/2) · RotX(ζ/2)`` in the base frame.

Frames returned by :meth:`ArmZ.fk` (``F = dof + 2``):

* ``0``: the base frame (``T_world_base``),
* ``1``: the top face of the base module = the axis frame of joint 1,
* ``i + 1``: the top face of module ``i`` = the axis frame of joint ``i + 1``;
  the last one is the end effector (``p`` = its origin, ``n`` = its z axis).

Links (collision capsules), ``L = n_modules``: link 0 is the base module (frame 0 to
frame 1, fixed), link ``i`` is module ``i`` (frame ``i`` to frame ``i + 1``). The capsule
runs along the chord between the two face centres; its radius is a parameter (the
paper's r = 0.8 m tube radius; 0.75 m keeps a module from touching walls exactly at the
margin ρ = 0.8 m). Modules fewer than ``self_exclude_within`` apart along the chain always
overlap geometrically and are excluded from self-collision.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.robots.base import Array, rot_x, rot_z, trans, urdf_origin


def _cross(a: Array, b: Array) -> Array:
    """``np.cross(a, b)`` of rows a (k, 3) and b (k, 3) or (3,), written out (the same
    products and differences, without np.cross's general-axis set-up)."""
    b = np.broadcast_to(b, a.shape)
    out = np.empty(a.shape)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


@dataclass(frozen=True, eq=False)
class ArmZ:
    """The Arm-Z chain.

    Args:
        n_modules: modules including the fixed base (paper: 24, i.e. 23 joints).
        zeta_rad: face angle ζ [rad] (paper: 22.5°).
        delta_y_m: module offset δy [m] (paper: -0.1397).
        delta_z_m: module offset δz [m] (paper: 0.7023).
        collision_radius_m: capsule radius of every module [m].
        self_exclude_within: link pairs closer than this along the chain are never
            counted as self-collision.
        T_world_base: (4, 4) base pose in the world.
        module_mass_kg, module_inertia_kgm2, joint_torque_limit_nm: dynamics for PyBullet
            (paper: 1 kg, diag(0.25, 0.25, 0.5), 100 N·m).
    """

    n_modules: int = 24
    zeta_rad: float = float(np.deg2rad(22.5))
    delta_y_m: float = -0.1397
    delta_z_m: float = 0.7023
    collision_radius_m: float = 0.75
    self_exclude_within: int = 5
    T_world_base: Array = field(default_factory=lambda: np.eye(4))
    module_mass_kg: float = 1.0
    module_inertia_kgm2: tuple[float, float, float] = (0.25, 0.25, 0.5)
    joint_torque_limit_nm: float = 100.0
    joint_velocity_limit_rad_s: float = 10.0
    #: fixed parts of the chain, computed in __post_init__
    _M: Array = field(init=False, repr=False, compare=False)
    _T_base_j1: Array = field(init=False, repr=False, compare=False)

    kind: str = field(default="armz", init=False)

    def __post_init__(self) -> None:
        if self.n_modules < 2:
            raise ValueError(f"n_modules must be >= 2, got {self.n_modules}")
        T = np.array(self.T_world_base, dtype=float)
        if T.shape != (4, 4):
            raise ValueError(f"T_world_base must be (4, 4), got {T.shape}")
        T.setflags(write=False)
        object.__setattr__(self, "T_world_base", T)
        # Fixed parts of the chain, computed once.
        M = trans(0.0, self.delta_y_m, self.delta_z_m) @ rot_x(self.zeta_rad)
        M.setflags(write=False)
        object.__setattr__(self, "_M", M)
        T_base_j1 = trans(0.0, self.delta_y_m, self.delta_z_m / 2.0) @ rot_x(self.zeta_rad / 2.0)
        T_base_j1.setflags(write=False)
        object.__setattr__(self, "_T_base_j1", T_base_j1)

    # ------------------------------------------------------------------ description
    @property
    def dof(self) -> int:
        return self.n_modules - 1

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(f"j{i}" for i in range(1, self.dof + 1))

    @property
    def link_names(self) -> tuple[str, ...]:
        return tuple(f"module_{i}" for i in range(self.n_modules))

    @property
    def link_frame_names(self) -> tuple[str, ...]:
        return ("module_0",) + tuple(f"face_{i}" for i in range(self.n_modules))

    @property
    def lower(self) -> Array:
        return np.full(self.dof, -np.pi)

    @property
    def upper(self) -> Array:
        return np.full(self.dof, np.pi)

    @property
    def continuous(self) -> np.ndarray:
        return np.ones(self.dof, dtype=bool)

    @property
    def link_radii_m(self) -> Array:
        return np.full(self.n_modules, self.collision_radius_m)

    @property
    def fixed_links(self) -> frozenset[int]:
        return frozenset({0})

    @property
    def excluded_pairs(self) -> frozenset[tuple[int, int]]:
        L = self.n_modules
        return frozenset(
            (i, j) for i in range(L) for j in range(i + 1, L) if j - i < self.self_exclude_within
        )

    @property
    def chord_m(self) -> float:
        """Distance between the centres of a module's two faces [m]."""
        return float(np.hypot(self.delta_y_m, self.delta_z_m))

    # ------------------------------------------------------------------ kinematics
    def fk(self, q: Array) -> Array:
        """Face frames in the world: (F, 4, 4) for q (dof,), (k, F, 4, 4) for (k, dof)."""
        q = np.asarray(q, dtype=float)
        single = q.ndim == 1
        Q = q[None, :] if single else q
        if Q.shape[-1] != self.dof:
            raise ValueError(f"q must have {self.dof} joints, got shape {q.shape}")
        k = Q.shape[0]
        frames = np.empty((k, self.dof + 2, 4, 4))
        frames[:, 0] = self.T_world_base
        frames[:, 1] = self.T_world_base @ self._T_base_j1
        step = rot_z(Q) @ self._M  # (k, dof, 4, 4): RotZ(θ_i) · Trans · RotX
        for i in range(self.dof):  # along the chain; the batch is vectorised
            frames[:, i + 2] = frames[:, i + 1] @ step[:, i]
        return frames[0] if single else frames

    def tip(self, q: Array) -> tuple[Array, Array]:
        """End effector position ``p_world`` [m] and face normal ``n_world``."""
        F = self.fk(q)
        T = F[..., -1, :, :]
        return T[..., :3, 3].copy(), T[..., :3, 2].copy()

    def tip_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Analytic ``dp/dq`` and ``dn/dq`` (3, dof) at one q.

        Joint i turns about the z axis of frame i (its bottom face) through that frame's
        origin, so ``dp/dθ_i = z_i × (p − o_i)`` and ``dn/dθ_i = z_i × n``.
        """
        return self.tip_and_jacobian(q)[2:]

    def tip_and_jacobian(self, q: Array) -> tuple[Array, Array, Array, Array]:
        """:meth:`tip` and :meth:`tip_jacobian` at one q from one forward kinematics
        (the same numbers): ``p_world`` (3,), ``n_world`` (3,), ``dp/dq``, ``dn/dq``
        (3, dof)."""
        F = self.fk(np.asarray(q, dtype=float).reshape(self.dof))
        p = F[-1, :3, 3]
        n = F[-1, :3, 2]
        z = F[1:-1, :3, 2]  # (dof, 3) joint axes
        o = F[1:-1, :3, 3]  # (dof, 3) points on them
        return p.copy(), n.copy(), _cross(z, p - o).T, _cross(z, n).T

    def chain_data(self) -> tuple[Any, ...]:
        """The chain as plain arrays for the compiled robot-scene model
        (:mod:`plannerlab.collision.model`), in the form of a URDF chain's ``chain_data``:
        per joint its parent body (dof,), the fixed transform parent body -> joint frame
        (dof, 4, 4), its unit axis (dof, 3), whether it slides (dof,); per capsule its body
        (L,) and its two end points in that body's frame (L, 3) each.

        Body 0 is the base (``T_world_base``); body ``i + 1`` is face frame ``i + 1`` turned
        by ``q_i`` about its z axis, so face ``i + 2 = body i+1 · M``. Module 0 runs from
        the base to face 1, module ``l ≥ 1`` from body ``l``'s origin to ``M``'s."""
        dof = self.dof
        parent = np.arange(dof, dtype=np.int64)
        pre = np.empty((dof, 4, 4))
        pre[0] = self._T_base_j1
        pre[1:] = self._M
        axes = np.tile([0.0, 0.0, 1.0], (dof, 1))
        prismatic = np.zeros(dof, dtype=bool)
        L = self.n_modules
        cap_body = np.arange(L, dtype=np.int64)
        cap_a = np.zeros((L, 3))
        cap_b = np.tile(self._M[:3, 3], (L, 1))
        cap_b[0] = self._T_base_j1[:3, 3]
        return parent, pre, axes, prismatic, cap_body, cap_a, cap_b

    def tip_data(self) -> tuple[int, Array, Array]:
        """The tip in :meth:`chain_data`'s terms: its body (the last), and the end
        effector's point and normal in that body's frame (face ``dof + 1 = body dof · M``:
        ``M``'s translation and z axis)."""
        return self.dof, self._M[:3, 3].copy(), self._M[:3, 2].copy()

    def link_segments(self, q: Array) -> Array:
        """Capsule axes (L, 2, 3) or (k, L, 2, 3): chord between consecutive face centres."""
        origins = self.fk(q)[..., :3, 3]  # (..., F, 3)
        return np.stack([origins[..., :-1, :], origins[..., 1:, :]], axis=-2)

    # ------------------------------------------------------------------ URDF
    def urdf(self) -> str:
        """URDF of the chain in its base frame (load it at ``T_world_base``, fixed base).

        A module is a link whose frame is its bottom face turned by its joint; a massless
        link ``face_i`` is fixed at its top face, so the URDF link frames ``module_0, face_0 …
        face_{n-1}`` are exactly the frames of :meth:`fk`. Collision: one capsule per
        module along its chord, radius ``collision_radius_m``.
        """
        ixx, iyy, izz = self.module_inertia_kgm2
        ell = self.chord_m
        # Capsule axis: z of the collision origin must point along (0, δy, δz).
        tilt = float(np.arctan2(-self.delta_y_m, self.delta_z_m))
        mid = (0.0, self.delta_y_m / 2.0, self.delta_z_m / 2.0)
        r = self.collision_radius_m

        def module_body(
            name: str,
            mid_xyz: tuple[float, float, float],
            tilt_rad: float,
            length_m: float,
            mass_kg: float,
        ) -> str:
            xyz = " ".join(repr(float(v)) for v in mid_xyz)
            return (
                f'  <link name="{name}">\n'
                f"    <inertial>\n"
                f'      <origin xyz="{xyz}" rpy="0 0 0"/>\n'
                f'      <mass value="{mass_kg!r}"/>\n'
                f'      <inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" '
                f'izz="{izz!r}"/>\n'
                f"    </inertial>\n"
                f"    <collision>\n"
                f'      <origin xyz="{xyz}" rpy="{tilt_rad!r} 0 0"/>\n'
                f'      <geometry><capsule radius="{r!r}" length="{length_m!r}"/></geometry>\n'
                f"    </collision>\n"
                f"    <visual>\n"
                f'      <origin xyz="{xyz}" rpy="{tilt_rad!r} 0 0"/>\n'
                f'      <geometry><capsule radius="{r!r}" length="{length_m!r}"/></geometry>\n'
                f"    </visual>\n"
                f"  </link>\n"
            )

        def frame_link(name: str) -> str:
            return (
                f'  <link name="{name}">\n'
                f"    <inertial>\n"
                f'      <origin xyz="0 0 0" rpy="0 0 0"/>\n'
                f'      <mass value="0.001"/>\n'
                f'      <inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/>\n'
                f"    </inertial>\n"
                f"  </link>\n"
            )

        def fixed(name: str, parent: str, child: str, T: Array) -> str:
            return (
                f'  <joint name="{name}" type="fixed">\n'
                f'    <parent link="{parent}"/><child link="{child}"/>\n'
                f"    {urdf_origin(T)}\n"
                f"  </joint>\n"
            )

        base_chord = float(np.hypot(self.delta_y_m, self.delta_z_m / 2.0))
        base_tilt = float(np.arctan2(-self.delta_y_m, self.delta_z_m / 2.0))
        base_mid = (0.0, self.delta_y_m / 2.0, self.delta_z_m / 4.0)
        parts = ['<?xml version="1.0"?>\n<robot name="armz">\n']
        parts.append(module_body("module_0", base_mid, base_tilt, base_chord, self.module_mass_kg))
        parts.append(frame_link("face_0"))
        parts.append(fixed("module_0_to_face_0", "module_0", "face_0", self._T_base_j1))
        for i in range(1, self.n_modules):
            parts.append(module_body(f"module_{i}", mid, tilt, ell, self.module_mass_kg))
            parts.append(
                f'  <joint name="j{i}" type="continuous">\n'
                f'    <parent link="face_{i - 1}"/><child link="module_{i}"/>\n'
                f'    <origin xyz="0 0 0" rpy="0 0 0"/>\n'
                f'    <axis xyz="0 0 1"/>\n'
                f'    <limit effort="{self.joint_torque_limit_nm!r}" '
                f'velocity="{self.joint_velocity_limit_rad_s!r}"/>\n'
                f"  </joint>\n"
            )
            parts.append(frame_link(f"face_{i}"))
            parts.append(fixed(f"module_{i}_to_face_{i}", f"module_{i}", f"face_{i}", self._M))
        parts.append("</robot>\n")
        return "".join(parts)

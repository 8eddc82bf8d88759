"""ASEA IRb-6 (5 DOF) on the LP-1 linear track: the kinematic model.

Source: Lubiński, "Zadanie kinematyki odwrotnej robota eksperymentalnego w położeniach
niejednoznacznych" (``docs/papers.md`` §2). Parameter defaults follow the table there.

Frames and joint conventions
----------------------------
*Station frame* S (the paper's x_s y_s z_s): x_s horizontal, y_s vertical (up), z_s along the
track. The column axis is the vertical line x_s = 0, z_s = λ0. ``T_world_base`` is
``T_world_station`` (identity unless a problem sets a base pose).

*Azimuth* α of a horizontal direction: a rotation about +y_s from +x_s, i.e. the direction
``u(α) = (cos α, 0, -sin α)`` in S. A small positive α turns +x_s towards -z_s.

Joint vector ``q = (λ0 [m], θ1, θ2, θ3, θ4, θ5 [rad])``:

* λ0: carriage position along +z_s, range ``track_range_m`` (0 … 0.851 m).
* θ1: rotation of the column about +y_s. The arm's vertical plane has the outward
  horizontal direction ``u = u(α)`` with ``α = theta1_zero_azimuth_rad + θ1``.
* θ2: tilt of the lower arm from the vertical, positive = leaning outward (along u).
  Lower arm direction ``sin θ2 · u + cos θ2 · y_s``.
* θ3: *absolute* elevation of the upper arm above the horizontal (parallelogram arm).
  Upper arm direction ``cos θ3 · u + sin θ3 · y_s``.
* θ4: *absolute* elevation of the approach vector c above the horizontal,
  ``c = cos θ4 · u + sin θ4 · y_s``. The range ±90° is the paper's "0 … 180° from y_s,
  without reaching behind itself" (the table's "±90° relative to the upper arm" is read as
  this absolute range: with a parallelogram wrist drive the wrist angle is absolute).
* θ5: roll of the flange about c.

Zero pose (q = 0): carriage at z_s = 0, arm plane at azimuth ``theta1_zero_azimuth_rad``,
lower arm vertical, upper arm and approach vector horizontal and outward; the wrist point is
then at height λ1 + l2 and distance l3 from the column axis, the flange λ5 further out.

Flange frame (the paper's T5 with columns a, b, c, d): z = c (approach), x = a, y = b,
origin d. At θ5 = 0, ``a = -sin θ4 · u + cos θ4 · y_s`` (the in-plane normal of c, "up"
when c is horizontal) and ``b = c × a`` (horizontal, normal to the arm plane); θ5 turns a
and b about c (right hand).

The 20° dead wedge
------------------
θ1 spans ``theta1_range_rad`` (±170°); the remaining 20° of azimuth is dead. Which side of
the base it sits on is a parameter, ``dead_wedge_side``: the wedge always has one edge on
+x_s (perpendicular to the track) and lies towards -z_s (``"-z"``, the paper's
``C = [d_z, d_z + d_x tan 20°]``) or towards +z_s (``"+z"``,
``C = [d_z - d_x tan 20°, d_z]``). ``theta1_zero_azimuth_rad`` follows from it.

Absolute angles and the URDF (decision)
---------------------------------------
q holds the paper's *absolute* angles θ2, θ3, θ4, because the joint limits are a box in
them (the planners sample and clip boxes). A URDF is a serial tree whose joint values are
*relative*, so the URDF is a different, linear parametrisation of the same arm::

    urdf = (λ0, θ1, θ2, θ2 + θ3, θ4 - θ3, θ5)

The URDF joints keep the names ``joint_names`` and q order, but **their values are
``urdf_joint_positions(q)``, not q**; ``q_from_urdf_joint_positions`` is the inverse.
With those values PyBullet's URDF link frames ``link_frame_names`` equal ``fk(q)``.
The URDF limits of the relative joints are the widest values the absolute box allows.

Collision capsules (``link_names``): the LP-1 rail (fixed), the column, the lower arm, the
upper arm and the wrist (wrist point → flange). Self-collision is not counted between
neighbours, nor between the column and the upper arm (the parallelogram links sit side by
side on the real arm; the capsule model would make them overlap when θ2 < 0 and θ3 < 0).

Problem files build the model from the ``[robot]`` table declared in
:mod:`plannerlab.robots.irb6.schema` (``type = "irb6"``); goal
regions are sampled through the analytic IK by
:func:`plannerlab.robots.irb6.goals.sample_goal_state`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, rot_x, rot_y, rot_z, trans, urdf_origin

#: rotation flange-at-θ5=0 in the wrist frame: columns a = y_w, b = z_w, c = x_w
_R_WRIST_FLANGE0 = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
_R_WRIST_FLANGE0.setflags(write=False)

_JOINT_NAMES = ("lambda0", "theta1", "theta2", "theta3", "theta4", "theta5")
_LINK_NAMES = ("lp1_rail", "irb6_column", "irb6_lower_arm", "irb6_upper_arm", "irb6_wrist")
_FRAME_NAMES = (
    "lp1_carriage",
    "irb6_column",
    "irb6_lower_arm",
    "irb6_upper_arm",
    "irb6_wrist",
    "irb6_flange",
)


def _deg_range(lo_deg: float, hi_deg: float) -> tuple[float, float]:
    return (math.radians(lo_deg), math.radians(hi_deg))


def azimuth_direction(alpha_rad: Array) -> Array:
    """Horizontal unit vector ``u(α) = (cos α, 0, -sin α)`` in S: (..., 3)."""
    a = np.asarray(alpha_rad, dtype=float)
    return np.stack([np.cos(a), np.zeros_like(a), -np.sin(a)], axis=-1)


def azimuth_of(v_station: Array) -> Array:
    """Azimuth α [rad] in (-π, π] of a horizontal direction (x, ·, z) in S."""
    v = np.asarray(v_station, dtype=float)
    return np.arctan2(-v[..., 2], v[..., 0])


@dataclass(frozen=True, eq=False)
class IRb6:
    """IRb-6 arm on the LP-1 track (parameters in SI units, angles in radians).

    Implements :class:`plannerlab.robots.base.Robot`. See the module docstring for the
    frames and the joint conventions.

    Attributes:
        shoulder_height_m: λ1, height of the shoulder axis above the track frame.
        lower_arm_m: l2, shoulder → elbow.
        upper_arm_m: l3, elbow → wrist point.
        wrist_to_flange_m: λ5, wrist point → flange along the approach vector.
        track_range_m: λ0 range along +z_s.
        theta1_range_rad .. theta5_range_rad: joint ranges (θ2..θ4 absolute, see above).
        dead_wedge_side: ``"-z"`` (paper) or ``"+z"``: where the dead wedge of θ1 lies.
        rail_height_m: height of the rail capsule axis; the rail runs at x_s = 0 over the
            track range.
        rail_radius_m .. wrist_radius_m: capsule radii.
        T_world_base: (4, 4) pose of the station frame in the world.
    """

    shoulder_height_m: float = 0.700
    lower_arm_m: float = 0.455
    upper_arm_m: float = 0.670
    wrist_to_flange_m: float = 0.095
    track_range_m: tuple[float, float] = (0.0, 0.851)
    theta1_range_rad: tuple[float, float] = _deg_range(-170.0, 170.0)
    theta2_range_rad: tuple[float, float] = _deg_range(-40.0, 40.0)
    theta3_range_rad: tuple[float, float] = _deg_range(-40.0, 25.0)
    theta4_range_rad: tuple[float, float] = _deg_range(-90.0, 90.0)
    theta5_range_rad: tuple[float, float] = _deg_range(-180.0, 180.0)
    dead_wedge_side: str = "-z"
    rail_height_m: float = 0.10
    rail_radius_m: float = 0.10
    column_radius_m: float = 0.15
    lower_arm_radius_m: float = 0.08
    upper_arm_radius_m: float = 0.07
    wrist_radius_m: float = 0.05
    T_world_base: Array = field(default_factory=lambda: np.eye(4))

    kind: str = field(default="irb6", init=False)
    dof: int = field(default=6, init=False)
    joint_names: tuple[str, ...] = field(default=_JOINT_NAMES, init=False)
    link_names: tuple[str, ...] = field(default=_LINK_NAMES, init=False)
    fixed_links: frozenset[int] = field(default=frozenset({0}), init=False)
    excluded_pairs: frozenset[tuple[int, int]] = field(
        default=frozenset({(0, 1), (1, 2), (2, 3), (3, 4), (1, 3)}), init=False
    )
    lower: Array = field(init=False, repr=False)
    upper: Array = field(init=False, repr=False)
    continuous: NDArray[np.bool_] = field(init=False, repr=False)
    link_radii_m: Array = field(init=False, repr=False)
    theta1_zero_azimuth_rad: float = field(init=False)

    def __post_init__(self) -> None:
        lengths = {
            "shoulder_height_m": self.shoulder_height_m,
            "lower_arm_m": self.lower_arm_m,
            "upper_arm_m": self.upper_arm_m,
            "wrist_to_flange_m": self.wrist_to_flange_m,
            "rail_radius_m": self.rail_radius_m,
            "column_radius_m": self.column_radius_m,
            "lower_arm_radius_m": self.lower_arm_radius_m,
            "upper_arm_radius_m": self.upper_arm_radius_m,
            "wrist_radius_m": self.wrist_radius_m,
        }
        for name, value in lengths.items():
            if not (math.isfinite(value) and value > 0.0):
                raise PlannerlabError(f"IRb6: {name} must be a positive length, got {value!r}")
        ranges = {
            "track_range_m": self.track_range_m,
            "theta1_range_rad": self.theta1_range_rad,
            "theta2_range_rad": self.theta2_range_rad,
            "theta3_range_rad": self.theta3_range_rad,
            "theta4_range_rad": self.theta4_range_rad,
            "theta5_range_rad": self.theta5_range_rad,
        }
        for name, (lo, hi) in ranges.items():
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise PlannerlabError(f"IRb6: {name} must be (lower, upper), got {(lo, hi)!r}")
        t1lo, t1hi = self.theta1_range_rad
        if t1hi - t1lo > 2.0 * math.pi:
            raise PlannerlabError("IRb6: theta1_range_rad may span at most 360°")
        for name in ("theta2_range_rad", "theta3_range_rad", "theta4_range_rad"):
            lo, hi = ranges[name]
            if lo < -math.pi or hi > math.pi:
                raise PlannerlabError(f"IRb6: {name} must lie within [-180°, 180°]")
        if self.dead_wedge_side not in ("-z", "+z"):
            raise PlannerlabError(
                f"IRb6: dead_wedge_side must be '-z' or '+z', got {self.dead_wedge_side!r}"
            )
        if self._min_wrist_radius_anywhere_m() <= 0.0:
            raise PlannerlabError(
                "IRb6: the joint ranges let the wrist pass the column axis; the model "
                "(and the paper's annulus) needs the wrist in front of the column"
            )
        T = np.array(self.T_world_base, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise PlannerlabError("IRb6: T_world_base must be a finite (4, 4) matrix")
        R = T[:3, :3]
        if not (
            np.allclose(R.T @ R, np.eye(3), atol=1e-9)
            and np.isclose(np.linalg.det(R), 1.0, atol=1e-9)
            and np.allclose(T[3], (0.0, 0.0, 0.0, 1.0))
        ):
            raise PlannerlabError("IRb6: T_world_base must be a rigid transform")
        T.setflags(write=False)
        object.__setattr__(self, "T_world_base", T)
        # dead arc of azimuths = [yaw0 + θ1_hi, yaw0 + θ1_lo + 2π]; one edge on +x_s
        yaw0 = -t1hi if self.dead_wedge_side == "-z" else -t1lo
        object.__setattr__(self, "theta1_zero_azimuth_rad", float(yaw0))
        lower = np.array([r[0] for r in ranges.values()], dtype=float)
        upper = np.array([r[1] for r in ranges.values()], dtype=float)
        radii = np.array(
            [
                self.rail_radius_m,
                self.column_radius_m,
                self.lower_arm_radius_m,
                self.upper_arm_radius_m,
                self.wrist_radius_m,
            ]
        )
        continuous = np.zeros(6, dtype=bool)
        for name, arr in (
            ("lower", lower),
            ("upper", upper),
            ("link_radii_m", radii),
            ("continuous", continuous),
        ):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    # ------------------------------------------------------------------ geometry helpers
    def _min_wrist_radius_anywhere_m(self) -> float:
        """Smallest horizontal wrist distance from the column axis over the joint box."""

        def min_over(f: Callable[[float], float], lo: float, hi: float) -> float:
            cands = [lo, hi] + [k * math.pi / 2 for k in range(-4, 5) if lo < k * math.pi / 2 < hi]
            return min(f(t) for t in cands)

        return self.lower_arm_m * min_over(math.sin, *self.theta2_range_rad) + (
            self.upper_arm_m * min_over(math.cos, *self.theta3_range_rad)
        )

    @property
    def dead_wedge_azimuth_rad(self) -> tuple[float, float]:
        """The dead arc of azimuths ``[start, end]`` (end ≥ start, may exceed π) [rad]."""
        lo, hi = self.theta1_range_rad
        yaw0 = self.theta1_zero_azimuth_rad
        return (yaw0 + hi, yaw0 + lo + 2.0 * math.pi)

    @property
    def link_frame_names(self) -> tuple[str, ...]:
        """URDF link names whose frames equal ``fk(q)`` frames, in order."""
        return _FRAME_NAMES

    def _check_q(self, q: Array) -> Array:
        q = np.asarray(q, dtype=float)
        if q.shape[-1:] != (self.dof,) or q.ndim not in (1, 2):
            raise PlannerlabError(f"IRb6: q must have shape (6,) or (k, 6), got {q.shape}")
        return q

    # ------------------------------------------------------------------ kinematics
    def fk_station(self, q: Array) -> Array:
        """Frames ``T_station_frame`` (F=6: carriage, column, lower arm, upper arm, wrist,
        flange): (6, 4, 4) for q (6,), (k, 6, 4, 4) for (k, 6)."""
        q = self._check_q(q)
        lam0, t1, t2, t3, t4, t5 = np.moveaxis(q, -1, 0)
        batch = q.shape[:-1]
        T0 = np.broadcast_to(np.eye(4), batch + (4, 4)).copy()
        T0[..., 2, 3] = lam0
        T1 = T0 @ rot_y(self.theta1_zero_azimuth_rad + t1)
        T2 = T1 @ trans(0.0, self.shoulder_height_m, 0.0) @ rot_z(-t2)
        T3 = T2 @ trans(0.0, self.lower_arm_m, 0.0) @ rot_z(t2 + t3)
        T4 = T3 @ trans(self.upper_arm_m, 0.0, 0.0) @ rot_z(t4 - t3)
        T_wrist_flange0 = trans(self.wrist_to_flange_m, 0.0, 0.0)
        T_wrist_flange0[:3, :3] = _R_WRIST_FLANGE0
        T5 = T4 @ T_wrist_flange0 @ rot_z(t5)
        return np.stack([T0, T1, T2, T3, T4, T5], axis=-3)

    def fk(self, q: Array) -> Array:
        """Frames ``T_world_frame``: (6, 4, 4) for q (6,), (k, 6, 4, 4) for (k, 6).

        Order: ``link_frame_names`` (carriage, column, lower arm, upper arm, wrist, flange).
        """
        return self.T_world_base @ self.fk_station(q)

    def tip(self, q: Array) -> tuple[Array, Array]:
        """Flange position ``p_world`` [m] and approach vector ``c_world`` (the normal n)."""
        T = self.fk(q)[..., 5, :, :]
        return T[..., :3, 3].copy(), T[..., :3, 2].copy()

    def tip_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Analytic ``dp/dq`` and ``dc/dq`` (3, 6) each, world frame, at one q (6,)."""
        q = self._check_q(q)
        if q.ndim != 1:
            raise PlannerlabError("IRb6.tip_jacobian takes one q of shape (6,)")
        _, t1, t2, t3, t4, _ = q
        l2, l3, l5 = self.lower_arm_m, self.upper_arm_m, self.wrist_to_flange_m
        alpha = self.theta1_zero_azimuth_rad + t1
        u = azimuth_direction(alpha)
        du = np.array([-math.sin(alpha), 0.0, -math.cos(alpha)])
        y = np.array([0.0, 1.0, 0.0])
        r_f = l2 * math.sin(t2) + l3 * math.cos(t3) + l5 * math.cos(t4)
        Jp = np.zeros((3, 6))
        Jn = np.zeros((3, 6))
        Jp[:, 0] = (0.0, 0.0, 1.0)
        Jp[:, 1] = du * r_f
        Jp[:, 2] = l2 * (math.cos(t2) * u - math.sin(t2) * y)
        Jp[:, 3] = l3 * (-math.sin(t3) * u + math.cos(t3) * y)
        Jp[:, 4] = l5 * (-math.sin(t4) * u + math.cos(t4) * y)
        Jn[:, 1] = du * math.cos(t4)
        Jn[:, 4] = -math.sin(t4) * u + math.cos(t4) * y
        R = self.T_world_base[:3, :3]
        return R @ Jp, R @ Jn

    def chain_data(self) -> tuple[Any, ...]:
        """The arm as a serial chain for the compiled robot-scene model
        (:mod:`plannerlab.collision.chain`): parent bodies (6,), fixed transforms
        (6, 4, 4), unit axes (6, 3), which slide (6,); per capsule its body (5,) and its
        end points in that body's frame (5, 3) twice; and the coupling (6, 6).

        The chain is :meth:`fk_station`'s: body 0 the station (``T_world_base``), body
        ``i + 1`` frame ``i`` (carriage, column, lower arm, upper arm, wrist, flange). Its
        joint values are the URDF's relative angles, ``coupling @ q =``
        :meth:`urdf_joint_positions` ``(q)``; the lower arm turns about -z (``rot_z(-θ2)``).
        """
        parent = np.arange(6, dtype=np.int64)
        T_wrist_flange0 = trans(self.wrist_to_flange_m, 0.0, 0.0)
        T_wrist_flange0[:3, :3] = _R_WRIST_FLANGE0
        pre = np.stack(
            [
                np.eye(4),
                rot_y(self.theta1_zero_azimuth_rad),
                trans(0.0, self.shoulder_height_m, 0.0),
                trans(0.0, self.lower_arm_m, 0.0),
                trans(self.upper_arm_m, 0.0, 0.0),
                T_wrist_flange0,
            ]
        )
        axes = np.array(
            [[0, 0, 1], [0, 1, 0], [0, 0, -1], [0, 0, 1], [0, 0, 1], [0, 0, 1]], dtype=float
        )
        prismatic = np.array([True, False, False, False, False, False])
        zlo, zhi = self.track_range_m
        h = self.rail_height_m
        cap_body = np.array([0, 2, 3, 4, 5], dtype=np.int64)
        cap_a = np.array([[0.0, h, zlo], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]], dtype=float)
        cap_b = np.array(
            [
                [0.0, h, zhi],
                [0.0, self.shoulder_height_m, 0.0],
                [0.0, self.lower_arm_m, 0.0],
                [self.upper_arm_m, 0.0, 0.0],
                [self.wrist_to_flange_m, 0.0, 0.0],
            ]
        )
        coupling = np.eye(6)
        coupling[3, 2] = 1.0  # θ2 + θ3
        coupling[4, 3] = -1.0  # θ4 - θ3
        coupling[4, 4] = 1.0
        return parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling

    def tip_data(self) -> tuple[int, Array, Array]:
        """The tip in :meth:`chain_data`'s terms: the flange (body 6, :meth:`fk_station`'s
        frame 5), its origin and approach vector (z) in its own frame."""
        return 6, np.zeros(3), np.array([0.0, 0.0, 1.0])

    def link_segments(self, q: Array) -> Array:
        """Capsule axes in the world: (5, 2, 3) for q (6,), (k, 5, 2, 3) for (k, 6)."""
        T = self.fk(q)
        o = T[..., :, :3, 3]  # (..., 6, 3) frame origins
        zlo, zhi = self.track_range_m
        rail = np.array([[0.0, self.rail_height_m, zlo, 1.0], [0.0, self.rail_height_m, zhi, 1.0]])
        rail_w = (self.T_world_base @ rail.T).T[:, :3]
        rail_w = np.broadcast_to(rail_w, o.shape[:-2] + (2, 3))
        starts = o[..., 1:5, :]  # column, lower arm, upper arm, wrist start at frames 1..4
        ends = o[..., 2:6, :]
        moving = np.stack([starts, ends], axis=-2)  # (..., 4, 2, 3)
        return np.concatenate([rail_w[..., None, :, :], moving], axis=-3)

    # ------------------------------------------------------------------ URDF
    def urdf_joint_positions(self, q: Array) -> Array:
        """URDF (relative) joint values for q: (λ0, θ1, θ2, θ2+θ3, θ4−θ3, θ5), (..., 6)."""
        q = np.asarray(q, dtype=float)
        out = q.copy()
        out[..., 3] = q[..., 2] + q[..., 3]
        out[..., 4] = q[..., 4] - q[..., 3]
        return out

    def q_from_urdf_joint_positions(self, q_urdf: Array) -> Array:
        """Inverse of :meth:`urdf_joint_positions`: absolute q from URDF values (..., 6)."""
        j = np.asarray(q_urdf, dtype=float)
        q = j.copy()
        q[..., 3] = j[..., 3] - j[..., 2]
        q[..., 4] = j[..., 4] + q[..., 3]
        return q

    def urdf(self) -> str:
        """URDF text in the station frame (load it with the base at ``T_world_base``).

        The joint values are :meth:`urdf_joint_positions` of q (relative angles), not q.
        """
        lo, hi = self.lower, self.upper
        # widest relative ranges the absolute box allows
        j_lo = [lo[0], lo[1], lo[2], lo[2] + lo[3], lo[4] - hi[3], lo[5]]
        j_hi = [hi[0], hi[1], hi[2], hi[2] + hi[3], hi[4] - lo[3], hi[5]]
        axes = ["0 0 1", "0 1 0", "0 0 -1", "0 0 1", "0 0 1", "0 0 1"]
        kinds = ["prismatic"] + ["revolute"] * 5
        effort = [1500.0, 300.0, 600.0, 400.0, 60.0, 20.0]
        velocity = [1.0, 1.7, 1.3, 1.3, 2.5, 3.5]
        T_wrist_flange0 = trans(self.wrist_to_flange_m, 0.0, 0.0)
        T_wrist_flange0[:3, :3] = _R_WRIST_FLANGE0
        origins = [
            np.eye(4),
            rot_y(self.theta1_zero_azimuth_rad),
            trans(0.0, self.shoulder_height_m, 0.0),
            trans(0.0, self.lower_arm_m, 0.0),
            trans(self.upper_arm_m, 0.0, 0.0),
            T_wrist_flange0,
        ]
        zlo, zhi = self.track_range_m
        rail_len = zhi - zlo
        # (link, mass [kg], capsule (T_link_capsule, length, radius) or None)
        x_axis_capsule = rot_y(math.pi / 2)  # capsule z axis along link x
        y_axis_capsule = rot_x(-math.pi / 2)  # capsule z axis along link y
        links = [
            (
                "lp1_rail",
                200.0,
                (trans(0.0, self.rail_height_m, 0.5 * (zlo + zhi)), rail_len, self.rail_radius_m),
            ),
            ("lp1_carriage", 40.0, None),
            (
                "irb6_column",
                60.0,
                (
                    trans(0.0, 0.5 * self.shoulder_height_m, 0.0) @ y_axis_capsule,
                    self.shoulder_height_m,
                    self.column_radius_m,
                ),
            ),
            (
                "irb6_lower_arm",
                20.0,
                (
                    trans(0.0, 0.5 * self.lower_arm_m, 0.0) @ y_axis_capsule,
                    self.lower_arm_m,
                    self.lower_arm_radius_m,
                ),
            ),
            (
                "irb6_upper_arm",
                15.0,
                (
                    trans(0.5 * self.upper_arm_m, 0.0, 0.0) @ x_axis_capsule,
                    self.upper_arm_m,
                    self.upper_arm_radius_m,
                ),
            ),
            (
                "irb6_wrist",
                3.0,
                (
                    trans(0.5 * self.wrist_to_flange_m, 0.0, 0.0) @ x_axis_capsule,
                    self.wrist_to_flange_m,
                    self.wrist_radius_m,
                ),
            ),
            ("irb6_flange", 0.5, None),
        ]
        parts = ['<?xml version="1.0"?>', '<robot name="irb6_lp1">']
        for name, mass, capsule in links:
            parts.append(f'  <link name="{name}">')
            if capsule is None:
                size = 0.3 if name == "lp1_carriage" else 0.04
                ixx = mass * size * size / 6.0
                parts.append(
                    f'    <inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="{mass}"/>'
                    f'<inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{ixx!r}" iyz="0" izz="{ixx!r}"/>'
                    "</inertial>"
                )
                parts.append(
                    f'    <visual><origin xyz="0 0 0" rpy="0 0 0"/><geometry><box size="{size} '
                    f'{size} {size}"/></geometry></visual>'
                )
            else:
                T_cap, length, radius = capsule
                # solid cylinder about its own z axis
                i_axial = 0.5 * mass * radius**2
                i_trans = mass * (3.0 * radius**2 + length**2) / 12.0
                origin = urdf_origin(T_cap)
                # the fixed root keeps its inertial frame at the link frame (PyBullet's base
                # pose is the inertial frame's)
                identity = '<origin xyz="0 0 0" rpy="0 0 0"/>'
                inertial_origin = identity if name == "lp1_rail" else origin
                parts.append(
                    f'    <inertial>{inertial_origin}<mass value="{mass}"/>'
                    f'<inertia ixx="{i_trans!r}" ixy="0" ixz="0" iyy="{i_trans!r}" iyz="0" '
                    f'izz="{i_axial!r}"/></inertial>'
                )
                geom = f'<capsule radius="{radius!r}" length="{length!r}"/>'
                parts.append(f"    <visual>{origin}<geometry>{geom}</geometry></visual>")
                parts.append(f"    <collision>{origin}<geometry>{geom}</geometry></collision>")
            parts.append("  </link>")
        parents = ["lp1_rail"] + list(_FRAME_NAMES[:-1])
        for i, jname in enumerate(_JOINT_NAMES):
            parts.append(f'  <joint name="{jname}" type="{kinds[i]}">')
            parts.append(f'    <parent link="{parents[i]}"/><child link="{_FRAME_NAMES[i]}"/>')
            parts.append(f'    {urdf_origin(origins[i])}<axis xyz="{axes[i]}"/>')
            parts.append(
                f'    <limit lower="{float(j_lo[i])!r}" upper="{float(j_hi[i])!r}" '
                f'effort="{effort[i]}" velocity="{velocity[i]}"/>'
            )
            parts.append("  </joint>")
        parts.append("</robot>")
        return "\n".join(parts) + "\n"

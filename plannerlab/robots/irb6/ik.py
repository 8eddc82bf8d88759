"""Analytic inverse kinematics of the IRb-6 on the LP-1 track, every solution.

Follows Lubiński (``docs/papers.md`` §2). All poses are in the *station frame* S of
:mod:`plannerlab.robots.irb6.model` (x_s horizontal, y_s up, z_s along the track); the target is
the flange pose ``T = X · E⁻¹`` (:func:`flange_target`) with columns a, b, c (approach),
d (position).

Cases (``IKAnswer.case``):

* ``"unambiguous"``: c not vertical and c_x ≠ 0: ``λ0 = d_z − d_x · c_z / c_x`` (3).
* ``"ambiguous_1"``: c_x = 0, d_x = 0, c not vertical: the arm plane runs along the track
  and every λ0 of an interval works: ``[d_z − R_zew, d_z − R_wew]`` (c_z > 0) or
  ``[d_z + R_wew, d_z + R_zew]`` (c_z < 0), clipped to the track; the paper's (4)–(7).
* ``"ambiguous_2"``: c vertical (c_x = c_z = 0): ``E = (A \\ (B ∪ C)) ∩ track`` with
  A the disc of radius R_zew, B the disc of radius R_wew and C the dead wedge of θ1; the
  paper's (8)–(12). The paper's case 1 with c_z = 0 ("both intervals") is this case with
  d_x = 0 and gives the same two intervals.

In the ambiguous cases one solution is built at the midpoint of each remaining interval;
:func:`solve_with_lambda0` solves at any λ0 the caller picks from
``IKAnswer.lambda0_intervals_m``.

The annulus radii (decision): the paper's r_min, r_max are read off a table of 11 height
bands. Here they are computed from the joint ranges at the exact wrist height
``h_w = d_y − λ5 · c_y`` (:func:`~plannerlab.robots.irb6.wrist.wrist_annulus_m` gives the
wrist radii r_w,min, r_w,max).
Near the lowest wrist heights (below ≈ 0.72 m for the default ranges) the reachable wrist
distances split into two intervals (only θ2 near ±40° gets that low); the gap between them
is removed as one more ring, which the paper's annulus does not do
(:func:`~plannerlab.robots.irb6.wrist.wrist_radius_intervals_m`).
With the paper's ``r_min = r_w,min`` and ``r_max = r_w,max + λ5`` (flange reach with a
horizontal approach), the paper's corrections ``k_rw = |λ5 c_z|``, ``k_rz = λ5 − k_rw``
give ``R_wew = r_w,min + λ5 |c_z|`` and ``R_zew = r_w,max + λ5 |c_z|``: exact at every
height, so the paper's height band y2…y5 (where the correction applies) is not needed.

θ5 spans 360°: at the range ends two values give the same orientation; with
``previous_theta5_rad`` the one closer to it is kept, else both are returned.

Only numpy is used.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array
from plannerlab.robots.irb6.model import IRb6
from plannerlab.robots.irb6.wrist import TOL as _TOL
from plannerlab.robots.irb6.wrist import two_link, wrist_radius_intervals_m

#: reason codes of an unreachable pose, in order of how far the solver got
REASON_CODES = (
    "no_arm_plane",
    "outside_track",
    "outside_annulus",
    "dead_wedge",
    "joint_limit",
)

_PLANE_TOL_M = 1e-8

Pose = Array | tuple[Array, Array, float] | Sequence[object]


@dataclass(frozen=True, eq=False)
class IKAnswer:
    """The result of :func:`solve_ik` (or :func:`solve_with_lambda0`).

    Attributes:
        case: ``"unambiguous"``, ``"ambiguous_1"`` or ``"ambiguous_2"``.
        lambda0_intervals_m: the feasible λ0 set [m] after every paper step (clipped to
            the track); a single point ``(λ0, λ0)`` in the unambiguous case; empty when
            no λ0 is feasible.
        solutions: every joint vector q (6,) found, within the joint ranges.
        reason: why there is no solution (None when there is one).
        reason_code: one of :data:`REASON_CODES`, or None.
        inner_radius_m: the paper's R_wew (ambiguous cases), else None.
        outer_radius_m: the paper's R_zew (ambiguous cases), else None.
    """

    case: str
    lambda0_intervals_m: tuple[tuple[float, float], ...]
    solutions: tuple[Array, ...]
    reason: str | None
    reason_code: str | None = None
    inner_radius_m: float | None = None
    outer_radius_m: float | None = None

    @property
    def ok(self) -> bool:
        """True when at least one solution exists."""
        return len(self.solutions) > 0


# ---------------------------------------------------------------------- pose helpers
def flange_target(T_station_tool: Array, T_flange_tool: Array) -> Array:
    """The flange pose ``T = X · E⁻¹`` (paper eq. 1) for a tool pose X and tool transform E.

    Args:
        T_station_tool: X, (4, 4) tool pose in the station frame.
        T_flange_tool: E, (4, 4) tool frame in the flange frame.

    Returns:
        (4, 4) ``T_station_flange``.
    """
    X = _check_transform(T_station_tool, "T_station_tool")
    E = _check_transform(T_flange_tool, "T_flange_tool")
    return X @ np.linalg.inv(E)


def pose_from_approach(p_station_m: Array, c_station: Array, roll_rad: float) -> Array:
    """Flange pose (4, 4) from a position, an approach vector and a roll angle.

    The roll turns the flange x-axis a about c (right hand) from a reference direction:
    the vertical y_s made perpendicular to c, or +x_s when c is vertical. For a
    non-vertical c with θ4 in (−90°, 90°), the roll equals θ5.

    Raises:
        PlannerlabError: NaN/inf input, wrong shape or a zero approach vector.
    """
    p = _finite_vector(p_station_m, "p_station_m")
    c = _unit(_finite_vector(c_station, "c_station"), "c_station")
    roll = float(roll_rad)
    if not math.isfinite(roll):
        raise PlannerlabError(f"IRb-6 IK: roll_rad must be finite, got {roll_rad!r}")
    ref = np.array([0.0, 1.0, 0.0]) - c[1] * c
    if np.linalg.norm(ref) < 1e-9:
        ref = np.array([1.0, 0.0, 0.0]) - c[0] * c
    ref = ref / np.linalg.norm(ref)
    a = math.cos(roll) * ref + math.sin(roll) * np.cross(c, ref)
    T = np.eye(4)
    T[:3, 0] = a
    T[:3, 1] = np.cross(c, a)
    T[:3, 2] = c
    T[:3, 3] = p
    return T


def _finite_vector(v: object, name: str) -> Array:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (3,):
        raise PlannerlabError(f"IRb-6 IK: {name} must have shape (3,), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise PlannerlabError(f"IRb-6 IK: {name} must be finite, got {arr.tolist()}")
    return arr


def _unit(v: Array, name: str) -> Array:
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise PlannerlabError(f"IRb-6 IK: {name} is a zero vector; an approach needs a direction")
    return v / n


def _check_transform(T: object, name: str) -> Array:
    arr = np.asarray(T, dtype=float)
    if arr.shape != (4, 4):
        raise PlannerlabError(f"IRb-6 IK: {name} must be (4, 4), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise PlannerlabError(f"IRb-6 IK: {name} contains NaN or inf")
    R = arr[:3, :3]
    if not (
        np.allclose(R.T @ R, np.eye(3), atol=1e-6)
        and np.linalg.det(R) > 0.0
        and np.allclose(arr[3], (0.0, 0.0, 0.0, 1.0))
    ):
        raise PlannerlabError(f"IRb-6 IK: {name} is not a rigid transform")
    return arr


def _parse_pose(pose: Pose) -> Array:
    """(4, 4) ``T_station_flange`` from a transform or a (p, c, roll) triple."""
    if isinstance(pose, (tuple, list)) and len(pose) == 3:
        p, c, roll = pose
        return pose_from_approach(p, c, float(roll))  # type: ignore[arg-type]
    if np.shape(pose) == (4, 4):  # type: ignore[arg-type]
        return _check_transform(pose, "T_station_flange")
    raise PlannerlabError(
        "IRb-6 IK: the pose must be a (4, 4) T_station_flange or a (p_station_m, "
        "c_station, roll_rad) triple"
    )


def _in_range(t: float, rng: tuple[float, float]) -> float | None:
    """t clipped into rng when within tolerance, else None."""
    lo, hi = rng
    if lo - _TOL <= t <= hi + _TOL:
        return min(max(t, lo), hi)
    return None


def _periodic_candidates(t: float, rng: tuple[float, float]) -> list[float]:
    """Every t + 2πk inside rng (tolerant at the ends), sorted, without duplicates."""
    lo, hi = rng
    k_lo = math.floor((lo - _TOL - t) / (2.0 * math.pi))
    k_hi = math.ceil((hi + _TOL - t) / (2.0 * math.pi))
    out: list[float] = []
    for k in range(k_lo, k_hi + 1):
        v = _in_range(t + 2.0 * math.pi * k, rng)
        if v is not None and all(abs(v - o) > 1e-12 for o in out):
            out.append(v)
    return sorted(out)


def _deg(t: float) -> str:
    return f"{math.degrees(t):.3f}°"


def _deg_range(rng: tuple[float, float]) -> str:
    return f"[{_deg(rng[0])}, {_deg(rng[1])}]"


class _Failure:
    """The furthest step any candidate reached, for the reason of an empty answer."""

    def __init__(self) -> None:
        self.rank = -1
        self.code: str | None = None
        self.text: str | None = None

    def note(self, code: str, text: str) -> None:
        rank = REASON_CODES.index(code)
        if rank > self.rank:
            self.rank, self.code, self.text = rank, code, text


def _solve_at(
    robot: IRb6,
    T: Array,
    lambda0_m: float,
    previous_theta5_rad: float | None,
    fail: _Failure,
) -> list[Array]:
    """Every q with the carriage at ``lambda0_m`` that puts the flange at T (station)."""
    d, c, a = T[:3, 3], T[:3, 2], T[:3, 0]
    l5 = robot.wrist_to_flange_m
    w = d - l5 * c
    v = np.array([w[0], w[2] - lambda0_m])  # wrist from the column axis, (x, z)
    ch = math.hypot(c[0], c[2])
    if ch > _TOL:
        dirs = [np.array([c[0], c[2]]) / ch, -np.array([c[0], c[2]]) / ch]
    else:
        rho = float(np.hypot(*v))
        if rho <= _TOL:
            fail.note("outside_annulus", "the wrist point is on the column axis")
            return []
        dirs = [v / rho]
    y = np.array([0.0, 1.0, 0.0])
    out: list[Array] = []
    for uxz in dirs:
        cross = uxz[0] * v[1] - uxz[1] * v[0]
        if abs(cross) > _PLANE_TOL_M:
            fail.note(
                "no_arm_plane",
                f"at λ0 = {lambda0_m:.6f} m the approach vector's vertical plane misses "
                f"the column axis by {abs(cross):.3g} m",
            )
            continue
        r_w = float(uxz @ v)
        h_w = float(w[1])
        radii = wrist_radius_intervals_m(robot, h_w)
        if not radii:
            fail.note(
                "outside_annulus",
                f"no wrist pose reaches the wrist height {h_w:.4f} m (λ0 = {lambda0_m:.4f} m)",
            )
            continue
        if not any(lo - _TOL <= r_w <= hi + _TOL for lo, hi in radii):
            spans = " ∪ ".join(f"[{lo:.4f}, {hi:.4f}]" for lo, hi in radii)
            fail.note(
                "outside_annulus",
                f"wrist distance {r_w:.4f} m from the column is outside the reachable annulus "
                f"{spans} m at wrist height {h_w:.4f} m (λ0 = {lambda0_m:.4f} m)",
            )
            continue
        alpha = math.atan2(-uxz[1], uxz[0])
        t1s = _periodic_candidates(alpha - robot.theta1_zero_azimuth_rad, robot.theta1_range_rad)
        if not t1s:
            fail.note(
                "dead_wedge",
                f"the arm azimuth {_deg(alpha)} lies in the dead wedge of θ1 "
                f"(θ1 range {_deg_range(robot.theta1_range_rad)}, λ0 = {lambda0_m:.4f} m)",
            )
            continue
        u = np.array([uxz[0], 0.0, uxz[1]])
        t4 = _in_range(math.atan2(float(c @ y), float(c @ u)), robot.theta4_range_rad)
        if t4 is None:
            t4_raw = math.atan2(float(c @ y), float(c @ u))
            fail.note(
                "joint_limit",
                f"θ4 = {_deg(t4_raw)} outside {_deg_range(robot.theta4_range_rad)}",
            )
            continue
        arms = []
        for t2, t3 in two_link(robot, r_w, h_w - robot.shoulder_height_m):
            t2c = _in_range(t2, robot.theta2_range_rad)
            t3c = _in_range(t3, robot.theta3_range_rad)
            if t2c is None or t3c is None:
                fail.note(
                    "joint_limit",
                    f"θ2 = {_deg(t2)} or θ3 = {_deg(t3)} outside "
                    f"{_deg_range(robot.theta2_range_rad)}, {_deg_range(robot.theta3_range_rad)}",
                )
                continue
            arms.append((t2c, t3c))
        if not arms:
            fail.note("joint_limit", "no arm pose reaches the wrist point within θ2, θ3 ranges")
            continue
        x5_0 = -math.sin(t4) * u + math.cos(t4) * y
        y5_0 = np.cross(c, x5_0)
        t5 = math.atan2(float(a @ y5_0), float(a @ x5_0))
        t5s = _periodic_candidates(t5, robot.theta5_range_rad)
        if not t5s:
            fail.note(
                "joint_limit", f"θ5 = {_deg(t5)} outside {_deg_range(robot.theta5_range_rad)}"
            )
            continue
        if previous_theta5_rad is not None and len(t5s) > 1:
            t5s = [min(t5s, key=lambda t: abs(t - previous_theta5_rad))]
        for t1 in t1s:
            for t2, t3 in arms:
                for t5v in t5s:
                    out.append(np.array([lambda0_m, t1, t2, t3, t4, t5v]))
    return out


# ---------------------------------------------------------------------- λ0 intervals
Interval = tuple[float, float]


def _subtract(pieces: list[Interval], cut: Interval) -> list[Interval]:
    out: list[Interval] = []
    for lo, hi in pieces:
        if cut[1] < lo or cut[0] > hi:
            out.append((lo, hi))
            continue
        if cut[0] > lo:
            out.append((lo, cut[0]))
        if cut[1] < hi:
            out.append((cut[1], hi))
    return out


def _intersect(pieces: list[Interval], keep: Interval) -> list[Interval]:
    out = []
    for lo, hi in pieces:
        a, b = max(lo, keep[0]), min(hi, keep[1])
        if b >= a:
            out.append((a, b))
    return out


def _dead_wedge_lambda0(robot: IRb6, d_x: float, d_z: float) -> list[Interval]:
    """λ0 values that put a wrist point (d_x, d_z) at an azimuth inside the dead wedge.

    The azimuth from the column at λ0 to the point is ``atan2(λ0 − d_z, d_x)``, so
    ``λ0 = d_z + d_x · tan α``; for the paper's wedge [0°, 20°] and d_x > 0 this is
    ``C = [d_z, d_z + d_x tan 20°]`` (eq. 10).
    """
    w0, w1 = robot.dead_wedge_azimuth_rad
    if w1 - w0 <= 0.0:
        return []
    two_pi = 2.0 * math.pi
    out: list[Interval] = []
    if abs(d_x) <= _TOL:
        for alpha, piece in ((math.pi / 2, (d_z, math.inf)), (-math.pi / 2, (-math.inf, d_z))):
            k = math.ceil((w0 - alpha) / two_pi)
            if alpha + two_pi * k <= w1:
                out.append(piece)
        return out
    center = 0.0 if d_x > 0 else math.pi
    for k in range(-2, 3):
        lo = max(w0 + two_pi * k, center - math.pi / 2)
        hi = min(w1 + two_pi * k, center + math.pi / 2)
        if hi < lo:
            continue
        ends = []
        for alpha in (lo, hi):
            if abs(alpha - (center - math.pi / 2)) < 1e-15:
                ends.append(-math.inf if d_x > 0 else math.inf)
            elif abs(alpha - (center + math.pi / 2)) < 1e-15:
                ends.append(math.inf if d_x > 0 else -math.inf)
            else:
                ends.append(d_z + d_x * math.tan(alpha))
        out.append((min(ends), max(ends)))
    return out


def _classify(T: Array, ambiguity_tol: float) -> tuple[str, Array]:
    """The case and the pose snapped onto it (exact zeros for the ambiguous components)."""
    c, d = T[:3, 2], T[:3, 3]
    if abs(c[0]) <= ambiguity_tol and abs(c[2]) <= ambiguity_tol:
        Ts = T.copy()
        Ts[:3, 2] = (0.0, math.copysign(1.0, c[1]), 0.0)
        a = Ts[:3, 0] - (Ts[:3, 0] @ Ts[:3, 2]) * Ts[:3, 2]
        Ts[:3, 0] = a / np.linalg.norm(a)
        Ts[:3, 1] = np.cross(Ts[:3, 2], Ts[:3, 0])
        return "ambiguous_2", Ts
    if abs(c[0]) <= ambiguity_tol and abs(d[0]) <= ambiguity_tol:
        Ts = T.copy()
        cs = np.array([0.0, c[1], c[2]]) / math.hypot(c[1], c[2])
        a = Ts[:3, 0] - (Ts[:3, 0] @ cs) * cs
        Ts[:3, 0] = a / np.linalg.norm(a)
        Ts[:3, 2] = cs
        Ts[:3, 1] = np.cross(cs, Ts[:3, 0])
        Ts[0, 3] = 0.0
        return "ambiguous_1", Ts
    return "unambiguous", T


def _feasible_lambda0(
    robot: IRb6, case: str, T: Array, fail: _Failure
) -> tuple[list[Interval], float | None, float | None]:
    """The λ0 interval set of a pose (station), with the paper's R_wew, R_zew."""
    c, d = T[:3, 2], T[:3, 3]
    track = robot.track_range_m
    l5 = robot.wrist_to_flange_m
    if case == "unambiguous":
        if abs(c[0]) <= _TOL:
            fail.note(
                "no_arm_plane",
                "c_x = 0 but d_x ≠ 0: the approach vector's vertical plane runs parallel to "
                "the track and never contains the column axis",
            )
            return [], None, None
        lam = float(d[2] - d[0] * c[2] / c[0])
        lam_c = _in_range(lam, track)
        if lam_c is None:
            fail.note(
                "outside_track",
                f"λ0 = d_z − d_x·c_z/c_x = {lam:.4f} m is outside the track range "
                f"[{track[0]:.4f}, {track[1]:.4f}] m",
            )
            return [], None, None
        return [(lam_c, lam_c)], None, None

    h_w = float(d[1] - l5 * c[1])
    radii = wrist_radius_intervals_m(robot, h_w)
    if not radii:
        fail.note("outside_annulus", f"no wrist pose reaches the wrist height {h_w:.4f} m")
        return [], None, None
    r_min, r_max = radii[0][0], radii[-1][1]
    gaps = [(radii[i][1], radii[i + 1][0]) for i in range(len(radii) - 1)]
    y = np.array([0.0, 1.0, 0.0])
    pieces: list[Interval] = []
    R_in_paper = R_out_paper = None
    if case == "ambiguous_1":
        cz = float(c[2])
        for s in (1.0, -1.0):  # s = +1: the approach points away from the column
            uz = s * math.copysign(1.0, cz)
            u = np.array([0.0, 0.0, uz])
            cu = float(c @ u)
            R_in = r_min + l5 * cu
            R_out = r_max + l5 * cu
            if s > 0:
                R_in_paper, R_out_paper = R_in, R_out
            t4 = math.atan2(float(c @ y), cu)
            if _in_range(t4, robot.theta4_range_rad) is None:
                if s > 0:  # reaching behind (s = −1) is only an option for wide θ4 ranges
                    fail.note(
                        "joint_limit",
                        f"θ4 = {_deg(t4)} outside {_deg_range(robot.theta4_range_rad)}",
                    )
                continue
            alpha = math.atan2(-uz, 0.0)
            if not _periodic_candidates(
                alpha - robot.theta1_zero_azimuth_rad, robot.theta1_range_rad
            ):
                fail.note("dead_wedge", f"the arm azimuth {_deg(alpha)} lies in the dead wedge")
                continue
            # flange at d_z, column behind it along −u: λ0 = d_z − uz · R; (6), (7)
            for r_lo, r_hi in radii:  # one interval unless the wrist slice has a gap
                R_lo, R_hi = r_lo + l5 * cu, r_hi + l5 * cu
                piece = (d[2] - R_hi, d[2] - R_lo) if uz > 0 else (d[2] + R_lo, d[2] + R_hi)
                pieces.append((float(piece[0]), float(piece[1])))
        pieces.sort()
        if not pieces:
            return [], R_in_paper, R_out_paper
    else:  # ambiguous_2: vertical approach, wrist right above/below the flange
        R_in_paper, R_out_paper = r_min, r_max
        t4 = math.copysign(math.pi / 2, c[1])
        if _in_range(t4, robot.theta4_range_rad) is None:
            fail.note(
                "joint_limit", f"θ4 = {_deg(t4)} outside {_deg_range(robot.theta4_range_rad)}"
            )
            return [], R_in_paper, R_out_paper
        dx, dz = float(d[0]), float(d[2])
        if abs(dx) > r_max:
            fail.note(
                "outside_annulus",
                f"|d_x| = {abs(dx):.4f} m exceeds the reach R_zew = {r_max:.4f} m at wrist "
                f"height {h_w:.4f} m",
            )
            return [], R_in_paper, R_out_paper
        half_a = math.sqrt(r_max * r_max - dx * dx)
        pieces = [(dz - half_a, dz + half_a)]  # A (8)
        if abs(dx) < r_min:
            half_b = math.sqrt(r_min * r_min - dx * dx)
            pieces = _subtract(pieces, (dz - half_b, dz + half_b))  # B (9)
            if not pieces:
                fail.note("outside_annulus", "every λ0 puts the wrist too close to the column")
                return [], R_in_paper, R_out_paper
        for g_lo, g_hi in gaps:  # rings of wrist distances unreachable at this height
            if abs(dx) < g_hi:
                outer = math.sqrt(g_hi * g_hi - dx * dx)
                inner = math.sqrt(g_lo * g_lo - dx * dx) if abs(dx) < g_lo else 0.0
                pieces = _subtract(pieces, (dz - outer, dz - inner))
                pieces = _subtract(pieces, (dz + inner, dz + outer))
        if not pieces:
            fail.note("outside_annulus", "every λ0 puts the wrist at an unreachable distance")
            return [], R_in_paper, R_out_paper
        for cut in _dead_wedge_lambda0(robot, dx, dz):  # C (10)
            pieces = _subtract(pieces, cut)
        if not pieces:  # D (11)
            fail.note("dead_wedge", "every remaining λ0 puts the arm in the dead wedge of θ1")
            return [], R_in_paper, R_out_paper
    before = pieces
    pieces = _intersect(pieces, track)  # E (12)
    if not pieces:
        spans = ", ".join(f"[{lo:.4f}, {hi:.4f}]" for lo, hi in before)
        fail.note(
            "outside_track",
            f"the feasible λ0 set {spans} m misses the track range "
            f"[{track[0]:.4f}, {track[1]:.4f}] m",
        )
    return pieces, R_in_paper, R_out_paper


# ---------------------------------------------------------------------- public solvers
def solve_ik(
    robot: IRb6,
    pose: Pose,
    previous_theta5_rad: float | None = None,
    ambiguity_tol: float = _TOL,
) -> IKAnswer:
    """Every joint vector that puts the flange at a pose (station frame).

    Args:
        robot: the model (its joint ranges, lengths and dead-wedge side are used).
        pose: ``T_station_flange`` (4, 4), or ``(p_station_m, c_station, roll_rad)``
            (see :func:`pose_from_approach`).
        previous_theta5_rad: θ5 of the previous pose on a trajectory; at the ends of the
            θ5 range only the equivalent value closest to it is kept.
        ambiguity_tol: |c_x|, |c_z|, |d_x| at or below this count as zero.

    Returns:
        An :class:`IKAnswer`; in the ambiguous cases one solution per λ0 interval, at its
        midpoint.

    Raises:
        PlannerlabError: malformed pose (NaN, zero approach vector, not a rigid transform).
    """
    T = _parse_pose(pose)
    case, Ts = _classify(T, ambiguity_tol)
    fail = _Failure()
    intervals, R_in, R_out = _feasible_lambda0(robot, case, Ts, fail)
    solutions: list[Array] = []
    for lo, hi in intervals:
        solutions.extend(_solve_at(robot, Ts, 0.5 * (lo + hi), previous_theta5_rad, fail))
    return IKAnswer(
        case=case,
        lambda0_intervals_m=tuple(intervals),
        solutions=tuple(solutions),
        reason=None if solutions else fail.text,
        reason_code=None if solutions else fail.code,
        inner_radius_m=R_in,
        outer_radius_m=R_out,
    )


def solve_with_lambda0(
    robot: IRb6,
    pose: Pose,
    lambda0_m: float,
    previous_theta5_rad: float | None = None,
    ambiguity_tol: float = _TOL,
) -> IKAnswer:
    """Every joint vector with the carriage at a chosen λ0 that reaches a pose.

    The answer's ``lambda0_intervals_m`` is the pose's full feasible set (as in
    :func:`solve_ik`), so a caller can see where else to look.

    Raises:
        PlannerlabError: malformed pose or a non-finite λ0.
    """
    lam = float(lambda0_m)
    if not math.isfinite(lam):
        raise PlannerlabError(f"IRb-6 IK: lambda0_m must be finite, got {lambda0_m!r}")
    T = _parse_pose(pose)
    case, Ts = _classify(T, ambiguity_tol)
    fail = _Failure()
    intervals, R_in, R_out = _feasible_lambda0(robot, case, Ts, _Failure())
    solutions: list[Array] = []
    lam_c = _in_range(lam, robot.track_range_m)
    if lam_c is None:
        lo, hi = robot.track_range_m
        fail.note("outside_track", f"λ0 = {lam:.4f} m is outside the track [{lo:.4f}, {hi:.4f}] m")
    else:
        solutions = _solve_at(robot, Ts, lam_c, previous_theta5_rad, fail)
    return IKAnswer(
        case=case,
        lambda0_intervals_m=tuple(intervals),
        solutions=tuple(solutions),
        reason=None if solutions else fail.text,
        reason_code=None if solutions else fail.code,
        inner_radius_m=R_in,
        outer_radius_m=R_out,
    )


def format_ik_answer(answer: IKAnswer) -> list[tuple[str, str]]:
    """Rows ``(label, value)`` of an answer, for a CLI table (λ0 in m, angles in °)."""
    rows = [("case", answer.case)]
    spans = ", ".join(f"[{lo:.4f}, {hi:.4f}]" for lo, hi in answer.lambda0_intervals_m)
    rows.append(("λ0 intervals [m]", spans or "none"))
    if answer.inner_radius_m is not None and answer.outer_radius_m is not None:
        rows.append(
            ("R_wew, R_zew [m]", f"{answer.inner_radius_m:.4f}, {answer.outer_radius_m:.4f}")
        )
    for i, q in enumerate(answer.solutions):
        angles = ", ".join(f"θ{j} = {math.degrees(q[j]):.3f}°" for j in range(1, 6))
        rows.append((f"solution {i + 1}", f"λ0 = {q[0]:.4f} m, {angles}"))
    if answer.reason is not None:
        rows.append(("unreachable", f"{answer.reason_code}: {answer.reason}"))
    return rows

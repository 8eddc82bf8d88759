"""Where the IRb-6's wrist can be: the horizontal wrist distances from the column axis
reachable at a wrist height (:func:`wrist_radius_intervals_m`, and their hull, the paper's
annulus, :func:`wrist_annulus_m`), and the two-link arm (θ2, θ3) that puts the wrist at a
distance and height (:func:`two_link`). Frames and lengths are those of
:mod:`plannerlab.robots.irb6.model`; the analytic IK that uses them is
:mod:`plannerlab.robots.irb6.ik` (why the annulus is computed here and not read off the
paper's table: its module docstring).

Only numpy is used.
"""

from __future__ import annotations

import math

from plannerlab.robots.irb6.model import IRb6

TOL = 1e-9  # [m] and [rad]: boundary and classification tolerance of the IRb-6's IK


def wrist_radius_intervals_m(robot: IRb6, wrist_height_m: float) -> list[tuple[float, float]]:
    """Horizontal wrist distances from the column axis reachable at a wrist height.

    The slice y = h of the wrist workspace (θ2, θ3 in their ranges) in closed form: for
    each sign of θ2 the slice is a set of curves parametrised by θ3 on the sub-ranges
    where ``cos θ2 = (h − λ1 − l3 sin θ3) / l2`` gives an admissible θ2; along each curve
    the distance r is extreme at its ends or where the two arms are aligned
    (θ2 + θ3 = ±90°, a singular pose). The union is usually one interval (the paper's
    annulus r_min … r_max); near the lowest wrist heights only θ2 close to ±40° reaches and
    the slice splits in two.

    Args:
        robot: the model.
        wrist_height_m: wrist point height y_s [m].

    Returns:
        Sorted, disjoint ``(r_lo, r_hi)`` intervals [m]; empty when no wrist pose has
        this height.
    """
    l2, l3 = robot.lower_arm_m, robot.upper_arm_m
    a2, b2 = robot.theta2_range_rad
    a3, b3 = robot.theta3_range_rad
    H = float(wrist_height_m) - robot.shoulder_height_m
    half_pi = 0.5 * math.pi

    def r_of(sign: float, t3: float) -> float:
        x = max(-1.0, min(1.0, (H - l3 * math.sin(t3)) / l2))
        return sign * l2 * math.sqrt(max(0.0, 1.0 - x * x)) + l3 * math.cos(t3)

    # θ3 where the arms are aligned (r extreme along a level curve), with the sign of θ2
    aligned: list[tuple[float, float]] = []
    for sgn, L in ((1.0, l2 + l3), (-1.0, l2 - l3)):
        if abs(L) > 1e-12 and abs(H / L) <= 1.0:
            base = math.acos(H / L)
            for t2 in (base, -base):
                t3 = (sgn * half_pi - t2 + math.pi) % (2.0 * math.pi) - math.pi
                if a2 - TOL <= t2 <= b2 + TOL:
                    aligned.append((t3, 1.0 if t2 >= 0.0 else -1.0))
    # monotone pieces of sin θ3 on [a3, b3]
    cuts = sorted({a3, b3, *(c for c in (-half_pi, half_pi) if a3 < c < b3)})
    pieces: list[tuple[float, float]] = []
    for sign in (1.0, -1.0):
        # |θ2| range on this branch and the matching sin θ3 range
        m_lo, m_hi = (
            (max(a2, 0.0), min(b2, math.pi)) if sign > 0 else (-min(b2, 0.0), -max(a2, -math.pi))
        )
        if m_lo > m_hi:
            continue
        s_lo = (H - l2 * math.cos(m_lo)) / l3
        s_hi = (H - l2 * math.cos(m_hi)) / l3
        if s_lo > 1.0 + 1e-12 or s_hi < -1.0 - 1e-12:
            continue
        s_lo, s_hi = max(s_lo, -1.0), min(s_hi, 1.0)
        for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
            sa, sb = math.sin(lo), math.sin(hi)
            if max(sa, sb) < s_lo - 1e-15 or min(sa, sb) > s_hi + 1e-15:
                continue
            # preimage of [s_lo, s_hi] in the monotone segment [lo, hi]
            rising = sb >= sa
            ends, rs = [], []
            for sv, m in ((s_lo, m_lo), (s_hi, m_hi)):
                inside = min(sa, sb) <= sv <= max(sa, sb)
                sv = min(max(sv, min(sa, sb)), max(sa, sb))
                t = math.asin(sv)
                if not (lo - 1e-12 <= t <= hi + 1e-12):  # the segment beyond ±90°
                    t = math.copysign(math.pi, t) - t
                t = min(max(t, lo), hi)
                ends.append(t)
                # at a θ2 limit use θ2 itself: r_of loses precision where θ2 ≈ 0
                rs.append(sign * l2 * math.sin(m) + l3 * math.cos(t) if inside else r_of(sign, t))
            p_lo, p_hi = (ends[0], ends[1]) if rising else (ends[1], ends[0])
            if p_hi < p_lo:
                continue
            rs += [r_of(sign, t3) for t3, sg in aligned if sg == sign and p_lo <= t3 <= p_hi]
            pieces.append((min(rs), max(rs)))
    pieces.sort()
    merged: list[tuple[float, float]] = []
    for lo, hi in pieces:
        if merged and lo <= merged[-1][1] + TOL:
            merged[-1] = (merged[-1][0], max(merged[-1][1], hi))
        else:
            merged.append((lo, hi))
    return merged


def wrist_annulus_m(robot: IRb6, wrist_height_m: float) -> tuple[float, float] | None:
    """The paper's annulus at a wrist height: ``(r_w_min, r_w_max)`` [m] or None.

    The hull of :func:`wrist_radius_intervals_m`.
    """
    iv = wrist_radius_intervals_m(robot, wrist_height_m)
    if not iv:
        return None
    return (iv[0][0], iv[-1][1])


def two_link(robot: IRb6, r_m: float, y_m: float) -> list[tuple[float, float]]:
    """(θ2, θ3) with l2 (sin θ2, cos θ2) + l3 (cos θ3, sin θ3) = (r, y); both branches."""
    l2, l3 = robot.lower_arm_m, robot.upper_arm_m
    D = math.hypot(r_m, y_m)
    if D < 1e-12:
        return []
    k = (D * D + l2 * l2 - l3 * l3) / (2.0 * l2 * D)
    if abs(k) > 1.0 + 1e-9:
        return []
    beta = math.atan2(r_m, y_m)
    gamma = math.acos(max(-1.0, min(1.0, k)))
    out = []
    for t2 in (beta + gamma, beta - gamma):
        t2 = (t2 + math.pi) % (2.0 * math.pi) - math.pi
        t3 = math.atan2(y_m - l2 * math.cos(t2), r_m - l2 * math.sin(t2))
        out.append((t2, t3))
    return out


__all__ = ["TOL", "two_link", "wrist_annulus_m", "wrist_radius_intervals_m"]

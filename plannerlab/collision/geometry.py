"""Exact capsule tests, compiled with numba: the narrow phase of :mod:`plannerlab.collision.core`.

Every link is a capsule: a segment ``a → b`` swept by a ball of radius ``r``. Its distance
to another shape is the distance from the *segment* to that shape minus ``r``, so each test
here is a segment against a convex shape:

* segment–segment (capsule–capsule): closest points in closed form (Ericson, *Real-Time
  Collision Detection* §5.1.9), exact up to rounding;
* segment–point (capsule–sphere): projection, exact;
* segment–box: exact. In the box frame the squared distance from ``p(t) = p0 + t·d`` to
  the box is a convex piecewise quadratic in ``t`` with at most six breakpoints (where a
  coordinate crosses a face plane); on each piece the quadratic is minimised in closed
  form and the smallest value wins;
* segment–cylinder: the signed distance from ``p(t)`` to a convex set is a convex function
  of ``t``, minimised by golden-section search down to a bracket of ``1e-13`` in ``t``; the
  value is then within ``|b − a|·1e-13`` m of the minimum (the function is
  ``|b − a|``-Lipschitz in ``t``), far below the 1e-6 m agreement asked of the core.

Penetration (negative distances): when the capsule's axis stays outside the shape the
depth ``r − dist(segment, shape)`` is exact (it is the minimal translation that separates
them). When the axis itself enters a box or a cylinder the depth reported is ``r`` plus the
depth of the segment's deepest point, a lower bound on the true penetration depth (FCL's
EPA answer); for two crossing capsule axes the depth is ``r_1 + r_2``.

All functions are ``cache=True`` (compiled once per machine, then loaded from
``__pycache__``) and ``nogil``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_GOLD = 0.5 * (math.sqrt(5.0) - 1.0)  # 0.618...
_T_TOL = 1e-13

BOX, CYLINDER, SPHERE = 0, 1, 2


@njit(cache=True, nogil=True)
def seg_seg(p1, q1, p2, q2):
    """Closest points of segments p1→q1 and p2→q2: (squared distance, s, t)."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    s = 0.0
    t = 0.0
    if a <= 1e-24 and e <= 1e-24:
        s = 0.0
        t = 0.0
    elif a <= 1e-24:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = d1x * rx + d1y * ry + d1z * rz
        if e <= 1e-24:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            b = d1x * d2x + d1y * d2y + d1z * d2z
            denom = a * e - b * b
            if denom > 1e-14 * a * e:
                s = min(max((b * f - c * e) / denom, 0.0), 1.0)
            else:
                s = 0.0
            tnom = b * s + f
            if tnom < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif tnom > e:
                t = 1.0
                s = min(max((b - c) / a, 0.0), 1.0)
            else:
                t = tnom / e
    dx = rx + s * d1x - t * d2x
    dy = ry + s * d1y - t * d2y
    dz = rz + s * d1z - t * d2z
    return dx * dx + dy * dy + dz * dz, s, t


@njit(cache=True, nogil=True)
def seg_point(p, q, c):
    """Closest point of segment p→q to point c: (squared distance, t)."""
    dx, dy, dz = q[0] - p[0], q[1] - p[1], q[2] - p[2]
    a = dx * dx + dy * dy + dz * dz
    t = 0.0
    if a > 1e-24:
        t = ((c[0] - p[0]) * dx + (c[1] - p[1]) * dy + (c[2] - p[2]) * dz) / a
        t = min(max(t, 0.0), 1.0)
    ex = p[0] + t * dx - c[0]
    ey = p[1] + t * dy - c[1]
    ez = p[2] + t * dz - c[2]
    return ex * ex + ey * ey + ez * ez, t


@njit(cache=True, nogil=True)
def _to_local(R, c, p, out):
    """out = Rᵀ (p − c): a world point in the obstacle's frame."""
    x, y, z = p[0] - c[0], p[1] - c[1], p[2] - c[2]
    out[0] = R[0, 0] * x + R[1, 0] * y + R[2, 0] * z
    out[1] = R[0, 1] * x + R[1, 1] * y + R[2, 1] * z
    out[2] = R[0, 2] * x + R[1, 2] * y + R[2, 2] * z


@njit(cache=True, nogil=True)
def _box_dist2_at(p0, d, h, t):
    s = 0.0
    for i in range(3):
        v = abs(p0[i] + t * d[i]) - h[i]
        if v > 0.0:
            s += v * v
    return s


@njit(cache=True, nogil=True)
def seg_box_local(p0, p1, h, w):
    """Exact squared distance from segment p0→p1 (box frame) to the box of half sizes h.

    ``w`` is scratch space (≥ 11 floats). Returns (squared distance, t of the closest point
    on the segment).
    """
    d = w[0:3]
    for i in range(3):
        d[i] = p1[i] - p0[i]
    ts = w[3:11]
    n = 0
    ts[n] = 0.0
    n += 1
    ts[n] = 1.0
    n += 1
    for i in range(3):
        if d[i] != 0.0:
            for sgn in (-1.0, 1.0):
                tb = (sgn * h[i] - p0[i]) / d[i]
                if 0.0 < tb < 1.0:
                    ts[n] = tb
                    n += 1
    # insertion sort of the n breakpoints
    for i in range(1, n):
        v = ts[i]
        j = i - 1
        while j >= 0 and ts[j] > v:
            ts[j + 1] = ts[j]
            j -= 1
        ts[j + 1] = v
    best = _box_dist2_at(p0, d, h, 0.0)
    best_t = 0.0
    v1 = _box_dist2_at(p0, d, h, 1.0)
    if v1 < best:
        best = v1
        best_t = 1.0
    for k in range(n - 1):
        ta = ts[k]
        tb = ts[k + 1]
        if tb <= ta:
            continue
        tm = 0.5 * (ta + tb)
        A = 0.0
        B = 0.0
        for i in range(3):
            x = p0[i] + tm * d[i]
            if x > h[i]:
                A += d[i] * d[i]
                B += d[i] * (p0[i] - h[i])
            elif x < -h[i]:
                A += d[i] * d[i]
                B += d[i] * (p0[i] + h[i])
        if A > 0.0:
            tt = min(max(-B / A, ta), tb)
        else:
            tt = tm
        v = _box_dist2_at(p0, d, h, tt)
        if v < best:
            best = v
            best_t = tt
    return best, best_t


@njit(cache=True, nogil=True)
def _sd_box(x, y, z, h):
    qx, qy, qz = abs(x) - h[0], abs(y) - h[1], abs(z) - h[2]
    ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
    return math.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, max(qy, qz)), 0.0)


@njit(cache=True, nogil=True)
def _sd_cyl(x, y, z, h):
    """Signed distance of a local point to the cylinder of radius h[0], half length h[1]."""
    qr = math.sqrt(x * x + y * y) - h[0]
    qz = abs(z) - h[1]
    orr, oz = max(qr, 0.0), max(qz, 0.0)
    return math.sqrt(orr * orr + oz * oz) + min(max(qr, qz), 0.0)


@njit(cache=True, nogil=True)
def _sd_shape(kind, x, y, z, h):
    if kind == 0:
        return _sd_box(x, y, z, h)
    return _sd_cyl(x, y, z, h)


@njit(cache=True, nogil=True)
def seg_sd_min(kind, p0, p1, h, stop_below):
    """Golden-section minimum over t of the signed distance from p0 + t(p1 − p0) (local).

    Convex in t, so the search is exact to the bracket. Stops early (returning the first
    value found) as soon as a value ≤ ``stop_below`` is seen; pass -inf to disable.
    Returns (signed distance, t).
    """
    dx, dy, dz = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    lo = 0.0
    hi = 1.0
    f_lo = _sd_shape(kind, p0[0], p0[1], p0[2], h)
    f_hi = _sd_shape(kind, p1[0], p1[1], p1[2], h)
    best = f_lo
    best_t = 0.0
    if f_hi < best:
        best = f_hi
        best_t = 1.0
    if best <= stop_below:
        return best, best_t
    m1 = hi - _GOLD * (hi - lo)
    m2 = lo + _GOLD * (hi - lo)
    f1 = _sd_shape(kind, p0[0] + m1 * dx, p0[1] + m1 * dy, p0[2] + m1 * dz, h)
    f2 = _sd_shape(kind, p0[0] + m2 * dx, p0[1] + m2 * dy, p0[2] + m2 * dz, h)
    while hi - lo > _T_TOL:
        if f1 <= f2:
            hi = m2
            m2 = m1
            f2 = f1
            m1 = hi - _GOLD * (hi - lo)
            f1 = _sd_shape(kind, p0[0] + m1 * dx, p0[1] + m1 * dy, p0[2] + m1 * dz, h)
            if f1 < best:
                best = f1
                best_t = m1
        else:
            lo = m1
            m1 = m2
            f1 = f2
            m2 = lo + _GOLD * (hi - lo)
            f2 = _sd_shape(kind, p0[0] + m2 * dx, p0[1] + m2 * dy, p0[2] + m2 * dz, h)
            if f2 < best:
                best = f2
                best_t = m2
        if best <= stop_below:
            return best, best_t
    return best, best_t


@njit(cache=True, nogil=True)
def capsule_obstacle(obstacles, o, a, b, r, want_normal, n_out, w):
    """Signed distance [m] of capsule (a→b, r) to obstacle ``o`` of ``obstacles`` (kinds,
    Rs, cs, hs), and t on the capsule axis.

    Its ``kind``: 0 box (h = half sizes), 1 cylinder (h = radius, half length), 2 sphere
    (h[0] = radius). With ``want_normal`` the unit direction (world) that increases the
    distance when the capsule's closest point moves along it is written to ``n_out``.
    ``w``: scratch space (≥ 32 floats).
    """
    kind, R, c, h = obstacles[0][o], obstacles[1][o], obstacles[2][o], obstacles[3][o]
    if kind == 2:
        d2, t = seg_point(a, b, c)
        dist = math.sqrt(d2)
        if want_normal:
            px = a[0] + t * (b[0] - a[0]) - c[0]
            py = a[1] + t * (b[1] - a[1]) - c[1]
            pz = a[2] + t * (b[2] - a[2]) - c[2]
            if dist > 0.0:
                n_out[0], n_out[1], n_out[2] = px / dist, py / dist, pz / dist
            else:
                n_out[0], n_out[1], n_out[2] = 0.0, 0.0, 1.0
        return dist - r - h[0], t
    p0 = w[0:3]
    p1 = w[3:6]
    _to_local(R, c, a, p0)
    _to_local(R, c, b, p1)
    if kind == 0:
        d2, t = seg_box_local(p0, p1, h, w[6:])
        if d2 > 0.0:
            sd = math.sqrt(d2)
        else:
            sd, t = seg_sd_min(kind, p0, p1, h, -np.inf)
    else:
        sd, t = seg_sd_min(kind, p0, p1, h, -np.inf)
    if want_normal:
        x = p0[0] + t * (p1[0] - p0[0])
        y = p0[1] + t * (p1[1] - p0[1])
        z = p0[2] + t * (p1[2] - p0[2])
        nl = w[20:23]
        nl[:] = 0.0
        if kind == 0:
            if sd > 0.0:
                nl[0] = x - min(max(x, -h[0]), h[0])
                nl[1] = y - min(max(y, -h[1]), h[1])
                nl[2] = z - min(max(z, -h[2]), h[2])
            else:  # inside: the face of least depth
                best = np.inf
                for i, v in enumerate((x, y, z)):
                    dep = h[i] - abs(v)
                    if dep < best:
                        best = dep
                        nl[:] = 0.0
                        nl[i] = 1.0 if v >= 0.0 else -1.0
        else:
            rho = math.sqrt(x * x + y * y)
            if sd > 0.0:
                if rho > h[0]:
                    nl[0] = x - x * h[0] / rho
                    nl[1] = y - y * h[0] / rho
                nl[2] = z - min(max(z, -h[1]), h[1])
            elif h[0] - rho < h[1] - abs(z) and rho > 0.0:
                nl[0] = x / rho
                nl[1] = y / rho
            else:
                nl[2] = 1.0 if z >= 0.0 else -1.0
        norm = math.sqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2])
        if norm == 0.0:
            nl[2] = 1.0
            norm = 1.0
        for i in range(3):
            n_out[i] = (R[i, 0] * nl[0] + R[i, 1] * nl[1] + R[i, 2] * nl[2]) / norm
    return sd - r, t


@njit(cache=True, nogil=True)
def capsule_obstacle_hit(kind, R, c, h, a, b, r, w):
    """True when capsule (a→b, r) touches or overlaps the obstacle (distance ≤ 0).

    ``w``: scratch space (≥ 32 floats), so the hot path allocates nothing.
    """
    if kind == 2:
        d2, _ = seg_point(a, b, c)
        rr = r + h[0]
        return d2 <= rr * rr
    p0 = w[0:3]
    p1 = w[3:6]
    _to_local(R, c, a, p0)
    _to_local(R, c, b, p1)
    if kind == 0:
        d2, _ = seg_box_local(p0, p1, h, w[6:])
        return d2 <= r * r
    # cylinder: reject with the enclosing capsule around its axis, else search
    ax0 = w[20:23]
    ax1 = w[23:26]
    ax0[0], ax0[1], ax1[0], ax1[1] = 0.0, 0.0, 0.0, 0.0
    ax0[2] = -h[1]
    ax1[2] = h[1]
    d2, _, _ = seg_seg(p0, p1, ax0, ax1)
    lim = r + h[0]
    if d2 > lim * lim:
        return False
    sd, _ = seg_sd_min(kind, p0, p1, h, r)
    return sd <= r

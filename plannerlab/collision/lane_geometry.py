"""Distance tests in vector lanes: the geometry of the state test
(:mod:`plannerlab.collision.state_test`), eight states a call, float32.

**Distances in the lanes.** A sphere (a capsule of zero length) against an obstacle or
another sphere is a point's distance, exact up to rounding (squared, no root). A
capsule's segment against a convex shape (a box, a cylinder, a sphere, another segment):
the distance from ``x(t) = a + t (b − a)`` to a convex set is convex in ``t``, so its
tangents at ``t = 0`` and ``t = 1`` (from the distance and its gradient at the ends) bound
it from below on ``[0, 1]``: the smaller end is the minimum when the slope there points
outward, else the tangents' crossing is a lower bound. That bound decides "free"; the
distance at the ends and at the crossing (real points of the segment) decides "hit". Both
are exact when the closest point is an end or the segment runs parallel to a face;
elsewhere the band between them is confirmed in float64.
"""

from __future__ import annotations

import numpy as np

from plannerlab.collision.geometry import BOX, SPHERE
from plannerlab.collision.simd import (
    LANES,
    fma,
    kernel,
    load,
    mask_bits,
    select,
    splat,
    store,
    vabs,
    vmax,
    vmin,
    vsqrt,
)

#: lanes of one call
W = LANES
_ALL = (1 << LANES) - 1
_F4 = np.float32


# ------------------------------------------------------------------ geometry in the lanes
# Helpers take tables and rows (``obs32``, ``caps32``, ...), never the model: a named
# tuple handed to a function inlined by numba has every array in it counted in and out
# (measured: ~2 000 cycles a call on the Panda's model).
@kernel
def _local(O, o, x, y, z):
    """Lane points in obstacle o's frame (O: ``obs32``)."""
    x = x - splat(O[o, 0])
    y = y - splat(O[o, 1])
    z = z - splat(O[o, 2])
    u = fma(splat(O[o, 6]), x, fma(splat(O[o, 9]), y, splat(O[o, 12]) * z))
    v = fma(splat(O[o, 7]), x, fma(splat(O[o, 10]), y, splat(O[o, 13]) * z))
    t = fma(splat(O[o, 8]), x, fma(splat(O[o, 11]), y, splat(O[o, 14]) * z))
    return u, v, t


@kernel
def _point_d2(kind, O, o, x, y, z):
    """Squared distance of lane points to obstacle o (0 inside)."""
    zero = splat(0.0)
    if kind == SPHERE:
        dx, dy, dz = x - splat(O[o, 0]), y - splat(O[o, 1]), z - splat(O[o, 2])
        d = vmax(vsqrt(fma(dx, dx, fma(dy, dy, dz * dz))) - splat(O[o, 3]), zero)
        return d * d
    u, v, t = _local(O, o, x, y, z)
    if kind == BOX:
        u = vmax(vabs(u) - splat(O[o, 3]), zero)
        v = vmax(vabs(v) - splat(O[o, 4]), zero)
        t = vmax(vabs(t) - splat(O[o, 5]), zero)
        return fma(u, u, fma(v, v, t * t))
    rr = vmax(vsqrt(fma(u, u, v * v)) - splat(O[o, 3]), zero)
    zz = vmax(vabs(t) - splat(O[o, 4]), zero)
    return fma(rr, rr, zz * zz)


@kernel
def _sd_grad(kind, O, o, x, y, z):
    """Signed distance of lane points to obstacle o, and its gradient (world)."""
    zero, one, tiny = splat(0.0), splat(1.0), splat(1e-20)
    if kind == SPHERE:
        dx, dy, dz = x - splat(O[o, 0]), y - splat(O[o, 1]), z - splat(O[o, 2])
        d = vsqrt(fma(dx, dx, fma(dy, dy, dz * dz)))
        inv = one / vmax(d, tiny)
        return d - splat(O[o, 3]), dx * inv, dy * inv, dz * inv
    u, v, t = _local(O, o, x, y, z)
    su = select(u >= zero, one, -one)
    sv = select(v >= zero, one, -one)
    st = select(t >= zero, one, -one)
    if kind == BOX:
        qu = vabs(u) - splat(O[o, 3])
        qv = vabs(v) - splat(O[o, 4])
        qt = vabs(t) - splat(O[o, 5])
        ou, ov, ot = vmax(qu, zero), vmax(qv, zero), vmax(qt, zero)
        out = vsqrt(fma(ou, ou, fma(ov, ov, ot * ot)))
        inv = one / vmax(out, tiny)
        iu = (qu >= qv) & (qu >= qt)
        iv = (~iu) & (qv >= qt)
        it = ~(iu | iv)
        outside = out > zero
        gu = select(outside, su * ou * inv, select(iu, su, zero))
        gv = select(outside, sv * ov * inv, select(iv, sv, zero))
        gt = select(outside, st * ot * inv, select(it, st, zero))
        d = out + vmin(vmax(qu, vmax(qv, qt)), zero)
    else:  # a cylinder along its z: radius O[o, 3], half length O[o, 4]
        rho = vsqrt(fma(u, u, v * v))
        qr = rho - splat(O[o, 3])
        qz = vabs(t) - splat(O[o, 4])
        orr, oz = vmax(qr, zero), vmax(qz, zero)
        out = vsqrt(fma(orr, orr, oz * oz))
        inv = one / vmax(out, tiny)
        inv_rho = one / vmax(rho, tiny)
        radial = qr >= qz
        outside = out > zero
        gr = select(outside, orr * inv, select(radial, one, zero))
        gu, gv = gr * u * inv_rho, gr * v * inv_rho
        gt = select(outside, oz * inv * st, select(radial, zero, st))
        d = out + vmin(vmax(qr, qz), zero)
    g0 = fma(splat(O[o, 6]), gu, fma(splat(O[o, 7]), gv, splat(O[o, 8]) * gt))
    g1 = fma(splat(O[o, 9]), gu, fma(splat(O[o, 10]), gv, splat(O[o, 11]) * gt))
    g2 = fma(splat(O[o, 12]), gu, fma(splat(O[o, 13]), gv, splat(O[o, 14]) * gt))
    return d, g0, g1, g2


@kernel
def _tangent_bounds(fa, sa, fb, sb):
    """The tangents' lower bound of a convex f on [0, 1] from f and its slope at both
    ends (see the module), and the t where they cross (where to look for an upper one)."""
    zero, one = splat(0.0), splat(1.0)
    den = sb - sa  # > 0 when the minimum is inside: the tangents cross at t
    ok = den > splat(1e-20)
    t = select(ok, (fa + sb - fb) / select(ok, den, one), zero)
    t = vmin(vmax(t, zero), one)
    lo = fma(sa, t, fa)
    lo = select(sa >= zero, fa, lo)
    lo = select(sb <= zero, fb, lo)
    return lo, t


@kernel
def _ends(X, l):
    """Capsule l's ends (a, b), three lane vectors each."""
    o = 6 * l * W
    return (
        load(X, o),
        load(X, o + W),
        load(X, o + 2 * W),
        load(X, o + 3 * W),
        load(X, o + 4 * W),
        load(X, o + 5 * W),
    )


@kernel
def _pt_seg(x0, x1, x2, S):
    """Distance from lane points x to segments p + u e (u in [0, 1]; S = p0, p1, p2, e0,
    e1, e2, e·e), and the vector to x from its closest point."""
    p0, p1, p2, e0, e1, e2, ee = S
    u = fma(x0 - p0, e0, fma(x1 - p1, e1, (x2 - p2) * e2)) / ee
    u = vmin(vmax(u, splat(0.0)), splat(1.0))
    y0 = x0 - fma(u, e0, p0)
    y1 = x1 - fma(u, e1, p1)
    y2 = x2 - fma(u, e2, p2)
    return vsqrt(fma(y0, y0, fma(y1, y1, y2 * y2))), y0, y1, y2


@kernel
def _segment_obstacle(kind, O, o, E):
    """Bounds of the signed distance from lane segments E = (a0, a1, a2, b0, b1, b2) to
    obstacle o: (lower, upper)."""
    a0, a1, a2, b0, b1, b2 = E
    fa, ga0, ga1, ga2 = _sd_grad(kind, O, o, a0, a1, a2)
    fb, gb0, gb1, gb2 = _sd_grad(kind, O, o, b0, b1, b2)
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    sa = fma(ga0, d0, fma(ga1, d1, ga2 * d2))
    sb = fma(gb0, d0, fma(gb1, d1, gb2 * d2))
    lo, t = _tangent_bounds(fa, sa, fb, sb)
    fm, _, _, _ = _sd_grad(kind, O, o, fma(t, d0, a0), fma(t, d1, a1), fma(t, d2, a2))
    return lo, vmin(vmin(fa, fb), fm)


@kernel
def _segments(E1, E2):
    """Bounds of the distance between lane segments E1 and E2 (six vectors each; a sphere
    is a segment of zero length): the distance from a point of the first to the second
    is convex along the first (the tangents' bound, as against an obstacle)."""
    a0, a1, a2, b0, b1, b2 = E1
    p0, p1, p2, q0, q1, q2 = E2
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    e0, e1, e2 = q0 - p0, q1 - p1, q2 - p2
    tiny = splat(1e-20)
    S = (p0, p1, p2, e0, e1, e2, vmax(fma(e0, e0, fma(e1, e1, e2 * e2)), tiny))
    fa, y0, y1, y2 = _pt_seg(a0, a1, a2, S)
    sa = fma(y0, d0, fma(y1, d1, y2 * d2)) / vmax(fa, tiny)
    fb, y0, y1, y2 = _pt_seg(b0, b1, b2, S)
    sb = fma(y0, d0, fma(y1, d1, y2 * d2)) / vmax(fb, tiny)
    lo, t = _tangent_bounds(fa, sa, fb, sb)
    fm, _, _, _ = _pt_seg(fma(t, d0, a0), fma(t, d1, a1), fma(t, d2, a2), S)
    return lo, vmin(vmin(fa, fb), fm)


@kernel
def _grade_d2(d2, r0, rg, eps, hu):
    """The lane masks ``hu`` = (hit, unsure grown, unsure plain) updated with squared
    distances d2: hit when closer than the plain radius r0 less eps (certainly, in
    float64 too); unsure grown unless farther than the grown radius rg plus eps; unsure
    plain unless farther than r0 plus eps."""
    lo = vmax(r0 - eps, splat(0.0))
    hg = rg + eps
    h0 = r0 + eps
    return (
        hu[0] | mask_bits(d2 < lo * lo),
        hu[1] | mask_bits(d2 <= hg * hg),
        hu[2] | mask_bits(d2 <= h0 * h0),
    )


@kernel
def _grade_bounds(lo_d, hi_d, r0, rg, eps, hu):
    """The lane masks (hit, unsure grown, unsure plain) updated with a distance's lower
    and upper bounds (as :func:`_grade_d2`)."""
    return (
        hu[0] | mask_bits(hi_d < r0 - eps),
        hu[1] | mask_bits(lo_d <= rg + eps),
        hu[2] | mask_bits(lo_d <= r0 + eps),
    )


@kernel
def _near(d2, r, live):
    """Some live lane has d2 within r (squared)."""
    return (mask_bits(d2 <= r * r) & live) != 0


@kernel
def _in_box(O, o, x, y, z, r, live):
    """Some live lane's ball (centre x, y, z, radius r) meets obstacle o's world box
    (``O[o, 16:19]``: the box around the obstacle, padded beyond rounding): the cheap
    prefilter of :func:`_point_d2`'s gate test (a ball clear of the box is clear of the
    obstacle)."""
    ix = vabs(x - splat(O[o, 0])) <= splat(O[o, 16]) + r
    iy = vabs(y - splat(O[o, 1])) <= splat(O[o, 17]) + r
    iz = vabs(z - splat(O[o, 2])) <= splat(O[o, 18]) + r
    return (mask_bits(ix & iy & iz) & live) != 0


@kernel
def _gap2(A, a, B, b):
    """Squared distance between the points in slots A[a:] and B[b:] (three each)."""
    x = load(A, a) - load(B, b)
    y = load(A, a + W) - load(B, b + W)
    z = load(A, a + 2 * W) - load(B, b + 2 * W)
    return fma(x, x, fma(y, y, z * z))


@kernel
def _slot3(A, i):
    """The three vectors of slot i (x, y, z)."""
    return load(A, 3 * i * W), load(A, (3 * i + 1) * W), load(A, (3 * i + 2) * W)


# ------------------------------------------------------------------ the filter's passes
# The passes (frames32, _scene_pass, _self_pass) are inlined into test_lanes by numba:
# out of line, each call takes the model and the scratch (some eighty arrays, each
# flattened into its fields) on the stack. Their callers are kernels (numba's reference
# counting off): inlined into a function that counts references, every array of the
# model would be counted in and out.
@kernel
def _group_box(gates, G, brate, order, k0, k1, grow, eps):
    """The lanes' world box around the body gates ``order[k0:k1]`` (G: their centres;
    each gate grown as against the scene, ``brate`` its body's rate): (lo x, y, z, hi x,
    y, z, any), its corners moved out by 2^-21 of their size and 1e-7 m beyond float32's
    rounding of a gate's centre ± radius (``any``: some body in the group is gated)."""
    big, small = splat(3.0e38), splat(-3.0e38)
    lx, ly, lz, hx, hy, hz = big, big, big, small, small, small
    some = False
    for kb in range(k0, k1):
        b = order[kb]
        if gates[b, 3] < 0.0:
            continue
        some = True
        gx, gy, gz = _slot3(G, b)
        rb = fma(grow, splat(brate[b]), splat(gates[b, 3]) + eps)
        lx, ly, lz = vmin(lx, gx - rb), vmin(ly, gy - rb), vmin(lz, gz - rb)
        hx, hy, hz = vmax(hx, gx + rb), vmax(hy, gy + rb), vmax(hz, gz + rb)
    rel, pad = splat(2.0**-21), splat(1e-7)
    return (
        lx - fma(vabs(lx), rel, pad),
        ly - fma(vabs(ly), rel, pad),
        lz - fma(vabs(lz), rel, pad),
        hx + fma(vabs(hx), rel, pad),
        hy + fma(vabs(hy), rel, pad),
        hz + fma(vabs(hz), rel, pad),
        some,
    )


@kernel
def _box_meets(O, o, B, live):
    """Some live lane's box B (lo x, y, z, hi x, y, z) meets obstacle o's world box
    (``O[o, 16:19]`` about its centre, padded beyond rounding)."""
    lx, ly, lz, hx, hy, hz = B[0], B[1], B[2], B[3], B[4], B[5]
    cx, cy, cz = splat(O[o, 0]), splat(O[o, 1]), splat(O[o, 2])
    wx, wy, wz = splat(O[o, 16]), splat(O[o, 17]), splat(O[o, 18])
    m = (lx - cx <= wx) & (cx - hx <= wx) & (ly - cy <= wy) & (cy - hy <= wy)
    m = m & (lz - cz <= wz) & (cz - hz <= wz)
    return (mask_bits(m) & live) != 0


@kernel
def _self_boxes(gates, G, brate, SB, group, grow, eps):
    """The self pass's broadphase (per call): into ``SB`` the lanes' world box around each
    group of ``group`` consecutive bodies (``g · group`` to ``g · group + group − 1``; the
    groups ``SB`` has room for): their gates' centres G ∓ their radii between links
    ``gates[b, 4]`` grown by ``grow · brate[b]`` and by eps (each ball alone carries the
    whole eps of a body pair's gate), corners moved out by 2^-21 relative and 1e-7 m
    beyond float32's rounding. A group without a gated body gets an empty box (it meets
    nothing). Returns the number of groups."""
    nb = gates.shape[0]
    ng = SB.shape[0] // (6 * W)
    rel, pad = splat(2.0**-21), splat(1e-7)
    for g in range(ng):
        big, small = splat(3.0e38), splat(-3.0e38)
        lx, ly, lz, hx, hy, hz = big, big, big, small, small, small
        for b in range(g * group, min(g * group + group, nb)):
            if gates[b, 4] < 0.0:
                continue
            gx, gy, gz = _slot3(G, b)
            rb = fma(grow, splat(brate[b]), splat(gates[b, 4]) + eps)
            lx, ly, lz = vmin(lx, gx - rb), vmin(ly, gy - rb), vmin(lz, gz - rb)
            hx, hy, hz = vmax(hx, gx + rb), vmax(hy, gy + rb), vmax(hz, gz + rb)
        o = 6 * g * W
        store(SB, o, lx - fma(vabs(lx), rel, pad))
        store(SB, o + W, ly - fma(vabs(ly), rel, pad))
        store(SB, o + 2 * W, lz - fma(vabs(lz), rel, pad))
        store(SB, o + 3 * W, hx + fma(vabs(hx), rel, pad))
        store(SB, o + 4 * W, hy + fma(vabs(hy), rel, pad))
        store(SB, o + 5 * W, hz + fma(vabs(hz), rel, pad))
    return ng


@kernel
def _boxes_meet(SB, g, h):
    """Lanes (bits) where the boxes of groups g and h in ``SB`` (see :func:`_self_boxes`)
    meet."""
    a, b = 6 * g * W, 6 * h * W
    m = (load(SB, a) <= load(SB, b + 3 * W)) & (load(SB, b) <= load(SB, a + 3 * W))
    m = m & (load(SB, a + W) <= load(SB, b + 4 * W)) & (load(SB, b + W) <= load(SB, a + 4 * W))
    m = m & (load(SB, a + 2 * W) <= load(SB, b + 5 * W))
    m = m & (load(SB, b + 2 * W) <= load(SB, a + 5 * W))
    return mask_bits(m)

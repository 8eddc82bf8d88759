"""Validity of a chain's states in one fused compiled call (its Python face:
:class:`~plannerlab.collision.chain_check.ChainValidity`; every
robot family's chain, :mod:`plannerlab.collision.chain`, and the compiled model's state test):
kinematics and the capsule tests of :mod:`plannerlab.collision.core` (moving capsules
against every obstacle, the checked link pairs) with the same verdicts, built for speed.

* **Few arguments.** numba's dispatcher pays per argument, most for a tuple (a call of
  ``core.chain_first_invalid``, twenty arguments and a tuple, costs ~2.7 µs before any work;
  ``bench/urdf_core_bench.py``): the chain, its capsules, the pairs and the scene are
  packed once (:func:`_pack`) into rows of three floats, 3 x 4 matrices and one int array,
  sliced in the kernel without a reshape, so a call passes the states and three arrays.
* **Kinematics about z.** Each joint's axis is turned onto its frame's z axis once (the
  turn folded into the fixed transforms and the capsules' points), so a joint costs one
  affine product and a turn of two columns; body frames are 3 x 4, made from scalars (a
  view per joint cost more than its arithmetic), with a joint coupling (IRb-6) applied
  once per state into a scratch, never tested per joint (that test alone made the
  kinematics 2.5 times slower).
* **Bounding balls.** The capsules are sorted by body and, within a body, into clusters of
  a few neighbours; a body ball, then cluster balls (grown by ``chain_pack._BOUND_PAD_M`` beyond
  rounding) are tested before the capsules under them, against the scene (after the
  obstacle's world box) and between bodies; a body's capsules are placed in the world only
  when one of its balls is not clear. Between links, balls around chunks of four
  consecutive bodies come first: a pair of chunks apart skips all its body pairs.
* **Spheres in closed form.** A zero-length capsule (a spherized URDF's spheres) against a
  box, a sphere or another sphere is tested inline with the very floats of
  :mod:`plannerlab.collision.geometry`; against a cylinder by geometry's own reject and
  the signed distance at the point (what its golden-section search returns for a
  zero-length segment); real capsules go through geometry's tests.
* **Early exit.** The first hit ends a state's test; bodies meet the scene in
  ``body_order`` (default: the last body first).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plannerlab.collision.chain_pack import (  # the packing, and its layout
    _BOUND_PAD_M,
    _CHUNK,
    _H_DOF,
    _H_I,
    _H_L,
    _H_NB,
    _H_NCL,
    _H_NCPL,
    _H_NOBS,
)
from plannerlab.collision.geometry import (
    BOX,
    SPHERE,
    _sd_cyl,
    _to_local,
    capsule_obstacle_hit,
    seg_seg,
)

_SCRATCH = 64  # floats of w (capsule tests)
_F64 = np.dtype(np.float64)


@njit(cache=True, nogil=True, inline="always")
def _box_d2(R, c, h, x0, x1, x2):
    """Squared distance from a world point to a box (frame R, c; half sizes h): the floats
    of ``geometry.seg_box_local`` for a zero-length segment."""
    x, y, z = x0 - c[0], x1 - c[1], x2 - c[2]
    p0 = R[0, 0] * x + R[1, 0] * y + R[2, 0] * z
    p1 = R[0, 1] * x + R[1, 1] * y + R[2, 1] * z
    p2 = R[0, 2] * x + R[1, 2] * y + R[2, 2] * z
    s = 0.0
    v = abs(p0) - h[0]
    if v > 0.0:
        s += v * v
    v = abs(p1) - h[1]
    if v > 0.0:
        s += v * v
    v = abs(p2) - h[2]
    if v > 0.0:
        s += v * v
    return s


@njit(cache=True, nogil=True)
def _sphere_hit(kind, R, c, h, x0, x1, x2, r, w):
    """A sphere (centre x, radius r) touches the obstacle: the verdict of
    ``geometry.capsule_obstacle_hit`` for a zero-length capsule, in closed form."""
    if kind == SPHERE:
        ex, ey, ez = x0 - c[0], x1 - c[1], x2 - c[2]
        rr = r + h[0]
        return ex * ex + ey * ey + ez * ez <= rr * rr
    if kind == BOX:
        return _box_d2(R, c, h, x0, x1, x2) <= r * r
    # cylinder: geometry's reject by the capsule around its axis, then the signed distance
    # at the point (its golden-section search over a zero-length segment sees only that)
    p = w[0:3]
    w[3] = x0
    w[4] = x1
    w[5] = x2
    _to_local(R, c, w[3:6], p)
    ax0 = w[20:23]
    ax1 = w[23:26]
    ax0[0], ax0[1], ax1[0], ax1[1] = 0.0, 0.0, 0.0, 0.0
    ax0[2] = -h[1]
    ax1[2] = h[1]
    d2, _, _ = seg_seg(p, p, ax0, ax1)
    lim = r + h[0]
    if d2 > lim * lim:
        return False
    return _sd_cyl(p[0], p[1], p[2], h) <= r


@njit(cache=True, nogil=True, inline="always")
def _bound_apart(kind, R, c, h, x0, x1, x2, rb):
    """A ball (centre x, radius rb) is certainly clear of the obstacle (cheap, conservative)."""
    if kind == SPHERE:
        ex, ey, ez = x0 - c[0], x1 - c[1], x2 - c[2]
        rr = rb + h[0]
        return ex * ex + ey * ey + ez * ez > rr * rr
    if kind == BOX:
        return _box_d2(R, c, h, x0, x1, x2) > rb * rb
    x, y, z = x0 - c[0], x1 - c[1], x2 - c[2]
    p0 = R[0, 0] * x + R[1, 0] * y + R[2, 0] * z
    p1 = R[0, 1] * x + R[1, 1] * y + R[2, 1] * z
    p2 = R[0, 2] * x + R[1, 2] * y + R[2, 2] * z
    qr = max(math.sqrt(p0 * p0 + p1 * p1) - h[0], 0.0)
    qz = max(abs(p2) - h[1], 0.0)
    return qr * qr + qz * qz > rb * rb


@njit(cache=True, nogil=True, inline="always")
def _frames_of(v, T0, parent, prism, pre, Bf):
    """Body frames (nb, 3, 4) from the chain's joint values v (n,); each joint turns (or
    slides) about its frame's z axis. Scalars, not views: a view per joint and 3-d
    indexing cost more than the arithmetic."""
    for a in range(3):
        for b in range(4):
            Bf[0, a, b] = T0[a, b]
    for i in range(parent.shape[0]):
        qi = v[i]
        f = parent[i]
        p00, p01, p02, p03 = pre[i, 0, 0], pre[i, 0, 1], pre[i, 0, 2], pre[i, 0, 3]
        p10, p11, p12, p13 = pre[i, 1, 0], pre[i, 1, 1], pre[i, 1, 2], pre[i, 1, 3]
        p20, p21, p22, p23 = pre[i, 2, 0], pre[i, 2, 1], pre[i, 2, 2], pre[i, 2, 3]
        slide = prism[i] != 0
        cq = 1.0
        sq = 0.0
        if not slide:
            cq = math.cos(qi)
            sq = math.sin(qi)
        for a in range(3):
            f0, f1, f2, f3 = Bf[f, a, 0], Bf[f, a, 1], Bf[f, a, 2], Bf[f, a, 3]
            g0 = f0 * p00 + f1 * p10 + f2 * p20
            g1 = f0 * p01 + f1 * p11 + f2 * p21
            g2 = f0 * p02 + f1 * p12 + f2 * p22
            g3 = f0 * p03 + f1 * p13 + f2 * p23
            g3 += f3
            if slide:
                g3 += qi * g2
                Bf[i + 1, a, 0] = g0
                Bf[i + 1, a, 1] = g1
            else:
                Bf[i + 1, a, 0] = cq * g0 + sq * g1
                Bf[i + 1, a, 1] = cq * g1 - sq * g0
            Bf[i + 1, a, 2] = g2
            Bf[i + 1, a, 3] = g3


@njit(cache=True, nogil=True, inline="always")
def _body_frames(q, T0, parent, prism, pre, Bf, cpl, v):
    """Body frames (nb, 3, 4) of one state q (the chain's axes are folded into ``pre`` and
    the capsules by ``_pack``). ``cpl``: the coupling's (starts, indices, coefficients),
    empty without one; with one, the chain's joint values ``Σ_k cpl_val[k] q[cpl_idx[k]]``
    go through the scratch v (n,) first (tested once here, not per joint: ~2.5 times
    faster kinematics)."""
    cpl_start, cpl_idx, cpl_val = cpl
    if cpl_start.shape[0] == 0:
        _frames_of(q, T0, parent, prism, pre, Bf)
        return
    for i in range(parent.shape[0]):
        x = 0.0
        for k in range(cpl_start[i], cpl_start[i + 1]):
            x += cpl_val[k // 3, k % 3] * q[cpl_idx[k]]
        v[i] = x
    _frames_of(v, T0, parent, prism, pre, Bf)


@njit(cache=True, nogil=True, inline="always")
def _iv(idat, k):
    """Int section k (see ``chain_pack._I_SECTIONS``), flat."""
    return idat[idat[_H_I + k] : idat[_H_I + k + 1]]


@njit(cache=True, nogil=True)
def _unpack(P, M, idat):
    """Views of the packed arrays (see ``_pack``): slices only (a reshape costs some 30 ns
    in numba, a slice about one)."""
    dof, nb, L, n, ncl = idat[_H_DOF], idat[_H_NB], idat[_H_L], idat[_H_NOBS], idat[_H_NCL]
    ncpl = idat[_H_NCPL]
    ints = (
        _iv(idat, 0),
        _iv(idat, 1),
        _iv(idat, 2),
        _iv(idat, 3),
        _iv(idat, 4),
        _iv(idat, 5),
        _iv(idat, 6),
        _iv(idat, 7),
        _iv(idat, 8),
        _iv(idat, 9),
        _iv(idat, 10),
        _iv(idat, 13),
    )
    o = 3 * L + 2 * nb + 2 * ncl  # the obstacles' rows of P
    e = o + 4 * n  # the coupling's coefficients, three a row, after the obstacles
    cpl = (_iv(idat, 11), _iv(idat, 12), P[e : e + (ncpl + 2) // 3])
    floats = (
        M[0],
        M[1 : 1 + dof],
        P[0:L],
        P[L : 2 * L],
        P[2 * L : 3 * L, 0],
        P[2 * L : 3 * L, 1],
        P[3 * L : 3 * L + nb],
        P[3 * L + nb : 3 * L + 2 * nb, 0],
        P[3 * L + nb : 3 * L + 2 * nb, 1],
        P[3 * L + 2 * nb : 3 * L + 2 * nb + ncl],
        P[3 * L + 2 * nb + ncl : o, 0],
        P[3 * L + 2 * nb + ncl : o, 1],
        M[1 + dof : 1 + dof + n, :, :3],
        P[o : o + n],
        P[o + n : o + 2 * n],
        P[o + 2 * n : o + 3 * n],
        P[o + 3 * n : o + 4 * n],
    )
    return ints, floats, cpl


@njit(cache=True, nogil=True, inline="always")
def _place_body(Bf, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, Kw):
    """World end points of body b's capsules into X, Y (a sphere's only into X), and the
    centres of its clusters into Kw."""
    f00, f01, f02, f03 = Bf[b, 0, 0], Bf[b, 0, 1], Bf[b, 0, 2], Bf[b, 0, 3]
    f10, f11, f12, f13 = Bf[b, 1, 0], Bf[b, 1, 1], Bf[b, 1, 2], Bf[b, 1, 3]
    f20, f21, f22, f23 = Bf[b, 2, 0], Bf[b, 2, 1], Bf[b, 2, 2], Bf[b, 2, 3]
    for K in range(body_cl[b], body_cl[b + 1]):
        px, py, pz = cl_c[K, 0], cl_c[K, 1], cl_c[K, 2]
        Kw[K, 0] = f00 * px + f01 * py + f02 * pz + f03
        Kw[K, 1] = f10 * px + f11 * py + f12 * pz + f13
        Kw[K, 2] = f20 * px + f21 * py + f22 * pz + f23
    for l in range(cl_start[body_cl[b]], cl_start[body_cl[b + 1]]):
        px, py, pz = cap_a[l, 0], cap_a[l, 1], cap_a[l, 2]
        X[l, 0] = f00 * px + f01 * py + f02 * pz + f03
        X[l, 1] = f10 * px + f11 * py + f12 * pz + f13
        X[l, 2] = f20 * px + f21 * py + f22 * pz + f23
        if not issph[l]:
            px, py, pz = cap_b[l, 0], cap_b[l, 1], cap_b[l, 2]
            Y[l, 0] = f00 * px + f01 * py + f02 * pz + f03
            Y[l, 1] = f10 * px + f11 * py + f12 * pz + f13
            Y[l, 2] = f20 * px + f21 * py + f22 * pz + f23


@njit(cache=True, nogil=True, inline="always")
def _capsules_hit(o, kind, Rs, cs, hs, l0, l1, issph, moving, rad, X, Y, w):
    """A moving capsule of l0:l1 touches obstacle o (boxes and spheres inline)."""
    r00, r01, r02 = Rs[o, 0, 0], Rs[o, 0, 1], Rs[o, 0, 2]
    r10, r11, r12 = Rs[o, 1, 0], Rs[o, 1, 1], Rs[o, 1, 2]
    r20, r21, r22 = Rs[o, 2, 0], Rs[o, 2, 1], Rs[o, 2, 2]
    c0, c1, c2 = cs[o, 0], cs[o, 1], cs[o, 2]
    h0, h1, h2 = hs[o, 0], hs[o, 1], hs[o, 2]
    for l in range(l0, l1):
        if moving[l] == 0:
            continue
        r = rad[l]
        if not issph[l]:
            if capsule_obstacle_hit(kind, Rs[o], cs[o], hs[o], X[l], Y[l], r, w):
                return True
            continue
        x, y, z = X[l, 0] - c0, X[l, 1] - c1, X[l, 2] - c2
        if kind == BOX:  # the floats of geometry.seg_box_local for a zero-length segment
            v = abs(r00 * x + r10 * y + r20 * z) - h0
            d2 = v * v if v > 0.0 else 0.0
            v = abs(r01 * x + r11 * y + r21 * z) - h1
            if v > 0.0:
                d2 += v * v
            v = abs(r02 * x + r12 * y + r22 * z) - h2
            if v > 0.0:
                d2 += v * v
            if d2 <= r * r:
                return True
        elif kind == SPHERE:
            rr = r + h0
            if x * x + y * y + z * z <= rr * rr:
                return True
        elif _sphere_hit(kind, Rs[o], cs[o], hs[o], X[l, 0], X[l, 1], X[l, 2], r, w):
            return True
    return False


@njit(cache=True, nogil=True, inline="always")
def _apart(P, i, Q, j, r):
    """Points P[i] and Q[j] are further apart than r."""
    dx = P[i, 0] - Q[j, 0]
    dy = P[i, 1] - Q[j, 1]
    dz = P[i, 2] - Q[j, 2]
    return dx * dx + dy * dy + dz * dz > r * r


@njit(cache=True, nogil=True, inline="always")
def _pair_hit(i, j, issph, rads, X, Y):
    """Capsules i < j touch (the floats of geometry.seg_seg, as core.py tests them)."""
    rr = rads[i] + rads[j]
    if issph[i] and issph[j]:
        return not _apart(X, i, X, j, rr)
    d2, _, _ = seg_seg(X[i], X[i] if issph[i] else Y[i], X[j], X[j] if issph[j] else Y[j])
    return d2 <= rr * rr


# not inlined into _run at numba's level: ~7 % slower, but compiled in ~13 s instead of ~25
@njit(cache=True, nogil=True)
def _state_ok(q, V, S):
    """One state is valid: no moving capsule touches an obstacle, no checked pair of
    capsules touches. ``V``: ``_unpack``'s views; ``S``: ``_scratch``'s.

    Against the scene, body by body (in ``order``) and obstacle by obstacle: the body's
    ball, then each cluster's ball, then its capsules. Between links, per pair of bodies
    holding a checked pair: the bodies' balls, then per pair of clusters holding one their
    balls, then the pairs. A body's capsules are placed only when one of its balls is not
    clear; the first hit ends the test."""
    (parent, prism, body_cl, cl_start, order, kinds, issph, moving, allowed, any_cl) = V[0][:10]
    groups, cgroups = V[0][10], V[0][11]
    (T0, pre, cap_a, cap_b, rad, rads, bc, br, brs, cl_c, cl_r, cl_rs, Rs, cs, hs) = V[1][:15]
    olo, ohi = V[1][15], V[1][16]
    Bf, Cw, Kw, X, Y, done, w = S
    _body_frames(q, T0, parent, prism, pre, Bf, V[2], done)  # done: reset below
    nb = bc.shape[0]
    for b in range(nb):
        x, y, z = bc[b, 0], bc[b, 1], bc[b, 2]
        for a in range(3):
            Cw[b, a] = Bf[b, a, 0] * x + Bf[b, a, 1] * y + Bf[b, a, 2] * z + Bf[b, a, 3]
        done[b] = 0.0
    n_obs = kinds.shape[0]
    for k in range(nb):
        b = order[k]
        if br[b] < 0.0:
            continue  # no moving capsule
        x, y, z, rb = Cw[b, 0], Cw[b, 1], Cw[b, 2], br[b]
        for o in range(n_obs):
            if (
                (x + rb < olo[o, 0])
                | (x - rb > ohi[o, 0])
                | (y + rb < olo[o, 1])
                | (y - rb > ohi[o, 1])
                | (z + rb < olo[o, 2])
                | (z - rb > ohi[o, 2])
            ):
                continue  # the body's ball is clear of the obstacle's box in the world
            kind = kinds[o]
            if _bound_apart(kind, Rs[o], cs[o], hs[o], x, y, z, rb):
                continue
            if done[b] == 0.0:
                _place_body(Bf, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, Kw)
                done[b] = 1.0
            for K in range(body_cl[b], body_cl[b + 1]):
                rk = cl_r[K]
                if rk < 0.0 or _bound_apart(
                    kind, Rs[o], cs[o], hs[o], Kw[K, 0], Kw[K, 1], Kw[K, 2], rk
                ):
                    continue
                if _capsules_hit(
                    o, kind, Rs, cs, hs, cl_start[K], cl_start[K + 1], issph, moving, rad, X, Y, w
                ):
                    return False
    ncl = Kw.shape[0]
    L = X.shape[0]
    # balls around chunks of _CHUNK consecutive bodies (around their body balls), rows
    # (x, y, z, r) after the capsule tests' scratch
    cb = w[_SCRATCH:]
    if cgroups.shape[0] > 0:
        for c in range((nb + _CHUNK - 1) // _CHUNK):
            b0, b1 = c * _CHUNK, min(nb, (c + 1) * _CHUNK)
            x, y, z = 0.0, 0.0, 0.0
            for b in range(b0, b1):
                x += Cw[b, 0]
                y += Cw[b, 1]
                z += Cw[b, 2]
            k = 1.0 / (b1 - b0)
            x, y, z = x * k, y * k, z * k
            r = 0.0
            for b in range(b0, b1):
                dx, dy, dz = Cw[b, 0] - x, Cw[b, 1] - y, Cw[b, 2] - z
                r = max(r, math.sqrt(dx * dx + dy * dy + dz * dz) + brs[b])
            cb[4 * c], cb[4 * c + 1], cb[4 * c + 2], cb[4 * c + 3] = x, y, z, r + _BOUND_PAD_M
    for t in range(cgroups.shape[0] // 4):
        cu, cv = cgroups[4 * t], cgroups[4 * t + 1]
        if cu != cv:
            dx = cb[4 * cu] - cb[4 * cv]
            dy = cb[4 * cu + 1] - cb[4 * cv + 1]
            dz = cb[4 * cu + 2] - cb[4 * cv + 2]
            rr = cb[4 * cu + 3] + cb[4 * cv + 3]
            if dx * dx + dy * dy + dz * dz > rr * rr:
                continue  # the chunks' balls are apart: none of their body pairs touch
        for g in range(cgroups[4 * t + 2], cgroups[4 * t + 3]):
            bu, bv = groups[2 * g], groups[2 * g + 1]
            if bu != bv and _apart(Cw, bu, Cw, bv, brs[bu] + brs[bv]):
                continue
            for b in (bu, bv):
                if done[b] == 0.0:
                    _place_body(Bf, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, Kw)
                    done[b] = 1.0
            for Ku in range(body_cl[bu], body_cl[bu + 1]):
                if bu != bv and _apart(Kw, Ku, Cw, bv, cl_rs[Ku] + brs[bv]):
                    continue
                for Kv in range(Ku if bu == bv else body_cl[bv], body_cl[bv + 1]):
                    if any_cl[Ku * ncl + Kv] == 0:
                        continue
                    if Ku != Kv and _apart(Kw, Ku, Kw, Kv, cl_rs[Ku] + cl_rs[Kv]):
                        continue
                    for i in range(cl_start[Ku], cl_start[Ku + 1]):
                        if Ku != Kv and issph[i] and _apart(X, i, Kw, Kv, rads[i] + cl_rs[Kv]):
                            continue
                        j0 = i + 1 if Ku == Kv else cl_start[Kv]
                        for j in range(j0, cl_start[Kv + 1]):
                            if allowed[i * L + j] and _pair_hit(i, j, issph, rads, X, Y):
                                return False
    return True


@njit(cache=True, nogil=True)
def _scratch(idat):
    """Per-call scratch of :func:`_state_ok`: (body frames, body ball centres, cluster ball
    centres, capsule ends a and b, placed flags (nb: also the coupled joint values while
    the frames are made), capsule-test scratch (then the chunk balls))."""
    nb, L, ncl = idat[_H_NB], idat[_H_L], idat[_H_NCL]
    Bf = np.empty((nb, 3, 4))
    W = np.empty((nb + ncl + 2 * L, 3))
    aux = np.zeros(nb + _SCRATCH + 4 * ((nb + _CHUNK - 1) // _CHUNK))
    return (
        Bf,
        W[:nb],
        W[nb : nb + ncl],
        W[nb + ncl : nb + ncl + L],
        W[nb + ncl + L :],
        aux[:nb],
        aux[nb:],
    )


@njit(cache=True, nogil=True)
def _run(Q, P, M, idat, out, first_only):
    """The states of Q (k, dof) in order: validity into out (k,); with ``first_only``
    stops at the first invalid one. Returns its index, or -1. (The one copy of the
    inlined test: the kernels below call it.)"""
    V = _unpack(P, M, idat)
    S = _scratch(idat)
    for s in range(Q.shape[0]):
        ok = _state_ok(Q[s], V, S)
        out[s] = ok
        if first_only and not ok:
            return s
    return -1


@njit(cache=True, nogil=True)
def chain_valid(Q, P, M, idat, out):
    """Validity of a batch Q (k, dof) -> out (k,) bool, kinematics included."""
    _run(Q, P, M, idat, out, False)
    return out


@njit(cache=True, nogil=True)
def chain_first_bad(Q, P, M, idat):
    """Index of the first invalid state of Q (k, dof) in order, or -1."""
    return _run(Q, P, M, idat, np.empty(Q.shape[0], dtype=np.bool_), True)


@njit(cache=True, nogil=True)
def chain_state_valid(q, P, M, idat):
    """Validity of one state q (dof,)."""
    out = np.empty(1, dtype=np.bool_)
    _run(q.reshape((1, q.shape[0])), P, M, idat, out, True)
    return out[0]


@njit(cache=True, nogil=True)
def chain_points(Q, P, M, idat, out):
    """Capsule axes of a batch, the kinematics of :func:`chain_valid`: Q (k, dof) -> out
    (k, L, 2, 3), the capsules in the packed order."""
    V = _unpack(P, M, idat)
    (parent, prism, body_cl, cl_start, _, _, issph) = V[0][:7]
    (T0, pre, cap_a, cap_b) = V[1][:4]
    cl_c = V[1][9]
    Bf, _, Kw, X, Y, v, _ = _scratch(idat)
    for s in range(Q.shape[0]):
        _body_frames(Q[s], T0, parent, prism, pre, Bf, V[2], v)
        for b in range(Bf.shape[0]):
            _place_body(Bf, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, Kw)
        for l in range(X.shape[0]):
            for a in range(3):
                out[s, l, 0, a] = X[l, a]
                out[s, l, 1, a] = X[l, a] if issph[l] else Y[l, a]
    return out


__all__ = [
    "chain_first_bad",
    "chain_points",
    "chain_state_valid",
    "chain_valid",
]

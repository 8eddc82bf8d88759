"""Several states at once: the compiled model's state test in vector lanes.

:func:`lanes_check` tests ``W`` states of one robot in one scene together: the chain's
kinematics, the bounding-ball culls and the sphere tests run with the states side by side
(arrays ``(..., W)``, the lanes innermost), so the compiler turns each step into a vector
instruction over the lanes (AVX: 4 or 8 doubles at once), the way VAMP checks the states
of an edge. A cull is skipped only when it is clear for every lane still tested; real
capsules (not spheres) and cylinders against spheres fall back to the scalar tests of
:mod:`plannerlab.collision.geometry`, lane by lane.

**The same verdicts, bit for bit.** Each lane runs the very floating-point operations of
the one-state test :func:`plannerlab.collision.chain_valid._state_ok`, in the same order
(the kinematics, the ball centres, the obstacle and pair tests); the culls are the same
conservative balls. A lane's verdict is therefore the one-state verdict of its state
(``tests/collision/test_model.py`` holds them equal, and both equal to FCL's, on random,
near-contact and self-colliding states of every family). An edge checked in lanes
therefore passes or fails exactly as it does state by state, and the re-check (which may
run either) agrees.

Its use: batches (:func:`valid_states_lanes`, :func:`chain_valid_lanes`,
:func:`chain_first_bad_lanes`: every lane's verdict), so the re-check, the OMPL planners'
edges (each edge one batch) and the executor's checks. The compiled planners' edges stay
one state at a time: they are checked lazily, the end state and a few coarse states, too
few to fill the lanes, and every kernel that calls the lanes compiles them again into its
own module (the native kernels took 175 s to compile cold with their edges in lanes,
against 46 s).

Numba vectorizes a loop over the lanes only when their count is read at run time (``nw``
below): a loop of a constant count is unrolled and left scalar, the arrays possibly
aliasing. Eight lanes cost about as much as three (Panda) to four and a half (Arm-Z)
one-state tests, whether one lane or eight is filled (``bench/lanes_bench.py``): the
culls' control flow and each small loop's alias check, not arithmetic.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.chain_pack import (
    _BOUND_PAD_M,
    _CHUNK,
    _H_DOF,
    _H_L,
    _H_NB,
    _H_NCL,
)
from plannerlab.collision.chain_valid import _SCRATCH, _sphere_hit, _unpack
from plannerlab.collision.geometry import BOX, SPHERE, capsule_obstacle_hit, seg_seg

#: lanes per call: 8 doubles fill one AVX-512 register or two AVX2 ones
W = 8


@njit(cache=True, nogil=True)
def lanes_scratch(idat):
    """Scratch of :func:`lanes_check` (made once per search): body frames (nb, 12, W),
    body, cluster and chunk ball centres, capsule ends, the lanes' joint values, masks,
    placed flags, the scalar tests' scratch; then the states being tested."""
    nb, L, ncl, dof = idat[_H_NB], idat[_H_L], idat[_H_NCL], idat[_H_DOF]
    nch = (nb + _CHUNK - 1) // _CHUNK
    F = np.empty((nb, 12, W))
    C = np.empty((nb, 3, W))
    K = np.empty((max(ncl, 1), 3, W))
    X = np.empty((max(L, 1), 3, W))
    Y = np.empty((max(L, 1), 3, W))
    CB = np.empty((max(nch, 1), 4, W))
    T = np.empty((2, W))  # cos, sin of one joint
    v = np.empty((max(dof, 1), W))  # the chain's joint values per lane
    Mk = np.zeros((8, W), dtype=np.bool_)  # masks: alive, then one per cull level
    done = np.zeros(nb, dtype=np.int64)  # placed bodies; done[-1]... see _group
    w = np.zeros(_SCRATCH + 6)  # the scalar tests' scratch, then two points
    QL = np.zeros((dof, W))  # the states being tested (lane k: QL[:, k])
    return F, C, K, X, Y, CB, T, v, Mk, done, w, QL


@njit(cache=True, nogil=True, inline="always")
def _frames_lanes(v, T0, parent, prism, pre, F, T):
    """Body frames of the W lanes (the floats of ``chain_valid._frames_of`` per lane)."""
    nw = F.shape[2]  # W, read at run time: loops over it vectorize
    for r in range(12):
        x = T0[r // 4, r % 4]
        for k in range(nw):
            F[0, r, k] = x
    for i in range(parent.shape[0]):
        f = parent[i]
        p00, p01, p02, p03 = pre[i, 0, 0], pre[i, 0, 1], pre[i, 0, 2], pre[i, 0, 3]
        p10, p11, p12, p13 = pre[i, 1, 0], pre[i, 1, 1], pre[i, 1, 2], pre[i, 1, 3]
        p20, p21, p22, p23 = pre[i, 2, 0], pre[i, 2, 1], pre[i, 2, 2], pre[i, 2, 3]
        slide = prism[i] != 0
        if not slide:
            for k in range(nw):
                T[0, k] = math.cos(v[i, k])
                T[1, k] = math.sin(v[i, k])
        for a in range(3):
            ra = 4 * a
            for k in range(nw):
                f0, f1, f2, f3 = F[f, ra, k], F[f, ra + 1, k], F[f, ra + 2, k], F[f, ra + 3, k]
                g0 = f0 * p00 + f1 * p10 + f2 * p20
                g1 = f0 * p01 + f1 * p11 + f2 * p21
                g2 = f0 * p02 + f1 * p12 + f2 * p22
                g3 = f0 * p03 + f1 * p13 + f2 * p23
                g3 += f3
                if slide:
                    g3 += v[i, k] * g2
                    F[i + 1, ra, k] = g0
                    F[i + 1, ra + 1, k] = g1
                else:
                    F[i + 1, ra, k] = T[0, k] * g0 + T[1, k] * g1
                    F[i + 1, ra + 1, k] = T[0, k] * g1 - T[1, k] * g0
                F[i + 1, ra + 2, k] = g2
                F[i + 1, ra + 3, k] = g3


@njit(cache=True, nogil=True, inline="always")
def _joint_values(QL, cpl, v):
    """v (n, W): the chain's joint values of the lanes' states QL (dof, W) (the coupling's
    sums in ``chain_valid._body_frames``' order, or the states themselves)."""
    nw = v.shape[1]  # W, read at run time: loops over it vectorize
    cpl_start, cpl_idx, cpl_val = cpl
    n = v.shape[0]
    if cpl_start.shape[0] == 0:
        for i in range(QL.shape[0]):
            for k in range(nw):
                v[i, k] = QL[i, k]
        return
    for i in range(n):
        for k in range(nw):
            v[i, k] = 0.0
        for c in range(cpl_start[i], cpl_start[i + 1]):
            a = cpl_val[c // 3, c % 3]
            j = cpl_idx[c]
            for k in range(nw):
                v[i, k] += a * QL[j, k]


@njit(cache=True, nogil=True, inline="always")
def _place(F, P, l0, l1, out):
    """out[l] (3, W) = the body frame F (12, W) applied to the points P[l0:l1] (the floats
    of ``chain_valid._place_body``)."""
    nw = out.shape[2]  # W, read at run time: loops over it vectorize
    for l in range(l0, l1):
        px, py, pz = P[l, 0], P[l, 1], P[l, 2]
        for a in range(3):
            ra = 4 * a
            for k in range(nw):
                out[l, a, k] = F[ra, k] * px + F[ra + 1, k] * py + F[ra + 2, k] * pz + F[ra + 3, k]


@njit(cache=True, nogil=True, inline="always")
def _place_body_lanes(F, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, K):
    """World capsule ends (and cluster centres) of body b for the W lanes."""
    nw = X.shape[2]  # W, read at run time: loops over it vectorize
    Fb = F[b]
    _place(Fb, cl_c, body_cl[b], body_cl[b + 1], K)
    l0, l1 = cl_start[body_cl[b]], cl_start[body_cl[b + 1]]
    _place(Fb, cap_a, l0, l1, X)
    for l in range(l0, l1):
        if not issph[l]:
            px, py, pz = cap_b[l, 0], cap_b[l, 1], cap_b[l, 2]
            for a in range(3):
                ra = 4 * a
                for k in range(nw):
                    Y[l, a, k] = (
                        Fb[ra, k] * px + Fb[ra + 1, k] * py + Fb[ra + 2, k] * pz + Fb[ra + 3, k]
                    )


@njit(cache=True, nogil=True, inline="always")
def _ball_live(kind, R, c, h, Pt, rb, src, dst):
    """dst[k] = src[k] and the ball (Pt[:, k], rb) is not certainly clear of the obstacle
    (``chain_valid._bound_apart``'s floats, per lane). Returns whether any lane is live."""
    nw = src.shape[0]  # W, read at run time: loops over it vectorize
    any_live = False
    r00, r01, r02 = R[0, 0], R[0, 1], R[0, 2]
    r10, r11, r12 = R[1, 0], R[1, 1], R[1, 2]
    r20, r21, r22 = R[2, 0], R[2, 1], R[2, 2]
    c0, c1, c2 = c[0], c[1], c[2]
    h0, h1, h2 = h[0], h[1], h[2]
    rr2 = rb * rb
    if kind == SPHERE:
        rr = rb + h0
        rs2 = rr * rr
        for k in range(nw):
            ex, ey, ez = Pt[0, k] - c0, Pt[1, k] - c1, Pt[2, k] - c2
            live = src[k] & (not (ex * ex + ey * ey + ez * ez > rs2))
            dst[k] = live
            any_live |= live
    elif kind == BOX:
        for k in range(nw):
            x, y, z = Pt[0, k] - c0, Pt[1, k] - c1, Pt[2, k] - c2
            p0 = r00 * x + r10 * y + r20 * z
            p1 = r01 * x + r11 * y + r21 * z
            p2 = r02 * x + r12 * y + r22 * z
            t0 = max(abs(p0) - h0, 0.0)  # adding 0.0 leaves the sum's floats alone
            t1 = max(abs(p1) - h1, 0.0)
            t2 = max(abs(p2) - h2, 0.0)
            s = 0.0 + t0 * t0
            s += t1 * t1
            s += t2 * t2
            live = src[k] & (not (s > rr2))
            dst[k] = live
            any_live |= live
    else:
        for k in range(nw):
            x, y, z = Pt[0, k] - c0, Pt[1, k] - c1, Pt[2, k] - c2
            p0 = r00 * x + r10 * y + r20 * z
            p1 = r01 * x + r11 * y + r21 * z
            p2 = r02 * x + r12 * y + r22 * z
            qr = max(math.sqrt(p0 * p0 + p1 * p1) - h0, 0.0)
            qz = max(abs(p2) - h1, 0.0)
            live = src[k] & (not (qr * qr + qz * qz > rr2))
            dst[k] = live
            any_live |= live
    return any_live


@njit(cache=True, nogil=True, inline="always")
def _hit(alive, k, stop):
    """Lane k collides: it leaves the alive lanes. True when the test is over (``stop``,
    or no lane is left)."""
    nw = alive.shape[0]  # W, read at run time: loops over it vectorize
    alive[k] = False
    if stop:
        return True
    for j in range(nw):
        if alive[j]:
            return False
    return True


@njit(cache=True, nogil=True, inline="always")
def _capsules_hit_lanes(o, kind, Rs, cs, hs, l0, l1, issph, moving, rad, X, Y, live, hits,
                        alive, stop, w):  # fmt: skip
    """The moving capsules l0:l1 against obstacle o in the live lanes (``chain_valid.
    _capsules_hit``'s floats per lane): a lane that touches leaves ``alive``. True when the
    test is over."""
    nw = hits.shape[0]  # W, read at run time: loops over it vectorize
    R = Rs[o]
    r00, r01, r02 = R[0, 0], R[0, 1], R[0, 2]
    r10, r11, r12 = R[1, 0], R[1, 1], R[1, 2]
    r20, r21, r22 = R[2, 0], R[2, 1], R[2, 2]
    c0, c1, c2 = cs[o, 0], cs[o, 1], cs[o, 2]
    h0, h1, h2 = hs[o, 0], hs[o, 1], hs[o, 2]
    pa = w[_SCRATCH : _SCRATCH + 3]
    pb = w[_SCRATCH + 3 : _SCRATCH + 6]
    for l in range(l0, l1):
        if moving[l] == 0:
            continue
        r = rad[l]
        if issph[l] and kind == BOX:
            rr = r * r
            for k in range(nw):
                x, y, z = X[l, 0, k] - c0, X[l, 1, k] - c1, X[l, 2, k] - c2
                t0 = max(abs(r00 * x + r10 * y + r20 * z) - h0, 0.0)
                t1 = max(abs(r01 * x + r11 * y + r21 * z) - h1, 0.0)
                t2 = max(abs(r02 * x + r12 * y + r22 * z) - h2, 0.0)
                d2 = t0 * t0
                d2 += t1 * t1
                d2 += t2 * t2
                hits[k] = live[k] & alive[k] & (d2 <= rr)
        elif issph[l] and kind == SPHERE:
            rr = r + h0
            rs2 = rr * rr
            for k in range(nw):
                x, y, z = X[l, 0, k] - c0, X[l, 1, k] - c1, X[l, 2, k] - c2
                hits[k] = live[k] & alive[k] & (x * x + y * y + z * z <= rs2)
        else:  # a real capsule, or a sphere against a cylinder: the scalar tests
            for k in range(nw):
                hit = False
                if live[k] and alive[k]:
                    if issph[l]:
                        hit = _sphere_hit(kind, R, cs[o], hs[o], X[l, 0, k], X[l, 1, k],
                                          X[l, 2, k], r, w)  # fmt: skip
                    else:
                        for a in range(3):
                            pa[a] = X[l, a, k]
                            pb[a] = Y[l, a, k]
                        hit = capsule_obstacle_hit(kind, R, cs[o], hs[o], pa, pb, r, w)
                hits[k] = hit
        for k in range(nw):
            if hits[k] and _hit(alive, k, stop):
                return True
    return False


@njit(cache=True, nogil=True, inline="always")
def _apart_lanes(A, i, B, j, r, src, dst):
    """dst[k] = src[k] and points A[i][:, k], B[j][:, k] are not further apart than r
    (``chain_valid._apart``'s floats); whether any lane is set."""
    nw = src.shape[0]  # W, read at run time: loops over it vectorize
    rr = r * r
    any_live = False
    for k in range(nw):
        dx = A[i, 0, k] - B[j, 0, k]
        dy = A[i, 1, k] - B[j, 1, k]
        dz = A[i, 2, k] - B[j, 2, k]
        live = src[k] & (not (dx * dx + dy * dy + dz * dz > rr))
        dst[k] = live
        any_live |= live
    return any_live


@njit(cache=True, nogil=True, inline="always")
def _scene_lanes(V, SL, alive, stop):
    """:func:`lanes_check`'s scene: body by body (in ``order``) and obstacle by obstacle,
    the body's ball, each cluster's ball, then its capsules. False when the test is over
    (a lane collided and ``stop``, or no lane is left)."""
    nw = alive.shape[0]  # W, read at run time: loops over it vectorize
    body_cl, cl_start, order, kinds, issph, moving = V[0][2:8]
    cap_a, cap_b, rad = V[1][2], V[1][3], V[1][4]
    br, cl_c, cl_r = V[1][7], V[1][9], V[1][10]
    Rs, cs, hs, olo, ohi = V[1][12], V[1][13], V[1][14], V[1][15], V[1][16]
    F, C, K, X, Y, Mk, done, w = SL[0], SL[1], SL[2], SL[3], SL[4], SL[8], SL[9], SL[10]
    m1, m2, m3 = Mk[1], Mk[2], Mk[3]
    nb = br.shape[0]
    n_obs = kinds.shape[0]
    for kk in range(nb):
        b = order[kk]
        rb = br[b]
        if rb < 0.0:
            continue  # no moving capsule
        Cb = C[b]
        for o in range(n_obs):
            lo0, lo1, lo2 = olo[o, 0], olo[o, 1], olo[o, 2]
            hi0, hi1, hi2 = ohi[o, 0], ohi[o, 1], ohi[o, 2]
            any_live = False
            for k in range(nw):
                x, y, z = Cb[0, k], Cb[1, k], Cb[2, k]
                clear = (
                    (x + rb < lo0)
                    | (x - rb > hi0)
                    | (y + rb < lo1)
                    | (y - rb > hi1)
                    | (z + rb < lo2)
                    | (z - rb > hi2)
                )
                live = alive[k] & (not clear)
                m1[k] = live
                any_live |= live
            if not any_live:
                continue  # the body's ball is clear of the obstacle's box in every lane
            kind = kinds[o]
            if not _ball_live(kind, Rs[o], cs[o], hs[o], Cb, rb, m1, m2):
                continue
            if done[b] == 0:
                _place_body_lanes(F, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, K)
                done[b] = 1
            for Kc in range(body_cl[b], body_cl[b + 1]):
                rk = cl_r[Kc]
                if rk < 0.0 or not _ball_live(kind, Rs[o], cs[o], hs[o], K[Kc], rk, m2, m3):
                    continue
                if _capsules_hit_lanes(o, kind, Rs, cs, hs, cl_start[Kc], cl_start[Kc + 1],
                                       issph, moving, rad, X, Y, m3, Mk[4], alive, stop,
                                       w):  # fmt: skip
                    return False
    return True


@njit(cache=True, nogil=True, inline="always")
def _pairs_lanes(V, SL, alive, stop):
    """:func:`lanes_check`'s link pairs: by chunk of bodies, body pair, cluster pair, then
    the checked pairs. Returns whether every lane that was alive still is."""
    nw = alive.shape[0]  # W, read at run time: loops over it vectorize
    body_cl, cl_start, issph, allowed, any_cl = V[0][2], V[0][3], V[0][6], V[0][8], V[0][9]
    groups, cgroups = V[0][10], V[0][11]
    cap_a, cap_b, rads, bc = V[1][2], V[1][3], V[1][5], V[1][6]
    brs, cl_c, cl_rs = V[1][8], V[1][9], V[1][11]
    F, C, K, X, Y, CB, Mk, done, w = SL[0], SL[1], SL[2], SL[3], SL[4], SL[5], SL[8], SL[9], SL[10]
    m1, m2, m3 = Mk[1], Mk[2], Mk[3]
    nb = bc.shape[0]
    ncl = K.shape[0]
    L = X.shape[0]
    if cgroups.shape[0] > 0:
        for c in range((nb + _CHUNK - 1) // _CHUNK):
            b0, b1 = c * _CHUNK, min(nb, (c + 1) * _CHUNK)
            inv = 1.0 / (b1 - b0)
            for k in range(nw):
                x, y, z = 0.0, 0.0, 0.0
                for b in range(b0, b1):
                    x += C[b, 0, k]
                    y += C[b, 1, k]
                    z += C[b, 2, k]
                x, y, z = x * inv, y * inv, z * inv
                r = 0.0
                for b in range(b0, b1):
                    dx, dy, dz = C[b, 0, k] - x, C[b, 1, k] - y, C[b, 2, k] - z
                    r = max(r, math.sqrt(dx * dx + dy * dy + dz * dz) + brs[b])
                CB[c, 0, k], CB[c, 1, k], CB[c, 2, k] = x, y, z
                CB[c, 3, k] = r + _BOUND_PAD_M
    m4, m5, m6 = Mk[4], Mk[5], Mk[6]
    pa = w[_SCRATCH : _SCRATCH + 3]
    pb = w[_SCRATCH + 3 : _SCRATCH + 6]
    for t in range(cgroups.shape[0] // 4):
        cu, cv = cgroups[4 * t], cgroups[4 * t + 1]
        any_live = False
        for k in range(nw):
            live = alive[k]
            if live and cu != cv:
                dx = CB[cu, 0, k] - CB[cv, 0, k]
                dy = CB[cu, 1, k] - CB[cv, 1, k]
                dz = CB[cu, 2, k] - CB[cv, 2, k]
                rr = CB[cu, 3, k] + CB[cv, 3, k]
                live = not (dx * dx + dy * dy + dz * dz > rr * rr)
            m1[k] = live
            any_live |= live
        if not any_live:
            continue  # the chunks' balls are apart in every lane
        for g in range(cgroups[4 * t + 2], cgroups[4 * t + 3]):
            bu, bv = groups[2 * g], groups[2 * g + 1]
            if bu != bv:
                if not _apart_lanes(C, bu, C, bv, brs[bu] + brs[bv], m1, m2):
                    continue
            else:
                for k in range(nw):
                    m2[k] = m1[k]
            for b in (bu, bv):
                if done[b] == 0:
                    _place_body_lanes(F, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, K)
                    done[b] = 1
            for Ku in range(body_cl[bu], body_cl[bu + 1]):
                if bu != bv:
                    if not _apart_lanes(K, Ku, C, bv, cl_rs[Ku] + brs[bv], m2, m3):
                        continue
                else:
                    for k in range(nw):
                        m3[k] = m2[k]
                for Kv in range(Ku if bu == bv else body_cl[bv], body_cl[bv + 1]):
                    if any_cl[Ku * ncl + Kv] == 0:
                        continue
                    if Ku != Kv:
                        if not _apart_lanes(K, Ku, K, Kv, cl_rs[Ku] + cl_rs[Kv], m3, m4):
                            continue
                    else:
                        for k in range(nw):
                            m4[k] = m3[k]
                    for i in range(cl_start[Ku], cl_start[Ku + 1]):
                        if Ku != Kv and issph[i]:
                            if not _apart_lanes(X, i, K, Kv, rads[i] + cl_rs[Kv], m4, m5):
                                continue
                        else:
                            for k in range(nw):
                                m5[k] = m4[k]
                        j0 = i + 1 if Ku == Kv else cl_start[Kv]
                        for j in range(j0, cl_start[Kv + 1]):
                            if not allowed[i * L + j]:
                                continue
                            rr = rads[i] + rads[j]
                            if issph[i] and issph[j]:
                                _apart_lanes(X, i, X, j, rr, m5, m6)
                            else:
                                for k in range(nw):
                                    hit = False
                                    if m5[k] and alive[k]:
                                        for a in range(3):
                                            pa[a] = X[i, a, k]
                                            pb[a] = X[j, a, k]
                                        qa = w[0:3]
                                        qb = w[3:6]
                                        for a in range(3):
                                            qa[a] = X[i, a, k] if issph[i] else Y[i, a, k]
                                            qb[a] = X[j, a, k] if issph[j] else Y[j, a, k]
                                        d2, _, _ = seg_seg(pa, qa, pb, qb)
                                        hit = d2 <= rr * rr
                                    m6[k] = hit
                            for k in range(nw):
                                if m6[k] and alive[k] and _hit(alive, k, stop):
                                    return False
    for k in range(nw):
        if not alive[k]:
            return False
    return True


@njit(cache=True, nogil=True)
def lanes_check(QL, V, SL, alive, stop):
    """Test the W states QL (dof, W) (lane k: QL[:, k]) of the lanes set in ``alive`` (W,)
    bool; a lane whose state collides is cleared from ``alive``. ``stop``: end at the
    first lane that collides (an edge fails with it). Returns whether every lane that
    was alive still is.

    The culls of ``chain_valid._state_ok`` in its order (the scene body by body, then the
    link pairs by chunk, body and cluster), each skipped only when clear in every live
    lane."""
    nw = alive.shape[0]  # W, read at run time: loops over it vectorize
    (parent, prism) = V[0][:2]
    T0, pre, bc = V[1][0], V[1][1], V[1][6]
    F, C, T, v, done = SL[0], SL[1], SL[6], SL[7], SL[9]
    _joint_values(QL, V[2], v)
    _frames_lanes(v, T0, parent, prism, pre, F, T)
    nb = bc.shape[0]
    for b in range(nb):
        x, y, z = bc[b, 0], bc[b, 1], bc[b, 2]
        for a in range(3):
            ra = 4 * a
            for k in range(nw):
                C[b, a, k] = (
                    F[b, ra, k] * x + F[b, ra + 1, k] * y + F[b, ra + 2, k] * z + F[b, ra + 3, k]
                )
        done[b] = 0
    if not _scene_lanes(V, SL, alive, stop):
        return False
    return _pairs_lanes(V, SL, alive, stop)


@njit(cache=True, nogil=True)
def lanes_views(m):
    """The model's views and a lanes scratch (made once per search)."""
    return _unpack(m.P, m.M, m.idat), lanes_scratch(m.idat)


@njit(cache=True, nogil=True)
def _batch(Q, V, SL, out, first_only):
    """The states of Q (k, dof) in groups of W: validity into out (k,); with
    ``first_only`` stops after the first group holding an invalid state. Returns the
    first invalid index, or -1."""
    dof = Q.shape[1]
    QL = SL[11]
    alive = SL[8][0]
    n = Q.shape[0]
    for s0 in range(0, n, W):
        cnt = min(W, n - s0)
        for k in range(W):
            src = s0 + (k if k < cnt else 0)
            for i in range(dof):
                QL[i, k] = Q[src, i]
            alive[k] = k < cnt
        lanes_check(QL, V, SL[:11], alive, False)  # what it reads: a call copies its tuples
        bad = -1
        for k in range(cnt):
            out[s0 + k] = alive[k]
            if bad < 0 and not alive[k]:
                bad = s0 + k
        if first_only and bad >= 0:
            return bad
    return -1


@njit(cache=True, nogil=True)
def chain_batch_lanes(Q, P, M, idat, out, first_only):
    """Validity of a batch Q (k, dof) into out (k,) bool, W states at a time, on the
    packed chain (``chain_pack._pack``'s arrays, a model's ``P, M, idat``); with
    ``first_only`` it stops after the first group holding an invalid state. Returns the
    first invalid index, or -1. The one compiled entry of the lanes: every kernel that
    calls them compiles them again into its own module (about 20 s cold each)."""
    return _batch(Q, _unpack(P, M, idat), lanes_scratch(idat), out, first_only)


def valid_states_lanes(Q: np.ndarray, m: Any, out: np.ndarray) -> np.ndarray:
    """Validity of a batch Q (k, dof) -> out (k,) bool of a compiled model, W states at a
    time (:func:`chain_batch_lanes`)."""
    kernel: Any = chain_batch_lanes  # a numba dispatcher
    kernel(Q, m.P, m.M, m.idat, out, False)
    return out

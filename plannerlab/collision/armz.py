"""Arm-Z's compiled kinematics and the conservative advancement of its paths (numba,
``cache=True``).

Arm-Z's chain ``H_i = RotZ(θ_i) · Trans(0, δy, δz) · RotX(ζ)`` (see
:class:`~plannerlab.robots.armz.model.ArmZ`): its frames (:func:`armz_frames`), capsule
axes (:func:`armz_segments`, and with the joints' axes :func:`armz_segments_axes`) for a
batch of states; and a whole path checked by conservative advancement with the bounds
taken at the configuration (:func:`armz_advance_dt`, :func:`armz_path_advance`: see
:mod:`plannerlab.collision.core`). The generic kernels they call are in
:mod:`plannerlab.collision.kernels`. Its states' validity is the compiled model's, as for
every chain (:mod:`plannerlab.collision.chain_valid`, :mod:`plannerlab.collision.lanes`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plannerlab.collision.geometry import capsule_obstacle, seg_seg
from plannerlab.collision.kernels import (
    box_gap,
    edge_rates,
    link_boxes,
    scratch,
    state_hits,
)


@njit(cache=True, nogil=True)
def armz_frames(Q, T0, T1, M, out):
    """Arm-Z frames for a batch: Q (k, dof) → out (k, dof + 2, 4, 4) (see ``ArmZ.fk``)."""
    k, dof = Q.shape
    for s in range(k):
        for i in range(4):
            for j in range(4):
                out[s, 0, i, j] = T0[i, j]
                out[s, 1, i, j] = T1[i, j]
        for f in range(dof):
            c = math.cos(Q[s, f])
            sn = math.sin(Q[s, f])
            for i in range(3):
                # row i of F · RotZ(θ): columns 0 and 1 turn, 2 and 3 stay
                f0 = out[s, f + 1, i, 0]
                f1 = out[s, f + 1, i, 1]
                f2 = out[s, f + 1, i, 2]
                f3 = out[s, f + 1, i, 3]
                g0 = c * f0 + sn * f1
                g1 = -sn * f0 + c * f1
                for j in range(4):
                    out[s, f + 2, i, j] = g0 * M[0, j] + g1 * M[1, j] + f2 * M[2, j]
                out[s, f + 2, i, 3] += f3
            out[s, f + 2, 3, 0] = 0.0
            out[s, f + 2, 3, 1] = 0.0
            out[s, f + 2, 3, 2] = 0.0
            out[s, f + 2, 3, 3] = 1.0
    return out


@njit(cache=True, nogil=True)
def armz_segments(Q, T0, T1, M, out):
    """Arm-Z capsule axes for a batch: Q (k, dof) → out (k, dof + 1, 2, 3)."""
    k, dof = Q.shape
    R = np.empty((3, 3))
    p = np.empty(3)
    for s in range(k):
        for i in range(3):
            out[s, 0, 0, i] = T0[i, 3]
            p[i] = T1[i, 3]
            for j in range(3):
                R[i, j] = T1[i, j]
        for f in range(dof):
            c = math.cos(Q[s, f])
            sn = math.sin(Q[s, f])
            for i in range(3):
                out[s, f, 1, i] = p[i]
                out[s, f + 1, 0, i] = p[i]
            for i in range(3):
                g0 = c * R[i, 0] + sn * R[i, 1]
                g1 = -sn * R[i, 0] + c * R[i, 1]
                g2 = R[i, 2]
                p[i] += g0 * M[0, 3] + g1 * M[1, 3] + g2 * M[2, 3]
                R[i, 0] = g0 * M[0, 0] + g1 * M[1, 0] + g2 * M[2, 0]
                R[i, 1] = g0 * M[0, 1] + g1 * M[1, 1] + g2 * M[2, 1]
                R[i, 2] = g0 * M[0, 2] + g1 * M[1, 2] + g2 * M[2, 2]
        for i in range(3):
            out[s, dof, 1, i] = p[i]
    return out


@njit(cache=True, nogil=True)
def armz_segments_axes(q, T0, T1, M, seg, z):
    """:func:`armz_segments` of one state q (dof,) → seg (dof + 1, 2, 3), and the joints'
    axis directions z (dof, 3) (joint ``f`` turns about ``z[f]`` through ``seg[f, 1]``);
    the same floats as :func:`armz_segments`."""
    dof = q.shape[0]
    R = np.empty((3, 3))
    p = np.empty(3)
    for i in range(3):
        seg[0, 0, i] = T0[i, 3]
        p[i] = T1[i, 3]
        for j in range(3):
            R[i, j] = T1[i, j]
    for f in range(dof):
        c = math.cos(q[f])
        sn = math.sin(q[f])
        for i in range(3):
            seg[f, 1, i] = p[i]
            seg[f + 1, 0, i] = p[i]
            z[f, i] = R[i, 2]
        for i in range(3):
            g0 = c * R[i, 0] + sn * R[i, 1]
            g1 = -sn * R[i, 0] + c * R[i, 1]
            g2 = R[i, 2]
            p[i] += g0 * M[0, 3] + g1 * M[1, 3] + g2 * M[2, 3]
            R[i, 0] = g0 * M[0, 0] + g1 * M[1, 0] + g2 * M[2, 0]
            R[i, 1] = g0 * M[0, 1] + g1 * M[1, 1] + g2 * M[2, 1]
            R[i, 2] = g0 * M[0, 2] + g1 * M[1, 2] + g2 * M[2, 2]
    for i in range(3):
        seg[dof, 1, i] = p[i]


@njit(cache=True, nogil=True)
def _quad_step(u, c2, c):
    """Largest s with ``u s + c2 s² / 2 <= c`` (u, c2 >= 0; inf when both are 0)."""
    if c2 <= 0.0:
        return c / u if u > 0.0 else np.inf
    return 2.0 * c / (u + math.sqrt(u * u + 2.0 * c2 * c))


@njit(cache=True, nogil=True)
def armz_advance_dt(
    seg,
    d,
    z_axes,
    radii,
    radii_self,
    moving,
    allowed,
    kinds,
    Rs,
    cs,
    hs,
    olo,
    ohi,
    v_link,
    v_pair,
    margin,
    dt_max,
    buf,
    rho,
):
    """:func:`advance_dt` for Arm-Z with bounds taken at this configuration.

    Joint ``f`` turns links ``f+1 ..`` about its axis, so a point of link ``l`` moves at
    ``|d_f| · ρ_fl`` per unit of the edge parameter from it, ``ρ_fl`` the largest distance
    of link ``l``'s axis points from joint ``f``'s axis (at an end point: the distance to
    a line is convex). Along the step ``ρ_fl`` grows at most as fast as link ``l`` moves
    relative to joint ``f``, at most ``v_link[l]``; so over a step ``s`` link ``l`` moves
    at most ``u s + a v s² / 2`` (``u = Σ_f |d_f| ρ_fl``, ``a = Σ_f |d_f|``), and at most
    ``v_link[l] · s`` (the configuration-free bound): the step is the larger of the two
    that keeps ``d + margin``. A link pair ``(i, j)`` is the same with the joints between
    them (``i <= f < j``) moving ``j`` relative to ``i``.
    """
    lo, hi, w, lo2, hi2, _ = buf
    L = seg.shape[0]
    dof = L - 1
    n_obs = kinds.shape[0]
    # joint f's axis: direction z_axes[f] through seg[f, 1] (armz_segments_axes)
    for f in range(dof):
        ox, oy, oz = seg[f, 1, 0], seg[f, 1, 1], seg[f, 1, 2]
        zx, zy, zz = z_axes[f, 0], z_axes[f, 1], z_axes[f, 2]
        for li in range(f + 1, L):
            best_r = 0.0
            for e in range(2):
                x = seg[li, e, 0] - ox
                y = seg[li, e, 1] - oy
                z = seg[li, e, 2] - oz
                t = x * zx + y * zy + z * zz
                r2 = x * x + y * y + z * z - t * t
                if r2 > best_r:
                    best_r = r2
            rho[f, li] = math.sqrt(best_r)
    link_boxes(seg, radii, lo, hi)
    nv = np.empty(3)
    best = dt_max
    for li in range(L):
        v = v_link[li]
        if not moving[li] or v <= 0.0:
            continue
        u = 0.0
        a = 0.0
        for f in range(li):
            u += abs(d[f]) * rho[f, li]
            a += abs(d[f])
        for oi in range(n_obs):
            cc = box_gap(lo, hi, li, olo, ohi, oi) + margin
            if cc / v >= best or _quad_step(u, a * v, cc) >= best:  # max(..) >= best
                continue
            dist, _ = capsule_obstacle(
                kinds[oi],
                Rs[oi],
                cs[oi],
                hs[oi],
                seg[li, 0],
                seg[li, 1],
                radii[li],
                False,
                nv,
                w,
            )
            cc = max(dist, 0.0) + margin
            dt = max(cc / v, _quad_step(u, a * v, cc))
            if dt < best:
                best = dt
    link_boxes(seg, radii_self, lo2[:L], hi2[:L])
    for j in range(L):
        u = 0.0
        a = 0.0
        for i in range(j - 1, -1, -1):
            u += abs(d[i]) * rho[i, j]
            a += abs(d[i])
            v = v_pair[i, j]
            if v <= 0.0 or not allowed[i, j]:
                continue
            cc = box_gap(lo2, hi2, i, lo2, hi2, j) + margin
            c2 = a * v_link[j]
            if cc / v >= best or _quad_step(u, c2, cc) >= best:  # max(..) >= best
                continue
            d2, _, _ = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
            cc = max(math.sqrt(d2) - radii_self[i] - radii_self[j], 0.0) + margin
            dt = max(cc / v, _quad_step(u, c2, cc))
            if dt < best:
                best = dt
    return best


@njit(cache=True, nogil=True)
def armz_path_advance(
    P,
    first,
    joint_step,
    limit,
    continuous,
    cap,
    weights,
    W,
    Pr,
    margin,
    T0,
    T1,
    M,
    radii,
    radii_self,
    moving,
    allowed,
    tree,
    kinds,
    Rs,
    cs,
    hs,
    olo,
    ohi,
):
    """An Arm-Z path (m, dof) checked edge by edge with conservative advancement (see
    :meth:`~plannerlab.collision.core.Core.path_advance`): returns (queries, status, edge,
    t), status 0 all valid, 1 the state ``P[edge] + t · d_edge`` is invalid, 2 ``limit``
    queries were spent first, 3 edge ``edge``'s grid would have more than ``cap`` states
    (nothing checked on it).
    """
    m, dof = P.shape
    L = dof + 1
    seg = np.empty((1, L, 2, 3))
    buf = scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    d = np.empty(dof)
    q = np.empty((1, dof))
    v_link = np.empty(L)
    v_pair = np.empty((L, L))
    rho = np.zeros((dof, L))
    z_axes = np.empty((dof, 3))  # the joints' axes at the state seg holds
    queries = 0
    have_seg = False  # seg holds the current vertex, validity known
    if first == 2:  # queried already by the caller: measured again, not counted
        armz_segments_axes(P[0], T0, T1, M, seg[0], z_axes)
        have_seg = True
    if first == 1:
        if limit < 1:
            return queries, 2, 0, 0.0
        armz_segments_axes(P[0], T0, T1, M, seg[0], z_axes)
        queries += 1
        have_seg = True
        if state_hits(
            seg[0],
            radii,
            radii_self,
            moving,
            allowed,
            tree,
            kinds,
            Rs,
            cs,
            hs,
            olo,
            ohi,
            buf,
            True,
            pairs,
        ):
            return queries, 1, 0, 0.0
    for e in range(m - 1):
        span = 0.0
        metric = 0.0
        for i in range(dof):
            x = P[e + 1, i] - P[e, i]
            if continuous[i]:
                x = (x + np.pi) % (2.0 * np.pi) - np.pi
            d[i] = x
            span = max(span, abs(x))
            metric += weights[i] * abs(x)
        n = max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12))
        if n > cap:
            return queries, 3, e, 0.0
        dt_min = 1.0 / n
        dt_cap = joint_step / span if span > 0.0 else 1.0
        adaptive = dt_cap > dt_min * (1.0 + 1e-12)
        if adaptive:
            edge_rates(d, W, Pr, v_link, v_pair)
        t = 0.0
        dt = dt_min
        if adaptive and not have_seg:  # the edge's start: measured, not checked (the caller's)
            if queries >= limit:
                return queries, 2, e, 0.0
            armz_segments_axes(P[e], T0, T1, M, seg[0], z_axes)
            queries += 1
        while True:
            if adaptive:
                dt = armz_advance_dt(
                    seg[0],
                    d,
                    z_axes,
                    radii,
                    radii_self,
                    moving,
                    allowed,
                    kinds,
                    Rs,
                    cs,
                    hs,
                    olo,
                    ohi,
                    v_link,
                    v_pair,
                    margin,
                    1.0 - t,
                    buf,
                    rho,
                )
            step = max(dt_min, min(dt, dt_cap))
            tn = t + step
            if tn >= 1.0 - 1e-9:
                tn = 1.0
            if queries >= limit:
                return queries, 2, e, t
            for i in range(dof):
                q[0, i] = P[e, i] + tn * d[i]
            armz_segments_axes(q[0], T0, T1, M, seg[0], z_axes)
            queries += 1
            if state_hits(
                seg[0],
                radii,
                radii_self,
                moving,
                allowed,
                tree,
                kinds,
                Rs,
                cs,
                hs,
                olo,
                ohi,
                buf,
                True,
                pairs,
            ):
                return queries, 1, e, tn
            if tn == 1.0:
                break
            t = tn
        have_seg = True
    return queries, 0, m - 1, 1.0

"""The geometry of the compiled clearance descent (:mod:`plannerlab.planners._descent_core`,
numba, cached): an Arm-Z chain's face frames, sphere centres and tip Jacobians, every
sphere pair's distance and direction (sphere against box, cylinder or sphere; sphere
against sphere), and one pair's distance gradient through the chain. The arithmetic of
:class:`~plannerlab.planners.clearance.ClearanceField` written as loops (same spheres,
same pairs in the same order)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: obstacle kinds of :func:`_pairs`
BOX, CYLINDER, SPHERE = 0, 1, 2


# ---------------------------------------------------------------------- kinematics
@njit(cache=True, nogil=True)
def _frames(q, F1, T0, M):
    """Arm-Z face frames (dof + 2, 4, 4) at q (dof,) (see ``ArmZ.fk``)."""
    dof = q.shape[0]
    F = np.zeros((dof + 2, 4, 4))
    F[0] = T0
    F[1] = F1
    step = np.zeros((4, 4))
    for i in range(dof):
        c, s = math.cos(q[i]), math.sin(q[i])
        for k in range(4):  # RotZ(q_i) @ M
            step[0, k] = c * M[0, k] - s * M[1, k]
            step[1, k] = s * M[0, k] + c * M[1, k]
            step[2, k] = M[2, k]
            step[3, k] = M[3, k]
        for r in range(4):
            for k in range(4):
                acc = 0.0
                for m in range(4):
                    acc += F[i + 1, r, m] * step[m, k]
                F[i + 2, r, k] = acc
    return F


@njit(cache=True, nogil=True)
def _centres(F, link, t):
    """Sphere centres (s, 3): on link i, ``a + t (b − a)`` between frames i and i + 1."""
    S = link.shape[0]
    P = np.empty((S, 3))
    for s in range(S):
        li = link[s]
        for k in range(3):
            a = F[li, k, 3]
            b = F[li + 1, k, 3]
            P[s, k] = a + t[s] * (b - a)
    return P


@njit(cache=True, nogil=True)
def _tip_jacobians(Fr, p, n):
    """The tip's Jacobians (3, dof) each: dp/dθ_j = z_j × (p − o_j), dn/dθ_j = z_j × n."""
    dof = Fr.shape[0] - 2
    Jp = np.empty((3, dof))
    Jn = np.empty((3, dof))
    for j in range(dof):
        zx, zy, zz = Fr[j + 1, 0, 2], Fr[j + 1, 1, 2], Fr[j + 1, 2, 2]
        dx = p[0] - Fr[j + 1, 0, 3]
        dy = p[1] - Fr[j + 1, 1, 3]
        dz = p[2] - Fr[j + 1, 2, 3]
        Jp[0, j] = zy * dz - zz * dy
        Jp[1, j] = zz * dx - zx * dz
        Jp[2, j] = zx * dy - zy * dx
        Jn[0, j] = zy * n[2] - zz * n[1]
        Jn[1, j] = zz * n[0] - zx * n[2]
        Jn[2, j] = zx * n[1] - zy * n[0]
    return Jp, Jn


# ---------------------------------------------------------------------- pairs
@njit(cache=True, nogil=True)
def _pairs(
    P,
    r,
    scene_idx,
    self_a,
    self_b,
    kinds,
    Rs,
    cs,
    pars,
    bound,
    far_m,
    A,
    B,
    lp_of_row,
    lp_links,
    link_ends,
):
    """Every sphere pair, in ``ClearanceField._pairs``' order: distance d (m,), direction
    n (m, 3), spheres a and b (b = −1: an obstacle). A pair at least ``far_m`` apart gets
    d = ``far_m`` and no direction (the descent asks nothing of it: only pairs closer than
    the margin cost, and only pairs closer than the clearance floor are held); an obstacle's
    pairs are skipped by its bounding sphere (radius ``bound``) when they are that far.
    ``A`` and ``B`` (m,) are the pairs' spheres, fixed (:func:`pair_spheres`); the self
    pairs of two links whose sphere chains are that far apart (their midpoints farther than
    both half-lengths, radii and ``far_m``) are skipped together (``lp_of_row``: each self
    pair's link pair, ``lp_links`` (k, 2) its links, ``link_ends`` (L, 2) each link's first
    and last sphere)."""
    n_scene = scene_idx.shape[0]
    n_obs = kinds.shape[0]
    m = n_obs * n_scene + self_a.shape[0]
    d = np.empty(m)
    nrm = np.empty((m, 3))
    loc = np.empty(3)
    g = np.empty(3)
    row = 0
    for o in range(n_obs):
        R = Rs[o]
        c = cs[o]
        kind = kinds[o]
        for ii in range(n_scene):
            s = scene_idx[ii]
            dx = P[s, 0] - c[0]
            dy = P[s, 1] - c[1]
            dz = P[s, 2] - c[2]
            reach = bound[o] + r[s] + far_m
            if dx * dx + dy * dy + dz * dz >= reach * reach:
                d[row] = far_m
                row += 1
                continue
            if kind == SPHERE:
                nd = math.sqrt(dx * dx + dy * dy + dz * dz)
                dist = nd - pars[o, 0]
                den = nd if nd > 1e-12 else 1.0
                g[0], g[1], g[2] = dx / den, dy / den, dz / den
            else:
                for k in range(3):
                    loc[k] = dx * R[0, k] + dy * R[1, k] + dz * R[2, k]
                gl0 = gl1 = gl2 = 0.0
                if kind == BOX:
                    q0 = abs(loc[0]) - pars[o, 0]
                    q1 = abs(loc[1]) - pars[o, 1]
                    q2 = abs(loc[2]) - pars[o, 2]
                    o0, o1, o2 = max(q0, 0.0), max(q1, 0.0), max(q2, 0.0)
                    on = math.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
                    dist = on + min(max(q0, max(q1, q2)), 0.0)
                    s0 = 1.0 if loc[0] >= 0 else -1.0
                    s1 = 1.0 if loc[1] >= 0 else -1.0
                    s2 = 1.0 if loc[2] >= 0 else -1.0
                    if on > 1e-12:
                        gl0, gl1, gl2 = s0 * o0 / on, s1 * o1 / on, s2 * o2 / on
                    else:  # inside: the face nearest (argmax, first on ties)
                        if q0 >= q1 and q0 >= q2:
                            gl0 = s0
                        elif q1 >= q2:
                            gl1 = s1
                        else:
                            gl2 = s2
                else:  # CYLINDER: pars = radius, half length
                    rho = math.hypot(loc[0], loc[1])
                    if rho > 1e-12:
                        r0, r1 = loc[0] / rho, loc[1] / rho
                    else:
                        r0, r1 = 1.0, 0.0
                    ax = 1.0 if loc[2] >= 0 else -1.0
                    q0 = rho - pars[o, 0]
                    q1 = abs(loc[2]) - pars[o, 1]
                    o0, o1 = max(q0, 0.0), max(q1, 0.0)
                    on = math.sqrt(o0 * o0 + o1 * o1)
                    dist = on + min(max(q0, q1), 0.0)
                    if on > 1e-12:
                        w0, w1 = o0 / on, o1 / on
                        gl0, gl1, gl2 = w0 * r0, w0 * r1, w1 * ax
                    elif q0 >= q1:
                        gl0, gl1 = r0, r1
                    else:
                        gl2 = ax
                for k in range(3):
                    g[k] = R[k, 0] * gl0 + R[k, 1] * gl1 + R[k, 2] * gl2
            dist = dist - r[s]
            if dist >= far_m:
                d[row] = far_m
            else:
                d[row] = dist
                nrm[row, 0], nrm[row, 1], nrm[row, 2] = g[0], g[1], g[2]
            row += 1
    n_links = link_ends.shape[0]
    mid = np.empty((n_links, 3))
    reach_l = np.empty(n_links)
    for li in range(n_links):
        s0, s1 = link_ends[li, 0], link_ends[li, 1]
        if s0 < 0:
            continue
        hx = 0.5 * (P[s1, 0] - P[s0, 0])
        hy = 0.5 * (P[s1, 1] - P[s0, 1])
        hz = 0.5 * (P[s1, 2] - P[s0, 2])
        mid[li, 0], mid[li, 1], mid[li, 2] = P[s0, 0] + hx, P[s0, 1] + hy, P[s0, 2] + hz
        reach_l[li] = math.sqrt(hx * hx + hy * hy + hz * hz) + r[s0]
    n_lp = lp_links.shape[0]
    lp_far = np.empty(n_lp, dtype=np.bool_)
    for k in range(n_lp):
        i, j = lp_links[k, 0], lp_links[k, 1]
        dx = mid[i, 0] - mid[j, 0]
        dy = mid[i, 1] - mid[j, 1]
        dz = mid[i, 2] - mid[j, 2]
        reach = reach_l[i] + reach_l[j] + far_m
        lp_far[k] = dx * dx + dy * dy + dz * dz >= reach * reach * (1.0 + 1e-12)
    for ii in range(self_a.shape[0]):
        if lp_far[lp_of_row[ii]]:
            d[row] = far_m
            row += 1
            continue
        a = self_a[ii]
        b = self_b[ii]
        dx = P[a, 0] - P[b, 0]
        dy = P[a, 1] - P[b, 1]
        dz = P[a, 2] - P[b, 2]
        reach = far_m + r[a] + r[b]
        sq = dx * dx + dy * dy + dz * dz
        if sq >= reach * reach:
            d[row] = far_m
        else:
            nd = math.sqrt(sq)
            d[row] = nd - r[a] - r[b]
            den = nd if nd > 1e-12 else 1.0
            nrm[row, 0], nrm[row, 1], nrm[row, 2] = dx / den, dy / den, dz / den
        row += 1
    return d, nrm


def pair_spheres(
    scene_idx: np.ndarray, n_obstacles: int, self_a: np.ndarray, self_b: np.ndarray, link
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The fixed bookkeeping of :func:`_pairs`: the spheres of every pair in its order,
    a (m,) and b (m,) (−1: an obstacle); each self pair's link pair, the link pairs' links
    (k, 2) and each link's first and last sphere (L, 2; −1 for a link without spheres)."""
    a = np.concatenate([np.tile(scene_idx, n_obstacles), self_a]).astype(np.int64)
    b = np.concatenate([np.full(len(scene_idx) * n_obstacles, -1), self_b]).astype(np.int64)
    link = np.asarray(link, dtype=np.int64)
    n_links = int(link.max()) + 1 if len(link) else 0
    ends = np.full((n_links, 2), -1, dtype=np.int64)
    for li in range(n_links):
        on = np.flatnonzero(link == li)
        if len(on):
            ends[li] = on[0], on[-1]
    pairs = np.stack([link[self_a], link[self_b]], axis=1) if len(self_a) else np.zeros((0, 2))
    lp_links, lp_of_row = np.unique(pairs.astype(np.int64), axis=0, return_inverse=True)
    return (
        a,
        b,
        np.asarray(lp_of_row, dtype=np.int64).reshape(-1),
        np.ascontiguousarray(lp_links, dtype=np.int64).reshape(-1, 2),
        ends,
    )


@njit(cache=True, nogil=True)
def _pair_gradient(F, P, link, nrm, a, b, row, out):
    """∇d (dof,) of one pair into ``out``: n · J_a (− n · J_b for a self pair), with the
    centre's Jacobian column ``J_s[:, j] = z_j × (p_s − o_j)`` for the joints j (0-based,
    about frame j + 1's z axis) below its link, 0 beyond."""
    dof = F.shape[0] - 2
    n0, n1, n2 = nrm[row, 0], nrm[row, 1], nrm[row, 2]
    for j in range(dof):
        out[j] = 0.0
    for side in range(2):
        s = a if side == 0 else b
        if s < 0:
            break
        sign = 1.0 if side == 0 else -1.0
        li = link[s]
        for j in range(min(dof, li)):
            zx, zy, zz = F[j + 1, 0, 2], F[j + 1, 1, 2], F[j + 1, 2, 2]
            dx = P[s, 0] - F[j + 1, 0, 3]
            dy = P[s, 1] - F[j + 1, 1, 3]
            dz = P[s, 2] - F[j + 1, 2, 3]
            g = n0 * (zy * dz - zz * dy) + n1 * (zz * dx - zx * dz) + n2 * (zx * dy - zy * dx)
            out[j] += sign * g

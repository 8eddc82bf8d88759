"""Compiled kinematics of a generic serial chain (a ``type = "urdf"`` robot) for the core.

:class:`~plannerlab.robots.urdf.model.UrdfChain` keeps its chain as plain arrays: per
movable joint its parent body, the fixed transform from that body to the joint frame,
the unit axis and whether it slides; per capsule its body and its two end points in the
body's frame. :func:`chain_segments` turns a batch of states into capsule axes in the world
in one numba call (``cache=True``), the same numbers as ``UrdfChain.link_segments`` (to
rounding), so that :class:`~plannerlab.collision.core.Core` checks a URDF robot without a
numpy detour per state.
"""

from __future__ import annotations

from typing import Any

import math

import numpy as np
from numba import njit

from plannerlab.collision.geometry import (
    BOX,
    SPHERE,
    _sd_cyl,
    _to_local,
    capsule_obstacle_hit,
    seg_seg,
)


@njit(cache=True, nogil=True)
def chain_segments(Q, T0, parent, pre, axes, prismatic, cap_body, cap_a, cap_b, out):
    """Capsule axes for a batch: Q (k, dof) -> out (k, L, 2, 3) (see ``link_segments``)."""
    k, dof = Q.shape
    L = cap_body.shape[0]
    B = np.empty((dof + 1, 4, 4))
    M = np.empty((4, 4))
    P = np.empty((4, 4))
    for s in range(k):
        B[0] = T0
        for i in range(dof):
            # M: the joint's motion
            x, y, z = axes[i, 0], axes[i, 1], axes[i, 2]
            q = Q[s, i]
            for a in range(4):
                for b in range(4):
                    M[a, b] = 1.0 if a == b else 0.0
            if prismatic[i]:
                M[0, 3] = q * x
                M[1, 3] = q * y
                M[2, 3] = q * z
            else:
                c = np.cos(q)
                sn = np.sin(q)
                t = 1.0 - c
                M[0, 0] = c + t * x * x
                M[0, 1] = t * x * y - sn * z
                M[0, 2] = t * x * z + sn * y
                M[1, 0] = t * x * y + sn * z
                M[1, 1] = c + t * y * y
                M[1, 2] = t * y * z - sn * x
                M[2, 0] = t * x * z - sn * y
                M[2, 1] = t * y * z + sn * x
                M[2, 2] = c + t * z * z
            F = B[parent[i]]
            # P = F @ pre[i]; B[i + 1] = P @ M
            for a in range(4):
                for b in range(4):
                    acc = 0.0
                    for m in range(4):
                        acc += F[a, m] * pre[i, m, b]
                    P[a, b] = acc
            for a in range(4):
                for b in range(4):
                    acc = 0.0
                    for m in range(4):
                        acc += P[a, m] * M[m, b]
                    B[i + 1, a, b] = acc
        for l in range(L):
            F = B[cap_body[l]]
            for a in range(3):
                out[s, l, 0, a] = (
                    F[a, 0] * cap_a[l, 0] + F[a, 1] * cap_a[l, 1] + F[a, 2] * cap_a[l, 2] + F[a, 3]
                )
                out[s, l, 1, a] = (
                    F[a, 0] * cap_b[l, 0] + F[a, 1] * cap_b[l, 1] + F[a, 2] * cap_b[l, 2] + F[a, 3]
                )
    return out


def chain_arrays(robot: Any) -> tuple[np.ndarray, ...]:
    """The chain's arrays in the kernel's order, after ``Q`` and before ``out``."""
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b = robot.chain_data()
    return (
        np.ascontiguousarray(robot.T_world_base, dtype=np.float64),
        np.ascontiguousarray(parent, dtype=np.int64),
        np.ascontiguousarray(pre, dtype=np.float64),
        np.ascontiguousarray(axes, dtype=np.float64),
        np.ascontiguousarray(prismatic, dtype=np.bool_),
        np.ascontiguousarray(cap_body, dtype=np.int64),
        np.ascontiguousarray(cap_a, dtype=np.float64),
        np.ascontiguousarray(cap_b, dtype=np.float64),
    )



# ---------------------------------------------------------------------- fused validity
#
# ``chain_valid`` answers "is this state valid" for a URDF chain in one compiled call with
# three array arguments (numba's dispatcher pays per argument: the twenty arguments and the
# tuple of core.chain_first_invalid cost some 4 µs a call before any work is done). Its data
# are packed once by :class:`ChainValidity` into one float and one int array (``_pack``).

# int header: counts, then the start of each section in the int and the float arrays
_H_DOF, _H_NB, _H_L, _H_NOBS, _H_NGRP, _H_NPAIR = range(6)
_H_PARENT, _H_PRISM, _H_BSTART, _H_ORDER, _H_KIND, _H_GROUPS, _H_PAIRS = range(6, 13)
_H_ISSPH, _H_MOVING = 13, 14
_F_T0, _F_PRE, _F_CAP_A, _F_CAP_B, _F_RAD, _F_RADS, _F_BC = range(15, 22)
_F_BR, _F_BRS, _F_R, _F_C, _F_H = range(22, 27)
_HEADER = 27
_SCRATCH = 64  # floats of w (capsule tests)


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


@njit(cache=True, nogil=True)
def _body_frames(q, T0, parent, prism, pre, Bf):
    """Body frames (nb, 3, 4) of one state; each joint turns (or slides) about its frame's
    z axis (the chain's axes are folded into ``pre`` and the capsules by ``_pack``)."""
    for a in range(3):
        for b in range(4):
            Bf[0, a, b] = T0[a, b]
    for i in range(q.shape[0]):
        F = Bf[parent[i]]
        P = pre[i]
        G = Bf[i + 1]
        for a in range(3):
            f0, f1, f2 = F[a, 0], F[a, 1], F[a, 2]
            for b in range(4):
                G[a, b] = f0 * P[0, b] + f1 * P[1, b] + f2 * P[2, b]
            G[a, 3] += F[a, 3]
        if prism[i]:
            for a in range(3):
                G[a, 3] += q[i] * G[a, 2]
        else:
            cq = math.cos(q[i])
            sq = math.sin(q[i])
            for a in range(3):
                g0, g1 = G[a, 0], G[a, 1]
                G[a, 0] = cq * g0 + sq * g1
                G[a, 1] = cq * g1 - sq * g0


@njit(cache=True, nogil=True, inline="always")
def _place(F, p, out, k):
    """out[k] = F · p (a body point in the world)."""
    for a in range(3):
        out[k, a] = F[a, 0] * p[0] + F[a, 1] * p[1] + F[a, 2] * p[2] + F[a, 3]


@njit(cache=True, nogil=True)
def _unpack(fd, idat):
    """Views of the packed arrays (see ``_pack``)."""
    dof, nb, L, n_obs = idat[_H_DOF], idat[_H_NB], idat[_H_L], idat[_H_NOBS]
    ngrp, npair = idat[_H_NGRP], idat[_H_NPAIR]
    o = idat[_H_GROUPS]
    groups = idat[o : o + 4 * ngrp].reshape((ngrp, 4))
    o = idat[_H_PAIRS]
    pairs = idat[o : o + 2 * npair].reshape((npair, 2))
    o = idat[_F_T0]
    T0 = fd[o : o + 12].reshape((3, 4))
    o = idat[_F_PRE]
    pre = fd[o : o + 12 * dof].reshape((dof, 3, 4))
    o = idat[_F_CAP_A]
    cap_a = fd[o : o + 3 * L].reshape((L, 3))
    o = idat[_F_CAP_B]
    cap_b = fd[o : o + 3 * L].reshape((L, 3))
    o = idat[_F_BC]
    bc = fd[o : o + 3 * nb].reshape((nb, 3))
    o = idat[_F_R]
    Rs = fd[o : o + 9 * n_obs].reshape((n_obs, 3, 3))
    o = idat[_F_C]
    cs = fd[o : o + 3 * n_obs].reshape((n_obs, 3))
    o = idat[_F_H]
    hs = fd[o : o + 3 * n_obs].reshape((n_obs, 3))
    return (
        idat[idat[_H_PARENT] : idat[_H_PARENT] + dof],
        idat[idat[_H_PRISM] : idat[_H_PRISM] + dof],
        idat[idat[_H_BSTART] : idat[_H_BSTART] + nb + 1],
        idat[idat[_H_ORDER] : idat[_H_ORDER] + nb],
        idat[idat[_H_KIND] : idat[_H_KIND] + n_obs],
        groups,
        pairs,
        idat[idat[_H_ISSPH] : idat[_H_ISSPH] + L],
        idat[idat[_H_MOVING] : idat[_H_MOVING] + L],
        T0,
        pre,
        cap_a,
        cap_b,
        fd[idat[_F_RAD] : idat[_F_RAD] + L],
        fd[idat[_F_RADS] : idat[_F_RADS] + L],
        bc,
        fd[idat[_F_BR] : idat[_F_BR] + nb],
        fd[idat[_F_BRS] : idat[_F_BRS] + nb],
        Rs,
        cs,
        hs,
    )


@njit(cache=True, nogil=True)
def _place_body(Bf, cap_a, cap_b, issph, bstart, b, X, Y):
    """World end points of body b's capsules into X, Y (a sphere's only into X)."""
    F = Bf[b]
    for l in range(bstart[b], bstart[b + 1]):
        _place(F, cap_a[l], X, l)
        if not issph[l]:
            _place(F, cap_b[l], Y, l)


@njit(cache=True, nogil=True)
def _state_ok(q, V, S):
    """One state is valid: no moving capsule touches an obstacle, no checked pair of
    capsules touches. ``V``: ``_unpack``'s views; ``S``: ``_scratch``'s. Bodies are tested
    through a bounding ball first (in ``order``, against each obstacle; per group of pairs
    between two bodies), their capsules placed only when a ball is not clear; the first
    hit ends the test."""
    (parent, prism, bstart, order, kinds, groups, pairs, issph, moving) = V[:9]
    (T0, pre, cap_a, cap_b, rad, rads, bc, br, brs, Rs, cs, hs) = V[9:]
    Bf, Cw, X, Y, done, w = S
    _body_frames(q, T0, parent, prism, pre, Bf)
    nb = bc.shape[0]
    for b in range(nb):
        _place(Bf[b], bc[b], Cw, b)
        done[b] = 0.0
    n_obs = kinds.shape[0]
    for k in range(nb):
        b = order[k]
        rb = br[b]
        if rb < 0.0:
            continue  # no moving capsule
        x0, x1, x2 = Cw[b, 0], Cw[b, 1], Cw[b, 2]
        for o in range(n_obs):
            kind = kinds[o]
            if _bound_apart(kind, Rs[o], cs[o], hs[o], x0, x1, x2, rb):
                continue
            if done[b] == 0.0:
                _place_body(Bf, cap_a, cap_b, issph, bstart, b, X, Y)
                done[b] = 1.0
            for l in range(bstart[b], bstart[b + 1]):
                if moving[l] == 0:
                    continue
                if issph[l]:
                    hit = _sphere_hit(kind, Rs[o], cs[o], hs[o], X[l, 0], X[l, 1], X[l, 2], rad[l], w)
                else:
                    hit = capsule_obstacle_hit(kind, Rs[o], cs[o], hs[o], X[l], Y[l], rad[l], w)
                if hit:
                    return False
    for g in range(groups.shape[0]):
        bu, bv = groups[g, 0], groups[g, 1]
        if bu != bv:
            dx = Cw[bu, 0] - Cw[bv, 0]
            dy = Cw[bu, 1] - Cw[bv, 1]
            dz = Cw[bu, 2] - Cw[bv, 2]
            rr = brs[bu] + brs[bv]
            if dx * dx + dy * dy + dz * dz > rr * rr:
                continue
        for b in (bu, bv):
            if done[b] == 0.0:
                _place_body(Bf, cap_a, cap_b, issph, bstart, b, X, Y)
                done[b] = 1.0
        for k in range(groups[g, 2], groups[g, 3]):
            i, j = pairs[k, 0], pairs[k, 1]
            if issph[i] and issph[j]:
                dx = X[i, 0] - X[j, 0]
                dy = X[i, 1] - X[j, 1]
                dz = X[i, 2] - X[j, 2]
                d2 = dx * dx + dy * dy + dz * dz
            else:
                d2, _, _ = seg_seg(X[i], X[i] if issph[i] else Y[i], X[j], X[j] if issph[j] else Y[j])
            rr = rads[i] + rads[j]
            if d2 <= rr * rr:
                return False
    return True


@njit(cache=True, nogil=True)
def _scratch(idat):
    """Per-call scratch of :func:`_state_ok`, in one allocation."""
    nb, L = idat[_H_NB], idat[_H_L]
    S = np.empty(16 * nb + 6 * L + _SCRATCH)
    Bf = S[: 12 * nb].reshape((nb, 3, 4))
    o = 12 * nb
    Cw = S[o : o + 3 * nb].reshape((nb, 3))
    o += 3 * nb
    X = S[o : o + 3 * L].reshape((L, 3))
    o += 3 * L
    Y = S[o : o + 3 * L].reshape((L, 3))
    o += 3 * L
    done = S[o : o + nb]
    o += nb
    w = S[o : o + _SCRATCH]
    w[:] = 0.0
    return Bf, Cw, X, Y, done, w


@njit(cache=True, nogil=True)
def chain_valid(Q, fd, idat, out):
    """Validity of a batch Q (k, dof) -> out (k,) bool, kinematics included."""
    V = _unpack(fd, idat)
    S = _scratch(idat)
    for s in range(Q.shape[0]):
        out[s] = _state_ok(Q[s], V, S)
    return out


@njit(cache=True, nogil=True)
def chain_first_bad(Q, fd, idat):
    """Index of the first invalid state of Q (k, dof) in order, or -1."""
    V = _unpack(fd, idat)
    S = _scratch(idat)
    for s in range(Q.shape[0]):
        if not _state_ok(Q[s], V, S):
            return s
    return -1


@njit(cache=True, nogil=True)
def chain_state_valid(q, fd, idat):
    """Validity of one state q (dof,)."""
    return _state_ok(q, _unpack(fd, idat), _scratch(idat))


# ---------------------------------------------------------------------- packing (once)
_BOUND_PAD_M = 1e-9  # grows every bounding ball beyond rounding: a ball clear is clear


def _align(u: np.ndarray) -> np.ndarray:
    """A rotation A (3, 3) with A e_z = u (the identity for u = e_z)."""
    z = np.asarray(u, dtype=float)
    if np.array_equal(z, [0.0, 0.0, 1.0]):
        return np.eye(3)
    e = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = np.cross(e, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _ball(centres: np.ndarray, reach: np.ndarray) -> tuple[np.ndarray, float]:
    """A ball around points each grown by its own reach: (centre, radius), radius -1 for none."""
    if len(centres) == 0:
        return np.zeros(3), -1.0
    c = (centres.min(axis=0) + centres.max(axis=0)) / 2.0
    return c, float(np.max(np.linalg.norm(centres - c, axis=1) + reach)) + _BOUND_PAD_M


def _pack(
    robot: Any,
    radii: np.ndarray,
    radii_self: np.ndarray,
    moving: np.ndarray,
    allowed: np.ndarray,
    kinds: np.ndarray,
    Rs: np.ndarray,
    cs: np.ndarray,
    hs: np.ndarray,
    order: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The chain, its capsules, the checked pairs and the scene in one float and one int
    array for :func:`chain_valid`, and the permutation of the capsules (sorted by body).

    Each joint's axis u is turned onto its frame's z axis: with A e_z = u, a turn about u
    is A Rz(q) Aᵀ, so the body frames are kept as B·A and A is folded into the fixed
    transforms and the capsules' points (the kinematics then turn about z only)."""
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b = robot.chain_data()
    dof = len(parent)
    nb = dof + 1
    A = [np.eye(3)] + [_align(axes[i]) for i in range(dof)]
    pre_f = np.empty((dof, 3, 4))
    for i in range(dof):
        Ap, Ai = np.eye(4), np.eye(4)
        Ap[:3, :3], Ai[:3, :3] = A[int(parent[i])], A[i + 1]
        pre_f[i] = (Ap.T @ np.asarray(pre[i], dtype=float) @ Ai)[:3]
    perm = np.argsort(np.asarray(cap_body), kind="stable")
    body = np.asarray(cap_body)[perm]
    ca = np.array([A[int(b)].T @ p for b, p in zip(body, np.asarray(cap_a)[perm])]).reshape(-1, 3)
    cb = np.array([A[int(b)].T @ p for b, p in zip(body, np.asarray(cap_b)[perm])]).reshape(-1, 3)
    issph = np.all(np.asarray(cap_a)[perm] == np.asarray(cap_b)[perm], axis=1)
    rad, rads, mov = radii[perm], radii_self[perm], moving[perm]
    bstart = np.searchsorted(body, np.arange(nb + 1))
    bc = np.zeros((nb, 3))
    br, brs = np.full(nb, -1.0), np.full(nb, -1.0)
    for b in range(nb):
        sl = slice(bstart[b], bstart[b + 1])
        pts = np.concatenate([ca[sl], cb[sl]])
        both = np.concatenate([rad[sl], rad[sl]])
        m = np.concatenate([mov[sl], mov[sl]])
        bc[b], brs[b] = _ball(pts, np.concatenate([rads[sl], rads[sl]]))
        if m.any():  # the scene's ball: the moving capsules only, about the same centre
            br[b] = float(np.max(np.linalg.norm(pts[m] - bc[b], axis=1) + both[m])) + _BOUND_PAD_M
    # the checked pairs (i < j in the capsules' new order), grouped by their two bodies
    inv = np.argsort(perm)
    sym = np.asarray(allowed, dtype=bool) | np.asarray(allowed, dtype=bool).T
    by_bodies: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for i0, j0 in zip(*np.nonzero(np.triu(sym, 1))):
        i, j = sorted((int(inv[i0]), int(inv[j0])))
        key = (int(body[i]), int(body[j]))
        by_bodies.setdefault((min(key), max(key)), []).append((i, j))
    groups, pairs = [], []
    for (bu, bv), members in sorted(by_bodies.items()):
        groups.append((bu, bv, len(pairs), len(pairs) + len(members)))
        pairs.extend(members)
    body_order = np.arange(nb)[::-1] if order is None else np.asarray(order)
    ints = [
        np.asarray(parent, dtype=np.int64),
        np.asarray(prismatic, dtype=np.int64),
        bstart.astype(np.int64),
        body_order.astype(np.int64),
        np.asarray(kinds, dtype=np.int64),
        np.asarray(groups, dtype=np.int64).reshape(-1),
        np.asarray(pairs, dtype=np.int64).reshape(-1),
        issph.astype(np.int64),
        mov.astype(np.int64),
    ]
    T0 = np.asarray(robot.T_world_base, dtype=float)[:3]
    floats = [T0, pre_f, ca, cb, rad, rads, bc, br, brs, Rs, cs, hs]
    idat = np.zeros(_HEADER, dtype=np.int64)
    idat[:_H_PARENT] = (dof, nb, len(body), len(kinds), len(groups), len(pairs))
    at = _HEADER
    for h, a in zip(range(_H_PARENT, _F_T0), ints):
        idat[h] = at
        at += a.size
    fat = 0
    for h, a in zip(range(_F_T0, _HEADER), floats):
        idat[h] = fat
        fat += np.asarray(a).size
    idat = np.concatenate([idat] + ints)
    fd = np.concatenate([np.asarray(a, dtype=float).reshape(-1) for a in floats])
    return np.ascontiguousarray(fd), np.ascontiguousarray(idat), perm


class ChainValidity:
    """Validity of a URDF chain's states in one compiled call each (:func:`chain_valid`,
    :func:`chain_first_bad`, :func:`chain_state_valid`): the same pairs and tests as the
    core's (``core.py``: moving capsules against every obstacle, the ``allowed`` link
    pairs), with the core's arrays (:class:`~plannerlab.collision.core.Core` ``radii``,
    ``radii_self``, ``moving``, ``allowed``, ``kinds``, ``Rs``, ``cs``, ``hs``).

    ``body_order``: the order in which bodies are tested against the scene (the first hit
    ends a test, so bodies that collide most often go first); default the last body first.
    """

    def __init__(
        self,
        robot: Any,
        radii: np.ndarray,
        radii_self: np.ndarray,
        moving: np.ndarray,
        allowed: np.ndarray,
        kinds: np.ndarray,
        Rs: np.ndarray,
        cs: np.ndarray,
        hs: np.ndarray,
        body_order: np.ndarray | None = None,
    ) -> None:
        self.dof = int(robot.dof)
        self._fd, self._idat, self.perm = _pack(
            robot, radii, radii_self, moving, allowed, kinds, Rs, cs, hs, body_order
        )

    @classmethod
    def of(cls, core: Any, body_order: np.ndarray | None = None) -> ChainValidity:
        """From a built :class:`~plannerlab.collision.core.Core` of a URDF chain."""
        c = core
        return cls(
            c.robot, c.radii, c.radii_self, c.moving, c.allowed, c.kinds, c.Rs, c.cs, c.hs,
            body_order,
        )

    def _Q(self, Q: Any) -> np.ndarray:
        Qc = np.ascontiguousarray(np.atleast_2d(np.asarray(Q, dtype=np.float64)))
        if Qc.ndim != 2 or Qc.shape[1] != self.dof:
            raise ValueError(f"q must have {self.dof} joints, got shape {np.shape(Q)}")
        return Qc

    def valid(self, Q: Any) -> np.ndarray:
        """(k,) bool validity of Q (k, dof)."""
        Qc = self._Q(Q)
        kernel: Any = chain_valid  # a numba dispatcher
        return kernel(Qc, self._fd, self._idat, np.empty(len(Qc), dtype=np.bool_))

    def first_invalid(self, Q: Any) -> int:
        """Index of the first invalid state of Q (k, dof) in order, -1 if all are valid."""
        kernel: Any = chain_first_bad
        return int(kernel(self._Q(Q), self._fd, self._idat))

    def is_valid(self, q: Any) -> bool:
        """Validity of one state q (dof,)."""
        if not (
            type(q) is np.ndarray
            and q.shape == (self.dof,)
            and q.dtype == np.float64
            and q.flags.c_contiguous
        ):
            q = self._Q(q)
            if len(q) != 1:
                raise ValueError(f"q must be one state ({self.dof},), got shape {q.shape}")
            q = q[0]
        kernel: Any = chain_state_valid
        return bool(kernel(q, self._fd, self._idat))


__all__ = [
    "ChainValidity",
    "chain_arrays",
    "chain_first_bad",
    "chain_segments",
    "chain_state_valid",
    "chain_valid",
]

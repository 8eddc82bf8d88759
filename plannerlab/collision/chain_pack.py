"""The packing of a chain, its capsules, the checked pairs and the scene into the three
arrays of :mod:`plannerlab.collision.chain_valid` (``P`` rows of three floats, ``M`` 3 x 4
frames, ``idat`` counts and indices), done once per robot, scene and margin: bounding balls
per body and per cluster of a few capsules, the joints' axes folded onto z, the checked
pairs by cluster and body, world boxes around the obstacles, the joints' coupling."""

from __future__ import annotations

from typing import Any

import numpy as np

from plannerlab.collision.chain import chain_parts
from plannerlab.collision.geometry import BOX, SPHERE

# the int array: a header of counts, then the sections (see _pack), flat
_H_DOF, _H_NB, _H_L, _H_NOBS, _H_NCL, _H_NCPL = range(6)  # _H_DOF: the chain's joints
_I_SECTIONS = (
    *("parent", "prism", "body_cl", "cl_start", "order", "kind", "issph", "moving"),
    *("allowed", "any_cl", "groups", "cpl_start", "cpl_idx", "cgroups"),
)
_H_I = 6
_HEADER = _H_I + len(_I_SECTIONS) + 1  # + 1: the end of the last section
_CLUSTER = 6  # capsules per cluster at most
_CHUNK = 4  # consecutive bodies per chunk (the self-check's first cull)


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


def _clusters(points: np.ndarray, idx: np.ndarray, size: int) -> list[np.ndarray]:
    """idx cut into groups of at most ``size`` neighbours (halved along the widest axis of
    their points, recursively)."""
    if len(idx) <= size:
        return [idx]
    p = points[idx]
    axis = int(np.argmax(p.max(axis=0) - p.min(axis=0)))
    by = idx[np.argsort(p[:, axis], kind="stable")]
    half = len(by) // 2
    return _clusters(points, by[:half], size) + _clusters(points, by[half:], size)


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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The chain, its capsules, the checked pairs and the scene for :func:`chain_valid`:
    points, centres and per-capsule, -body, -cluster radii as rows of three (P), frames
    as 3 x 4 matrices (M), counts and indices (idat); and the capsules' new order (by body,
    then cluster).

    Each joint's axis u is turned onto its frame's z axis: with A e_z = u, a turn about u
    is A Rz(q) Aᵀ, so the body frames are kept as B·A and A is folded into the fixed
    transforms and the capsules' points (the kinematics then turn about z only)."""
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling = chain_parts(robot)
    dof = len(parent)  # the chain's joints
    # the coupling, sparse: per chain joint its entries (state index, coefficient)
    cpl_start: list[int] = []
    cpl_idx: list[int] = []
    cpl_val: list[float] = []
    if coupling is not None:
        cpl_start.append(0)
        for i in range(dof):
            for col in np.flatnonzero(coupling[i]):
                cpl_idx.append(int(col))
                cpl_val.append(float(coupling[i, col]))
            cpl_start.append(len(cpl_idx))
    nb = dof + 1
    A = [np.eye(3)] + [_align(axes[i]) for i in range(dof)]
    pre_f = np.empty((dof, 3, 4))
    for i in range(dof):
        Ap, Ai = np.eye(4), np.eye(4)
        Ap[:3, :3], Ai[:3, :3] = A[int(parent[i])], A[i + 1]
        pre_f[i] = (Ap.T @ np.asarray(pre[i], dtype=float) @ Ai)[:3]
    cap_body = np.asarray(cap_body, dtype=np.int64)
    mid = (np.asarray(cap_a, dtype=float) + np.asarray(cap_b, dtype=float)) / 2.0
    perm_l: list[int] = []
    cl_start, body_cl = [0], [0]
    for b in range(nb):
        for members in _clusters(mid, np.flatnonzero(cap_body == b), _CLUSTER):
            perm_l.extend(int(m) for m in members)
            cl_start.append(len(perm_l))
        body_cl.append(len(cl_start) - 1)
    perm = np.array(perm_l, dtype=np.int64)
    body = cap_body[perm]
    ca = np.array(
        [A[int(b)].T @ p for b, p in zip(body, np.asarray(cap_a)[perm], strict=True)]
    ).reshape(-1, 3)
    cb = np.array(
        [A[int(b)].T @ p for b, p in zip(body, np.asarray(cap_b)[perm], strict=True)]
    ).reshape(-1, 3)
    issph = np.all(np.asarray(cap_a)[perm] == np.asarray(cap_b)[perm], axis=1)
    rad, rads, mov = radii[perm], radii_self[perm], np.asarray(moving, dtype=bool)[perm]

    def balls(ranges: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per range of capsules: centre, radius against the scene (moving capsules only;
        -1: none) and between links."""
        c, r, rs = np.zeros((len(ranges), 3)), np.full(len(ranges), -1.0), np.zeros(len(ranges))
        for k, (l0, l1) in enumerate(ranges):
            pts = np.concatenate([ca[l0:l1], cb[l0:l1]])
            c[k], rs[k] = _ball(pts, np.tile(rads[l0:l1], 2))
            m = np.tile(mov[l0:l1], 2)
            if m.any():
                reach = np.tile(rad[l0:l1], 2)[m]
                r[k] = float(np.max(np.linalg.norm(pts[m] - c[k], axis=1) + reach)) + _BOUND_PAD_M
        return c, r, rs

    ncl = len(cl_start) - 1
    cl_c, cl_r, cl_rs = balls([(cl_start[k], cl_start[k + 1]) for k in range(ncl)])
    bc, br, brs = balls([(cl_start[body_cl[b]], cl_start[body_cl[b + 1]]) for b in range(nb)])
    # the checked pairs in the new order (i < j), and which clusters and bodies hold one
    sym = np.asarray(allowed, dtype=bool) | np.asarray(allowed, dtype=bool).T
    al = np.triu(sym[np.ix_(perm, perm)], 1)
    cl_of = np.repeat(np.arange(ncl), np.diff(cl_start))
    any_cl = np.zeros((ncl, ncl), dtype=np.int64)
    for i, j in zip(*np.nonzero(al), strict=True):
        any_cl[cl_of[i], cl_of[j]] = 1
    cl_body = np.repeat(np.arange(nb), np.diff(body_cl))
    # the body pairs holding a checked pair, by chunk pair (chunks of _CHUNK consecutive
    # bodies: a pair of chunks whose balls are apart skips all its body pairs at once)
    groups = sorted(
        {(int(cl_body[u]), int(cl_body[v])) for u, v in zip(*np.nonzero(any_cl), strict=True)},
        key=lambda g: (g[0] // _CHUNK, g[1] // _CHUNK, g[0], g[1]),
    )
    cgroups: list[int] = []  # rows (chunk u, chunk v, first group, end)
    for gi, (bu, bv) in enumerate(groups):
        cu, cv = bu // _CHUNK, bv // _CHUNK
        if cgroups and cgroups[-4] == cu and cgroups[-3] == cv:
            cgroups[-1] = gi + 1
        else:
            cgroups.extend((cu, cv, gi, gi + 1))
    body_order = np.arange(nb)[::-1] if order is None else np.asarray(order)
    # world boxes around the obstacles (a first, cheaper cull), grown beyond rounding
    Rs, cs, hs = (np.asarray(a, dtype=float) for a in (Rs, cs, hs))
    kinds = np.asarray(kinds)
    sph = (kinds == SPHERE)[:, None]
    ext = np.where(
        (kinds == BOX)[:, None],
        hs,
        np.where(sph, hs[:, :1], np.stack([hs[:, 0], hs[:, 0], hs[:, 1]], 1)),
    )
    half = (np.abs(Rs) @ ext[:, :, None])[..., 0] if len(kinds) else np.zeros((0, 3))
    half = np.where(sph, ext, half) + _BOUND_PAD_M
    ints = [
        np.asarray(parent),
        np.asarray(prismatic),
        np.asarray(body_cl),
        np.asarray(cl_start),
        body_order,
        kinds,
        issph,
        mov,
        al,
        any_cl,
        np.asarray(groups).reshape(-1, 2),
        np.asarray(cpl_start, dtype=np.int64),
        np.asarray(cpl_idx, dtype=np.int64),
        np.asarray(cgroups, dtype=np.int64),
    ]
    head = np.zeros(_HEADER, dtype=np.int64)
    head[:_H_I] = (dof, nb, len(body), len(kinds), ncl, len(cpl_val))
    at = _HEADER
    for k, a in enumerate(ints):
        head[_H_I + k] = at
        at += np.asarray(a).size
    head[_H_I + len(ints)] = at
    idat = np.concatenate([head] + [np.asarray(a, dtype=np.int64).reshape(-1) for a in ints])
    zeros = np.zeros
    cpl_rows = zeros(((len(cpl_val) + 2) // 3, 3))  # the coefficients, three a row
    cpl_rows.reshape(-1)[: len(cpl_val)] = cpl_val
    P = np.concatenate(
        [ca, cb, np.column_stack([rad, rads, zeros(len(rad))]), bc]
        + [np.column_stack([br, brs, zeros(nb)]), cl_c, np.column_stack([cl_r, cl_rs, zeros(ncl)])]
        + [cs.reshape(-1, 3), hs.reshape(-1, 3), (cs - half).reshape(-1, 3)]
        + [(cs + half).reshape(-1, 3)]
        + [cpl_rows]
    )
    R34 = zeros((len(kinds), 3, 4))
    R34[:, :, :3] = Rs.reshape(-1, 3, 3)
    T0 = np.asarray(robot.T_world_base, dtype=float)[None, :3]
    M = np.concatenate([T0, pre_f, R34])
    return np.ascontiguousarray(P), np.ascontiguousarray(M), idat, perm


__all__ = ["_pack"]

"""The compiled kernels of the collision core that hold for any robot: numba (``cache=True``,
compiled once per machine into ``__pycache__``), on capsule axes ``seg`` (L, 2, 3) that
some kinematics made.

* **Broad phase.** Per state, world-aligned boxes of every capsule (:func:`link_boxes`)
  and a bounding-box tree over the chain's consecutive links (:func:`chain_tree`: topology
  built once, boxes refit per state), traversed against each obstacle and against itself
  (:func:`state_hits`); node pairs that are apart or hold no checked pair are pruned.
* **Narrow phase.** Exact capsule tests (:mod:`plannerlab.collision.geometry`).
* **Distances.** Every checked pair below a margin (:func:`pair_distances_kernel`), the
  smallest over a batch (:func:`min_clearance_kernel`), every colliding pair
  (:func:`all_hits`).

:class:`~plannerlab.collision.core.Core` is their Python front (on the segments of the one
kinematics, :mod:`plannerlab.collision.kinematics`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.geometry import capsule_obstacle, capsule_obstacle_hit, seg_seg
from plannerlab.collision.simd import unliteral


class PairGeometry(NamedTuple):
    """What the distance kernels need besides the capsule axes (one argument: numba loads
    kernels taking a named tuple of arrays from its cache)."""

    radii: np.ndarray  # (L,) against the scene, margin included
    radii_self: np.ndarray  # (L,) against each other
    moving: np.ndarray  # (L,) bool
    allowed: np.ndarray  # (L, L) bool: the checked link pairs
    tree: tuple  # :func:`chain_tree` of ``allowed``
    kinds: np.ndarray  # (n,) obstacle kinds
    Rs: np.ndarray  # (n, 3, 3)
    cs: np.ndarray  # (n, 3)
    hs: np.ndarray  # (n, 3)
    olo: np.ndarray  # (n, 3) the obstacles' world boxes
    ohi: np.ndarray
    bodies: tuple  # :func:`body_pairs`: the capsules by rigid body, the body pairs to test
    touch: np.ndarray  # (L, n) bool: declared contacts (capsule, obstacle), never tested


@njit(cache=True, nogil=True)
def link_boxes(seg, radii, lo, hi):
    """World-aligned boxes lo, hi (L, 3) of the capsules seg (L, 2, 3) with radii (L,)."""
    L = seg.shape[0]
    for li in range(L):
        r = radii[li]
        for i in range(3):
            a = seg[li, 0, i]
            b = seg[li, 1, i]
            lo[li, i] = min(a, b) - r
            hi[li, i] = max(a, b) + r


@njit(cache=True, nogil=True)
def _overlap(lo, hi, i, olo, ohi, j, pad):
    """Boxes i of (lo, hi) and j of (olo, ohi), grown by ``pad``, overlap.

    Bitwise ``&`` on purpose: without branches this is ten times faster than ``and``.
    """
    return (
        (lo[i, 0] <= ohi[j, 0] + pad)
        & (hi[i, 0] >= olo[j, 0] - pad)
        & (lo[i, 1] <= ohi[j, 1] + pad)
        & (hi[i, 1] >= olo[j, 1] - pad)
        & (lo[i, 2] <= ohi[j, 2] + pad)
        & (hi[i, 2] >= olo[j, 2] - pad)
    )


def chain_tree(allowed: np.ndarray) -> tuple[np.ndarray, ...]:
    """A balanced binary tree over consecutive link ranges, and allowed-pair counts.

    Returns ``(start, end, left, right, prefix)``: node ``k`` covers links
    ``start[k]:end[k]``, children ``left[k]``, ``right[k]`` (-1 for a leaf), nodes in
    preorder (children after parents, root 0); ``prefix`` (L+1, L+1) the 2-D prefix sums of
    the symmetric allowed-pair matrix, so "does any allowed pair join ranges A and B" is
    four lookups. The topology depends only on the links, so it is built once per robot.
    """
    L = allowed.shape[0]
    start: list[int] = []
    end: list[int] = []
    left: list[int] = []
    right: list[int] = []

    def build(a: int, b: int) -> int:
        k = len(start)
        start.append(a)
        end.append(b)
        left.append(-1)
        right.append(-1)
        if b - a > 1:
            mid = (a + b) // 2
            left[k] = build(a, mid)
            right[k] = build(mid, b)
        return k

    build(0, L)
    sym = allowed | allowed.T
    prefix = np.zeros((L + 1, L + 1), dtype=np.int64)
    prefix[1:, 1:] = np.cumsum(np.cumsum(sym.astype(np.int64), axis=0), axis=1)
    return (
        np.array(start, dtype=np.int64),
        np.array(end, dtype=np.int64),
        np.array(left, dtype=np.int64),
        np.array(right, dtype=np.int64),
        prefix,
    )


@njit(cache=True, nogil=True)
def _any_allowed(prefix, a0, a1, b0, b1):
    return prefix[a1, b1] - prefix[a0, b1] - prefix[a1, b0] + prefix[a0, b0] > 0


@njit(cache=True, nogil=True)
def _node_boxes(tree, lo, hi, nlo, nhi):
    start, end, left, right, prefix = tree
    for k in range(start.shape[0] - 1, -1, -1):
        if left[k] < 0:
            i = start[k]
            for c in range(3):
                nlo[k, c] = lo[i, c]
                nhi[k, c] = hi[i, c]
        else:
            a = left[k]
            b = right[k]
            for c in range(3):
                nlo[k, c] = min(nlo[a, c], nlo[b, c])
                nhi[k, c] = max(nhi[a, c], nhi[b, c])


@njit(cache=True, nogil=True)
def state_hits(seg, geo, buf, first_only, out_pairs):
    """Colliding pairs of one state; returns how many were written to out_pairs (m, 3).

    Row = (link, other, other_is_link). With ``first_only`` stops at the first. ``buf``:
    scratch from :func:`scratch`. Broad phase: a bounding-box tree over the chain's
    consecutive links, traversed against each obstacle and against itself, pruning node
    pairs whose boxes are apart or that hold no checked pair; cost ~ L log L.
    """
    radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, _, touch = geo
    lo, hi, w, nlo, nhi, stack = buf
    start, end, left, right, prefix = tree
    n_obs = kinds.shape[0]
    link_boxes(seg, radii, lo, hi)
    _node_boxes(tree, lo, hi, nlo, nhi)
    m = 0
    for oi in range(n_obs):
        top = 0
        stack[0, 0] = 0
        top = 1
        while top > 0:
            top -= 1
            k = stack[top, 0]
            if not _overlap(nlo, nhi, k, olo, ohi, oi, 0.0):
                continue
            if left[k] >= 0:
                stack[top, 0] = left[k]
                stack[top + 1, 0] = right[k]
                top += 2
                continue
            li = start[k]
            if (
                moving[li]
                and not touch[li, oi]
                and capsule_obstacle_hit(
                    kinds[oi], Rs[oi], cs[oi], hs[oi], seg[li, 0], seg[li, 1], radii[li], w
                )
            ):
                out_pairs[m, 0] = li
                out_pairs[m, 1] = oi
                out_pairs[m, 2] = 0
                m += 1
                if first_only:
                    return m
    # self: node pairs (a, b); a == b means "pairs within a"
    stack[0, 0] = 0
    stack[0, 1] = 0
    top = 1
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        if not _any_allowed(prefix, start[a], end[a], start[b], end[b]):
            continue
        if a == b:
            if left[a] >= 0:
                stack[top, 0] = left[a]
                stack[top, 1] = left[a]
                stack[top + 1, 0] = right[a]
                stack[top + 1, 1] = right[a]
                stack[top + 2, 0] = left[a]
                stack[top + 2, 1] = right[a]
                top += 3
            continue
        if not _overlap(nlo, nhi, a, nlo, nhi, b, 0.0):
            continue
        a_leaf = left[a] < 0
        b_leaf = left[b] < 0
        if a_leaf and b_leaf:
            p = min(start[a], start[b])
            q = max(start[a], start[b])
            d2, _, _ = seg_seg(seg[p, 0], seg[p, 1], seg[q, 0], seg[q, 1])
            rr = radii_self[p] + radii_self[q]
            if d2 <= rr * rr:
                out_pairs[m, 0] = p
                out_pairs[m, 1] = q
                out_pairs[m, 2] = 1
                m += 1
                if first_only:
                    return m
            continue
        if b_leaf or (not a_leaf and end[a] - start[a] >= end[b] - start[b]):
            stack[top, 0] = left[a]
            stack[top, 1] = b
            stack[top + 1, 0] = right[a]
            stack[top + 1, 1] = b
        else:
            stack[top, 0] = a
            stack[top, 1] = left[b]
            stack[top + 1, 0] = a
            stack[top + 1, 1] = right[b]
        top += 2
    return m


@njit(cache=True, nogil=True)
def scratch(L):
    """Per-call scratch of the narrow and broad phase: (lo, hi, w, node lo, node hi, stack)."""
    n = 2 * L
    return (
        np.empty((L, 3)),
        np.empty((L, 3)),
        np.zeros(32),
        np.empty((n, 3)),
        np.empty((n, 3)),
        np.empty((4 * n + 64, 2), dtype=np.int64),
    )


@njit(cache=True, nogil=True)
def box_gap(lo, hi, i, olo, ohi, j):
    """A lower bound of the distance between the shapes in boxes i and j: the boxes' gap."""
    g2 = 0.0
    for c in range(3):
        x = max(olo[j, c] - hi[i, c], lo[i, c] - ohi[j, c], 0.0)
        g2 += x * x
    return math.sqrt(g2)


@njit(cache=True, nogil=True)
def all_hits(seg, geo):
    """Every colliding pair of one state (L, 2, 3): (m, 3) rows (link, other, other_is_link);
    ``geo`` the pairs' geometry (:class:`PairGeometry`)."""
    L = seg.shape[0]
    out = np.empty((L * geo.kinds.shape[0] + L * L, 3), dtype=np.int64)
    m = state_hits(seg, geo, scratch(L), False, out)
    return out[:m].copy()


@njit(cache=True, nogil=True)
def pair_distances_kernel(seg, geo, margin):
    """Every checked pair of one state whose signed distance is below ``margin`` [m]
    (``geo``: :class:`PairGeometry`).

    Returns (idx (m, 3) int: link, other, other_is_link; d (m,); t_link (m,);
    t_other (m,); n (m, 3)).
    """
    radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, _, touch = geo
    L = seg.shape[0]
    n_obs = kinds.shape[0]
    lo = np.empty((L, 3))
    hi = np.empty((L, 3))
    link_boxes(seg, radii, lo, hi)
    cap = L * n_obs + L * L
    idx = np.empty((cap, 3), dtype=np.int64)
    d = np.empty(cap)
    tl = np.empty(cap)
    to = np.empty(cap)
    n = np.empty((cap, 3))
    pad = margin if margin < 1e300 else 1e300
    m = 0
    nv = np.empty(3)
    w = np.zeros(32)
    for li in range(L):
        if not moving[li]:
            continue
        for oi in range(n_obs):
            if touch[li, oi] or not _overlap(lo, hi, li, olo, ohi, oi, pad):
                continue
            dist, t = capsule_obstacle(
                (kinds, Rs, cs, hs), oi, seg[li, 0], seg[li, 1], radii[li], unliteral(True), nv, w
            )
            if dist < margin:
                idx[m, 0] = li
                idx[m, 1] = oi
                idx[m, 2] = 0
                d[m] = dist
                tl[m] = t
                to[m] = 0.0
                n[m, 0], n[m, 1], n[m, 2] = nv[0], nv[1], nv[2]
                m += 1
    for i in range(L):
        for j in range(i + 1, L):
            if not allowed[i, j]:
                continue
            if not _overlap(lo, hi, i, lo, hi, j, pad):
                continue
            d2, s, t = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
            dist_axis = math.sqrt(d2)
            dist = dist_axis - radii_self[i] - radii_self[j]
            if dist < margin:
                idx[m, 0] = i
                idx[m, 1] = j
                idx[m, 2] = 1
                d[m] = dist
                tl[m] = s
                to[m] = t
                for c in range(3):
                    nv[c] = (seg[i, 0, c] + s * (seg[i, 1, c] - seg[i, 0, c])) - (
                        seg[j, 0, c] + t * (seg[j, 1, c] - seg[j, 0, c])
                    )
                if dist_axis > 0.0:
                    for c in range(3):
                        nv[c] /= dist_axis
                else:  # crossing axes: the common normal of the two segments
                    u = seg[i, 1] - seg[i, 0]
                    v = seg[j, 1] - seg[j, 0]
                    nv[0] = u[1] * v[2] - u[2] * v[1]
                    nv[1] = u[2] * v[0] - u[0] * v[2]
                    nv[2] = u[0] * v[1] - u[1] * v[0]
                    nn = math.sqrt(nv[0] ** 2 + nv[1] ** 2 + nv[2] ** 2)
                    if nn > 0.0:
                        for c in range(3):
                            nv[c] /= nn
                    else:
                        nv[0], nv[1], nv[2] = 0.0, 0.0, 1.0
                n[m, 0], n[m, 1], n[m, 2] = nv[0], nv[1], nv[2]
                m += 1
    return idx[:m].copy(), d[:m].copy(), tl[:m].copy(), to[:m].copy(), n[:m].copy()


def body_pairs(cap_body: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, ...]:
    """The capsules by rigid body and the body pairs that hold a checked capsule pair, for
    :func:`min_clearance_kernel`'s gates (built once per robot).

    Args:
        cap_body: (L,) each capsule's body (the robot's capsule order).
        allowed: (L, L) bool, upper triangle: the checked pairs.

    Returns ``(order, start, bpairs, checked)``: ``order[start[b]:start[b + 1]]`` are body
    ``b``'s capsules (ascending), ``bpairs`` (P, 2) the body pairs ``u <= v`` holding a
    checked pair, ``checked`` (L,) bool the capsules in one.
    """
    body = np.asarray(cap_body, dtype=np.int64)
    nb = int(body.max(initial=-1)) + 1
    order = np.argsort(body, kind="stable").astype(np.int64)
    start = np.searchsorted(body[order], np.arange(nb + 1)).astype(np.int64)
    ii, jj = np.nonzero(np.triu(np.asarray(allowed, dtype=bool), 1))
    bu, bv = body[ii], body[jj]
    pairs = np.unique(np.stack([np.minimum(bu, bv), np.maximum(bu, bv)], axis=1), axis=0)
    checked = np.zeros(len(body), dtype=np.bool_)
    checked[ii] = True
    checked[jj] = True
    return order, start, np.ascontiguousarray(pairs.reshape(-1, 2), dtype=np.int64), checked


@njit(cache=True, nogil=True)
def _body_boxes(lo, hi, bodies, mask, blo, bhi):
    """Per body, the box around its capsules' boxes (lo, hi) that ``mask`` selects into
    (blo, bhi); a body with none gets an empty box (lo +inf, hi -inf)."""
    order, start, _, _ = bodies
    for b in range(start.shape[0] - 1):
        for c in range(3):
            blo[b, c] = np.inf
            bhi[b, c] = -np.inf
        for k in range(start[b], start[b + 1]):
            li = order[k]
            if not mask[li]:
                continue
            for c in range(3):
                blo[b, c] = min(blo[b, c], lo[li, c])
                bhi[b, c] = max(bhi[b, c], hi[li, c])


@njit(cache=True, nogil=True)
def _scene_min(seg, geo, boxes, best):
    """:func:`min_clearance_kernel`'s scene part of one state: ``best`` lowered by every
    moving capsule's distance to every obstacle, a body's capsules skipped against an
    obstacle whose box is at least ``best`` from the body's (boxes: capsule lo, hi, body
    lo, hi, the geometry's scratch w and nv)."""
    radii, _, moving, _, _, kinds, Rs, cs, hs, olo, ohi, bodies, touch = geo
    lo, hi, blo, bhi, w, nv = boxes
    order, start, _, _ = bodies
    for b in range(start.shape[0] - 1):
        if blo[b, 0] > bhi[b, 0]:  # no capsule of the body meets the scene
            continue
        for oi in range(kinds.shape[0]):
            g = box_gap(blo, bhi, b, olo, ohi, oi)
            if g > 0.0 and g >= best:
                continue
            for k in range(start[b], start[b + 1]):
                li = order[k]
                if not moving[li] or touch[li, oi]:
                    continue
                g = box_gap(lo, hi, li, olo, ohi, oi)
                if g > 0.0 and g >= best:
                    continue
                dist, _ = capsule_obstacle(
                    (kinds, Rs, cs, hs),
                    oi,
                    seg[li, 0],
                    seg[li, 1],
                    radii[li],
                    unliteral(False),
                    nv,
                    w,
                )
                if dist < best:
                    best = dist
    return best


@njit(cache=True, nogil=True)
def _pair_min(seg, geo, boxes, u, v, best):
    """:func:`min_clearance_kernel`'s link pairs of body pair (u, v) in one state: ``best``
    lowered by every checked capsule pair's distance; a capsule of u whose box is at least
    ``best`` from v's box meets none of v's (boxes: the capsules' and the bodies' boxes with
    the radii between links)."""
    _, radii_self, _, allowed, _, _, _, _, _, _, _, bodies, _ = geo
    lo, hi, blo, bhi = boxes
    order, start, _, _ = bodies
    for x in range(start[u], start[u + 1]):
        i = order[x]
        if u != v:
            g = box_gap(lo, hi, i, blo, bhi, v)
            if g > 0.0 and g >= best:
                continue
        y0 = x + 1 if u == v else start[v]
        for y in range(y0, start[v + 1]):
            j = order[y]
            a = min(i, j)
            c = max(i, j)
            if not allowed[a, c]:
                continue
            g = box_gap(lo, hi, a, lo, hi, c)
            if g > 0.0 and g >= best:
                continue
            d2, _, _ = seg_seg(seg[a, 0], seg[a, 1], seg[c, 0], seg[c, 1])
            dist = math.sqrt(d2) - radii_self[a] - radii_self[c]
            if dist < best:
                best = dist
    return best


@njit(cache=True, nogil=True)
def min_clearance_kernel(segs, geo, include_self):
    """Smallest signed distance [m] over every checked pair of every state (k, L, 2, 3)
    (link pairs only with ``include_self``; inf when none): the minimum of
    :func:`pair_distances_kernel`'s distances over the states, the same distance functions
    on the same pairs, without measuring every pair. A pair whose bounding boxes (the
    capsule's, grown by its radius, and the obstacle's or the other capsule's) are apart
    by a gap ``g > 0`` is at least ``g`` apart, so once ``g`` is no smaller than the
    smallest distance found so far the pair cannot lower it and is not measured (boxes
    that touch bound nothing: a penetration may hide inside). The same gate is taken a
    level up, per rigid body (``geo.bodies``, :func:`body_pairs`): a box around a body's
    capsules against an obstacle's, against another body's (the body pairs nearest first,
    so that the far ones are skipped whole), and a capsule's box against the other body's,
    so a pair of mesh links of 128 capsules each costs a few box gaps when apart, not
    128 x 128. ``geo``: :class:`PairGeometry`."""
    radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, bodies, _ = geo
    L = segs.shape[1]
    order, start, bpairs, checked = bodies
    nb = start.shape[0] - 1
    P = bpairs.shape[0]
    lo = np.empty((L, 3))
    hi = np.empty((L, 3))
    lo2 = np.empty((L, 3))
    hi2 = np.empty((L, 3))
    blo = np.empty((nb, 3))
    bhi = np.empty((nb, 3))
    gaps = np.empty(P)
    nv = np.empty(3)
    w = np.zeros(32)
    best = np.inf
    for s in range(segs.shape[0]):
        seg = segs[s]
        if kinds.shape[0] > 0:
            link_boxes(seg, radii, lo, hi)
            _body_boxes(lo, hi, bodies, moving, blo, bhi)
            best = _scene_min(seg, geo, (lo, hi, blo, bhi, w, nv), best)
        if not include_self or P == 0:
            continue
        link_boxes(seg, radii_self, lo2, hi2)
        _body_boxes(lo2, hi2, bodies, checked, blo, bhi)
        for p in range(P):
            gaps[p] = box_gap(blo, bhi, bpairs[p, 0], blo, bhi, bpairs[p, 1])
        for p in np.argsort(gaps):
            g = gaps[p]
            if g > 0.0 and g >= best:
                break  # the rest are no nearer
            best = _pair_min(seg, geo, (lo2, hi2, blo, bhi), bpairs[p, 0], bpairs[p, 1], best)
    return best

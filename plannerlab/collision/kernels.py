"""The compiled kernels of the collision core that hold for any robot: numba (``cache=True``,
compiled once per machine into ``__pycache__``), on capsule axes ``seg`` (L, 2, 3) that
some kinematics made.

* **Broad phase.** Per state, world-aligned boxes of every capsule (:func:`link_boxes`)
  and a bounding-box tree over the chain's consecutive links (:func:`chain_tree`: topology
  built once, boxes refit per state), traversed against each obstacle and against itself
  (:func:`state_hits`); node pairs that are apart or hold no checked pair are pruned.
* **Narrow phase.** Exact capsule tests (:mod:`plannerlab.collision.geometry`).
* **Batches and edges.** :func:`valid_batch`, :func:`first_invalid`, a URDF chain's states
  with its kinematics fused in (:func:`chain_first_invalid`), an edge's states
  (:func:`edge_states`, bit for bit ``interpolate_edge``'s).
* **Conservative advancement.** One step from a valid state (:func:`advance_dt`) with the
  configuration-free rates of :func:`edge_rates` (see :mod:`plannerlab.collision.core`).
* **Distances.** Every checked pair below a margin (:func:`pair_distances_kernel`), the
  smallest over a batch (:func:`min_clearance_kernel`), every colliding pair
  (:func:`all_hits`).

Arm-Z's kinematics and the checks with them fused in are in
:mod:`plannerlab.collision.armz`; :class:`~plannerlab.collision.core.Core` is the Python
front of both.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plannerlab.collision.chain import chain_segments
from plannerlab.collision.geometry import capsule_obstacle, capsule_obstacle_hit, seg_seg


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
def state_hits(
    seg,
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
    first_only,
    out_pairs,
):
    """Colliding pairs of one state; returns how many were written to out_pairs (m, 3).

    Row = (link, other, other_is_link). With ``first_only`` stops at the first. ``buf``:
    scratch from :func:`scratch`. Broad phase: a bounding-box tree over the chain's
    consecutive links, traversed against each obstacle and against itself, pruning node
    pairs whose boxes are apart or that hold no checked pair; cost ~ L log L.
    """
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
            if moving[li] and capsule_obstacle_hit(
                kinds[oi], Rs[oi], cs[oi], hs[oi], seg[li, 0], seg[li, 1], radii[li], w
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
def valid_batch(segs, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, out):
    """Validity of every state: segs (k, L, 2, 3) → out (k,) bool."""
    k, L = segs.shape[0], segs.shape[1]
    buf = scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(k):
        m = state_hits(
            segs[s],
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
        )
        out[s] = m == 0
    return out


@njit(cache=True, nogil=True)
def first_invalid(segs, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi):
    """Index of the first invalid state of segs (k, L, 2, 3), or -1."""
    k, L = segs.shape[0], segs.shape[1]
    buf = scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(k):
        if state_hits(
            segs[s],
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
            return s
    return -1


@njit(cache=True, nogil=True)
def chain_first_invalid(
    Q,
    T0,
    parent,
    pre,
    axes,
    prismatic,
    cap_body,
    cap_a,
    cap_b,
    coupling,
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
    """:func:`first_invalid` of a URDF chain's states Q (k, dof), kinematics included
    (:func:`~plannerlab.collision.chain.chain_segments`): one compiled call per query."""
    segs = np.empty((Q.shape[0], cap_body.shape[0], 2, 3))
    chain_segments(Q, T0, parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling, segs)
    return first_invalid(
        segs, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi
    )


@njit(cache=True, nogil=True)
def edge_states(q_a, q_b, joint_step, continuous, limit, cap, weights):
    """The states of ``interpolate_edge(q_a, q_b, joint_step)[1:]``, bit for bit, at most
    ``limit`` of them: (n, Q (min(n, limit), dof)), n the edge's full count; an edge of
    more than ``cap`` states gives (cap + 1, no states).

    ``weights`` (dof,) adds a metric bound: at least ``ceil(sum_i weights_i |d_i|)``
    steps (weights = reach_i / step_m: no point moves more than step_m per step); zeros
    leave the count of ``interpolate_edge``."""
    dof = q_a.shape[0]
    d = np.empty(dof)
    span = 0.0
    metric = 0.0
    for i in range(dof):
        x = q_b[i] - q_a[i]
        if continuous[i]:
            x = (x + np.pi) % (2.0 * np.pi) - np.pi
        d[i] = x
        span = max(span, abs(x))
        metric += weights[i] * abs(x)
    n_f = max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12))
    if n_f > cap:  # refused: the caller raises
        return cap + 1, np.empty((0, dof))
    n = int(n_f)
    m = min(n, limit)
    Q = np.empty((m, dof))
    inv = 1.0 / n
    for j in range(1, m + 1):
        t = 1.0 if j == n else j * inv
        for i in range(dof):
            Q[j - 1, i] = q_a[i] + t * d[i]
    return n, Q


@njit(cache=True, nogil=True)
def box_gap(lo, hi, i, olo, ohi, j):
    """A lower bound of the distance between the shapes in boxes i and j: the boxes' gap."""
    g2 = 0.0
    for c in range(3):
        x = max(olo[j, c] - hi[i, c], lo[i, c] - ohi[j, c], 0.0)
        g2 += x * x
    return math.sqrt(g2)


@njit(cache=True, nogil=True)
def advance_dt(
    seg,
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
):
    """Conservative advancement from one valid state: the largest ``dt <= dt_max`` with
    ``v_p · dt <= d_p + margin`` for every checked pair ``p``.

    ``d_p``: the pair's distance with the capsules inflated (by the margin against the
    scene, by half of it each against each other; clamped at 0), ``v_p``: an upper bound
    of how fast the pair's distance changes per unit of the edge parameter (``v_link``
    (L,) for a link against the scene, ``v_pair`` (L, L) for a link pair). Pairs whose
    boxes are so far apart that they cannot limit the step are not measured.
    """
    lo, hi, w, lo2, hi2, _ = buf
    L = seg.shape[0]
    n_obs = kinds.shape[0]
    link_boxes(seg, radii, lo, hi)
    nv = np.empty(3)
    best = dt_max
    for li in range(L):
        v = v_link[li]
        if not moving[li] or v <= 0.0:
            continue
        for oi in range(n_obs):
            if box_gap(lo, hi, li, olo, ohi, oi) + margin >= best * v:
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
            dt = (max(dist, 0.0) + margin) / v
            if dt < best:
                best = dt
    link_boxes(seg, radii_self, lo2[:L], hi2[:L])
    for i in range(L):
        for j in range(i + 1, L):
            v = v_pair[i, j]
            if v <= 0.0 or not allowed[i, j]:
                continue
            if box_gap(lo2, hi2, i, lo2, hi2, j) + margin >= best * v:
                continue
            d2, _, _ = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
            dist = math.sqrt(d2) - radii_self[i] - radii_self[j]
            dt = (max(dist, 0.0) + margin) / v
            if dt < best:
                best = dt
    return best


@njit(cache=True, nogil=True)
def edge_rates(d, W, Pr, v_link, v_pair):
    """Per unit of the edge parameter, bounds of how fast each link (against the scene)
    and each link pair moves along an edge of joint change ``d``: ``|d| @ W``, ``|d| @ Pr``."""
    dof, L = W.shape
    for li in range(L):
        v_link[li] = 0.0
        for j in range(L):
            v_pair[li, j] = 0.0
    for k in range(dof):
        a = abs(d[k])
        if a == 0.0:
            continue
        for li in range(L):
            v_link[li] += a * W[k, li]
            for j in range(li + 1, L):
                v_pair[li, j] += a * Pr[k, li, j]


@njit(cache=True, nogil=True)
def all_hits(seg, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi):
    """Every colliding pair of one state (L, 2, 3): (m, 3) rows (link, other, other_is_link)."""
    L = seg.shape[0]
    out = np.empty((L * kinds.shape[0] + L * L, 3), dtype=np.int64)
    m = state_hits(
        seg,
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
        scratch(L),
        False,
        out,
    )
    return out[:m].copy()


@njit(cache=True, nogil=True)
def pair_distances_kernel(
    seg, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, margin
):
    """Every checked pair of one state whose signed distance is below ``margin`` [m].

    Returns (idx (m, 3) int: link, other, other_is_link; d (m,); t_link (m,);
    t_other (m,); n (m, 3)).
    """
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
            if not _overlap(lo, hi, li, olo, ohi, oi, pad):
                continue
            dist, t = capsule_obstacle(
                kinds[oi], Rs[oi], cs[oi], hs[oi], seg[li, 0], seg[li, 1], radii[li], True, nv, w
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


@njit(cache=True, nogil=True)
def min_clearance_kernel(
    segs, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi, include_self
):
    """Smallest signed distance [m] over every checked pair of every state (k, L, 2, 3)
    (link pairs only with ``include_self``; inf when none): the minimum of
    :func:`pair_distances_kernel`'s distances over the states, the same distance functions
    on the same pairs, without measuring every pair. A pair whose bounding boxes (the
    capsule's, grown by its radius, and the obstacle's or the other capsule's) are apart
    by a gap ``g > 0`` is at least ``g`` apart, so once ``g`` is no smaller than the
    smallest distance found so far the pair cannot lower it and is not measured (boxes
    that touch bound nothing: a penetration may hide inside)."""
    L = segs.shape[1]
    n_obs = kinds.shape[0]
    lo = np.empty((L, 3))
    hi = np.empty((L, 3))
    lo2 = np.empty((L, 3))
    hi2 = np.empty((L, 3))
    nv = np.empty(3)
    w = np.zeros(32)
    best = np.inf
    for s in range(segs.shape[0]):
        seg = segs[s]
        link_boxes(seg, radii, lo, hi)
        for li in range(L):
            if not moving[li]:
                continue
            for oi in range(n_obs):
                g = box_gap(lo, hi, li, olo, ohi, oi)
                if g > 0.0 and g >= best:
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
                if dist < best:
                    best = dist
        if not include_self:
            continue
        link_boxes(seg, radii_self, lo2, hi2)
        for i in range(L):
            for j in range(i + 1, L):
                if not allowed[i, j]:
                    continue
                g = box_gap(lo2, hi2, i, lo2, hi2, j)
                if g > 0.0 and g >= best:
                    continue
                d2, _, _ = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
                dist = math.sqrt(d2) - radii_self[i] - radii_self[j]
                if dist < best:
                    best = dist
    return best

"""The compiled collision and kinematics core: batched, exact, FCL's equal on capsules.

:class:`Core` answers, for one robot in one scene, the questions the planners ask millions
of times: is a batch of states valid, which state of an edge is the first invalid one, and
how far is every pair of shapes (:meth:`Core.pair_distances`, for clearance-aware
optimisation). Everything on the hot path is one numba call over the whole batch (``cache=
True``: compiled once per machine into ``__pycache__``, loaded in later processes):

* **Kinematics.** Arm-Z's chain ``H_i = RotZ(θ_i) · Trans(0, δy, δz) · RotX(ζ)`` is compiled
  (:func:`armz_frames`, :func:`armz_segments`); other robots give their segments through
  their own numpy ``link_segments``.
* **Broad phase.** Per state, world-aligned boxes of every capsule and a bounding-box tree
  over the chain's consecutive links (:func:`chain_tree`: topology built once, boxes
  refit per state), traversed against each obstacle and against itself; node pairs that
  are apart or hold no checked pair are pruned, so the cost grows as ``L log L`` with the
  number of links, not ``L²``.
* **Narrow phase.** Exact capsule tests (:mod:`plannerlab.collision.geometry`).

The pairs checked are the checker's: moving links against every obstacle, and the robot's
link pairs except ``excluded_pairs`` and pairs of two fixed links.

**Edges in metres by conservative advancement** (:meth:`Core.path_advance`; the checker's
``edge_check="advance"``, its default with a margin on the core). With a clearance margin
``m`` an edge must be checked so that nothing slips between two checked states. The grid
(``edge_check="grid"``, :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify`)
cuts each edge into equal steps over which no point moves more than ``m`` (the bound
``Σ |Δq_i| r_i`` of :func:`~plannerlab.collision.reach.joint_reach_m`): about 40 times the
states of radian steps on the 16-m Arm-Z. Conservative advancement measures instead, at
each checked state, the distance ``d_p`` of every checked pair with the capsules inflated
(:func:`advance_dt`), and steps as far as a bound ``v_p`` of how fast that distance can
change allows: ``Δt = min_p (d_p + m) / v_p``, never less than the grid's step and never
more than ``joint_step`` on any joint. The guarantee is the grid's, pair by pair:

* every checked state keeps the margin (the ordinary inflated check, unchanged);
* every state between two checked ones keeps at least ``m / 2`` to the scene and between
  links: a pair at ``t + s`` is at least ``d_p + m − v_p s`` from the left and at least
  ``m − v_p (Δt − s)`` from the right, whose larger is ``≥ m / 2`` when
  ``v_p Δt ≤ d_p + m``. (The grid gives the same ``m / 2`` against the scene, and ``≥ 0``
  between two links, both of which move.)

The rates ``v_p`` (:func:`edge_rates`, from :func:`~plannerlab.collision.reach.
reach_bounds`): per joint and link, how fast the link's points move (the chain sum of
``joint_reach_m`` stopped at that link), and per link pair only the joints that move one
link and not the other (a joint that turns both rigidly leaves their distance alone). On
Arm-Z the bound is taken at the configuration (:func:`armz_advance_dt`): a link's speed
from joint ``f`` is ``|Δq_f|`` times the link's real distance from ``f``'s axis, which is
grown along the step by how far the link can move relative to that axis (a quadratic
term, sound), instead of the length of the chain behind the joint.

Counting: each state visited is one check (its validity, plus its pair distances when
the step needs them), and an edge measured at its start costs one more. A visited state
costs more than a plain check (a distance pass, with box pruning, after it); its cost
ratio has not been measured in isolation: the wall times in the table are the honest
account. A path's states never
outnumber its grid's (each step is at least the grid's), so a planner's re-check reserve
computed from the grid (``_recheck_cost`` in planners/ompl.py) stays an upper bound.

Measured on ``bench/mplib_bench.py --seeds 10`` (12-module Arm-Z, ``ompl.rrtconnect``,
margin 0.01 m; median per solve, this 2-core machine under other jobs, ``nice -n 19``)::

    option                                          checks/solve  wall s  MPlib/pl  solved
    grid, Σ|Δq_i| r_i ≤ m (main at bc741f5)               479 003   0.643     0.40x   10/10
    advance, per-link chain bounds                         44 803   0.302        -    10/10
    advance, + bounds at the configuration (Arm-Z)         14 888   0.181     1.13x   10/10
    ... + joint and link bounds in one pass                14 888   0.157     1.31x   10/10

Then, on main f729c34 (the same checks per solve; ``MPlib/pl`` is now given for wall and
CPU time, both from the bench's own lines; the machine shared by about five jobs, load
4-10, so wall times vary by about ±30 % from run to run)::

    option                                          checks/solve  CPU s   MPlib/pl wall, CPU
    rebased, as above                                     14 888   0.173     1.57x, 1.35x
    + reach bounds vectorised, goal distance from the
      compiled tip, path clearance in one call            14 888   ~0.141         -
    + OMPL states read in one binding call                14 888   0.113     1.95x, 1.89x
    + joint axes with the capsule axes, leaner calls,
      scalar goal distance                                14 888   0.096     2.14x, 2.34x
    the same, merged with main 689e916 (a second run)     14 888   0.096     2.19x, 2.19x

Where a solve's time went before these (cProfile with CPU time, and timers around the
callbacks): edge checks about a third (their compiled part ~2.5 µs per visited state, of
which the distance pass 1.5 µs), reading OMPL states joint by joint ~20 %, the goal
heuristic's NumPy kinematics ~15 %, building the checker's reach bounds ~10 %, the
planned clearance ~5 %; OMPL itself (nearest neighbours on the SO(2) compound metric)
about a fifth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.chain import chain_arrays, chain_segments
from plannerlab.collision.geometry import (
    BOX,
    CYLINDER,
    SPHERE,
    capsule_obstacle,
    capsule_obstacle_hit,
    seg_seg,
)
from plannerlab.collision.reach import pair_rates
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.robots.paths import (
    MAX_EDGE_STATES,
    edge_steps,
    edge_too_long,
    require_joint_step,
)

_NO_LIMIT = 2**62  # "check every state of the edge"

# ---------------------------------------------------------------------- kinematics


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


# ---------------------------------------------------------------------- broad + narrow phase


@njit(cache=True, nogil=True)
def _link_boxes(seg, radii, lo, hi):
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
def _state_hits(
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
    scratch from :func:`_scratch`. Broad phase: a bounding-box tree over the chain's
    consecutive links, traversed against each obstacle and against itself, pruning node
    pairs whose boxes are apart or that hold no checked pair; cost ~ L log L.
    """
    lo, hi, w, nlo, nhi, stack = buf
    start, end, left, right, prefix = tree
    n_obs = kinds.shape[0]
    _link_boxes(seg, radii, lo, hi)
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
def _scratch(L):
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
    buf = _scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(k):
        m = _state_hits(
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
    buf = _scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(k):
        if _state_hits(
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
def armz_first_invalid(
    Q, T0, T1, M, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi
):
    """As :func:`first_invalid` with Arm-Z kinematics fused in: no FK past the first hit."""
    k, dof = Q.shape
    L = dof + 1
    seg = np.empty((1, L, 2, 3))
    buf = _scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(k):
        armz_segments(Q[s : s + 1], T0, T1, M, seg)
        if _state_hits(
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
    (:func:`~plannerlab.collision.chain.chain_segments`): one compiled call per query,
    state by state (no state after the first invalid one is placed)."""
    L = cap_body.shape[0]
    seg = np.empty((1, L, 2, 3))
    buf = _scratch(L)
    pairs = np.empty((1, 3), dtype=np.int64)
    for s in range(Q.shape[0]):
        chain_segments(Q[s : s + 1], T0, parent, pre, axes, prismatic, cap_body, cap_a, cap_b, seg)
        if _state_hits(
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
            return s
    return -1


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
def armz_edge_first_invalid(
    q_a,
    q_b,
    joint_step,
    continuous,
    limit,
    cap,
    weights,
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
    """An Arm-Z edge checked in order, interpolation and kinematics fused in: (n, first bad
    index among the first min(n, limit) states or -1)."""
    n, Q = edge_states(q_a, q_b, joint_step, continuous, limit, cap, weights)
    if n > cap:
        return n, -1
    bad = armz_first_invalid(
        Q, T0, T1, M, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi
    )
    return n, bad


@njit(cache=True, nogil=True)
def _box_gap(lo, hi, i, olo, ohi, j):
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
    _link_boxes(seg, radii, lo, hi)
    nv = np.empty(3)
    best = dt_max
    for li in range(L):
        v = v_link[li]
        if not moving[li] or v <= 0.0:
            continue
        for oi in range(n_obs):
            if _box_gap(lo, hi, li, olo, ohi, oi) + margin >= best * v:
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
    _link_boxes(seg, radii_self, lo2[:L], hi2[:L])
    for i in range(L):
        for j in range(i + 1, L):
            v = v_pair[i, j]
            if v <= 0.0 or not allowed[i, j]:
                continue
            if _box_gap(lo2, hi2, i, lo2, hi2, j) + margin >= best * v:
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
    _link_boxes(seg, radii, lo, hi)
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
            cc = _box_gap(lo, hi, li, olo, ohi, oi) + margin
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
    _link_boxes(seg, radii_self, lo2[:L], hi2[:L])
    for j in range(L):
        u = 0.0
        a = 0.0
        for i in range(j - 1, -1, -1):
            u += abs(d[i]) * rho[i, j]
            a += abs(d[i])
            v = v_pair[i, j]
            if v <= 0.0 or not allowed[i, j]:
                continue
            cc = _box_gap(lo2, hi2, i, lo2, hi2, j) + margin
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
    :meth:`Core.path_advance`): returns (queries, status, edge, t), status 0 all valid,
    1 the state ``P[edge] + t · d_edge`` is invalid, 2 ``limit`` queries were spent first,
    3 edge ``edge``'s grid would have more than ``cap`` states (nothing checked on it).
    """
    m, dof = P.shape
    L = dof + 1
    seg = np.empty((1, L, 2, 3))
    buf = _scratch(L)
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
        if _state_hits(
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
            if _state_hits(
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


@njit(cache=True, nogil=True)
def all_hits(seg, radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi):
    """Every colliding pair of one state (L, 2, 3): (m, 3) rows (link, other, other_is_link)."""
    L = seg.shape[0]
    out = np.empty((L * kinds.shape[0] + L * L, 3), dtype=np.int64)
    m = _state_hits(
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
        _scratch(L),
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
    _link_boxes(seg, radii, lo, hi)
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
        _link_boxes(seg, radii, lo, hi)
        for li in range(L):
            if not moving[li]:
                continue
            for oi in range(n_obs):
                g = _box_gap(lo, hi, li, olo, ohi, oi)
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
        _link_boxes(seg, radii_self, lo2, hi2)
        for i in range(L):
            for j in range(i + 1, L):
                if not allowed[i, j]:
                    continue
                g = _box_gap(lo2, hi2, i, lo2, hi2, j)
                if g > 0.0 and g >= best:
                    continue
                d2, _, _ = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
                dist = math.sqrt(d2) - radii_self[i] - radii_self[j]
                if dist < best:
                    best = dist
    return best


# ---------------------------------------------------------------------- Python front


@dataclass(frozen=True)
class PairDistances:
    """Signed distances of the checked pairs of one state below a margin.

    Attributes:
        link: (m,) link index.
        other: (m,) obstacle index (``other_is_link`` False) or link index (True).
        other_is_link: (m,) bool.
        d_m: (m,) signed distance [m]; negative = penetration depth (exact while the
            capsule axes stay outside the other shape, a lower bound on it otherwise).
        t_link: (m,) parameter in [0, 1] of the closest point on the link's axis
            ``p = a + t (b − a)``.
        t_other: (m,) the same on the other link's axis (0 for obstacles).
        n_world: (m, 3) unit direction that increases the distance when the link's
            closest point moves along it.
    """

    link: np.ndarray
    other: np.ndarray
    other_is_link: np.ndarray
    d_m: np.ndarray
    t_link: np.ndarray
    t_other: np.ndarray
    n_world: np.ndarray


def supports(scene: Scene) -> bool:
    """True when every obstacle of the scene is a shape the core tests exactly."""
    return all(isinstance(o, Box | Cylinder | Sphere) for o in scene.obstacles)


class Core:
    """Compiled validity and distances for one robot in one scene (no check counter:
    :class:`~plannerlab.collision.fcl_checker.CollisionChecker` counts)."""

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        margin_m: float = 0.0,
        edge_weights: Array | None = None,
        link_rates: tuple[Array, Array] | None = None,
    ) -> None:
        if not supports(scene):
            raise ValueError("the core tests boxes, cylinders and spheres only")
        self.robot = robot
        self.scene = scene
        self.margin_m = float(margin_m)
        r = np.asarray(robot.link_radii_m, dtype=float)
        #: capsule radii against the scene: inflated by the whole margin
        self.radii = np.ascontiguousarray(r + self.margin_m)
        #: capsule radii against each other: by half of it (a pair keeps one margin)
        self.radii_self = np.ascontiguousarray(r + self.margin_m / 2.0)
        #: metric edge bound (see :func:`edge_states`); zeros: radian steps only
        self.edge_weights = np.ascontiguousarray(
            np.zeros(robot.dof) if edge_weights is None else edge_weights, dtype=float
        )
        L = len(self.radii)
        self.n_links = L
        self.moving = np.array([i not in robot.fixed_links for i in range(L)])
        allowed = np.zeros((L, L), dtype=bool)
        excluded = set(robot.excluded_pairs)  # a property: computed once here
        fixed = set(robot.fixed_links)
        for i in range(L):
            for j in range(i + 1, L):
                allowed[i, j] = (i, j) not in excluded and not (i in fixed and j in fixed)
        self.allowed = allowed
        n = len(scene.obstacles)
        self.kinds = np.zeros(n, dtype=np.int64)
        self.Rs = np.zeros((n, 3, 3))
        self.cs = np.zeros((n, 3))
        self.hs = np.zeros((n, 3))
        for k, o in enumerate(scene.obstacles):
            T = o.T_world_obstacle
            self.Rs[k] = T[:3, :3]
            self.cs[k] = T[:3, 3]
            if isinstance(o, Box):
                self.kinds[k] = BOX
                self.hs[k] = np.asarray(o.size_m, dtype=float) / 2.0
            elif isinstance(o, Cylinder):
                self.kinds[k] = CYLINDER
                self.hs[k] = (o.radius_m, o.length_m / 2.0, 0.0)
            else:
                self.kinds[k] = SPHERE
                self.hs[k] = (o.radius_m, 0.0, 0.0)
        lo, hi = scene.aabbs()
        self.olo = np.ascontiguousarray(lo, dtype=float).reshape(n, 3)
        self.ohi = np.ascontiguousarray(hi, dtype=float).reshape(n, 3)
        self.tree = chain_tree(allowed)
        #: conservative advancement (:meth:`path_advance`): per joint and link, and per
        #: joint and link pair, bounds of how fast they move (see reach.py); None: off
        self._rates: tuple[np.ndarray, np.ndarray] | None = None
        if link_rates is not None:
            W, rigid = link_rates
            self._rates = (
                np.ascontiguousarray(W, dtype=float),
                np.ascontiguousarray(pair_rates(np.asarray(W), np.asarray(rigid), allowed)),
            )
        self._geo = (
            self.radii,
            self.radii_self,
            self.moving,
            self.allowed,
            self.tree,
            self.kinds,
            self.Rs,
            self.cs,
            self.hs,
            self.olo,
            self.ohi,
        )
        self._continuous = np.ascontiguousarray(robot.continuous, dtype=np.bool_)
        self._armz = getattr(robot, "kind", "") == "armz"
        #: a URDF chain: its capsules from compiled kinematics (collision/chain.py)
        self._chain: Any = None
        if callable(getattr(robot, "chain_data", None)):
            self._chain = chain_arrays(robot)
        if self._armz:
            armz: Any = robot  # an ArmZ: its fixed transforms feed the compiled kinematics
            T0 = np.ascontiguousarray(armz.T_world_base, dtype=np.float64)
            self._T0 = T0
            self._T1 = T0 @ armz._T_base_j1
            self._M = np.ascontiguousarray(armz._M, dtype=np.float64)
        #: armz_path_advance's arguments after (P, first, joint_step, limit)
        self._advance_args: tuple[Any, ...] = ()
        if self._armz and self._rates is not None:
            self._advance_args = (
                self._continuous,
                MAX_EDGE_STATES,
                self.edge_weights,
                *self._rates,
                self.margin_m,
                self._T0,
                self._T1,
                self._M,
                *self._geo,
            )
        self._warm_up()

    def _warm_up(self) -> None:
        """Call every compiled kernel once, so that numba's compilation (first run on an
        empty cache, about 11 s) or loading from its cache (about 0.5 s per process) happens
        here, when the checker is built, and not inside a planner's time limit."""
        kernels: tuple[Any, ...] = (
            (armz_frames, armz_segments, armz_first_invalid, armz_edge_first_invalid)
            + ((armz_path_advance,) if self._rates is not None else ())
            if self._armz
            else (first_invalid, edge_states, chain_segments, chain_first_invalid)
            if self._chain is not None
            else (first_invalid, edge_states)
            + ((advance_dt, edge_rates) if self._rates is not None else ())
        ) + (valid_batch, all_hits, pair_distances_kernel, min_clearance_kernel)
        if all(k.signatures for k in kernels):
            return  # compiled or loaded already in this process
        q = np.clip(np.zeros(self.robot.dof), self.robot.lower, self.robot.upper)
        q2 = np.vstack([q, q])
        self.fk(q)
        self.valid(q2)
        self.is_valid(q)
        self.first_invalid(q2)
        self.edge_first_invalid(q, q, 1.0)
        self.hits(q)
        self.pair_distances(q, 0.0)
        self.min_clearance(q2)
        if self._rates is not None:
            q1 = q.copy()
            q1[0] += 0.5 if q[0] + 0.5 <= self.robot.upper[0] else -0.5
            self.path_advance(np.vstack([q, q1]), 1, 0.05, None)

    # ------------------------------------------------------------------ kinematics
    def _Q(self, Q: Array) -> np.ndarray:
        Q = np.ascontiguousarray(np.atleast_2d(np.asarray(Q, dtype=float)))
        if Q.shape[1] != self.robot.dof:
            raise ValueError(f"q must have {self.robot.dof} joints, got shape {Q.shape}")
        return Q

    def fk(self, Q: Array) -> np.ndarray:
        """Frames (k, F, 4, 4) for Q (k, dof), or (F, 4, 4) for one q (compiled for Arm-Z)."""
        single = np.ndim(Q) == 1
        if not self._armz:
            return self.robot.fk(Q)
        Qc = self._Q(Q)
        out = np.empty((len(Qc), self.robot.dof + 2, 4, 4))
        armz_frames(Qc, self._T0, self._T1, self._M, out)
        return out[0] if single else out

    def tip(self, q: Array) -> tuple[Array, Array]:
        """The robot's ``tip(q)`` (position [m], face normal) for one q (dof,): compiled for
        Arm-Z (its last frame, as ``ArmZ.tip``), else the robot's own."""
        if not self._armz:
            return self.robot.tip(q)
        F = self.fk(q)[-1]
        return F[:3, 3].copy(), F[:3, 2].copy()

    def segments(self, Q: Array) -> np.ndarray:
        """Capsule axes (k, L, 2, 3) for Q (k, dof)."""
        Qc = self._Q(Q)
        if self._armz:
            out = np.empty((len(Qc), self.n_links, 2, 3))
            return armz_segments(Qc, self._T0, self._T1, self._M, out)
        if self._chain is not None:
            out = np.empty((len(Qc), self.n_links, 2, 3))
            kinematics: Any = chain_segments  # a numba dispatcher
            return kinematics(Qc, *self._chain, out)
        return np.ascontiguousarray(self.robot.link_segments(Qc), dtype=float)

    # ------------------------------------------------------------------ queries
    def valid(self, Q: Array) -> np.ndarray:
        """(k,) bool validity of Q (k, dof)."""
        segs = self.segments(Q)
        out = np.empty(len(segs), dtype=bool)
        return valid_batch(segs, *self._geo, out)

    def is_valid(self, q: Array) -> bool:
        """Validity of one state q (dof,): one compiled call for Arm-Z."""
        if (
            type(q) is np.ndarray
            and q.shape == (self.robot.dof,)
            and q.dtype == np.float64
            and q.flags.c_contiguous
        ):
            Qc = q.reshape(1, -1)  # a view: what _Q would make, without its checks
        else:
            Qc = self._Q(q)
        if len(Qc) != 1:
            raise ValueError(f"q must be one state ({self.robot.dof},), got shape {np.shape(q)}")
        if self._armz:
            return armz_first_invalid(Qc, self._T0, self._T1, self._M, *self._geo) < 0
        if self._chain is not None:
            kernel: Any = chain_first_invalid  # a numba dispatcher
            return bool(kernel(Qc, *self._chain, *self._geo) < 0)
        return bool(self.valid(Qc)[0])

    def first_invalid(self, Q: Array) -> int:
        """Index of the first invalid state of Q (k, dof) in order, -1 if all are valid."""
        Qc = self._Q(Q)
        if self._armz:
            return int(armz_first_invalid(Qc, self._T0, self._T1, self._M, *self._geo))
        if self._chain is not None:
            kernel: Any = chain_first_invalid  # a numba dispatcher
            return int(kernel(Qc, *self._chain, *self._geo))
        return int(first_invalid(self.segments(Qc), *self._geo))

    def edge_first_invalid(
        self, q_a: Array, q_b: Array, joint_step: float, limit: int | None = None
    ) -> tuple[int, int]:
        """Check the states of ``interpolate_edge(q_a, q_b, joint_step)[1:]`` in order.

        Only the first ``limit`` states are looked at (all when None). Returns (n, bad):
        n the edge's number of states, bad the index of the first invalid one, -1 if none.

        Raises:
            PlannerlabError: as ``interpolate_edge`` (bad ``joint_step``, or more than
                ``MAX_EDGE_STATES`` states).
        """
        qa = np.ascontiguousarray(q_a, dtype=float)
        qb = np.ascontiguousarray(q_b, dtype=float)
        step = float(joint_step)
        require_joint_step(step)
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        if self._armz:
            n, bad = armz_edge_first_invalid(
                qa,
                qb,
                step,
                self._continuous,
                lim,
                MAX_EDGE_STATES,
                self.edge_weights,
                self._T0,
                self._T1,
                self._M,
                *self._geo,
            )
        else:
            n, Q = edge_states(
                qa, qb, step, self._continuous, lim, MAX_EDGE_STATES, self.edge_weights
            )
            bad = (
                -1
                if n > MAX_EDGE_STATES or len(Q) == 0
                else self.first_invalid(Q)  # a chain's: kinematics state by state
            )
        if n > MAX_EDGE_STATES:
            span = float(np.max(np.abs(joint_difference(qb, qa, self._continuous))))
            raise edge_too_long(span, step, max(n, edge_steps(qa, qb, step, self._continuous)))
        return int(n), int(bad)

    def path_advance(
        self, path: Array, first: int, joint_step: float, limit: int | None
    ) -> tuple[int, int, int, float]:
        """Check a path (m, dof) edge by edge with conservative advancement.

        Along each edge ``q(t) = P[e] + t · d_e`` (the short way round for continuous
        joints), from a valid state at ``t`` the next checked state is at
        ``t + max(1/n, min(dt_ca, joint_step / span))``: ``n`` the edge's uniform count
        (:func:`edge_states`, radian and metric steps), ``dt_ca`` the conservative
        advancement step (:func:`advance_dt`). Each state visited is one query (its
        validity, plus its pair distances when the step needs them). The first state:
        ``first`` 1 checks it (one query), 0 only measures it when a step needs it (one
        query then), 2 measures it without counting (the caller queried it already: a
        path checked in pieces). At most ``limit`` queries (None: no limit).

        Returns (queries, status, edge, t): status 0 every checked state valid, 1 the
        state at ``t`` on edge ``edge`` invalid, 2 the limit was reached first.

        Raises:
            PlannerlabError: as ``interpolate_edge``, an edge whose grid would have more
                than ``MAX_EDGE_STATES`` states (the edges before it are checked).
        """
        if self._rates is None:
            raise ValueError("path_advance needs link rates (a checker with a margin)")
        P = path
        if not (
            type(P) is np.ndarray and P.ndim == 2 and P.dtype == np.float64 and P.flags.c_contiguous
        ):
            P = np.ascontiguousarray(np.atleast_2d(np.asarray(path, dtype=float)))
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        step = float(joint_step)
        require_joint_step(step)
        if self._armz:
            qn, status, e, t = armz_path_advance(P, int(first), step, lim, *self._advance_args)
        else:
            qn, status, e, t = self._path_advance_py(P, int(first), step, lim)
        if status == 3:
            qa, qb = P[e], P[e + 1]
            span = float(np.max(np.abs(joint_difference(qb, qa, self._continuous))))
            raise edge_too_long(
                span, step, max(MAX_EDGE_STATES + 1, edge_steps(qa, qb, step, self._continuous))
            )
        return int(qn), int(status), int(e), float(t)

    def _path_advance_py(
        self, P: np.ndarray, first: int, joint_step: float, limit: int
    ) -> tuple[int, int, int, float]:
        """:meth:`path_advance` for robots whose kinematics are not compiled: the same
        steps, one compiled call per state."""
        W, Pr = self._rates  # type: ignore[misc]
        r, rs, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi = self._geo
        L = self.n_links
        buf = _scratch(L)
        v_link = np.empty(L)
        v_pair = np.empty((L, L))
        queries = 0
        seg: np.ndarray | None = self.segments(P[0]) if first == 2 else None
        if first == 1:
            if limit < 1:
                return queries, 2, 0, 0.0
            seg = self.segments(P[0])
            queries += 1
            if first_invalid(seg, *self._geo) >= 0:
                return queries, 1, 0, 0.0
        for e in range(len(P) - 1):
            d = joint_difference(P[e + 1], P[e], self._continuous)
            span = float(np.max(np.abs(d), initial=0.0))
            metric = float(np.abs(d) @ self.edge_weights)
            n = max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12))
            if n > MAX_EDGE_STATES:
                return queries, 3, e, 0.0
            dt_min = 1.0 / n
            dt_cap = joint_step / span if span > 0.0 else 1.0
            adaptive = dt_cap > dt_min * (1.0 + 1e-12)
            t, dt = 0.0, dt_min
            if adaptive:
                edge_rates(d, W, Pr, v_link, v_pair)
                if seg is None:
                    if queries >= limit:
                        return queries, 2, e, 0.0
                    seg = self.segments(P[e])
                    queries += 1
                dt = advance_dt(
                    seg[0],
                    r,
                    rs,
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
                    self.margin_m,
                    1.0,
                    buf,
                )
            while True:
                tn = t + max(dt_min, min(dt, dt_cap))
                if tn >= 1.0 - 1e-9:
                    tn = 1.0
                if queries >= limit:
                    return queries, 2, e, t
                seg = self.segments(P[e] + tn * d)
                queries += 1
                if first_invalid(seg, *self._geo) >= 0:
                    return queries, 1, e, tn
                if tn == 1.0:
                    break
                if adaptive:
                    dt = advance_dt(
                        seg[0],
                        r,
                        rs,
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
                        self.margin_m,
                        1.0 - tn,
                        buf,
                    )
                t = tn
        return queries, 0, len(P) - 1, 1.0

    def hits(self, q: Array) -> np.ndarray:
        """Every colliding pair at q: (m, 3) rows (link, other, other_is_link)."""
        h = all_hits(self.segments(q)[0], *self._geo)
        # the checker's order: scene pairs by (link, obstacle), then link pairs by (i, j)
        return h[np.lexsort((h[:, 1], h[:, 0], h[:, 2]))]

    def pair_distances(self, q: Array, margin_m: float) -> PairDistances:
        """Every checked pair at q (dof,) whose signed distance is below ``margin_m``."""
        seg = self.segments(q)[0]
        idx, d, tl, to, n = pair_distances_kernel(seg, *self._geo, float(margin_m))
        return PairDistances(
            link=idx[:, 0].copy(),
            other=idx[:, 1].copy(),
            other_is_link=idx[:, 2].astype(bool),
            d_m=d,
            t_link=tl,
            t_other=to,
            n_world=n,
        )

    def min_clearance(self, Q: Array, include_self: bool = True) -> float:
        """:meth:`clearance`'s smallest over the states Q (k, dof), in one compiled call
        (inf when there is no state or no pair)."""
        return float(min_clearance_kernel(self.segments(Q), *self._geo, bool(include_self)))

    def clearance(self, q: Array, include_self: bool = True) -> float:
        """Smallest signed distance [m] over every checked pair (inf when none)."""
        pd = self.pair_distances(q, np.inf)
        d = pd.d_m if include_self else pd.d_m[~pd.other_is_link]
        return float(d.min()) if len(d) else float("inf")

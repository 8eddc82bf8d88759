"""Edges: is the robot free along a straight joint-space motion? Certified, in lanes.

The checker's **grid** (:meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify`)
cuts an edge ``q_a → q_b`` into ``n`` equal steps, at most ``joint_step`` per joint and,
with a margin, so that no point of the robot moves more than the margin between two grid
states (``robots.paths.edge_counts``); the edge is valid when its grid states
``q_a + (j / n) d``, ``j = 1..n``, are. That is the verdict here, bit for bit, reached
with far fewer state tests:

**Certified stretches.** Per joint ``i`` and capsule ``l`` the model holds how fast the
capsule can move, ``link_rates[i, l]`` [m per rad or per m]; along the edge, one grid step
moves capsule ``l`` by at most ``rate_l = Σ_i |d_i| / n · link_rates[i, l]``. A state
``j`` free with every capsule grown by ``g · rate_l`` proves free every grid state within
``g`` steps of it: no capsule of those states comes closer to anything than the grown
capsule of state ``j`` reaches (between links both capsules grow, so the pair keeps its
distance). So a stretch ``[lo, hi]`` of grid states is proved by one test at its middle
grown by its half-length, and a free edge takes a handful of tests however long it is.

**Rakes.** Eight stretches are tested at once, one per lane of the state test
(:func:`~plannerlab.collision.state_test.test_lanes`, each lane with its own growth): the
edge is first cut into eight stretches; a stretch that is not proved is cut into eight
again, until every stretch is proved or a state has hit. Each lane tests a grid state
(its stretch's middle): the test says both whether the state itself collides (then the
edge is invalid at once, as the grid's check would find) and whether the grown state is
free (the stretch is proved). A stretch of one state is tested plain, so the recursion
ends at the grid; the re-check (the grid, state by state) passes every edge this passes.

With a margin ``m`` the grid is fine enough that a point moves at most ``m`` between grid
states, so a path of valid grid states keeps ``m / 2`` of clearance everywhere: no wall,
however thin, is crossed between two checked states. (Without a margin the grid's
resolution is ``joint_step``'s alone, as in the checker.)

Counting: each lane tested is one check (the eight lanes of a call are eight, but lanes
that repeat lane 0 to fill a call are not counted).
"""

from __future__ import annotations

import math

import numpy as np

from plannerlab.collision.simd import kernel, unliteral
from plannerlab.collision.state_test import (
    ANY_HIT,
    W,
    fill_lanes,
    load_state,
    set_rates,
    test_lanes,
)

#: an edge's status: every grid state is free
FREE = 0
#: a grid state is invalid
INVALID = 1
#: the check limit came first: nothing proved
LIMIT = 2


@kernel
def edge_delta(q_a, q_b, continuous, d):
    """d = q_b - q_a, continuous joints the short way round (``joint_difference``)."""
    for i in range(q_a.shape[0]):
        x = q_b[i] - q_a[i]
        if continuous[i]:
            x = (x + np.pi) % (2.0 * np.pi) - np.pi
        d[i] = x


@kernel
def edge_count(d, joint_step, edge_weights):
    """The grid's number of steps of an edge ``d``: at most ``joint_step`` per joint and
    ``ceil(Σ |d_i| · w_i)`` (``robots.paths.edge_counts``)."""
    span = 0.0
    metric = 0.0
    for i in range(d.shape[0]):
        a = abs(d[i])
        span = max(span, a)
        metric += edge_weights[i] * a
    return int(max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12)))


@kernel
def edge_state(q_a, d, j, n, out):
    """Grid state ``j`` (0..n) of the edge: ``q_a + t d``, ``t = j · (1 / n)`` (exactly 1
    at ``j = n``), the floats of ``densify``."""
    t = 1.0 if j == n else j * (1.0 / n)
    for i in range(q_a.shape[0]):
        out[i] = q_a[i] + t * d[i]


@kernel
def step_rates(m, d, n, out):
    """Per capsule (packed order), how far [m] it can move in one grid step of edge d
    with n steps: ``Σ_i |d_i| / n · link_rates[i, l]``."""
    R = m.link_rates
    for l in range(out.shape[0]):
        out[l] = 0.0
    for i in range(d.shape[0]):
        a = abs(d[i]) / n
        if a == 0.0:
            continue
        for l in range(R.shape[1]):
            out[l] += a * R[i, l]


@kernel
def _push_pieces(stack, top, lo, hi, pieces):
    """Push [lo, hi] cut into at most ``pieces`` stretches (nothing when empty)."""
    s = hi - lo + 1
    if s <= 0:
        return top
    k = min(pieces, s)
    for p in range(k):
        stack[top, 0] = lo + (p * s) // k
        stack[top, 1] = lo + ((p + 1) * s) // k - 1
        top += 1
    return top


@kernel
def _load_stretches(m, Z, E, q_ad, stack, top, most):
    """Pop up to ``most`` (at most W) stretches into the lanes (each its middle grid
    state, grown by its half-length): returns (lanes filled, top). ``E`` = (los, mids,
    his) the lanes' stretches; ``q_ad`` = (qa, d, n)."""
    los, mids, his = E
    qa, d, n = q_ad
    q = Z.edge_q
    k = unliteral(0)
    while k < most and top > 0:
        top -= 1
        lo, hi = stack[top, 0], stack[top, 1]
        mid = (lo + hi) // 2
        reach = max(mid - lo, hi - mid)
        edge_state(qa, d, mid, n, q)
        load_state(Z, k, q, m.continuous)
        Z.grow[k] = np.float32(reach)
        Z.grow64[k] = float(reach)
        los[k], mids[k], his[k] = lo, mid, hi
        k += 1
    return k, top


@kernel
def edge_check(m, Z, qa, qb, joint_step, limit):
    """Check edge qa -> qb on the grid (see the module). Z: the state test's scratch
    (:func:`~plannerlab.collision.state_test.lanes`). Returns ``(status, checks, n)``:
    FREE, INVALID or LIMIT, the lanes tested, the grid's number of states."""
    return edge_span(m, Z, (qa, qb), joint_step, unliteral((1, -1)), limit)


@kernel
def edge_span(m, Z, ends, joint_step, span, limit):
    """Check grid states ``span[0]`` … ``span[1]`` (``span[1] < 0``: to ``n``) of the edge
    ``ends`` = (qa, qb), certified as :func:`edge_check` checks the whole grid (the same
    grid: its ``n`` comes from the whole edge, so a span's verdict is the verdict of those
    grid states, bit for bit). Returns ``(status, checks, n)`` as :func:`edge_check`."""
    qa, qb = ends
    d, rate, stack, marks = Z.edge_d, Z.edge_rate, Z.edge_stack, Z.edge_marks
    los, mids, his = marks[0], marks[1], marks[2]
    edge_delta(qa, qb, m.continuous, d)
    n = edge_count(d, joint_step, m.edge_weights)
    step_rates(m, d, n, rate)
    set_rates(m, Z, rate)
    first, last = max(span[0], 1), (n if span[1] < 0 else min(span[1], n))
    # the first stretches: [first, last] cut into at most W pieces
    top = _push_pieces(stack, unliteral(0), first, last, unliteral(W))
    checks = 0
    while top > 0:
        if checks >= limit:
            return LIMIT, checks, n
        # the last call of a budget tests only the lanes it has left: a budget is used
        # to its last check
        most = min(W, limit - checks)
        k, top = _load_stretches(m, Z, (los, mids, his), (qa, d, n), stack, top, most)
        fill_lanes(Z, k)
        free, hit, _ = test_lanes(m, Z, unliteral(ANY_HIT))
        checks += k
        if hit & ((1 << k) - 1):
            return INVALID, checks, n  # a grid state collides
        for j in range(k):
            if (free >> j) & 1:
                continue
            # not proved at its growth (its own state is free: not hit): the stretch's
            # two sides of it, in at most W pieces
            lo, mid, hi = los[j], mids[j], his[j]
            if top + W > stack.shape[0]:
                return LIMIT, checks, n
            top = _push_pieces(stack, top, lo, mid - 1, W // 2)
            top = _push_pieces(stack, top, mid + 1, hi, W // 2)
    return FREE, checks, n


@kernel
def edge_rake(m, Z, qa, qb, joint_step, stride, limit):
    """The edge's coarse check: its grid cut into stretches of ``stride`` states, each
    stretch's middle state tested (eight a call) grown by the stretch's half-length.
    Returns ``(status, checks, n, proved)``: INVALID when a tested state collides, LIMIT
    when ``limit`` came first, else FREE, and then ``proved`` when every stretch was
    proved free (the whole grid: :func:`edge_check` would say FREE), else only the tested
    states are known free (the rest is the lazy planners' to check later)."""
    d = Z.edge_d
    los, mids, his = Z.edge_marks[0], Z.edge_marks[1], Z.edge_marks[2]
    stack = Z.edge_stack
    edge_delta(qa, qb, m.continuous, d)
    n = edge_count(d, joint_step, m.edge_weights)
    step_rates(m, d, n, Z.edge_rate)
    set_rates(m, Z, Z.edge_rate)
    pieces = (n + stride - 1) // stride
    checks = 0
    proved = True
    done = 0
    while done < pieces:
        # up to W stretches, the far end's first (an extension's new node): pushed
        # nearest first, popped from the top
        if checks >= limit:
            return LIMIT, checks, n, False
        b = min(W, pieces - done, limit - checks)
        top = unliteral(0)
        for r in range(b):
            p = pieces - done - b + r
            stack[top, 0] = 1 + (p * n) // pieces
            stack[top, 1] = ((p + 1) * n) // pieces
            top += 1
        done += b
        k, _ = _load_stretches(m, Z, (los, mids, his), (qa, d, n), stack, top, b)
        fill_lanes(Z, k)
        free, hit, _ = test_lanes(m, Z, unliteral(ANY_HIT))
        checks += k
        if hit & ((1 << k) - 1):
            return INVALID, checks, n, False
        if (free & ((1 << k) - 1)) != (1 << k) - 1:
            proved = False
    return FREE, checks, n, proved


__all__ = [
    "FREE",
    "INVALID",
    "LIMIT",
    "edge_check",
    "edge_count",
    "edge_delta",
    "edge_rake",
    "edge_span",
    "edge_state",
    "step_rates",
]

"""What the projection planner (:mod:`~plannerlab.planners.native.kpiece`) asks of the
collision core, in one place: "is this state valid", "is this edge valid, and how many
checks did that take", "how far along this edge is it valid". Its kernels call nothing
else of :mod:`plannerlab.collision`, so moving them onto another state test or edge
check is a change of this file alone.

:func:`bundle` gives the one argument a search's entry takes from Python (the checker's
packed model, :attr:`~plannerlab.collision.fcl_checker.CollisionChecker.packed_model`);
the entry opens it once with :func:`open_bundle` and hands the opened bundle (the model,
the state test's scratch and the one-state road's tables) to the queries below. A state
is tested alone by the one-state road (:func:`~plannerlab.collision.one_state.one_valid`:
one state's capsules eight to a float32 vector, float64 confirmation: the float64
verdict); an edge is the re-check's grid (``n`` states ``q_a + (j / n) d``,
``j = 1 … n``, ``d`` the joint difference the short way round) proved free by certified
stretches (:func:`~plannerlab.collision.edges.edge_check`), so a path whose edges were all
found valid here passes the re-check on the same grid.
"""

from __future__ import annotations

from typing import Any

from numba import njit

from plannerlab.collision.edges import (
    INVALID,
    edge_check,
    edge_count,
    edge_delta,
    edge_span,
    edge_state,
)
from plannerlab.collision.edges import (
    LIMIT as EDGE_LIMIT,
)
from plannerlab.collision.one_lanes import checker_tables, open_one
from plannerlab.collision.one_state import one_valid
from plannerlab.collision.queries import open_packed
from plannerlab.collision.simd import unliteral

#: edge statuses: every state asked is valid / one is invalid / the check limit came first
FREE, BLOCKED, LIMIT = 0, 1, 2


def bundle(checker: Any) -> tuple[Any, ...]:
    """The collision bundle a search's entry takes: the checker's packed model and its
    one-state tables (:func:`~plannerlab.collision.one_lanes.checker_tables`)."""
    return (tuple(checker.packed_model), checker_tables(checker))


def opened(checker: Any) -> tuple[Any, Any, Any]:
    """The opened bundle, (model, scratch, one-state tables), for calling the queries
    below from Python (tests and benches; a search opens :func:`bundle`'s inside its
    entry)."""
    return open_bundle(bundle(checker))


@njit(cache=True, nogil=True, inline="always")
def open_bundle(B):
    """The bundle the queries take, (model, scratch, one-state tables), from
    :func:`bundle`'s."""
    m, Z = open_packed(B[0])
    return m, Z, open_one(B[1])


@njit(cache=True, nogil=True)
def state_valid(ck, q):
    """Is state q (dof,) free? (The one-state road: the float64 verdict.)"""
    return one_valid(ck[0], ck[1], ck[2], q)


@njit(cache=True, nogil=True)
def grid_count(ck, q_a, q_b, joint_step, d):
    """The grid's number of states of edge q_a -> q_b; leaves its joint difference in d."""
    edge_delta(q_a, q_b, ck[0].continuous, d)
    return edge_count(d, joint_step, ck[0].edge_weights)


@njit(cache=True, nogil=True)
def grid_state(q_a, d, j, n, out):
    """State j (1 … n) of the grid of the edge from q_a with difference d into out."""
    edge_state(q_a, d, j, n, out)


@njit(cache=True, nogil=True)
def edge_valid(ck, q_a, q_b, joint_step, limit, d, q):
    """Are all grid states of edge q_a -> q_b free (certified stretches, at most
    ``limit`` state tests; d, q (dof,) scratch, unused)? Returns (status: :data:`FREE`,
    :data:`BLOCKED` or :data:`LIMIT`, checks)."""
    status, checks, _ = edge_check(ck[0], ck[1], q_a, q_b, joint_step, limit)
    return status, checks


@njit(cache=True, nogil=True)
def _block(ck, ends, dq, span, grid, limit):
    """Grid states ``min(i · stride, n)`` for i = lo + 1 … hi (``span`` = (lo, hi)) of the
    edge ``ends`` = (q_a, q_b) (``dq`` = (d, q): its difference d; ``grid`` = (n, stride,
    joint_step): its n states, the stride, the grid's joint step; q the scratch state).
    First the far end alone (a blocked block is most often blocked there: one test);
    then, every state (``stride`` 1), the rest in certified stretches
    (:func:`~plannerlab.collision.edges.edge_span`: the grid's verdict on those states, in
    a few tests where space is free); else each ``stride``-th state alone, coarse to fine:
    the midpoints of ever finer halvings. Returns (status, checks)."""
    d, q = dq
    q_a = ends[0]
    n, stride, joint_step = grid
    lo, hi = span
    L = hi - lo
    if limit < 1:
        return LIMIT, 0
    if stride == 1:
        status, k, _ = edge_span(ck[0], ck[1], ends, joint_step, (lo + 1, hi), limit)
        if status == INVALID:
            return BLOCKED, k
        if status == EDGE_LIMIT:
            return LIMIT, k
        return FREE, k
    edge_state(q_a, d, min(hi * stride, n), n, q)
    if not state_valid(ck, q):
        return BLOCKED, 1
    checks = 1
    step = 1
    while step < L:
        step *= 2
    h = step // 2
    while h >= 1:
        k = h
        while k < L:
            if checks >= limit:
                return LIMIT, checks
            edge_state(q_a, d, (lo + k) * stride, n, q)
            checks += 1
            if not state_valid(ck, q):
                return BLOCKED, checks
            k += 2 * h
        h //= 2
    return FREE, checks


@njit(cache=True, nogil=True)
def edge_reach(ck, q_a, q_b, joint_step, min_fraction, stride, limit, dq):
    """How far from q_a along edge q_a -> q_b its grid states are free, looking at every
    ``stride``-th state only (and the last), in blocks that double: the states up to the
    first beyond ``min_fraction`` of the edge, then as many again, twice as many, …, each
    block checked coarse to fine (its far end first), until a block holds a blocked state
    or the edge ends. The reach is the end of the last free block: never beyond a blocked
    state looked at, found with few checks in a blocked block.

    Returns (status, j, n, checks): :data:`FREE` (every state looked at is free, j = n),
    :data:`BLOCKED` (those up to state j are free, j / n > ``min_fraction``, and one of
    the next block is blocked; j = -1: one of the first block is), or :data:`LIMIT`
    (``limit`` checks were made first); n the grid's number of states; ``dq`` = (d, q) the
    scratch: d then holds the edge's joint difference."""
    d = dq[0]
    edge_delta(q_a, q_b, ck[0].continuous, d)
    n = edge_count(d, joint_step, ck[0].edge_weights)
    nc = (n + stride - 1) // stride  # the states looked at: min(i · stride, n), i = 1 … nc
    m = min(int(min_fraction * n) // stride + 1, nc)  # the first beyond the fraction
    status, checks = _block(ck, (q_a, q_b), dq, unliteral((0, m)), (n, stride, joint_step), limit)
    if status == LIMIT:
        return LIMIT, 0, n, checks
    if status == BLOCKED:
        return BLOCKED, -1, n, checks
    lo = m
    while lo < nc:
        hi = min(2 * lo, nc)
        status, k = _block(ck, (q_a, q_b), dq, (lo, hi), (n, stride, joint_step), limit - checks)
        checks += k
        if status == LIMIT:
            return LIMIT, 0, n, checks
        if status == BLOCKED:
            return BLOCKED, lo * stride, n, checks
        lo = hi
    return FREE, n, n, checks


__all__ = [
    "BLOCKED",
    "FREE",
    "LIMIT",
    "bundle",
    "open_bundle",
    "opened",
    "edge_reach",
    "edge_valid",
    "grid_count",
    "grid_state",
    "state_valid",
]

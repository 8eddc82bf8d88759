"""A path checked on the checker's grid inside the compiled robot–scene model: the states
of :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify` made in compiled
code (:func:`~plannerlab.collision.model.edge_state`'s floats) and tested in order,
:data:`~plannerlab.collision.lanes.W` at a time in the model's vector lanes
(:mod:`plannerlab.collision.lanes`: the one-state test's verdicts), without building the
dense path in numpy.

This is the re-check of ``check_path(path, joint_step, mode="grid")`` when the checker's
core has a model: the very states, in the very order, that the compiled planners check
their edges on (:func:`~plannerlab.collision.model.edge_count`,
:func:`~plannerlab.collision.model.edge_state`), so a path they return passes it by
construction, at the model's speed per state.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from plannerlab.collision.lanes import LANES_MIN, W, lanes_check
from plannerlab.collision.model import edge_count, edge_delta, state_ok, views

#: :func:`grid_check`'s return codes: every state is valid / the cursor's state is
#: invalid / ``limit`` states were checked and at least one is left
GRID_VALID, GRID_INVALID, GRID_LIMIT = 0, 1, 2


@njit(cache=True, nogil=True, inline="always")
def _lane_state(path, e, j, d, n, QL, k):
    """Lane k of QL (dof, W) = grid state j of edge e (``d``: its change, ``n``: its
    states; j = 0 is ``path[0]``), ``model.edge_state``'s floats."""
    if j == 0:
        for i in range(path.shape[1]):
            QL[i, k] = path[0, i]
        return
    t = 1.0 if j == n else j * (1.0 / n)
    for i in range(path.shape[1]):
        QL[i, k] = path[e, i] + t * d[i]


@njit(cache=True, nogil=True, inline="always")
def _flush(QL, cnt, V, SL, alive, S, q):
    """Test lanes 0..cnt-1 of QL: the first invalid lane, or -1. A group of fewer than
    ``LANES_MIN`` states is tested state by state (as ``lanes.group_flush``)."""
    if cnt < LANES_MIN:
        for k in range(cnt):
            for i in range(q.shape[0]):
                q[i] = QL[i, k]
            if not state_ok(q, V, S):
                return k
        return -1
    for k in range(alive.shape[0]):
        alive[k] = k < cnt
    lanes_check(QL, V, SL, alive, False)
    for k in range(cnt):
        if not alive[k]:
            return k
    return -1


@njit(cache=True, nogil=True)
def grid_check(path, joint_step, m, cur, limit, d, q):
    """Check the grid states of ``path`` (k, dof) in order from the cursor ``cur`` (3,)
    int64 (edge e, state j of that edge: 0 is ``path[0]``, which only edge 0 has, 1..n
    the edge's grid states; states checked so far), at most ``limit`` of them, ``lanes.W``
    at a time in vector lanes (the verdicts of the one-state test). The model's views are
    made here: passed in, their fifty-odd arrays would cost numba's dispatcher about
    0.1 ms a call to type.

    The order is ``densify``'s: ``path[0]``, then per edge e its states j = 1..n (``n``:
    :func:`edge_count` of the edge, ``q = path[e] + t d``, ``t = j / n``, exactly 1 at
    j = n). The states up to the first invalid one count (as the checker's
    ``first_invalid`` counts them). ``d``, ``q`` (dof,) scratch; on :data:`GRID_INVALID`
    ``q`` holds the invalid state and the cursor points at it.

    Returns :data:`GRID_VALID`, :data:`GRID_INVALID` or :data:`GRID_LIMIT` (the cursor at
    the next state to check)."""
    k_rows = path.shape[0]
    V, S = views(m)
    SL = V[3]
    QL = SL[11]
    alive = SL[8][0]
    lane_e = np.empty(W, dtype=np.int64)
    lane_j = np.empty(W, dtype=np.int64)
    e = cur[0]
    j = cur[1]
    n = 0
    if j > 0 and e < k_rows - 1:
        edge_delta(path[e], path[e + 1], m.continuous, d)
        n = edge_count(d, joint_step, m.edge_weights)
    done = 0
    cnt = 0
    while True:
        first = e == 0 and j == 0  # path[0]
        if not first:
            while e < k_rows - 1 and j > n:  # past this edge: the next one
                e += 1
                j = 1
                if e < k_rows - 1:
                    edge_delta(path[e], path[e + 1], m.continuous, d)
                    n = edge_count(d, joint_step, m.edge_weights)
        end = not first and e >= k_rows - 1
        if cnt > 0 and (end or cnt == W or done + cnt >= limit):
            bad = _flush(QL, cnt, V, SL, alive, S, q)
            if bad >= 0:
                cur[0] = lane_e[bad]
                cur[1] = lane_j[bad]
                cur[2] += bad + 1
                for i in range(q.shape[0]):
                    q[i] = QL[i, bad]
                return GRID_INVALID
            cur[2] += cnt
            done += cnt
            cnt = 0
        if end or done >= limit:
            cur[0] = e
            cur[1] = j
            return GRID_VALID if end else GRID_LIMIT
        _lane_state(path, e, j, d, n, QL, cnt)
        lane_e[cnt] = e
        lane_j[cnt] = j
        cnt += 1
        if first:
            j = 1
            if k_rows > 1:
                edge_delta(path[0], path[1], m.continuous, d)
                n = edge_count(d, joint_step, m.edge_weights)
        else:
            j += 1


__all__ = ["GRID_INVALID", "GRID_LIMIT", "GRID_VALID", "grid_check"]

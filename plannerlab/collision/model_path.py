"""A path checked on the checker's grid inside the compiled robot–scene model: the states
of :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify` made one at a time
in compiled code (:func:`~plannerlab.collision.model.edge_state`, the same floats) and
tested in order by the model's state test, without building the dense path in numpy.

This is the re-check of ``check_path(path, joint_step, mode="grid")`` when the checker's
core has a model: the very states, in the very order, that the compiled planners check
their edges on (:func:`~plannerlab.collision.model.edge_count`,
:func:`~plannerlab.collision.model.edge_state`), so a path they return passes it by
construction, at the model's speed per state.
"""

from __future__ import annotations

from numba import njit

from plannerlab.collision.model import edge_count, edge_delta, edge_state, state_ok

#: :func:`grid_check`'s return codes: every state is valid / the cursor's state is
#: invalid / ``limit`` states were checked and at least one is left
GRID_VALID, GRID_INVALID, GRID_LIMIT = 0, 1, 2


@njit(cache=True, nogil=True)
def grid_check(path, joint_step, m, V, S, cur, limit, d, q):
    """Check the grid states of ``path`` (k, dof) in order from the cursor ``cur`` (3,)
    int64 (edge e, state j of that edge: 0 is ``path[0]``, which only edge 0 has, 1..n
    the edge's grid states; states checked so far), at most ``limit`` of them.

    The order is ``densify``'s: ``path[0]``, then per edge e its states j = 1..n (``n``:
    :func:`edge_count` of the edge, ``q = path[e] + t d``, ``t = j / n``, exactly 1 at
    j = n). ``d``, ``q`` (dof,) scratch; on :data:`GRID_INVALID` ``q`` holds the invalid
    state (unless it is ``path[0]``: j = 0) and the cursor points at it.

    Returns :data:`GRID_VALID`, :data:`GRID_INVALID` or :data:`GRID_LIMIT` (the cursor at
    the next state to check)."""
    k = path.shape[0]
    e = cur[0]
    j = cur[1]
    done = 0
    if e == 0 and j == 0:
        if done >= limit:
            return GRID_LIMIT
        cur[2] += 1
        done += 1
        if not state_ok(path[0], V, S):
            return GRID_INVALID
        j = 1
    while e < k - 1:
        edge_delta(path[e], path[e + 1], m.continuous, d)
        n = edge_count(d, joint_step, m.edge_weights)
        while j <= n:
            if done >= limit:
                cur[0] = e
                cur[1] = j
                return GRID_LIMIT
            edge_state(path[e], d, j, n, q)
            cur[2] += 1
            done += 1
            if not state_ok(q, V, S):
                cur[0] = e
                cur[1] = j
                return GRID_INVALID
            j += 1
        e += 1
        j = 1
    cur[0] = e
    cur[1] = j
    return GRID_VALID


__all__ = ["GRID_INVALID", "GRID_LIMIT", "GRID_VALID", "grid_check"]

"""The checker's compiled queries, called from Python on the packed model.

Each takes ``P``: :func:`~plannerlab.collision.packing.pack` ``(model, lanes)`` as a tuple
of its five arrays, rebuilt into the named model and the state test's scratch inside
(views: ~1 µs), so a call from Python unboxes five arrays, not seventy. They are few:
every compiled entry compiles the state test again into itself (numba links its callees
into it and optimizes them with it). Compiled
consumers call :mod:`plannerlab.collision.state_test` and :mod:`plannerlab.collision.edges`
with the named tuples directly.

* :func:`states`: a batch's verdicts, eight states a call, or its first invalid state;
* :func:`edge`: an edge on the grid, certified in rakes (the verdict of the grid, few
  tests), or the grid's first invalid state, in order;
* :func:`segments`: capsule axes of a batch in float64 (the one kinematics);
  :func:`tip`: the robot's tip (position, normal) from the same frames.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from plannerlab.collision._unpacked import unpack_lanes, unpack_model
from plannerlab.collision.edges import edge_check, edge_count, edge_delta, edge_state
from plannerlab.collision.exact import frames64
from plannerlab.collision.kinematics import place
from plannerlab.collision.simd import kernel, unliteral
from plannerlab.collision.state_test import (
    ANY_HIT,
    EVERY_LANE,
    W,
    fill_lanes,
    load_state,
    set_plain,
    test_lanes,
)


@njit(cache=True, nogil=True, inline="always")
def open_packed(P):
    """The model and the state test's scratch from the packed tuple a checker gives
    (``checker.packed_model``), unpacked inline in the calling kernel: the first line of
    any compiled planner, whose queries are then :func:`~plannerlab.collision.edges.
    edge_check`, :func:`~plannerlab.collision.state_test.valid_one` and their kin."""
    f64, f32, i64, b1, head = P
    return unpack_model(f64, f32, i64, b1, head), unpack_lanes(f64, f32, i64, b1, head)


_open = open_packed


def kernel_states(a: np.ndarray) -> np.ndarray:
    """``a`` as the compiled queries take states: float64, C-contiguous and *writeable*.
    numba compiles a kernel once per argument type, and a read-only array (a frozen
    record's path: :class:`~plannerlab.record.leg.LegResult`) is another type: the state
    test would be compiled again, inside whatever clock is running (seen: a first leg on a
    fresh cache 10 s over its time limit). A copy costs far less."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    return a if a.flags.writeable else a.copy()


#: :func:`states`' modes: every state's verdict; the first invalid state's index
EACH, FIRST = 0, 1
#: :func:`edge`'s modes: certified stretches; the grid's first invalid state in order
CERTIFIED, IN_ORDER = 0, 1


@kernel
def states(P, Q, out, mode):
    """Validity of Q (k, dof), eight states a call (one compiled entry for every state
    query: each entry compiles the state test again into itself). ``EACH``: every verdict
    into out (k,) bool, returns how many the float64 confirmation decided; ``FIRST``:
    returns the index of the first invalid state in order, -1 if none (out not written
    past it)."""
    m, Z = _open(P)
    set_plain(Z)
    confirmed = 0
    for s0 in range(0, Q.shape[0], W):
        nn = min(W, Q.shape[0] - s0)
        for j in range(nn):
            load_state(Z, j, Q[s0 + j], m.continuous)
        fill_lanes(Z, nn)
        free, _, c = test_lanes(m, Z, ANY_HIT if nn == 1 else EVERY_LANE)
        confirmed += c
        for j in range(nn):
            ok = (free >> j) & 1
            out[s0 + j] = ok
            if mode == FIRST and not ok:
                return s0 + j
    return -1 if mode == FIRST else confirmed


@kernel
def edge(P, qa, qb, joint_step, limits):
    """Edge qa -> qb on the grid, ``limits`` = (limit, mode). ``CERTIFIED``: (status,
    tests, n) of :func:`~plannerlab.collision.edges.edge_check` (the grid's verdict from
    certified stretches); ``IN_ORDER``: (n, the index of the first invalid grid state among
    the first ``limit`` in order, -1 if none, 0)."""
    limit, mode = limits
    m, Z = _open(P)
    if mode == CERTIFIED:
        return edge_check(m, Z, qa, qb, joint_step, limit)
    set_plain(Z)
    d, q = Z.edge_d, Z.edge_q
    edge_delta(qa, qb, m.continuous, d)
    n = edge_count(d, joint_step, m.edge_weights)
    k = min(n, limit)
    for s0 in range(0, k, W):
        nn = min(W, k - s0)
        for j in range(nn):
            edge_state(qa, d, s0 + j + 1, n, q)
            load_state(Z, j, q, m.continuous)
        fill_lanes(Z, nn)
        free, _, _ = test_lanes(m, Z, unliteral(EVERY_LANE))
        for j in range(nn):
            if not (free >> j) & 1:
                return n, s0 + j, 0
    return n, -1, 0


@kernel
def segments(P, Q, out):
    """Capsule axes of a batch in the robot's capsule order, float64 (the one kinematics):
    Q (k, dof) -> out (k, L, 2, 3)."""
    m, Z = _open(P)
    for s in range(Q.shape[0]):
        frames64(m, Z, Q[s])
        for k in range(m.cap_body.shape[0]):
            b = m.cap_body[k]
            l = m.perm[k]
            x, y, z = place(Z.e_F, b, m.cap_a, k, 0)
            out[s, l, 0, 0], out[s, l, 0, 1], out[s, l, 0, 2] = x, y, z
            x, y, z = place(Z.e_F, b, m.cap_b, k, 0)
            out[s, l, 1, 0], out[s, l, 1, 1], out[s, l, 1, 2] = x, y, z
    return out


@kernel
def tip(P, q, body, tip_p, out):
    """The tip of one state q (dof,): ``tip_p`` (2, 3) the tip point and its normal in
    body ``body``'s frame (axes folded: see the model) -> out (2, 3): position [m], unit
    normal, in the world."""
    m, Z = _open(P)
    frames64(m, Z, q)
    x, y, z = place(Z.e_F, body, tip_p, unliteral(0), 0)
    out[0, 0], out[0, 1], out[0, 2] = x, y, z
    F = Z.e_F
    o = 12 * body
    for a in range(3):
        out[1, a] = (F[o + 4 * a] * tip_p[1, 0] + F[o + 4 * a + 1] * tip_p[1, 1]
                     + F[o + 4 * a + 2] * tip_p[1, 2])  # fmt: skip
    return out


__all__ = [
    "CERTIFIED",
    "EACH",
    "FIRST",
    "IN_ORDER",
    "edge",
    "open_packed",
    "segments",
    "states",
    "tip",
]

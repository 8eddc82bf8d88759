"""The k-d tree of a compiled planner's tree: exact nearest nodes without scanning every
row. Rows are put in as they are added (:func:`kd_insert`: row 0 the root, the split
joint cycling over the bounded joints); :func:`kd_nearest` finds the very row the
brute-force scan (:func:`~plannerlab.planners.native.kernels.nearest`) finds, with the
same sums, so a search gives the same path either way (``tests/planners/test_native.py``
compares them on random trees with many ties). A robot whose joints are all
continuous has no split joint (:func:`split_dims` is empty): its planners scan.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_TWO_PI = 2.0 * math.pi
#: a cell is skipped only when its squared distance exceeds the best sum by this factor
CELL_MARGIN = 1.0 + 1e-9


@njit(cache=True, nogil=True)
def split_dims(continuous):
    """The joints a k-d tree splits on, in turn: the bounded ones (a continuous joint's
    wrapped difference gives no bound from one side of a plane). Empty: no k-d tree."""
    k = 0
    for i in range(continuous.shape[0]):
        if not continuous[i]:
            k += 1
    sd = np.empty(k, dtype=np.int64)
    k = 0
    for i in range(continuous.shape[0]):
        if not continuous[i]:
            sd[k] = i
            k += 1
    return sd


@njit(cache=True, nogil=True)
def kd_insert(Q, Kd, r, sd):
    """Insert row r of Q into the k-d tree ``Kd`` (cap, 3) int64 over Q's rows (per row:
    left child, right child, its split's position in ``sd``; -1: not in the tree). Row 0
    is the root; a row goes left of a node when its coordinate on the node's split joint
    is smaller than the node's, else right."""
    Kd[r, 0] = -1
    Kd[r, 1] = -1
    if r == 0:
        Kd[0, 2] = 0
        return
    node = 0
    while True:
        k = sd[Kd[node, 2]]
        side = 0 if Q[r, k] < Q[node, k] else 1
        nxt = Kd[node, side]
        if nxt < 0:
            Kd[node, side] = r
            Kd[r, 2] = (Kd[node, 2] + 1) % sd.shape[0]
            return
        node = nxt


@njit(cache=True, nogil=True)
def kd_catch_up(Q, n, Kd, sd):
    """Insert the rows of Q[:n] not yet in the k-d tree (in index order: row 0 first)."""
    if sd.shape[0] == 0:
        return
    for r in range(n):
        if Kd[r, 2] < 0:
            kd_insert(Q, Kd, r, sd)


#: a row's flag when it is dead (left out of the search)
DEAD = 2


@njit(cache=True, nogil=True)
def kd_nearest(T, q, continuous, sd, KS):
    """:func:`~plannerlab.planners.native.kernels.nearest` over the rows of tree T
    (``T.Q`` its states, ``T.F`` flags, ``T.Kd`` its k-d tree: :func:`kd_insert`): the same
    row, the lowest index among the live rows (``F[r] != DEAD``) at the least squared
    distance, each row's sum made as ``nearest`` makes it (the same terms in the same
    order, ties to the lower index).

    A subtree is skipped when its cell is farther than the best row: the cell's squared
    distance is the sum of q's squared gaps to it on the split joints (the incremental
    distance of Arya and Mount; ``offs`` keeps each pending cell's gaps). The test keeps a
    relative margin of ``CELL_MARGIN`` over the best sum, far beyond the rounding of
    these sums (a few ulps), so a cell holding a row that ties or beats the best in
    floating point is never skipped. ``KS = (stack, bounds, offs)`` scratch (at least the
    tree's depth + 2 rows; offs dof columns). -1 when every row is dead."""
    Q, F, Kd = T.Q, T.F, T.Kd
    stack, bounds, offs = KS
    best = np.inf
    best_i = -1
    dof = q.shape[0]
    stack[0] = 0
    bounds[0] = 0.0
    for i in range(dof):
        offs[0, i] = 0.0
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        b = bounds[top]
        if b > best * CELL_MARGIN:
            continue
        if F[node] != DEAD:
            acc = 0.0
            for i in range(dof):
                x = q[i] - Q[node, i]
                if continuous[i]:
                    if x >= math.pi:
                        x -= _TWO_PI
                    elif x < -math.pi:
                        x += _TWO_PI
                acc += x * x
                if acc > best:
                    break
            if acc < best or (acc == best and node < best_i):
                best = acc
                best_i = node
        k = sd[Kd[node, 2]]
        diff = q[k] - Q[node, k]
        if diff < 0.0:
            near, far = Kd[node, 0], Kd[node, 1]
        else:
            near, far = Kd[node, 1], Kd[node, 0]
        # the popped cell's gaps are in offs[top]; the far cell differs on joint k only
        gap = abs(diff)
        fb = 0.0
        if far >= 0:
            for i in range(dof):
                o = gap if i == k else offs[top, i]
                fb += o * o
        if far >= 0 and fb <= best * CELL_MARGIN:
            # far at `top` (visited after near), near above it with the popped gaps
            for i in range(dof):
                offs[top + 1, i] = offs[top, i]
            offs[top, k] = gap
            stack[top] = far
            bounds[top] = fb
            top += 1
        if near >= 0:  # offs[top] holds the popped cell's gaps
            stack[top] = near
            bounds[top] = b
            top += 1
    return best_i


__all__ = ["DEAD", "kd_catch_up", "kd_insert", "kd_nearest", "split_dims"]

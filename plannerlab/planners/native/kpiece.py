"""KPIECE compiled end to end (``native.kpiece``): the kernels (numba).

KPIECE (Şucan and Kavraki 2009; OMPL's ``KPIECE1``) grows one tree from the start and
steers its growth with a grid over a low-dimensional projection of the states: every tree
state falls in a cell; a cell with all its ``2k`` axis neighbours in the grid is
*interior*, else *exterior* (the frontier). Each iteration picks the cell of highest
importance (``score / ((neighbours + 1) · motions · selections)``) among the exterior
cells with probability ``max(border_fraction, exterior share)``, else among the interior
ones; in it a motion, the recent ones preferred (a half-normal draw); a target near that
motion's state (uniform within ``range_rad`` per joint) or, with probability
``goal_bias``, a goal state; and moves towards it as far as the motion stays free. The
motion is kept when more than ``min_valid_fraction`` of it is free; when none of it is, the
cell's score is multiplied by ``failed_score_factor``. A new cell's score is ``(1 + ln
iteration) / (1 + goal distance)``; when the best cell's score falls to zero every score
is raised by ``1 + ln`` of its cell's creation iteration.

The kernels ask everything of the collision core through
:mod:`~plannerlab.planners.native.shim` (a state, an edge, how far along an edge).

A kept motion whose end is not its target (the last free state of the grid of the edge
towards the target) is a new edge with a grid of its own: it is checked on that grid only
when a path through it is found (:func:`_certify`); a blocked one kills its subtree and
the search goes on, so a returned path passes the re-check by construction.

Data: :class:`Motions` (the tree), :class:`Cells` (the grid: cells, their two max-heaps
by importance, a hash table from coordinates to cells), :class:`Projection`; the
counters' and parameters' slots are named below. Limits and return codes are the other
native kernels' (:mod:`~plannerlab.planners.native.kernels`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from plannerlab.planners.native import shim
from plannerlab.planners.native.kernels import (
    CHECKED,
    CHUNK,
    COARSE,
    DEAD,
    DONE,
    FULL,
    HARD,
    ITERATIONS,
    gauss,
    randint,
    uniform,
    wrap,
)

# counters (int64): what carries a search across calls
C_ITER = 0  # iterations
C_CHECKS = 1  # collision checks
C_MOTIONS = 2  # tree states
C_CELLS = 3  # grid cells
C_EXT = 4  # exterior heap's size (C_EXT + 1: interior's)
C_FOUND = 6  # the goal motion of a certified path (-1: none)
C_FAILED = 7  # paths a certification refused
C_DISC_ITER = 8  # the grid's iteration count (OMPL's: from 1)
C_SOFT = 9  # limits of this call: soft checks, hard checks, iterations (totals)
C_HARD = 10
C_MAX_ITER = 11
C_GOAL_TRIES = 12  # goal-biased targets tried
N_COUNTERS = 13

# parameters (float64)
P_GOAL_BIAS = 0
P_BORDER = 1
P_FAILED_FACTOR = 2
P_MIN_FRACTION = 3
P_RANGE = 4
P_STEP = 5  # the grid's joint step (the re-check's)
P_GOAL_TOL = 6  # a state within this of a goal state in every joint reaches it [rad]
P_OCTAVES = 7  # the target's radius: range_rad · 2^-u, u uniform in [0, octaves)
P_STRIDE = 8  # motions look at every stride-th grid state; the rest when on a path
N_PARAMS = 9

EXTERIOR, INTERIOR = 0, 1
_EMPTY = -1
_H1 = np.uint64(0x9E3779B97F4A7C15)
_H2 = np.uint64(0xBF58476D1CE4E5B9)
_S31 = np.uint64(31)


class Motions(NamedTuple):
    """The tree: states (cap, dof), parents (-1: a root), flags (``CHECKED``: the edge
    from the parent is checked on its own grid; ``COARSE``: as part of a longer edge;
    ``DEAD``), each state's cell, and the previous state in that cell (-1)."""

    Q: np.ndarray
    parent: np.ndarray
    flag: np.ndarray
    cell: np.ndarray
    prev: np.ndarray


class Cells(NamedTuple):
    """The grid: per cell its coordinates (ccap, k), newest motion, motions, selections,
    score, creation iteration, neighbours in the grid, importance; the exterior and
    interior max-heaps by importance (2, ccap) with each cell's heap and position; the
    hash table (a power of two) from coordinates to cells."""

    coord: np.ndarray
    head: np.ndarray
    n_motions: np.ndarray
    selections: np.ndarray
    score: np.ndarray
    born: np.ndarray
    neighbors: np.ndarray
    importance: np.ndarray
    heap: np.ndarray
    hwhich: np.ndarray
    hpos: np.ndarray
    table: np.ndarray


class Projection(NamedTuple):
    """A linear projection: rows (k, dof); coordinates ``floor(matrix q / cell_size)``."""

    matrix: np.ndarray
    cell_size: np.ndarray


def new_motions(cap: int, dof: int) -> Motions:
    return Motions(
        Q=np.zeros((cap, dof)),
        parent=np.full(cap, -1, dtype=np.int64),
        flag=np.full(cap, CHECKED, dtype=np.int8),
        cell=np.full(cap, -1, dtype=np.int64),
        prev=np.full(cap, -1, dtype=np.int64),
    )


def new_cells(cap: int, k: int) -> Cells:
    size = 1
    while size < 2 * cap:
        size *= 2
    return Cells(
        coord=np.zeros((cap, k), dtype=np.int64),
        head=np.full(cap, -1, dtype=np.int64),
        n_motions=np.zeros(cap, dtype=np.int64),
        selections=np.ones(cap),
        score=np.ones(cap),
        born=np.ones(cap, dtype=np.int64),
        neighbors=np.zeros(cap, dtype=np.int64),
        importance=np.zeros(cap),
        heap=np.full((2, cap), -1, dtype=np.int64),
        hwhich=np.zeros(cap, dtype=np.int64),
        hpos=np.zeros(cap, dtype=np.int64),
        table=np.full(size, _EMPTY, dtype=np.int64),
    )


# ---------------------------------------------------------------------- the hash table
@njit(cache=True, nogil=True)
def _hash(x, mask):
    h = np.uint64(0)
    for i in range(x.shape[0]):
        h = (h ^ np.uint64(x[i] & 0xFFFFFFFF)) * _H1
        h ^= h >> _S31
        h *= _H2
    return np.int64(h & np.uint64(mask))


@njit(cache=True, nogil=True)
def _slot(C, x):
    """The table slot of coordinates x: the cell's, or the empty one where it goes."""
    mask = C.table.shape[0] - 1
    s = _hash(x, mask)
    k = x.shape[0]
    while True:
        c = C.table[s]
        if c == _EMPTY:
            return s
        same = True
        for i in range(k):
            if C.coord[c, i] != x[i]:
                same = False
                break
        if same:
            return s
        s = (s + 1) & mask


@njit(cache=True, nogil=True)
def rehash(C, n_cells):
    """Fill C's (empty) table with its first n_cells cells (after the arrays grew)."""
    for c in range(n_cells):
        C.table[_slot(C, C.coord[c])] = c


# ---------------------------------------------------------------------- the heaps
@njit(cache=True, nogil=True)
def _importance(C, c):
    return C.score[c] / ((C.neighbors[c] + 1.0) * C.n_motions[c] * C.selections[c])


@njit(cache=True, nogil=True)
def _swap(C, w, i, j):
    a, b = C.heap[w, i], C.heap[w, j]
    C.heap[w, i], C.heap[w, j] = b, a
    C.hpos[b], C.hpos[a] = i, j


@njit(cache=True, nogil=True)
def _down(C, n, w, i):
    """Sift position i of heap w (n cells) down."""
    while True:
        a, b, m = 2 * i + 1, 2 * i + 2, i
        if a < n and C.importance[C.heap[w, a]] > C.importance[C.heap[w, m]]:
            m = a
        if b < n and C.importance[C.heap[w, b]] > C.importance[C.heap[w, m]]:
            m = b
        if m == i:
            return
        _swap(C, w, i, m)
        i = m


@njit(cache=True, nogil=True)
def _sift(C, n, w, i):
    """Restore heap w (n cells) around position i (its cell's importance changed)."""
    while i > 0:
        p = (i - 1) // 2
        if C.importance[C.heap[w, i]] <= C.importance[C.heap[w, p]]:
            break
        _swap(C, w, i, p)
        i = p
    _down(C, n, w, i)


@njit(cache=True, nogil=True)
def _push(C, counters, w, c):
    n = counters[C_EXT + w]
    C.heap[w, n] = c
    C.hwhich[c] = w
    C.hpos[c] = n
    counters[C_EXT + w] = n + 1
    _sift(C, n + 1, w, n)


@njit(cache=True, nogil=True)
def _remove(C, counters, c):
    w = C.hwhich[c]
    n = counters[C_EXT + w] - 1
    i = C.hpos[c]
    if i != n:
        _swap(C, w, i, n)
        counters[C_EXT + w] = n
        _sift(C, n, w, i)
    else:
        counters[C_EXT + w] = n


@njit(cache=True, nogil=True)
def _update(C, counters, c):
    """Cell c's importance again, and its place in its heap."""
    C.importance[c] = _importance(C, c)
    w = C.hwhich[c]
    _sift(C, counters[C_EXT + w], w, C.hpos[c])


@njit(cache=True, nogil=True)
def _rescore(C, counters):
    """Every score raised by 1 + ln(its cell's creation iteration); heaps rebuilt."""
    n = counters[C_CELLS]
    for c in range(n):
        C.score[c] += 1.0 + math.log(C.born[c])
        C.importance[c] = _importance(C, c)
    for w in range(2):
        m = counters[C_EXT + w]
        for i in range(m // 2 - 1, -1, -1):
            _down(C, m, w, i)


# ---------------------------------------------------------------------- cells
@njit(cache=True, nogil=True)
def project(proj, q, x):
    """Coordinates x (k,) int64 of state q's cell."""
    for r in range(x.shape[0]):
        acc = 0.0
        for i in range(q.shape[0]):
            acc += proj.matrix[r, i] * q[i]
        x[r] = int(math.floor(acc / proj.cell_size[r]))


@njit(cache=True, nogil=True)
def _new_cell(C, counters, x, score):
    """A cell at coordinates x (not in the grid yet): its neighbours counted both ways
    (a neighbour that gets its last one turns interior), put in its heap."""
    c = counters[C_CELLS]
    counters[C_CELLS] = c + 1
    k = x.shape[0]
    C.coord[c] = x
    C.table[_slot(C, x)] = c
    C.head[c] = -1
    C.n_motions[c] = 1
    C.selections[c] = 1.0
    C.score[c] = score
    C.born[c] = counters[C_DISC_ITER]
    C.neighbors[c] = 0
    for i in range(k):
        for s in (-1, 1):
            x[i] += s
            b = C.table[_slot(C, x)]
            x[i] -= s
            if b == _EMPTY:
                continue
            C.neighbors[c] += 1
            C.neighbors[b] += 1
            if C.neighbors[b] >= 2 * k and C.hwhich[b] == EXTERIOR:
                _remove(C, counters, b)
                C.importance[b] = _importance(C, b)
                _push(C, counters, INTERIOR, b)
            else:
                _update(C, counters, b)
    C.importance[c] = _importance(C, c)
    _push(C, counters, INTERIOR if C.neighbors[c] >= 2 * k else EXTERIOR, c)
    return c


@njit(cache=True, nogil=True)
def goal_distance(q, goals, continuous):
    """Joint distance from q to the nearest goal state; and whether q is within ``tol``
    of it in every joint is :func:`_reaches`'s."""
    best = np.inf
    for g in range(goals.shape[0]):
        acc = 0.0
        for i in range(q.shape[0]):
            x = goals[g, i] - q[i]
            if continuous[i]:
                x = wrap(x)
            acc += x * x
        best = min(best, acc)
    return math.sqrt(best)


@njit(cache=True, nogil=True)
def _reaches(q, goals, continuous, tol):
    for g in range(goals.shape[0]):
        ok = True
        for i in range(q.shape[0]):
            x = goals[g, i] - q[i]
            if continuous[i]:
                x = wrap(x)
            if abs(x) > tol:
                ok = False
                break
        if ok:
            return True
    return False


@njit(cache=True, nogil=True)
def add_motion(T, C, proj, counters, q, edge, x):
    """Motion q (from ``parent``, edge ``flag``) into the tree and its cell (a new cell
    scored by ``dist``, its goal distance); ``edge`` = (parent, flag, dist); returns its
    index."""
    parent, flag, dist = edge
    r = counters[C_MOTIONS]
    counters[C_MOTIONS] = r + 1
    T.Q[r] = q
    T.parent[r] = parent
    T.flag[r] = flag
    project(proj, q, x)
    c = C.table[_slot(C, x)]
    if c == _EMPTY:
        score = (1.0 + math.log(counters[C_DISC_ITER])) / (1.0 + dist)
        c = _new_cell(C, counters, x, score)
    else:
        C.n_motions[c] += 1
        _update(C, counters, c)
    T.cell[r] = c
    T.prev[r] = C.head[c]
    C.head[c] = r
    return r


# ---------------------------------------------------------------------- the search
@njit(cache=True, nogil=True)
def _half_normal(rng, n):
    """OMPL's ``halfNormalInt(0, n - 1)``: an index in [0, n), the last ones likeliest."""
    mean = float(n)
    v = mean + (mean / 3.0) * gauss(rng)
    if v > mean:
        v = 2.0 * mean - v
    r = int(math.floor(max(v, 0.0)))
    return min(r, n - 1)


@njit(cache=True, nogil=True)
def _select(C, counters, rng, border):
    """The cell to expand (see the module docstring)."""
    n_ext, n_int = counters[C_EXT], counters[C_EXT + 1]
    frac = n_ext / (n_ext + n_int)
    w = EXTERIOR if (n_int == 0 or (n_ext > 0 and uniform(rng) < max(border, frac))) else INTERIOR
    c = C.heap[w, 0]
    if C.score[c] < 2.220446049250313e-16:
        _rescore(C, counters)
    return c


@njit(cache=True, nogil=True)
def _target(T, m, goals, prm, bounds, rng, out):
    """Where to move from motion m: a goal state (probability ``goal_bias``) or a state
    uniform within ``range_rad`` of m's per joint (wrapped, or clipped to the bounds:
    ``bounds`` = (lower, upper, continuous))."""
    lower, upper, continuous = bounds
    if goals.shape[0] > 0 and uniform(rng) < prm[P_GOAL_BIAS]:
        out[:] = goals[randint(rng, goals.shape[0])]
        return True
    r = prm[P_RANGE]
    if prm[P_OCTAVES] > 0.0:
        r *= 2.0 ** (-prm[P_OCTAVES] * uniform(rng))
    for i in range(out.shape[0]):
        x = T.Q[m, i] + r * (2.0 * uniform(rng) - 1.0)
        out[i] = wrap(x) if continuous[i] else min(max(x, lower[i]), upper[i])
    return False


@njit(cache=True, nogil=True)
def _kill(T, c, n):
    """Motion c and its subtree are dead (parents come before their children)."""
    T.flag[c] = DEAD
    for i in range(c + 1, n):
        if T.parent[i] >= 0 and T.flag[T.parent[i]] == DEAD:
            T.flag[i] = DEAD


@njit(cache=True, nogil=True)
def _certify(ck, T, counters, c, step, d, q):
    """Check the edges on the path to motion c not yet checked on their own grid.
    Returns 0 the path is checked, 1 an edge is blocked (its subtree killed), 2 the
    hard limit came first."""
    while T.parent[c] >= 0:
        if T.flag[c] == COARSE:
            p = T.parent[c]
            left = counters[C_HARD] - counters[C_CHECKS]
            status, k = shim.edge_valid(ck, T.Q[p], T.Q[c], step, left, d, q)
            counters[C_CHECKS] += k
            if status == shim.LIMIT:
                return 2
            if status == shim.BLOCKED:
                _kill(T, c, counters[C_MOTIONS])
                return 1
            T.flag[c] = CHECKED
        c = T.parent[c]
    return 0


@njit(cache=True, nogil=True)
def kpiece_run(ck, T, C, proj, goals, prm, counters, rng):
    """KPIECE iterations until a certified path to a goal state, a limit, or a full
    tree (``ck``: the shim's collision bundle; ``goals`` (g, dof); ``prm`` the parameters,
    ``counters`` the counters and this call's limits, both by the slots above; ``rng`` the
    generator). Returns :data:`CHUNK`, :data:`DONE` (the goal motion in
    ``counters[C_FOUND]``), :data:`HARD`, :data:`ITERATIONS` or :data:`FULL`."""
    ck = shim.open_bundle(ck)
    m = ck[0]
    dof = T.Q.shape[1]
    k = proj.matrix.shape[0]
    x = np.empty(k, dtype=np.int64)
    target = np.empty(dof)
    d = np.empty(dof)
    q = np.empty(dof)
    q_new = np.empty(dof)
    step = prm[P_STEP]
    stride = int(prm[P_STRIDE])
    while True:
        if counters[C_ITER] >= counters[C_MAX_ITER]:
            return ITERATIONS
        if counters[C_CHECKS] >= counters[C_HARD]:
            return HARD
        if counters[C_CHECKS] >= counters[C_SOFT]:
            return CHUNK
        if counters[C_MOTIONS] >= T.Q.shape[0]:
            return FULL
        counters[C_ITER] += 1
        counters[C_DISC_ITER] += 1
        c = _select(C, counters, rng, prm[P_BORDER])
        C.selections[c] += 1.0
        i = C.head[c]
        for _ in range(C.n_motions[c] - 1 - _half_normal(rng, C.n_motions[c])):
            i = T.prev[i]
        kept = False
        if T.flag[i] != DEAD:
            to_goal = _target(T, i, goals, prm, (m.lower, m.upper, m.continuous), rng, target)
            counters[C_GOAL_TRIES] += 1 if to_goal else 0
            left = counters[C_HARD] - counters[C_CHECKS]
            status, j, n, checks = shim.edge_reach(
                ck, T.Q[i], target, step, prm[P_MIN_FRACTION], stride, left, (d, q)
            )
            counters[C_CHECKS] += checks
            if status == shim.LIMIT:
                _update(C, counters, c)  # its selection counted
                return HARD
            if j > 0:
                kept = True
                if j == n:
                    q_new[:] = target
                else:
                    shim.grid_state(T.Q[i], d, j, n, q_new)
                dist = goal_distance(q_new, goals, m.continuous)
                flag = CHECKED if (j == n and stride == 1) else COARSE
                r = add_motion(T, C, proj, counters, q_new, (i, flag, dist), x)
                if _reaches(q_new, goals, m.continuous, prm[P_GOAL_TOL]):
                    code = _certify(ck, T, counters, r, step, d, q)
                    if code == 2:
                        _update(C, counters, c)
                        return HARD
                    if code == 0:
                        counters[C_FOUND] = r
                        return DONE
                    counters[C_FAILED] += 1
        if not kept:
            C.score[c] *= prm[P_FAILED_FACTOR]
        _update(C, counters, c)


@njit(cache=True, nogil=True)
def tree_path(T, r, out):
    """The states from the root to motion r into out; returns their number."""
    k = 0
    i = r
    while i >= 0:
        k += 1
        i = T.parent[i]
    i = r
    for s in range(k - 1, -1, -1):
        out[s] = T.Q[i]
        i = T.parent[i]
    return k

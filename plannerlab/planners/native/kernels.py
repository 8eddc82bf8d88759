"""The compiled sampling planners' kernels: a generator, sampling (uniform or guided),
nearest neighbours, RRT-Connect in chunks of work (RRT*'s kernel, on these, is in
:mod:`~plannerlab.planners.native.rrtstar`), and the path's shortcuts. Every kernel takes
the robot–scene model (:class:`~plannerlab.collision.model.CompiledModel`) and the state
test's scratch in a :class:`Search` and works for any robot that gives one.

Edges are checked by the collision core's certified edge check
(:func:`~plannerlab.collision.edges.edge_check`): the verdict of the re-check's own grid
(the states :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify` makes, bit
for bit) from a few certified stretches tested eight at a time, in the direction the path
will run: start-tree edges parent → child, goal-tree edges child → parent (the path runs
from a goal tree's leaf to its root), shortcuts along the path. A returned path therefore
passes the re-check ``checker.check_path(path, step, mode="grid")`` by construction.

Budgets: a kernel call runs until a *soft* limit on its checks is passed (the chunk:
the caller looks at the clock between chunks; given only with a time limit), checked
between two edges (an edge is never cut short by it, so every chunk makes progress), or
until a *hard* one (the budget) is reached, if need be inside an edge, which is then left
unproved, or the iteration budget is used up. Without a time limit there is one chunk,
so the search does not depend on the machine: the same seed gives the same path, checks
and iterations.

Arguments travel in named tuples (:class:`Search`, :class:`Tree`, :class:`Options`), so no
kernel takes more than eight. The kernels run without numba's reference counting
(``_nrt=False``): they allocate nothing, every array comes from the caller.

Generator: xoshiro256+ (state: 4 uint64, seeded by :func:`seed_state`); doubles from
its upper 53 bits; Gaussian noise by Box–Muller.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision._unpacked import unpack_lanes, unpack_model
from plannerlab.collision.edges import (
    FREE,
    INVALID,
    LIMIT,
    edge_check,
    edge_count,
    edge_delta,
    edge_rake,
)
from plannerlab.collision.simd import kernel
from plannerlab.planners.native.kdtree import DEAD, kd_catch_up, kd_insert, kd_nearest

# ---------------------------------------------------------------------- return codes
#: the chunk's soft limit (checks or iterations of this call) was reached: call again
CHUNK = 0
#: a path was found (RRT-Connect) / the shortcuts are done
DONE = 1
#: the hard check limit came inside an iteration: the budget is spent
HARD = 2
#: the iteration budget is used up
ITERATIONS = 3
#: a tree has no room for another iteration's nodes: grow its arrays and call again
FULL = 4

# node flags (Tree.F): the edge to the node's parent is known free at its coarse states
# only (:func:`~plannerlab.collision.edges.edge_rake`), or proved free on its whole grid;
# a dead node (:data:`DEAD`: its edge failed its full check) and its subtree are left out
# of nearest-node searches
COARSE = 0
CHECKED = 1

_U11 = np.uint64(11)
_U17 = np.uint64(17)
_U45 = np.uint64(45)
_U19 = np.uint64(19)
_INV53 = 1.0 / 9007199254740992.0
_TWO_PI = 2.0 * math.pi


class Search(NamedTuple):
    """What every kernel of a search shares (made once per solve by the caller)."""

    m: Any  # the compiled robot–scene model
    Z: Any  # the state test's scratch (collision.state_test.lanes)
    rng: np.ndarray  # (4,) uint64: the generator's state
    buf: np.ndarray  # (4, dof) scratch states
    sd: np.ndarray  # the k-d trees' split joints (empty: scan)
    KS: tuple  # the k-d search's scratch (stack, bounds, offs)


@njit(cache=True, nogil=True, inline="always")
def open_search(P, aux):
    """The :class:`Search` of a packed model ``P`` (the checker core's five arrays: a call
    from Python unboxes those, not the model's seventy) and ``aux`` = (rng, buf, sd,
    KS)."""
    f64, f32, i64, b1, head = P
    rng, buf, sd, KS = aux
    return Search(
        unpack_model(f64, f32, i64, b1, head), unpack_lanes(f64, f32, i64, b1, head), rng,
        buf, sd, KS,
    )  # fmt: skip


class Tree(NamedTuple):
    """A search tree's rows: states, parents (-1: a root), flags, dynamic-domain radii
    (inf: none), its k-d tree (rows, 3; -1: not in it yet)."""

    Q: np.ndarray
    P: np.ndarray
    F: np.ndarray
    R: np.ndarray
    Kd: np.ndarray


class Options(NamedTuple):
    """A search's settings: guide states (k, dof; k = 0: none), ``f`` = (guide_bias,
    guide_sigma_rad, range_rad, joint_step), the dynamic domain ``dd`` = (radius,
    min_radius, alpha) (radius 0: none), ``i`` = (max_iterations, need_free, every: the
    coarse check's stride, 1 for every edge in full at once; balance: 1 to grow the
    smaller tree while it has at most half the other's nodes)."""

    guides: np.ndarray
    f: np.ndarray
    dd: np.ndarray
    i: np.ndarray


# ---------------------------------------------------------------------- the generator
def seed_state(rng: np.random.Generator) -> np.ndarray:
    """A generator state (4,) uint64 drawn from the trial's numpy generator (never all
    zero)."""
    s = rng.integers(1, 2**63 - 1, size=4, dtype=np.int64).astype(np.uint64)
    return s


@kernel
def next_u64(s):
    """xoshiro256+: the next 64 bits; advances the state s (4,) uint64."""
    result = s[0] + s[3]
    t = s[1] << _U17
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = (s[3] << _U45) | (s[3] >> _U19)
    return result


@kernel
def uniform(s):
    """A double in [0, 1)."""
    return float(next_u64(s) >> _U11) * _INV53


@kernel
def randint(s, n):
    """An integer in [0, n)."""
    i = int(uniform(s) * n)
    return min(i, n - 1)


@kernel
def gauss(s):
    """A standard normal number (Box–Muller)."""
    u1 = 1.0 - uniform(s)  # (0, 1]
    u2 = uniform(s)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(_TWO_PI * u2)


# ---------------------------------------------------------------------- states
@kernel
def copy_row(dst, i, src, j):
    """dst[i] = src[j] (rows; a slice assignment needs numba's reference counting)."""
    for c in range(dst.shape[1]):
        dst[i, c] = src[j, c]


@kernel
def wrap(x):
    """An angle into [-π, π) (``wrap_to_pi``)."""
    return (x + math.pi) % _TWO_PI - math.pi


@kernel
def sample(s, lower, upper, continuous, guides, guide_bias, guide_sigma_rad, out):
    """A sample into out (dof,): with probability ``guide_bias`` (and guides (k, dof),
    k > 0) a guide state drawn uniformly plus Gaussian noise ``guide_sigma_rad`` per joint,
    clipped to the bounds; else uniform in the bounds. Continuous joints in [-π, π)."""
    dof = out.shape[0]
    if guides.shape[0] > 0 and guide_bias > 0.0 and uniform(s) < guide_bias:
        g = randint(s, guides.shape[0])
        for i in range(dof):
            x = guides[g, i] + guide_sigma_rad * gauss(s)
            if continuous[i]:
                x = wrap(x)
            else:
                x = min(max(x, lower[i]), upper[i])
            out[i] = x
        return
    for i in range(dof):
        u = uniform(s)
        if continuous[i]:
            out[i] = -math.pi + _TWO_PI * u
        else:
            out[i] = lower[i] + (upper[i] - lower[i]) * u


@kernel
def distance2(a, b, continuous):
    """Squared joint distance, continuous joints the short way round."""
    acc = 0.0
    for i in range(a.shape[0]):
        x = b[i] - a[i]
        if continuous[i]:
            x = wrap(x)
        acc += x * x
    return acc


@kernel
def nearest(Q, n, q, continuous, any_continuous, F):
    """Index of the state of Q[:n] nearest to q, rows with ``F[r] == DEAD`` left out
    (brute force over contiguous rows, each row's sum abandoned once it exceeds the
    best); -1 when every row is dead."""
    best = np.inf
    best_i = -1
    dof = q.shape[0]
    for r in range(n):
        if F[r] == DEAD:
            continue
        acc = 0.0
        if any_continuous:
            for i in range(dof):
                x = q[i] - Q[r, i]
                if continuous[i]:
                    if x >= math.pi:
                        x -= _TWO_PI
                    elif x < -math.pi:
                        x += _TWO_PI
                acc += x * x
                if acc >= best:
                    break
        else:
            for i in range(dof):
                x = q[i] - Q[r, i]
                acc += x * x
                if acc >= best:
                    break
        if acc < best:
            best = acc
            best_i = r
    return best_i


@kernel
def steer(q_from, q_to, range_rad, continuous, d, out):
    """out = the state at most ``range_rad`` from q_from towards q_to (q_to itself, copied,
    when it is that close); True when out is q_to. Uses d (dof,) as scratch."""
    edge_delta(q_from, q_to, continuous, d)
    dist = 0.0
    for i in range(d.shape[0]):
        dist += d[i] * d[i]
    dist = math.sqrt(dist)
    if dist <= range_rad:
        for i in range(d.shape[0]):
            out[i] = q_to[i]
        return True
    f = range_rad / dist
    for i in range(d.shape[0]):
        x = q_from[i] + f * d[i]
        out[i] = wrap(x) if continuous[i] else x
    return False


# ---------------------------------------------------------------------- edges
@kernel
def edge_states(q_a, q_b, joint_step, m, d):
    """The grid's number of states of edge q_a -> q_b (its re-check's checks)."""
    edge_delta(q_a, q_b, m.continuous, d)
    return edge_count(d, joint_step, m.edge_weights)


@kernel
def _tree_edge(S, T, c, goal_tree, joint_step, limits):
    """The edge of node c to its parent, in the direction the path runs (start tree
    parent -> child, goal tree child -> parent). ``limits`` = (check limit, stride):
    stride 1 checks the whole grid (:func:`~plannerlab.collision.edges.edge_check`), a
    larger one its coarse states (:func:`~plannerlab.collision.edges.edge_rake`).
    Returns (status, checks, flag): FREE, INVALID or LIMIT, and the node's flag when free
    (CHECKED: the whole grid proved; COARSE: its coarse states only)."""
    limit, stride = limits
    p = T.P[c]
    a, b = (T.Q[c], T.Q[p]) if goal_tree else (T.Q[p], T.Q[c])
    if stride <= 1:
        status, checks, _ = edge_check(S.m, S.Z, a, b, joint_step, limit)
        return status, checks, CHECKED
    status, checks, _, proved = edge_rake(S.m, S.Z, a, b, joint_step, stride, limit)
    return status, checks, (CHECKED if proved else COARSE)


@kernel
def _kill(T, c, n):
    """Node c and its subtree are dead (parents come before their children)."""
    T.F[c] = DEAD
    for i in range(c + 1, n):
        if T.P[i] >= 0 and T.F[T.P[i]] == DEAD:
            T.F[i] = DEAD


@kernel
def _certify(S, A, B, ab, sizes, joint_step, limit):
    """Check in full the found path's edges known only at their coarse states (A's chain
    from a, B's from b; ``ab`` = (a, b)), each marked CHECKED when free; an invalid one
    kills its node's subtree. Returns (status, checks): FREE the path is checked, INVALID
    an edge failed, LIMIT the limit came first."""
    checks = 0
    for t in range(2):
        T, c = (A, ab[0]) if t == 0 else (B, ab[1])
        while T.P[c] >= 0:
            if T.F[c] == COARSE:
                status, k, _ = _tree_edge(S, T, c, t == 1, joint_step, (limit - checks, 1))
                checks += k
                if status == LIMIT:
                    return LIMIT, checks
                if status == INVALID:
                    _kill(T, c, sizes[t])
                    return INVALID, checks
                T.F[c] = CHECKED
            c = T.P[c]
    return FREE, checks


# ---------------------------------------------------------------------- RRT-Connect
@kernel
def _nearest(S, T, n, q):
    """The nearest live node of T[:n] to q (k-d tree, or a scan without split joints)."""
    if S.sd.shape[0] > 0:
        return kd_nearest(T, q, S.m.continuous, S.sd, S.KS)
    return nearest(T.Q, n, q, S.m.continuous, S.m.continuous.any(), T.F)


@kernel
def _grow(S, T, n, goal_tree, near, q_to, O, limit):
    """Grow tree T of n nodes from node ``near`` (-1: the nearest live one; -2: the same
    without the dynamic domain) towards q_to: a
    node at most ``range_rad`` on, added at index n when its edge is free; the caller puts
    it in the k-d tree.

    Dynamic domain (``O.dd`` = (radius, min_radius, alpha) [rad, rad, 1], radius > 0; only
    for the nearest-node step): a sample farther from its nearest node than the node's
    radius ``T.R`` is dropped unchecked; a node's first failed extension sets its radius
    to ``radius``, later ones shrink it by (1 - alpha) down to ``min_radius``, successes
    grow it by (1 + alpha) (Yershova et al. 2005, as VAMP's RRT-Connect).

    Returns (code, checks, near): code 0 trapped, 1 advanced, 2 reached q_to, 3 the
    hard limit came first, 4 dropped by the dynamic domain."""
    dd = O.dd
    domain = near == -1 and dd[0] > 0.0
    Q, R = T.Q, T.R
    continuous = S.m.continuous
    if near < 0:
        near = _nearest(S, T, n, q_to)
        if domain and distance2(Q[near], q_to, continuous) > R[near] * R[near]:
            return 4, 0, near
    T.P[n] = near  # the new row: the edge from near towards the target

    reached = steer(Q[near], q_to, O.f[2], continuous, S.buf[2], Q[n])
    status, checks, flag = _tree_edge(S, T, n, goal_tree, O.f[3], (limit, O.i[2]))
    if status == LIMIT:
        return 3, checks, near
    if status != FREE:
        if domain:
            R[near] = dd[0] if R[near] == np.inf else max(R[near] * (1.0 - dd[2]), dd[1])
        return 0, checks, near
    if domain and R[near] != np.inf:
        R[near] *= 1.0 + dd[2]
    T.F[n] = flag
    R[n] = np.inf
    return (2 if reached else 1), checks, near


@kernel
def _added(S, T, sizes, t):
    """Node sizes[t] of tree t joins it (and its k-d tree); returns its index."""
    new = sizes[t]
    sizes[t] += 1
    if S.sd.shape[0] > 0:
        kd_insert(T.Q, T.Kd, new, S.sd)
    return new


@kernel
def rrtc_run(S, A, B, sizes, O, counters, limits):
    """RRT-Connect iterations until a path, a limit, or a full tree.

    Trees A (the start's) and B (the goal tree, a root per goal state); ``sizes`` (2,)
    their node counts. Nearest nodes come from the k-d trees (:func:`kd_nearest`: the very
    node :func:`nearest`'s brute force finds); rows not in them yet (the roots, seeded
    branches) are put in when the call starts. ``counters`` (6,) int64 carries the search
    across calls: iterations, checks, the tree to grow next (0 A, 1 B), on a path the
    meeting node in A and in B (equal states), the found paths whose full check failed.

    Lazy full checks (``O.i[2]`` > 1, the stride): a tree edge is checked on its coarse
    states when it is added (:func:`~plannerlab.collision.edges.edge_rake`, which proves
    the whole edge when its coarse states, grown, are free); the others only when a path
    through it is found (:func:`_certify`); a failure kills the subtree below it and the
    search goes on.

    Each iteration draws a sample (:func:`sample`: uniform, or a guide state perturbed,
    with probability ``guide_bias``), extends the tree whose turn it is one step of at
    most ``range_rad`` towards it, and, if that edge is free, connects the other tree to
    the new node step by step (OMPL's RRT-Connect); the trees then swap roles, unless
    ``O.i[3]`` (balance, VAMP's default) and one tree has at most half the other's nodes:
    then the smaller one grows (a goal tree in a pocket gets the iterations, not the start
    tree sprawling outside).

    Limits: ``O.i[0]`` iterations (total), ``limits`` = (soft, hard) total checks: the
    soft one ends this call (:data:`CHUNK`) between two edges (a connection stops where
    it got to, its nodes checked), the hard one is never crossed (:data:`HARD`);
    ``O.i[1]`` free rows each tree needs before an iteration starts, else :data:`FULL`.

    Returns a code (:data:`CHUNK`, :data:`DONE`, :data:`HARD`, :data:`ITERATIONS`,
    :data:`FULL`)."""
    q_rand = S.buf[0]
    m = S.m
    soft, hard = limits[0], limits[1]
    max_iterations, need_free = O.i[0], O.i[1]
    if S.sd.shape[0] > 0:
        kd_catch_up(A.Q, sizes[0], A.Kd, S.sd)
        kd_catch_up(B.Q, sizes[1], B.Kd, S.sd)
    while True:
        if counters[0] >= max_iterations:
            return ITERATIONS
        if counters[1] >= hard:
            return HARD
        if counters[1] >= soft:
            return CHUNK
        if A.Q.shape[0] - sizes[0] < need_free or B.Q.shape[0] - sizes[1] < need_free:
            return FULL
        counters[0] += 1
        sample(S.rng, m.lower, m.upper, m.continuous, O.guides, O.f[0], O.f[1], q_rand)
        t = counters[2]
        if O.i[3] != 0 and 2 * sizes[1 - t] <= sizes[t]:
            t = 1 - t  # balanced: the tree of at most half the other's nodes grows
        counters[2] = 1 - t
        Tt, To = (A, B) if t == 0 else (B, A)
        code, c, _ = _grow(S, Tt, sizes[t], t == 1, -1, q_rand, O, hard - counters[1])
        counters[1] += c
        if code == 3:
            return HARD
        if code == 0 or code == 4:
            continue
        new_t = _added(S, Tt, sizes, t)
        q_new = Tt.Q[new_t]
        # connect the other tree to q_new: after a step, its nearest node to q_new is the
        # node just added (it lies on the segment from the previous nearest)
        o = 1 - t
        near = -2  # the nearest node, no dynamic domain for a connection
        while True:
            code, c, _ = _grow(S, To, sizes[o], o == 1, near, q_new, O, hard - counters[1])
            counters[1] += c
            if code == 3:
                return HARD
            if code == 0:
                break
            near = _added(S, To, sizes, o)
            if code == 2:
                a = new_t if t == 0 else near
                b = near if t == 0 else new_t
                status, c = _certify(S, A, B, (a, b), sizes, O.f[3], hard - counters[1])
                counters[1] += c
                if status == LIMIT:
                    return HARD
                if status == INVALID:  # a state between the coarse ones collides: search on
                    counters[5] += 1
                    break
                counters[3] = a
                counters[4] = b
                return DONE
            if counters[1] >= soft:  # the connection so far stays (checked nodes)
                return CHUNK


@kernel
def rrtc_entry(P, aux, A, B, sizes, O, counters, limits):
    """:func:`rrtc_run` on the packed model (a call from Python)."""
    return rrtc_run(open_search(P, aux), A, B, sizes, O, counters, limits)


@kernel
def tree_path(A, a, B, b, out):
    """The path from A's root to node a (= B's node b), then from b's parent to B's
    root, into out (rows); returns its number of states."""
    k = 0
    i = a
    while i >= 0:
        k += 1
        i = A.P[i]
    i = a
    for r in range(k - 1, -1, -1):
        copy_row(out, r, A.Q, i)
        i = A.P[i]
    i = B.P[b]
    while i >= 0:
        copy_row(out, k, B.Q, i)
        k += 1
        i = B.P[i]
    return k


# ---------------------------------------------------------------------- shortcuts
@kernel
def _cut(P, k, i, j):
    """Remove the states strictly between i and j of P[:k]; returns the new length."""
    gap = j - i - 1
    for r in range(j, k):
        copy_row(P, r - gap, P, r)
    return k - gap


@kernel
def _try_shortcut(S, P, k, ij, joint_step, limit):
    """Replace P[i..j] (``ij``) by the edge P[i] -> P[j] when it is free and its grid has
    no more states than the edges it replaces (the re-check never grows). Returns (k,
    code, checks): code 0 kept, 1 cut, 2 the limit came first."""
    i, j = ij
    d = S.buf[2]
    n_new = edge_states(P[i], P[j], joint_step, S.m, d)
    n_old = 0
    for e in range(i, j):
        n_old += edge_states(P[e], P[e + 1], joint_step, S.m, d)
    if n_new > n_old:
        return k, 0, 0
    status, checks, _ = edge_check(S.m, S.Z, P[i], P[j], joint_step, limit)
    if status == LIMIT:
        return k, 2, checks
    if status != FREE:
        return k, 0, checks
    return _cut(P, k, i, j), 1, checks


@kernel
def shortcut_run(S, P, k, joint_step, tries, counters, limits):
    """Shorten the path P[:k] in place: ``tries`` random shortcuts (states i < j - 1
    drawn uniformly, the edge P[i] -> P[j] replacing those between when free; they end
    early once as many tries in a row failed as the path has such pairs), then one pass
    dropping each waypoint whose neighbours see each other. ``counters`` (4,) int64
    carries the work across calls: shortcuts tried, checks, the pass's position (0: not
    started), tries failed in a row. ``limits`` = (soft, hard) total checks, as
    :func:`rrtc_run`'s.

    Returns (k, code): :data:`CHUNK` (call again), :data:`DONE`, :data:`HARD`."""
    soft, hard = limits[0], limits[1]
    rng = S.rng
    while counters[0] < tries:
        if k < 3 or counters[3] >= (k - 1) * (k - 2) // 2:
            counters[0] = tries
            break
        if counters[1] >= hard:
            return k, HARD
        if counters[1] >= soft:
            return k, CHUNK
        counters[0] += 1
        i = randint(rng, k - 2)
        j = i + 2 + randint(rng, k - i - 2)
        k, code, c = _try_shortcut(S, P, k, (i, j), joint_step, hard - counters[1])
        counters[1] += c
        if code == 2:
            return k, HARD
        counters[3] = 0 if code == 1 else counters[3] + 1
    if counters[2] == 0:
        counters[2] = 1
    while counters[2] < k - 1:
        if counters[1] >= hard:
            return k, HARD
        if counters[1] >= soft:
            return k, CHUNK
        i = counters[2]
        k, code, c = _try_shortcut(S, P, k, (i - 1, i + 1), joint_step, hard - counters[1])
        counters[1] += c
        if code == 2:
            return k, HARD
        if code == 0:
            counters[2] += 1
    return k, DONE


@kernel
def shortcut_entry(P, aux, path, joint_step, tries, counters, limits):
    """:func:`shortcut_run` on the packed model (a call from Python); ``path`` = (P, k)."""
    return shortcut_run(open_search(P, aux), path[0], path[1], joint_step, tries, counters, limits)

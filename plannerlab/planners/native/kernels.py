"""The compiled sampling planners' kernels: a generator, sampling (uniform or guided),
nearest neighbours, edges on the checker's grid, RRT-Connect in chunks of work (RRT*'s
kernel, on these, is in :mod:`~plannerlab.planners.native.rrtstar`), and the path's
shortcuts. Every kernel takes the robot–scene model
(:class:`~plannerlab.collision.model.CompiledModel`, with its views ``V, S``) and works
for any robot that gives one.

Edges are checked on the re-check's own grid (:func:`~plannerlab.collision.model.
edge_state`: the floats :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify`
makes) in the direction the path will run: start-tree edges parent → child, goal-tree
edges child → parent (the path runs from a goal tree's leaf to its root), shortcuts along
the path. The re-check ``checker.check_path(path, step, mode="grid")`` thus checks states
the search checked, bit for bit, and a returned path passes it by construction.

Budgets: a kernel call runs until a *soft* limit on its checks is passed (the chunk:
the caller looks at the clock between chunks; given only with a time limit), checked
between two edges (an edge is never cut short by it, so every chunk makes progress), or
until a *hard* one (the budget) is reached, if need be inside an edge, which is then left
unproved, or the iteration budget is used up. Without a time limit there is one chunk,
so the search does not depend on the machine: the same seed gives the same path, checks
and iterations.

Generator: xoshiro256+ (state: 4 uint64, seeded by :func:`seed_state`); doubles from
its upper 53 bits; Gaussian noise by Box–Muller.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plannerlab.collision.model_old import edge_count, edge_delta, edge_state, state_ok
from plannerlab.planners.native.kdtree import kd_catch_up, kd_insert, kd_nearest, split_dims

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

# node flags (F arrays): the edge to the node's parent is checked on its coarse states, on
# all of them, or was found invalid on its fine states (the node and its subtree are dead)
COARSE = 0
CHECKED = 1
DEAD = 2

_U11 = np.uint64(11)
_U17 = np.uint64(17)
_U45 = np.uint64(45)
_U19 = np.uint64(19)
_INV53 = 1.0 / 9007199254740992.0
_TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------- the generator
def seed_state(rng: np.random.Generator) -> np.ndarray:
    """A generator state (4,) uint64 drawn from the trial's numpy generator (never all
    zero)."""
    s = rng.integers(1, 2**63 - 1, size=4, dtype=np.int64).astype(np.uint64)
    return s


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def uniform(s):
    """A double in [0, 1)."""
    return float(next_u64(s) >> _U11) * _INV53


@njit(cache=True, nogil=True)
def randint(s, n):
    """An integer in [0, n)."""
    i = int(uniform(s) * n)
    return min(i, n - 1)


@njit(cache=True, nogil=True)
def gauss(s):
    """A standard normal number (Box–Muller)."""
    u1 = 1.0 - uniform(s)  # (0, 1]
    u2 = uniform(s)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(_TWO_PI * u2)


# ---------------------------------------------------------------------- states
@njit(cache=True, nogil=True)
def wrap(x):
    """An angle into [-π, π) (``wrap_to_pi``)."""
    return (x + math.pi) % _TWO_PI - math.pi


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def distance2(a, b, continuous):
    """Squared joint distance, continuous joints the short way round."""
    acc = 0.0
    for i in range(a.shape[0]):
        x = b[i] - a[i]
        if continuous[i]:
            x = wrap(x)
        acc += x * x
    return acc


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def steer(q_from, q_to, range_rad, continuous, d, out):
    """out = the state at most ``range_rad`` from q_from towards q_to (q_to itself, copied,
    when it is that close); True when out is q_to. Uses d (dof,) as scratch."""
    edge_delta(q_from, q_to, continuous, d)
    dist = 0.0
    for i in range(d.shape[0]):
        dist += d[i] * d[i]
    dist = math.sqrt(dist)
    if dist <= range_rad:
        out[:] = q_to
        return True
    f = range_rad / dist
    for i in range(d.shape[0]):
        x = q_from[i] + f * d[i]
        out[i] = wrap(x) if continuous[i] else x
    return False


# ---------------------------------------------------------------------- edges
@njit(cache=True, nogil=True)
def edge_free(q_a, q_b, joint_step, m, V, S, d, q, limit, near_a_first, every=1, fine=False):
    """Check grid states of edge q_a -> q_b (states 1..n of ``densify``; q_a itself is
    not one) in an order that finds a collision early: the new end first
    (``near_a_first``: j = 1, the state next to q_a; else j = n, the state reaching q_b),
    then the midpoints of ever finer halvings (the way VAMP checks a whole edge at once).

    ``every`` (a power of two) splits the grid in two: the *coarse* states (the ends and
    every ``every``-th state) are checked with ``fine`` False, the others with ``fine``
    True; ``every`` = 1 checks all at once. No check is made once ``limit`` checks were
    made.

    Returns (status, checks): 0 every state asked is valid, 1 one is invalid, 2 the limit
    came first (nothing proved)."""
    edge_delta(q_a, q_b, m.continuous, d)
    n = edge_count(d, joint_step, m.edge_weights)
    first = 1 if near_a_first else n
    if limit <= 0:
        return 2, 0
    checks = 0
    if not fine:
        edge_state(q_a, d, first, n, q)
        checks += 1
        if not state_ok(q, V, S):
            return 1, checks
        if n == 1:
            return 0, checks
        if near_a_first:  # then the far end, j = n
            if checks >= limit:
                return 2, checks
            edge_state(q_a, d, n, n, q)
            checks += 1
            if not state_ok(q, V, S):
                return 1, checks
    step = 1
    while step < n:
        step *= 2
    h = step // 2 if not fine else every // 2
    h_end = every if not fine else 1
    while h >= h_end:
        j = h
        while j < n:
            if not (fine and near_a_first and j == 1) and not (not fine and j == first):
                if checks >= limit:
                    return 2, checks
                edge_state(q_a, d, j, n, q)
                checks += 1
                if not state_ok(q, V, S):
                    return 1, checks
            j += 2 * h
        h //= 2
    return 0, checks


@njit(cache=True, nogil=True)
def edge_states(q_a, q_b, joint_step, m, d):
    """The grid's number of states of edge q_a -> q_b (its re-check's checks)."""
    edge_delta(q_a, q_b, m.continuous, d)
    return edge_count(d, joint_step, m.edge_weights)


# ---------------------------------------------------------------------- RRT-Connect
@njit(cache=True, nogil=True)
def _tree_edge(Qt, Pt, c, goal_tree, joint_step, m, V, S, buf, limit, every, fine):
    """:func:`edge_free` on the edge of node c to its parent, in the direction the path
    runs (start tree parent -> child, goal tree child -> parent)."""
    p = Pt[c]
    if goal_tree:
        return edge_free(Qt[c], Qt[p], joint_step, m, V, S, buf[2], buf[3], limit, True,
                         every, fine)  # fmt: skip
    return edge_free(Qt[p], Qt[c], joint_step, m, V, S, buf[2], buf[3], limit, False,
                     every, fine)  # fmt: skip


@njit(cache=True, nogil=True)
def _grow(Qt, Pt, Ft, Rt, Kt, nt, goal_tree, near, q_to, range_rad, joint_step, m, V, S, buf,
          limit, every, dd, sd, stack, bounds, offs):  # fmt: skip
    """Grow tree (Qt, Pt, Ft, Rt, Kt: its k-d tree, :func:`kd_insert`) of nt nodes from
    node ``near`` (-1: the nearest live one, by the k-d tree over the joints ``sd``, or
    by brute force when ``sd`` is empty) towards q_to: a node at most ``range_rad`` on,
    added at index nt when the coarse states of its edge are free (all of them with
    ``every`` = 1); the caller puts it in the k-d tree.

    Dynamic domain (``dd`` = (radius, min_radius, alpha) [rad, rad, 1], radius > 0; only
    for the nearest-node step): a sample farther from its nearest node than the node's
    radius ``Rt`` is dropped unchecked; a node's first failed extension sets its radius
    to ``radius``, later ones shrink it by (1 - alpha) down to ``min_radius``, successes
    grow it by (1 + alpha) (Yershova et al. 2005, as VAMP's RRT-Connect).

    Returns (code, checks, near): code 0 trapped, 1 advanced, 2 reached q_to, 3 the
    hard limit came first, 4 dropped by the dynamic domain."""
    domain = near < 0 and dd[0] > 0.0
    if near < 0:
        if sd.shape[0] > 0:
            near = kd_nearest(Qt, q_to, m.continuous, Ft, DEAD, Kt, sd, stack, bounds, offs)
        else:
            near = nearest(Qt, nt, q_to, m.continuous, m.continuous.any(), Ft)
        if domain and distance2(Qt[near], q_to, m.continuous) > Rt[near] * Rt[near]:
            return 4, 0, near
    Qt[nt] = Qt[near]  # the new row's parent edge, from near to the target
    Pt[nt] = near
    reached = steer(Qt[near], q_to, range_rad, m.continuous, buf[2], Qt[nt])
    status, checks = _tree_edge(Qt, Pt, nt, goal_tree, joint_step, m, V, S, buf, limit, every,
                                False)  # fmt: skip
    if status == 2:
        return 3, checks, near
    if status == 1:
        if domain:
            Rt[near] = dd[0] if Rt[near] == np.inf else max(Rt[near] * (1.0 - dd[2]), dd[1])
        return 0, checks, near
    if domain and Rt[near] != np.inf:
        Rt[near] *= 1.0 + dd[2]
    Ft[nt] = CHECKED if every == 1 else COARSE
    Rt[nt] = np.inf
    return (2 if reached else 1), checks, near


@njit(cache=True, nogil=True)
def _kill(Pt, Ft, c, n):
    """Node c and its subtree are dead (parents come before their children)."""
    Ft[c] = DEAD
    for i in range(c + 1, n):
        if Pt[i] >= 0 and Ft[Pt[i]] == DEAD:
            Ft[i] = DEAD


@njit(cache=True, nogil=True)
def _certify(QA, PA, FA, a, QB, PB, FB, b, sizes, joint_step, m, V, S, buf, limit, every):
    """Check the fine states of the found path's edges not checked in full (A's chain
    from a, B's from b), each marked CHECKED when free; an invalid one kills its node's
    subtree. Returns (status, checks): 0 the path is checked, 1 an edge failed, 2 the
    limit came first."""
    checks = 0
    for t in range(2):
        Qt, Pt, Ft, c = (QA, PA, FA, a) if t == 0 else (QB, PB, FB, b)
        while Pt[c] >= 0:
            if Ft[c] == COARSE:
                status, k = _tree_edge(Qt, Pt, c, t == 1, joint_step, m, V, S, buf,
                                       limit - checks, every, True)  # fmt: skip
                checks += k
                if status == 2:
                    return 2, checks
                if status == 1:
                    _kill(Pt, Ft, c, sizes[t])
                    return 1, checks
                Ft[c] = CHECKED
            c = Pt[c]
    return 0, checks


@njit(cache=True, nogil=True)
def rrtc_run(
    m,
    V,
    S,
    QA,
    PA,
    FA,
    RA,
    QB,
    PB,
    FB,
    RB,
    KA,
    KB,
    sizes,
    counters,
    rng,
    guides,
    guide_bias,
    guide_sigma_rad,
    range_rad,
    joint_step,
    every,
    dd,
    max_iterations,
    soft_checks,
    hard_checks,
    need_free,
    buf,
):
    """RRT-Connect iterations until a path, a limit, or a full tree.

    Trees: A (QA (cap_a, dof) states, PA parents, -1 at the root: the start, FA flags,
    RA dynamic-domain radii, inf: none, KA (cap_a, 3) int64 its k-d tree, rows -1: not
    in it yet) and B (the goal tree, a root per goal state); ``sizes`` (2,) their node
    counts. Nearest nodes come from the k-d trees (:func:`kd_nearest`: the very node
    :func:`nearest`'s brute force finds); rows not in them yet (the roots, seeded
    branches) are put in when the call starts.
    ``counters`` (6,) int64 carries the search across calls: iterations, checks, the tree
    to grow next (0 A, 1 B), on a path the meeting node in A and in B (equal states), and
    the found paths whose fine check failed.

    Lazy fine checks (``every`` > 1, a power of two): a tree edge is checked on its coarse
    states (its ends and every ``every``-th grid state) when it is added; the others only
    when a path through it is found (:func:`_certify`); a failure kills the subtree below
    it and the search goes on. With ``every`` = 1 every edge is checked in full at once.
    ``dd``: the dynamic domain of the extension (:func:`_grow`; radius 0: none).

    Each iteration draws a sample (:func:`sample`: uniform, or a guide state perturbed,
    with probability ``guide_bias``; ``guides`` (k, dof), k = 0 for none), extends the
    tree whose turn it is one step of at most ``range_rad`` towards it, and, if that
    edge is free, connects the other tree to the new node step by step (OMPL's
    RRT-Connect); the trees then swap roles.

    Limits: ``max_iterations`` (total), ``soft_checks`` (total checks after which this
    call returns :data:`CHUNK` between two edges: a connection stops where it got to, its
    nodes checked), ``hard_checks`` (total checks never crossed, inside an edge if need
    be: :data:`HARD`), ``need_free`` (free rows each tree needs before an
    iteration starts, else :data:`FULL`). ``buf`` (4, dof) scratch.

    Returns a code (:data:`CHUNK`, :data:`DONE`, :data:`HARD`, :data:`ITERATIONS`,
    :data:`FULL`)."""
    q_rand = buf[0]
    no_domain = np.zeros(3)  # the connection steps have none
    sd = split_dims(m.continuous)
    kd_catch_up(QA, sizes[0], KA, sd)
    kd_catch_up(QB, sizes[1], KB, sd)
    depth = max(QA.shape[0], QB.shape[0]) + 2
    stack = np.empty(depth, dtype=np.int64)
    bounds = np.empty(depth)
    offs = np.empty((depth, QA.shape[1]))
    while True:
        if counters[0] >= max_iterations:
            return ITERATIONS
        if counters[1] >= hard_checks:
            return HARD
        if counters[1] >= soft_checks:
            return CHUNK
        if QA.shape[0] - sizes[0] < need_free or QB.shape[0] - sizes[1] < need_free:
            return FULL
        counters[0] += 1
        sample(rng, m.lower, m.upper, m.continuous, guides, guide_bias, guide_sigma_rad, q_rand)
        t = counters[2]
        counters[2] = 1 - t
        if t == 0:
            Qt, Pt, Ft, Rt, Kt = QA, PA, FA, RA, KA
            Qo, Po, Fo, Ro, Ko = QB, PB, FB, RB, KB
        else:
            Qt, Pt, Ft, Rt, Kt = QB, PB, FB, RB, KB
            Qo, Po, Fo, Ro, Ko = QA, PA, FA, RA, KA
        code, c, _ = _grow(
            Qt,
            Pt,
            Ft,
            Rt,
            Kt,
            sizes[t],
            t == 1,
            -1,
            q_rand,
            range_rad,
            joint_step,
            m,
            V,
            S,
            buf,
            hard_checks - counters[1],
            every,
            dd,
            sd,
            stack,
            bounds,
            offs,
        )
        counters[1] += c
        if code == 3:
            return HARD
        if code == 0 or code == 4:
            continue
        new_t = sizes[t]
        sizes[t] += 1
        if sd.shape[0] > 0:
            kd_insert(Qt, Kt, new_t, sd)
        q_new = Qt[new_t]
        # connect the other tree to q_new: after a step, its nearest node to q_new is the
        # node just added (it lies on the segment from the previous nearest)
        o = 1 - t
        near = -1
        while True:
            code, c, _ = _grow(
                Qo,
                Po,
                Fo,
                Ro,
                Ko,
                sizes[o],
                o == 1,
                near,
                q_new,
                range_rad,
                joint_step,
                m,
                V,
                S,
                buf,
                hard_checks - counters[1],
                every,
                no_domain,
                sd,
                stack,
                bounds,
                offs,
            )
            counters[1] += c
            if code == 3:
                return HARD
            if code == 0:
                break
            near = sizes[o]
            sizes[o] += 1
            if sd.shape[0] > 0:
                kd_insert(Qo, Ko, near, sd)
            if code == 2:
                a = new_t if t == 0 else near
                b = near if t == 0 else new_t
                status, c = _certify(QA, PA, FA, a, QB, PB, FB, b, sizes, joint_step, m, V,
                                     S, buf, hard_checks - counters[1], every)  # fmt: skip
                counters[1] += c
                if status == 2:
                    return HARD
                if status == 1:  # a fine state of the path collides: search on
                    counters[5] += 1
                    break
                counters[3] = a
                counters[4] = b
                return DONE
            if counters[1] >= soft_checks:  # the connection so far stays (checked nodes)
                return CHUNK


@njit(cache=True, nogil=True)
def tree_path(QA, PA, a, QB, PB, b, out):
    """The path from A's root to node a (= B's node b), then from b's parent to B's
    root, into out (rows); returns its number of states."""
    k = 0
    i = a
    while i >= 0:
        k += 1
        i = PA[i]
    i = a
    for r in range(k - 1, -1, -1):
        out[r] = QA[i]
        i = PA[i]
    i = PB[b]
    while i >= 0:
        out[k] = QB[i]
        k += 1
        i = PB[i]
    return k


# ---------------------------------------------------------------------- shortcuts
@njit(cache=True, nogil=True)
def _cut(P, k, i, j):
    """Remove the states strictly between i and j of P[:k]; returns the new length."""
    gap = j - i - 1
    for r in range(j, k):
        P[r - gap] = P[r]
    return k - gap


@njit(cache=True, nogil=True)
def _try_shortcut(P, k, i, j, m, V, S, joint_step, buf, limit):
    """Replace P[i..j] by the edge P[i] -> P[j] when it is free and its grid has no more
    states than the edges it replaces (the re-check never grows). Returns (k, code,
    checks): code 0 kept, 1 cut, 2 the limit came first."""
    n_new = edge_states(P[i], P[j], joint_step, m, buf[2])
    n_old = 0
    for e in range(i, j):
        n_old += edge_states(P[e], P[e + 1], joint_step, m, buf[2])
    if n_new > n_old:
        return k, 0, 0
    status, checks = edge_free(P[i], P[j], joint_step, m, V, S, buf[2], buf[3], limit, False)
    if status == 2:
        return k, 2, checks
    if status == 1:
        return k, 0, checks
    return _cut(P, k, i, j), 1, checks


@njit(cache=True, nogil=True)
def shortcut_run(P, k, m, V, S, joint_step, rng, tries, counters, soft_checks, hard_checks, buf):
    """Shorten the path P[:k] in place: ``tries`` random shortcuts (states i < j - 1
    drawn uniformly, the edge P[i] -> P[j] replacing those between when free; they end
    early once as many tries in a row failed as the path has such pairs), then one pass
    dropping each waypoint whose neighbours see each other. ``counters`` (4,) int64
    carries the work across calls: shortcuts tried, checks, the pass's position (0: not
    started), tries failed in a row. Limits as :func:`rrtc_run` (``soft_checks``,
    ``hard_checks``: totals).

    Returns (k, code): :data:`CHUNK` (call again), :data:`DONE`, :data:`HARD`."""
    while counters[0] < tries:
        if k < 3 or counters[3] >= (k - 1) * (k - 2) // 2:
            counters[0] = tries
            break
        if counters[1] >= hard_checks:
            return k, HARD
        if counters[1] >= soft_checks:
            return k, CHUNK
        counters[0] += 1
        i = randint(rng, k - 2)
        j = i + 2 + randint(rng, k - i - 2)
        k, code, c = _try_shortcut(P, k, i, j, m, V, S, joint_step, buf, hard_checks - counters[1])
        counters[1] += c
        if code == 2:
            return k, HARD
        counters[3] = 0 if code == 1 else counters[3] + 1
    if counters[2] == 0:
        counters[2] = 1
    while counters[2] < k - 1:
        if counters[1] >= hard_checks:
            return k, HARD
        if counters[1] >= soft_checks:
            return k, CHUNK
        i = counters[2]
        k, code, c = _try_shortcut(
            P, k, i - 1, i + 1, m, V, S, joint_step, buf, hard_checks - counters[1]
        )
        counters[1] += c
        if code == 2:
            return k, HARD
        if code == 0:
            counters[2] += 1
    return k, DONE

"""RRT* compiled end to end (``native.rrtstar``): one tree from the start, goal-biased
samples (a goal state of the pool with probability ``goal_bias``), the parent chosen among
the ``k`` nearest (``k = rewire_factor · e · (1 + 1/dof) · log n``, OMPL's k-nearest
RRT*), the neighbours rewired through the new node, costs (joint-space length) carried
down a rewired subtree. It runs until a limit and returns the best path to a goal state.

Why RRT*: plannerlab compares the gradient method with sampling on path quality as well as
success; RRT* is the asymptotically optimal planner every OMPL user knows, and
``ompl.rrtstar`` sits in the same registry, so the two isolate the engine from the method.

Edges are checked as :mod:`~plannerlab.planners.native.kernels` checks them: on the
re-check's grid in the direction the path runs (parent → child). The best path's re-check
is held back from the budget: the search never spends those checks (a better path is
taken only if its re-check fits), and stops when the time left is that re-check's.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from plannerlab.collision.edges import FREE, LIMIT, edge_check
from plannerlab.collision.simd import kernel, unliteral
from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native.solve import (
    FIRST_ROWS,
    RESERVE_FACTOR,
    UNLIMITED,
    NativeSolve,
    space_extent,
)
from plannerlab.robots.paths import path_length

#: neighbours considered at most (the k of a million nodes is about 50)
K_MAX = 128


@kernel
def _k_nearest(Q, n, q, continuous, k, nb_idx, nb_d2):
    """The k nearest nodes of Q[:n] to q into nb_idx, nb_d2 (squared distances),
    nearest first; returns how many (min(k, n))."""
    cnt = 0
    for r in range(n):
        d2 = K.distance2(Q[r], q, continuous)
        if cnt < k:
            j = cnt
            cnt += 1
        elif d2 < nb_d2[cnt - 1]:
            j = cnt - 1
        else:
            continue
        while j > 0 and nb_d2[j - 1] > d2:
            nb_d2[j] = nb_d2[j - 1]
            nb_idx[j] = nb_idx[j - 1]
            j -= 1
        nb_d2[j] = d2
        nb_idx[j] = r
    return cnt


@kernel
def _unlink(child, sibling, p, c):
    """Remove c from p's children."""
    if child[p] == c:
        child[p] = sibling[c]
        return
    i = child[p]
    while sibling[i] != c:
        i = sibling[i]
    sibling[i] = sibling[c]


@kernel
def _shift_costs(cost, child, sibling, root, delta, stack):
    """Add delta to the cost of root's subtree (root excluded)."""
    top = 0
    c = child[root]
    while c >= 0:
        stack[top] = c
        top += 1
        c = sibling[c]
    while top > 0:
        top -= 1
        v = stack[top]
        cost[v] += delta
        c = child[v]
        while c >= 0:
            stack[top] = c
            top += 1
            c = sibling[c]


class StarTree(NamedTuple):
    """RRT*'s tree: Q (cap, dof) states, ``parent`` (-1 at the root, the start), ``cost``
    (joint-space length from the root), children lists (``child`` first child,
    ``sibling`` next sibling, -1 ends), ``goal_nodes`` the nodes that are goal states,
    ``stack`` scratch, ``flags`` (cap,) int8 zeros (the nearest-node search's)."""

    Q: np.ndarray
    parent: np.ndarray
    cost: np.ndarray
    child: np.ndarray
    sibling: np.ndarray
    goal_nodes: np.ndarray
    stack: np.ndarray
    flags: np.ndarray


class Star(NamedTuple):
    """RRT*'s own settings and scratch: the goal states (g, dof) and the node of each
    (-1: not in the tree), ``f`` = (goal_bias, k_factor), the neighbours' scratch."""

    goals: np.ndarray
    goal_node_of: np.ndarray
    f: np.ndarray
    nb_idx: np.ndarray
    nb_d2: np.ndarray


@kernel
def _recheck_states(S, T, node, joint_step):
    """The re-check's checks of the path from the root to node (1 + its grid states)."""
    total = 1
    while T.parent[node] >= 0:
        total += K.edge_states(T.Q[T.parent[node]], T.Q[node], joint_step, S.m, S.buf[2])
        node = T.parent[node]
    return total


@kernel
def _connect_goal(S, T, X, sizes, new, O, limit):
    """Try the edge from node ``new`` to its nearest goal state not yet in the tree, when
    it is within ``range_rad``: the goal state joins the tree. Returns (status, checks)
    as :func:`~plannerlab.collision.edges.edge_check` (FREE also when nothing was
    tried)."""
    Q, goals, goal_node_of = T.Q, X.goals, X.goal_node_of
    range_rad = O.f[2]
    best = -1
    best_d2 = range_rad * range_rad
    for g in range(goals.shape[0]):
        if goal_node_of[g] < 0:
            d2 = K.distance2(Q[new], goals[g], S.m.continuous)
            if d2 <= best_d2:
                best_d2 = d2
                best = g
    if best < 0:
        return FREE, 0
    status, checks, _ = edge_check(S.m, S.Z, Q[new], goals[best], O.f[3], limit)
    if status != FREE:
        return status, checks
    v = sizes[0]
    K.copy_row(Q, v, goals, best)
    T.parent[v] = new
    T.cost[v] = T.cost[new] + math.sqrt(best_d2)
    T.child[v] = -1
    T.sibling[v] = T.child[new]
    T.child[new] = v
    sizes[0] += 1
    T.goal_nodes[sizes[1]] = v
    sizes[1] += 1
    goal_node_of[best] = v
    return FREE, checks


@kernel
def _by_cost(cost, nb_idx, nb_d2, cnt):
    """The neighbours nb_idx[:cnt] (squared distances nb_d2) sorted by the cost through
    them (cost + distance), which nb_d2 then holds."""
    for a in range(cnt):
        nb_d2[a] = cost[nb_idx[a]] + math.sqrt(nb_d2[a])
    for a in range(1, cnt):
        j = a
        while j > 0 and nb_d2[j - 1] > nb_d2[j]:
            nb_d2[j - 1], nb_d2[j] = nb_d2[j], nb_d2[j - 1]
            nb_idx[j - 1], nb_idx[j] = nb_idx[j], nb_idx[j - 1]
            j -= 1


@kernel
def _rewire(S, T, X, node, cnt, joint_step, limits):
    """Rewire the neighbours ``X.nb_idx[:cnt]`` through the new node (``node`` = (new,
    its parent, its cost)) when that is shorter and the edge new -> neighbour is free;
    their subtrees' costs follow. Returns (status, checks): 0 done, 2 a limit (``limits``
    = (hard, soft), both counted from here) ended it."""
    new, best_p, best_c = node
    limit, soft = limits
    Q, parent, cost, child, sibling = T.Q, T.parent, T.cost, T.child, T.sibling
    checks = 0
    for a in range(cnt):
        v = X.nb_idx[a]
        if v == best_p or parent[v] < 0:
            continue
        through = best_c + math.sqrt(K.distance2(Q[new], Q[v], S.m.continuous))
        if through >= cost[v]:
            continue
        if checks >= soft:
            return 2, checks
        status, c, _ = edge_check(S.m, S.Z, Q[new], Q[v], joint_step, limit - checks)
        checks += c
        if status == LIMIT:
            return 2, checks
        if status == FREE:
            _unlink(child, sibling, parent[v], v)
            parent[v] = new
            sibling[v] = child[new]
            child[new] = v
            _shift_costs(cost, child, sibling, v, through - cost[v], T.stack)
            cost[v] = through
    return 0, checks


@kernel
def _update_best(S, T, sizes, counters, hard_checks, joint_step):
    """The best path to a goal state whose re-check fits the checks left: its goal node
    into counters[2], its re-check's checks into counters[3]."""
    if sizes[1] == 0:
        return
    b = counters[2]
    for g in range(sizes[1]):
        v = T.goal_nodes[g]
        if v != b and (b < 0 or T.cost[v] < T.cost[b]):
            held = _recheck_states(S, T, v, joint_step)
            if counters[1] + held <= hard_checks:
                b = v
                counters[3] = held
    if b >= 0 and b == counters[2]:
        counters[3] = _recheck_states(S, T, b, joint_step)
    counters[2] = b


@kernel
def _best_parent(S, T, X, target, near, cnt, limits):
    """The new node's parent: the neighbour of least cost through it whose edge is free
    (``near`` if none is cheaper). Returns (parent, cost, checks, code): code 0, or 2 the
    hard limit came (the node is dropped). ``limits`` = (hard, soft, joint_step)."""
    hard, soft, joint_step = limits
    Q, cost, continuous = T.Q, T.cost, S.m.continuous
    best_p = near
    best_c = cost[near] + math.sqrt(K.distance2(Q[near], target, continuous))
    _by_cost(cost, X.nb_idx, X.nb_d2, cnt)  # nb_d2 now: the cost through each, cheapest first
    checks = 0
    for a in range(cnt):
        p = X.nb_idx[a]
        if X.nb_d2[a] >= best_c:
            break
        if p == near:
            continue
        if checks >= soft:  # the chunk's end: the best parent so far
            break
        status, c, _ = edge_check(S.m, S.Z, Q[p], target, joint_step, hard - checks)
        checks += c
        if status == LIMIT:
            return best_p, best_c, checks, 2
        if status == FREE:
            return p, X.nb_d2[a], checks, 0
    return best_p, best_c, checks, 0


@kernel
def rrtstar_run(S, T, X, sizes, O, counters, limits):
    """RRT* iterations until a limit or a full tree.

    The tree T (:class:`StarTree`, ``sizes`` (2,): nodes, goal nodes), RRT*'s own
    settings X (:class:`Star`). A new node within ``range_rad`` of a goal state not in the
    tree tries the edge to it (the start too, first). ``counters`` (4,) int64:
    iterations, checks, the best goal node (-1: none yet), the held re-check checks of
    its path (never spent: the hard limit of an edge is the hard limit less them). Goal
    states are sampled with probability ``goal_bias``. Other limits and codes as
    :func:`~plannerlab.planners.native.kernels.rrtc_run` (``FULL``: fewer than 3 free
    rows)."""
    m = S.m
    q_rand = S.buf[0]
    target = S.buf[1]
    Q, goals = T.Q, X.goals
    soft_checks, hard_checks = limits[0], limits[1]
    range_rad, joint_step = O.f[2], O.f[3]
    goal_bias, k_factor = X.f[0], X.f[1]
    while True:
        hard = hard_checks - counters[3]  # the best path's re-check is not spent
        if counters[0] >= O.i[0]:
            return K.ITERATIONS
        if counters[1] >= hard:
            return K.HARD
        if counters[1] >= soft_checks:
            return K.CHUNK
        if Q.shape[0] - sizes[0] < 3 or T.goal_nodes.shape[0] - sizes[1] < 2:
            return K.FULL
        if counters[0] == 0:  # the start straight to a goal state
            status, c = _connect_goal(S, T, X, sizes, unliteral(0), O, hard - counters[1])
            counters[1] += c
            if status == LIMIT:
                return K.HARD
        counters[0] += 1
        to_goal = goals.shape[0] > 0 and K.uniform(S.rng) < goal_bias
        if to_goal:
            g = K.randint(S.rng, goals.shape[0])
            for i in range(q_rand.shape[0]):
                q_rand[i] = goals[g, i]
        else:
            K.sample(S.rng, m.lower, m.upper, m.continuous, O.guides, O.f[0], O.f[1], q_rand)
        n = sizes[0]
        near = K.nearest(Q, n, q_rand, m.continuous, m.continuous.any(), T.flags)
        if K.distance2(Q[near], q_rand, m.continuous) == 0.0:
            continue
        reached = K.steer(Q[near], q_rand, range_rad, m.continuous, S.buf[2], target)
        status, c, _ = edge_check(m, S.Z, Q[near], target, joint_step, hard - counters[1])
        counters[1] += c
        if status == LIMIT:
            return K.HARD
        if status != FREE:
            continue
        k = min(int(math.ceil(k_factor * math.log(n + 1.0))), X.nb_idx.shape[0])
        cnt = _k_nearest(Q, n, target, m.continuous, k, X.nb_idx, X.nb_d2)
        best_p, best_c, c, code = _best_parent(
            S, T, X, target, near, cnt,
            (hard - counters[1], soft_checks - counters[1], joint_step),
        )  # fmt: skip
        counters[1] += c
        if code == 2:  # the new node is dropped
            return K.HARD
        new = n
        for i in range(target.shape[0]):
            Q[new, i] = target[i]
        T.parent[new] = best_p
        T.cost[new] = best_c
        T.child[new] = -1
        T.sibling[new] = T.child[best_p]
        T.child[best_p] = new
        sizes[0] += 1
        if to_goal and reached:
            for g in range(goals.shape[0]):
                if X.goal_node_of[g] < 0 and K.distance2(goals[g], target, m.continuous) == 0.0:
                    X.goal_node_of[g] = new
                    T.goal_nodes[sizes[1]] = new
                    sizes[1] += 1
                    break
        else:  # the new node straight to a goal state within range
            status, c = _connect_goal(S, T, X, sizes, new, O, hard - counters[1])
            counters[1] += c
            if status == LIMIT:
                return K.HARD
        # rewire the neighbours through the new node (a limit ends the rewiring)
        status, c = _rewire(S, T, X, (new, best_p, best_c), cnt, joint_step,
                            (hard - counters[1], soft_checks - counters[1]))  # fmt: skip
        counters[1] += c
        _update_best(S, T, sizes, counters, hard_checks, joint_step)
        if status == 2:
            return K.HARD if counters[1] >= hard_checks - counters[3] else K.CHUNK
    return K.CHUNK


@kernel
def rrtstar_entry(P, aux, T, X, sizes, O, counters, limits):
    """:func:`rrtstar_run` on the packed model (a call from Python)."""
    return rrtstar_run(K.open_search(P, aux), T, X, sizes, O, counters, limits)


@kernel
def chain(Q, parent, node, out):
    """The path from the root to node into out; returns its number of states."""
    k = 0
    i = node
    while i >= 0:
        k += 1
        i = parent[i]
    i = node
    for r in range(k - 1, -1, -1):
        K.copy_row(out, r, Q, i)
        i = parent[i]
    return k


def rrtstar(solve: NativeSolve) -> PlanResult:
    """RRT* on the leg of ``solve`` until a limit: its best path, shortened and
    re-checked (see the module docstring)."""
    s, robot, q0 = solve.s, solve.robot, solve.q0
    if solve.ctx.start_problem is not None:
        return solve.result(Status.INVALID_START, solve.ctx.start_problem, q0[None])
    model = solve.checker.model
    solve.run.progress.note(float(solve.goal.distance(robot, q0)))
    G, failed = solve.goal_pool()
    if failed is not None:
        return failed
    rng_state = K.seed_state(solve.rng)
    dof = len(q0)
    extent = space_extent(model)
    range_rad = s.range_rad or 0.2 * extent
    solve.extra["range_rad"] = range_rad
    k_factor = s.rewire_factor * math.e * (1.0 + 1.0 / dof)  # type: ignore[attr-defined]
    cap = max(solve.tree_rows(solve.hard_checks(), 1, dof) * 2, 4)  # one tree: both halves
    solve.extra["tree_rows"] = cap
    rows = min(cap, FIRST_ROWS)
    tree: dict[str, np.ndarray] = {
        "Q": np.empty((rows, dof)),
        "parent": np.full(rows, -1, dtype=np.int64),
        "cost": np.zeros(rows),
        "child": np.full(rows, -1, dtype=np.int64),
        "sibling": np.full(rows, -1, dtype=np.int64),
        "goal_nodes": np.full(rows, -1, dtype=np.int64),
        "stack": np.empty(rows, dtype=np.int64),
        "flags": np.zeros(rows, dtype=np.int8),  # no node is ever dead here
    }
    tree["Q"][0] = q0
    sizes = np.array([1, 0], dtype=np.int64)
    counters = np.array([0, 0, -1, 0], dtype=np.int64)
    b = solve.budget
    max_it = UNLIMITED if b.max_iterations is None else b.max_iterations
    X = Star(
        G,
        np.full(len(G), -1, dtype=np.int64),
        np.array([s.goal_bias, k_factor]),  # type: ignore[attr-defined]
        np.empty(K_MAX, dtype=np.int64),
        np.empty(K_MAX),
    )
    O = solve.options(range_rad, max_it, 3)
    solve._charged = 0
    seen = [math.inf]

    def call(soft: int, hard: int) -> int:
        aux = solve.aux(rng_state, len(tree["Q"]))
        limits = np.array([soft, hard], dtype=np.int64)
        code = rrtstar_entry(solve.packed, aux, StarTree(**tree), X, sizes, O, counters, limits)
        best = int(counters[2])
        if best >= 0 and tree["cost"][best] < seen[0]:
            seen[0] = float(tree["cost"][best])
            solve.run.progress.note(goal_dist=0.0, cost=seen[0])
        return int(code)

    def stop() -> bool:
        if solve.out_of_time():
            return True
        held = int(counters[3]) if counters[2] >= 0 else 0
        return held > 0 and solve._time_reserve_reached(held)

    while True:
        code = solve.run_chunks(call, counters, stop)
        solve.iterations = int(counters[0])
        if code == K.FULL and len(tree["Q"]) < cap:
            grown = min(cap, 4 * len(tree["Q"]))
            for key, a in tree.items():
                bigger = np.full((grown,) + a.shape[1:], -1, dtype=a.dtype)
                bigger[: len(a)] = a
                tree[key] = bigger
            continue
        break
    solve.extra["planning_checks"] = int(counters[1])
    solve.extra["nodes"] = int(sizes[0])
    solve.extra["goal_nodes"] = int(sizes[1])
    best = int(counters[2])
    if best < 0:
        return solve.stopped(code, f"{int(sizes[0])} tree nodes, none at a goal state")
    out = np.empty((int(sizes[0]), dof))
    k = chain(tree["Q"], tree["parent"], best, out)
    path = out[:k].copy()
    solve.extra["waypoints_raw"] = k
    solve.extra["length_raw"] = path_length(path, robot.continuous)
    solve.extra["reserve_checks"] = int(counters[3])
    if s.simplify:
        path = solve.simplify(path, rng_state)
    return solve.checked(path)


__all__ = ["RESERVE_FACTOR", "Star", "StarTree", "rrtstar", "rrtstar_entry", "rrtstar_run"]

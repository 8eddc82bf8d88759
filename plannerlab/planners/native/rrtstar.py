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

import numpy as np
from numba import njit

from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native.solve import (
    FIRST_ROWS,
    RESERVE_FACTOR,
    UNLIMITED,
    K_views,
    NativeSolve,
    space_extent,
    writable_model,
)
from plannerlab.robots.paths import path_length

#: neighbours considered at most (the k of a million nodes is about 50)
K_MAX = 128


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def _unlink(child, sibling, p, c):
    """Remove c from p's children."""
    if child[p] == c:
        child[p] = sibling[c]
        return
    i = child[p]
    while sibling[i] != c:
        i = sibling[i]
    sibling[i] = sibling[c]


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def _recheck_states(Q, parent, node, joint_step, m, d):
    """The re-check's checks of the path from the root to node (1 + its grid states)."""
    total = 1
    while parent[node] >= 0:
        total += K.edge_states(Q[parent[node]], Q[node], joint_step, m, d)
        node = parent[node]
    return total


@njit(cache=True, nogil=True)
def _connect_goal(Q, parent, cost, child, sibling, goal_nodes, goal_node_of, sizes, new, goals,
                  range_rad, joint_step, m, V, S, buf, limit):  # fmt: skip
    """Try the edge from node ``new`` to its nearest goal state not yet in the tree, when
    it is within ``range_rad``: the goal state joins the tree. Returns (status, checks)
    as :func:`~plannerlab.planners.native.kernels.edge_free` (0 also when nothing was
    tried)."""
    best = -1
    best_d2 = range_rad * range_rad
    for g in range(goals.shape[0]):
        if goal_node_of[g] < 0:
            d2 = K.distance2(Q[new], goals[g], m.continuous)
            if d2 <= best_d2:
                best_d2 = d2
                best = g
    if best < 0:
        return 0, 0
    status, checks = K.edge_free(
        Q[new], goals[best], joint_step, m, V, S, buf[2], buf[3], limit, False
    )
    if status != 0:
        return status, checks
    v = sizes[0]
    Q[v] = goals[best]
    parent[v] = new
    cost[v] = cost[new] + math.sqrt(best_d2)
    child[v] = -1
    sibling[v] = child[new]
    child[new] = v
    sizes[0] += 1
    goal_nodes[sizes[1]] = v
    sizes[1] += 1
    goal_node_of[best] = v
    return 0, checks


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def _rewire(Q, parent, cost, child, sibling, stack, new, best_p, best_c, nb_idx, cnt,
            joint_step, m, V, S, buf, limit, soft):  # fmt: skip
    """Rewire the neighbours nb_idx[:cnt] through node ``new`` (of cost best_c) when that
    is shorter and the edge new -> neighbour is free; their subtrees' costs follow.
    Returns (status, checks): 0 done, 2 a limit (``limit`` hard, ``soft`` the chunk's,
    both counted from here) ended it."""
    checks = 0
    for a in range(cnt):
        v = nb_idx[a]
        if v == best_p or parent[v] < 0:
            continue
        through = best_c + math.sqrt(K.distance2(Q[new], Q[v], m.continuous))
        if through >= cost[v]:
            continue
        if checks >= soft:
            return 2, checks
        status, c = K.edge_free(
            Q[new], Q[v], joint_step, m, V, S, buf[2], buf[3], limit - checks, False
        )
        checks += c
        if status == 2:
            return 2, checks
        if status == 0:
            _unlink(child, sibling, parent[v], v)
            parent[v] = new
            sibling[v] = child[new]
            child[new] = v
            _shift_costs(cost, child, sibling, v, through - cost[v], stack)
            cost[v] = through
    return 0, checks


@njit(cache=True, nogil=True)
def _update_best(Q, parent, cost, goal_nodes, sizes, counters, hard_checks, joint_step, m, buf):
    """The best path to a goal state whose re-check fits the checks left: its goal node
    into counters[2], its re-check's checks into counters[3]."""
    if sizes[1] == 0:
        return
    b = counters[2]
    for g in range(sizes[1]):
        v = goal_nodes[g]
        if v != b and (b < 0 or cost[v] < cost[b]):
            held = _recheck_states(Q, parent, v, joint_step, m, buf[2])
            if counters[1] + held <= hard_checks:
                b = v
                counters[3] = held
    if b >= 0 and b == counters[2]:
        counters[3] = _recheck_states(Q, parent, b, joint_step, m, buf[2])
    counters[2] = b


@njit(cache=True, nogil=True)
def rrtstar_run(
    m,
    V,
    S,
    Q,
    parent,
    cost,
    child,
    sibling,
    goal_nodes,
    goal_node_of,
    flags,
    sizes,
    counters,
    rng,
    goals,
    goal_bias,
    guides,
    guide_bias,
    guide_sigma_rad,
    range_rad,
    joint_step,
    k_factor,
    max_iterations,
    soft_checks,
    hard_checks,
    buf,
    nb_idx,
    nb_d2,
    stack,
):
    """RRT* iterations until a limit or a full tree.

    The tree: Q (cap, dof) states, ``parent`` (-1 at the root, the start), ``cost``
    (joint-space length from the root), children lists (``child`` first child,
    ``sibling`` next sibling, -1 ends), ``goal_nodes`` the nodes that are goal states
    (``sizes`` (2,): nodes, goal nodes), ``goal_node_of`` (g,) the node of each goal
    state (-1: not in the tree), ``flags`` (cap,) int8 zeros (the nearest-node search's
    flags; RRT* checks its edges in full). A new node within ``range_rad`` of a goal state not in
    the tree tries the edge to it (the start too, first). ``counters`` (4,) int64:
    iterations, checks, the best goal node (-1: none yet), the held re-check checks of
    its path (never spent: the hard limit of an edge is ``hard_checks`` less them).
    ``goals`` (g, dof): the goal states, sampled with probability ``goal_bias``. Other
    limits and codes as :func:`~plannerlab.planners.native.kernels.rrtc_run` (``FULL``:
    fewer than 3 free rows)."""
    q_rand = buf[0]
    target = buf[1]
    while True:
        hard = hard_checks - counters[3]  # the best path's re-check is not spent
        if counters[0] >= max_iterations:
            return K.ITERATIONS
        if counters[1] >= hard:
            return K.HARD
        if counters[1] >= soft_checks:
            return K.CHUNK
        if Q.shape[0] - sizes[0] < 3 or goal_nodes.shape[0] - sizes[1] < 2:
            return K.FULL
        if counters[0] == 0:  # the start straight to a goal state
            status, c = _connect_goal(
                Q, parent, cost, child, sibling, goal_nodes, goal_node_of, sizes, 0, goals,
                range_rad, joint_step, m, V, S, buf, hard - counters[1],
            )  # fmt: skip
            counters[1] += c
            if status == 2:
                return K.HARD
        counters[0] += 1
        to_goal = goals.shape[0] > 0 and K.uniform(rng) < goal_bias
        if to_goal:
            q_rand[:] = goals[K.randint(rng, goals.shape[0])]
        else:
            K.sample(
                rng, m.lower, m.upper, m.continuous, guides, guide_bias, guide_sigma_rad, q_rand
            )
        n = sizes[0]
        near = K.nearest(Q, n, q_rand, m.continuous, m.continuous.any(), flags)
        if K.distance2(Q[near], q_rand, m.continuous) == 0.0:
            continue
        reached = K.steer(Q[near], q_rand, range_rad, m.continuous, buf[2], target)
        status, c = K.edge_free(
            Q[near], target, joint_step, m, V, S, buf[2], buf[3], hard - counters[1], False,
        )  # fmt: skip
        counters[1] += c
        if status == 2:
            return K.HARD
        if status == 1:
            continue
        # the parent: the neighbour of least cost through it whose edge is free
        k = min(int(math.ceil(k_factor * math.log(n + 1.0))), nb_idx.shape[0])
        cnt = _k_nearest(Q, n, target, m.continuous, k, nb_idx, nb_d2)
        best_p = near
        best_c = cost[near] + math.sqrt(K.distance2(Q[near], target, m.continuous))
        _by_cost(cost, nb_idx, nb_d2, cnt)  # nb_d2 now: the cost through each, cheapest first
        for a in range(cnt):
            p = nb_idx[a]
            if nb_d2[a] >= best_c:
                break
            if p == near:
                continue
            if counters[1] >= soft_checks:  # the chunk's end: the best parent so far
                break
            status, c = K.edge_free(
                Q[p], target, joint_step, m, V, S, buf[2], buf[3], hard - counters[1], False,
            )  # fmt: skip
            counters[1] += c
            if status == 2:  # the new node is dropped
                return K.HARD
            if status == 0:
                best_p = p
                best_c = nb_d2[a]
                break
        new = n
        Q[new] = target
        parent[new] = best_p
        cost[new] = best_c
        child[new] = -1
        sibling[new] = child[best_p]
        child[best_p] = new
        sizes[0] += 1
        if to_goal and reached:
            for g in range(goals.shape[0]):
                if goal_node_of[g] < 0 and K.distance2(goals[g], target, m.continuous) == 0.0:
                    goal_node_of[g] = new
                    goal_nodes[sizes[1]] = new
                    sizes[1] += 1
                    break
        else:  # the new node straight to a goal state within range
            status, c = _connect_goal(
                Q, parent, cost, child, sibling, goal_nodes, goal_node_of, sizes, new, goals,
                range_rad, joint_step, m, V, S, buf, hard - counters[1],
            )  # fmt: skip
            counters[1] += c
            if status == 2:
                return K.HARD
        # rewire the neighbours through the new node (a limit ends the rewiring)
        status, c = _rewire(Q, parent, cost, child, sibling, stack, new, best_p, best_c, nb_idx,
                            cnt, joint_step, m, V, S, buf, hard - counters[1],
                            soft_checks - counters[1])  # fmt: skip
        counters[1] += c
        _update_best(Q, parent, cost, goal_nodes, sizes, counters, hard_checks, joint_step, m,
                     buf)  # fmt: skip
        if status == 2:
            return K.HARD if counters[1] >= hard_checks - counters[3] else K.CHUNK
    return K.CHUNK


@njit(cache=True, nogil=True)
def chain(Q, parent, node, out):
    """The path from the root to node into out; returns its number of states."""
    k = 0
    i = node
    while i >= 0:
        k += 1
        i = parent[i]
    i = node
    for r in range(k - 1, -1, -1):
        out[r] = Q[i]
        i = parent[i]
    return k


def rrtstar(solve: NativeSolve) -> PlanResult:
    """RRT* on the leg of ``solve`` until a limit: its best path, shortened and
    re-checked (see the module docstring)."""
    s, robot, q0 = solve.s, solve.robot, solve.q0
    if solve.ctx.start_problem is not None:
        return solve.result(Status.INVALID_START, solve.ctx.start_problem, q0[None])
    model = writable_model(solve.checker.model)
    solve.run.progress.note(float(solve.goal.distance(robot, q0)))
    G, failed = solve.goal_pool()
    if failed is not None:
        return failed
    rng_state = K.seed_state(solve.rng)
    V, S = K_views(model)
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
    goal_node_of = np.full(len(G), -1, dtype=np.int64)
    buf = np.empty((4, dof))
    nb_idx = np.empty(K_MAX, dtype=np.int64)
    nb_d2 = np.empty(K_MAX)
    b = solve.budget
    max_it = UNLIMITED if b.max_iterations is None else b.max_iterations
    goal_bias = s.goal_bias  # type: ignore[attr-defined]
    solve._charged = 0
    seen = [math.inf]

    def call(soft: int, hard: int) -> int:
        t = tree
        code = rrtstar_run(
            model, V, S, t["Q"], t["parent"], t["cost"], t["child"], t["sibling"],
            t["goal_nodes"], goal_node_of, t["flags"], sizes, counters, rng_state, G, goal_bias,
            solve.guides, s.guide_bias, s.guide_sigma_rad, range_rad, solve.step, k_factor, max_it,
            soft, hard, buf, nb_idx, nb_d2, t["stack"],
        )  # fmt: skip
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
        path = solve.simplify(path, model, V, S, rng_state)
    return solve.checked(path)


__all__ = ["RESERVE_FACTOR", "rrtstar", "rrtstar_run"]

"""PRM and PRM* driven single-threaded: OMPL's ``PRM::solve`` checks for a solution in a
second thread, and with Python callbacks the wheel deadlocks there (the caller keeps the
GIL while joining). The roadmap grows in slices of termination polls (not OMPL's timed
``constructRoadmap``), then the start and the goal pool are joined to their nearest
roadmap vertices and the roadmap is searched with scipy's Dijkstra."""

from __future__ import annotations

from typing import Any

import numpy as np
import ompl.base as ob
import ompl.geometric as og
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from plannerlab.planners.ompl.guard import Guard
from plannerlab.planners.ompl.settings import OMPLSettings
from plannerlab.planners.ompl.space import Space
from plannerlab.robots.base import Array


def roadmap_solve(
    planner: Any,
    settings: OMPLSettings,
    si: Any,
    space: Space,
    guard: Guard,
    pool: list[Array],
    q0: Array,
    joint_step: float,
) -> tuple[Any, bool, str]:
    """PRM / PRM* without OMPL's solution thread (see the package docstring): the path
    (an OMPL path, or None), whether it is exact, and OMPL's status in words."""
    k = getattr(settings, "max_nearest_neighbors", 10)
    slice_polls = settings.roadmap_slice_polls  # type: ignore[attr-defined]
    if not pool:
        return None, False, "no goal states to connect"
    while True:
        # OMPL's constructRoadmap alternates growing and expanding in *timed* sub-slices
        # (so the roadmap would depend on the machine's load): do the alternation here,
        # sliced by termination polls, which are deterministic.
        grow_until = guard.polls + max(1, (2 * slice_polls) // 3)
        planner.growRoadmapPtc(
            ob.PlannerTerminationCondition(lambda s=grow_until: guard.poll() or guard.polls >= s)
        )
        expand_until = guard.polls + max(1, slice_polls // 3)
        planner.expandRoadmapPtc(
            ob.PlannerTerminationCondition(lambda s=expand_until: guard.poll() or guard.polls >= s)
        )
        if guard.out_of_time():
            return None, False, "Timeout"  # no search of a roadmap grown past the time
        data = ob.PlannerData(si)
        planner.getPlannerData(data)
        n = data.numVertices()
        if n:
            V = np.array([space.to_q(data.getVertex(i).getState()) for i in range(n)])
            rows, cols = [], []
            for i in range(n):
                for j in data.getEdges(i):
                    rows.append(i)
                    cols.append(int(j))
            special = [q0, *pool]  # index n = start, n+1.. = goals
            extra_rows, extra_cols, extra_w = [], [], []
            for m, q in enumerate(special):
                dist = space.metric(V, q)
                for i in np.argsort(dist)[:k]:
                    if guard.edge_valid(q, V[i], joint_step):
                        extra_rows.append(n + m)
                        extra_cols.append(int(i))
                        extra_w.append(float(dist[i]))
            allV = np.vstack([V, np.array(special)])
            r = np.array(rows + extra_rows, dtype=int)
            c = np.array(cols + extra_cols, dtype=int)
            if len(r):
                w = (
                    np.concatenate(
                        [space.pair_metric(allV[r[: len(rows)]], allV[c[: len(rows)]]), extra_w]
                    )
                    + 1e-12
                )
                size = len(allV)
                graph = coo_matrix((w, (r, c)), shape=(size, size)).tocsr()
                dist_from_start, pred = dijkstra(
                    graph, directed=False, indices=n, return_predecessors=True
                )
                goals = np.arange(n + 1, size)
                reachable = goals[np.isfinite(dist_from_start[goals])]
                if len(reachable):
                    g = int(reachable[np.argmin(dist_from_start[reachable])])
                    chain = [g]
                    while chain[-1] != n:
                        chain.append(int(pred[chain[-1]]))
                    path = og.PathGeometric(si)
                    for idx in reversed(chain):
                        st = space.space.allocState()
                        space.set_state(st, allV[idx])
                        path.append(st)
                    return path, True, "Exact solution"
        if guard.exhausted() is not None:
            return None, False, "Timeout"

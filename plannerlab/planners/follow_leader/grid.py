"""Follow-the-leader's search for the tip: the scene's signed distance on a voxel grid
(capped in size), and the shortest path for the tip through the free voxels
(:func:`tip_path`, scipy's Dijkstra on the 26-connected graph), corners cut where the
straight line keeps the clearance. Used by :mod:`plannerlab.planners.follow_leader` (see
its module docstring) and the leader-guided sampler."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from plannerlab.errors import PlannerlabError
from plannerlab.planners.clearance.slide import scene_distance_m
from plannerlab.problem.scene import Box, Scene
from plannerlab.robots.base import Array


def grid_distance_m(scene: Scene, axes: list[Array], cap_m: float) -> Array:
    """Obstacle distances [m] at the points of the grid ``axes`` (three 1-D arrays of
    coordinates), exact up to ``cap_m`` and ``inf`` beyond it: each obstacle is measured
    only in the block of the grid within ``cap_m`` of its bounding box."""
    shape = tuple(len(a) for a in axes)
    d = np.full(shape, np.inf)
    for o in scene.obstacles:
        T = o.T_world_obstacle
        half = o.half_extents_world()
        block = []
        for k in range(3):
            lo = np.searchsorted(axes[k], T[k, 3] - half[k] - cap_m, side="left")
            hi = np.searchsorted(axes[k], T[k, 3] + half[k] + cap_m, side="right")
            block.append(slice(int(lo), int(hi)))
        if any(b.start >= b.stop for b in block):
            continue
        sub = [axes[k][block[k]] for k in range(3)]
        if isinstance(o, Box) and np.allclose(np.abs(T[:3, :3]), np.eye(3)):
            # an axis-aligned box: separable, no point array needed
            qx, qy, qz = ((np.abs(sub[k] - T[k, 3]) - o.size_m[k] / 2.0) for k in range(3))
            qx, qy, qz = qx[:, None, None], qy[None, :, None], qz[None, None, :]
            di = np.sqrt(
                np.maximum(qx, 0.0) ** 2 + np.maximum(qy, 0.0) ** 2 + np.maximum(qz, 0.0) ** 2
            ) + np.minimum(np.maximum(np.maximum(qx, qy), qz), 0.0)
        else:
            pts = np.stack(np.meshgrid(*sub, indexing="ij"), axis=-1).reshape(-1, 3)
            di = scene_distance_m(Scene((o,)), pts).reshape(tuple(len(a) for a in sub))
        view = d[block[0], block[1], block[2]]
        np.minimum(view, di, out=view)
    d[d > cap_m] = np.inf
    return d


def grid_voxels(extent_m: Array, voxel_m: float) -> int:
    """Voxels of the search grid over a box of ``extent_m`` (3,) [m] with edge ``voxel_m``
    (one more per axis for the grid's shift, as :func:`tip_path` lays it)."""
    shape = np.maximum(np.ceil(np.asarray(extent_m, dtype=float) / voxel_m).astype(int) + 2, 2)
    return int(np.prod(shape.astype(float)))


def grid_voxel_m(
    extent_m: Array, voxel_m: float, max_voxels: int, *, voxel_set: bool = False
) -> float:
    """The voxel edge [m] of a search grid over a box of ``extent_m`` (3,): ``voxel_m``
    when its grid holds at most ``max_voxels`` voxels, else the smallest edge whose grid
    does (coarser: the path keeps its clearance, it only finds narrower gaps less well).
    A ``voxel_m`` the user set (``voxel_set``) that passes the cap: PlannerlabError."""
    if grid_voxels(extent_m, voxel_m) <= max_voxels:
        return float(voxel_m)
    if voxel_set:
        raise PlannerlabError(
            f"follow-the-leader: voxel_m = {voxel_m:g} m gives a search grid of "
            f"{grid_voxels(extent_m, voxel_m):.3g} voxels over a box of "
            f"{np.round(np.asarray(extent_m, dtype=float), 3).tolist()} m, more than "
            f"max_voxels = {max_voxels}: set a coarser voxel_m (or leave it at 0: "
            "coarsened to fit)"
        )
    edge = float(voxel_m)
    while grid_voxels(extent_m, edge) > max_voxels:
        # the edge at which the volume alone would fit, then a little more for the ceilings
        vol = float(np.prod(np.maximum(np.asarray(extent_m, dtype=float), edge)))
        edge = max(edge * 1.01, (vol / max_voxels) ** (1.0 / 3.0))
    return edge


#: the 13 grid offsets of a 26-neighbourhood, one of each opposite pair
_OFFSETS = np.array(
    [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) > (0, 0, 0)]
)


@dataclass(frozen=True)
class TipPath:
    """The leader's path.

    Attributes:
        points_m: (m, 3) from the start tip to the goal, the last two the approach point
            and the goal point [m].
        arc_m: (m,) arc length at each point [m].
        min_distance_m: the smallest obstacle distance of the grid part [m].
        free_voxels: how many voxels of the search box were free.
    """

    points_m: Array
    arc_m: Array
    min_distance_m: float
    free_voxels: int


def tip_path(
    scene: Scene,
    start_m: Array,
    goal_m: Array,
    goal_n: Array,
    *,
    clearance_m: float,
    approach_m: float,
    voxel_m: float,
    centre_m: float,
    centre_weight: float,
    pad_m: float,
    reach_centre_m: Array,
    reach_m: float,
    offset_m: Array | None = None,
    stop: Callable[[], bool] | None = None,
    max_voxels: int | None = None,
    voxel_set: bool = False,
) -> TipPath | None:
    """The leader's path from ``start_m`` to the approach point ``goal_m − approach_m ·
    goal_n`` on the free voxels (obstacle distance >= ``clearance_m``), then to ``goal_m``;
    None when the two are not connected. The start and the approach point are joined to
    their nearest free voxel (a tip that starts close to a wall). See the module docstring.
    ``stop()`` is asked between the stages (distances, graph, search): True gives None.
    The grid holds at most ``max_voxels`` voxels (:func:`grid_voxel_m`): a finer
    ``voxel_m`` is coarsened to fit, or, when the user set it (``voxel_set``), refused.
    """
    start = np.asarray(start_m, dtype=float)
    goal = np.asarray(goal_m, dtype=float)
    approach = goal - approach_m * np.asarray(goal_n, dtype=float)
    pts = np.vstack([start, approach, goal, reach_centre_m])
    lo = np.min(pts, axis=0) - pad_m
    hi = np.max(pts, axis=0) + pad_m
    lo = np.maximum(lo, np.asarray(reach_centre_m) - reach_m)
    hi = np.minimum(hi, np.asarray(reach_centre_m) + reach_m)
    if max_voxels is not None:
        voxel_m = grid_voxel_m(hi - lo, voxel_m, max_voxels, voxel_set=voxel_set)
    lo = lo + (np.zeros(3) if offset_m is None else np.asarray(offset_m) - voxel_m)
    shape = np.maximum(np.ceil((hi - lo) / voxel_m).astype(int) + 1, 2)
    axes = [lo[k] + voxel_m * np.arange(shape[k]) for k in range(3)]
    dist = grid_distance_m(scene, axes, max(centre_m, clearance_m) + voxel_m)
    free = dist >= clearance_m
    n_free = int(free.sum())
    if n_free == 0 or (stop is not None and stop()):
        return None
    index = np.full(tuple(shape), -1, dtype=np.int64)
    index[free] = np.arange(n_free)
    ijk = np.argwhere(free)
    w_node = 1.0 + centre_weight * np.maximum(0.0, 1.0 - dist[free] / centre_m)
    rows, cols, vals = [], [], []
    for off in _OFFSETS:
        if stop is not None and stop():  # the graph's 13 directions: a poll each
            return None
        nb = ijk + off
        ok = np.all((nb >= 0) & (nb < shape), axis=1)
        a = np.flatnonzero(ok)
        b = index[nb[ok, 0], nb[ok, 1], nb[ok, 2]]
        keep = b >= 0
        a, b = a[keep], b[keep]
        length = voxel_m * float(np.linalg.norm(off))
        rows.append(a)
        cols.append(b)
        vals.append(length * 0.5 * (w_node[a] + w_node[b]))
    graph = coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_free, n_free),
    ).tocsr()
    centres = lo + voxel_m * ijk
    if stop is not None and stop():
        return None

    def nearest(p: Array) -> int:
        return int(np.argmin(np.linalg.norm(centres - p, axis=1)))

    i0, i1 = nearest(start), nearest(approach)
    cost, pred = dijkstra(graph, directed=False, indices=i0, return_predecessors=True)
    if not np.isfinite(cost[i1]) or (stop is not None and stop()):
        return None
    chain = [i1]
    while chain[-1] != i0:
        chain.append(int(pred[chain[-1]]))
    grid_pts = centres[chain[::-1]]
    points = np.vstack([start, grid_pts, approach, goal])
    # drop repeated points (start or approach on a voxel centre)
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate([[True], seg > 1e-9])]
    points = _shortcut(points, scene, clearance_m, voxel_m / 3)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return TipPath(points, arc, float(dist[free][chain].min()), n_free)


def joined(first: TipPath, second: TipPath) -> TipPath:
    """The leader's path ``first`` (ending at a waypoint) then ``second`` (from it): the
    waypoint stays a corner (no shortcut across it; that is what it is for)."""
    points = np.vstack([first.points_m, second.points_m[1:]])
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate([[True], seg > 1e-9])]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return TipPath(
        points,
        arc,
        min(first.min_distance_m, second.min_distance_m),
        max(first.free_voxels, second.free_voxels),
    )


def _shortcut(points: Array, scene: Scene, clearance_m: float, step_m: float) -> Array:
    """The path with every point skipped whose neighbours see each other with the same
    clearance (greedy, from the start; the first and last two points kept)."""
    if len(points) <= 3:
        return points
    keep = [0]
    i = 0
    last = len(points) - 2  # the approach point
    while i < last:
        j = last
        while j > i + 1:
            a, b = points[i], points[j]
            n = max(2, int(np.ceil(np.linalg.norm(b - a) / step_m)) + 1)
            line = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
            # the start may be closer to a wall than clearance_m: do not ask more than it has
            need = min(clearance_m, float(scene_distance_m(scene, a[None])[0]))
            if float(scene_distance_m(scene, line).min()) >= need - 1e-9:
                break
            j -= 1
        keep.append(j)
        i = j
    keep.append(len(points) - 1)
    return points[keep]


# ---------------------------------------------------------------------- the planner

"""Follow-the-leader: a path for the tip through free workspace, tracked by the clearance
descent, so the body follows the tip through a window.

The clearance descent (:mod:`plannerlab.planners.gradient_clearance`) pulls the tip
straight at the goal; in a room entered through a window it presses the tip against the
outside of the wall, at the point nearest the goal, and stalls there (measured on
``armz_deep_a``: 2 m from the goal, the window 3.7 m to the side; no retract of its
detour leads through the window). A hyper-redundant arm's classic answer is
follow-the-leader:

1. **The leader's path** (:func:`tip_path`): a shortest path for the tip on a voxel grid
   of the scene's signed distance, from the tip of the start state to the goal's approach
   point ``p_d − approach_m · n_d`` (then along the goal's normal into the goal). Only
   voxels whose centre is at least the tip module's radius plus the problem's safety
   margin plus ``extra_clearance_m`` from every obstacle are free, and
   a step costs its length times ``1 + centre_weight · max(0, 1 − d / centre_m)``, so the
   path keeps to the middle of a window rather than grazing its frame. The search is
   :func:`scipy.sparse.csgraph.dijkstra` on the 26-connected graph of free voxels, in a
   box round the start tip, the approach point, the goal and the base (``pad_m``, within
   the arm's reach); corners are then cut where the straight line keeps the clearance.
2. **The body follows** (:class:`FollowLeader`): the clearance descent
   (:meth:`~plannerlab.planners.gradient_clearance.ClearanceDescent.descend`, its public
   entry point) tracks a sub-goal that moves along the path (:meth:`FollowLeader.subgoals`):
   to the path's first corner (the tip turns there as the descent takes it), then along
   every later segment every ``stride_m``, looking along it, each within
   ``subgoal_pos_tol_m`` and ``subgoal_angle_tol_deg``: the tip advances along its own
   normal and the descent's clearance term keeps the body off the window's frame while
   the tip leads it in. A sub-goal the descent stalls before is passed over; two in a row
   end the tracking.
3. **The finish** is the clearance descent of the leg
   (:meth:`~plannerlab.planners.gradient_clearance.ClearanceDescent.leg_descent`) from the
   state the tracking reached (its approach point, then the goal, with its settling); if
   it stalls, the ``+detour`` variant hands the stall to the descent's own ``plan`` with
   its detour escape (a sub-solve in the leg's context). Where no leader's path exists
   (no way for the tip at that clearance), the finish alone runs: the planner is then the
   clearance descent.

4. **Leaving from deep inside** (``retract``, on by default): the voxel grid knows the
   scene, not the body. From the far wall of a room the leader's path leads the tip back
   across the room and out through the window that its own body fills, and the tracking
   stalls at the second sub-goal (measured on the far-ended variants
   ``problems/variants/armz_inspection_v21`` … ``v39``, leaving from B: 5 of 10 stall
   so; ``gradient.clearance+detour`` stalls at its eighth iteration and no retract of its
   detour works on 6 of 10). What got the body in gets it out: the body lies on the curve
   its tip came in by, so the tip is drawn back along the start's own body
   (:meth:`FollowLeader.retract`: sub-goals at its faces from the tip's towards the
   base's, each looking along the body) until it sees the goal's approach point, then
   the leader's path from there. It comes first when the leader's path runs back
   through the body (:func:`crosses_body`), else after the forward tries.

The search and the tracking are deterministic (``gradient.follow_leader``: its seeds are
one run). The randomised variant (``+random``, ``random_grid``) shifts the voxel grid by
a random fraction of a voxel and scales the centring weight by the seed's draw, and draws
a new leader path from where a try ended (``max_replans`` times), so its seeds are
different runs and a success rate over them says how often the method works.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from plannerlab.errors import PlannerlabError
from plannerlab.planners import leader_moves
from plannerlab.planners.base import (
    Planner,
    PlanResult,
    Status,
    settings_dict,
    with_overrides,
)
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.gradient_clearance import ClearanceDescent, ClearanceSettings, LegPath
from plannerlab.planners.leader_moves import Track, crosses_body
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import Array, joint_difference


@dataclass(frozen=True)
class FollowLeaderSettings:
    """Settings of follow-the-leader.

    Attributes:
        voxel_m: edge of the search grid's voxels [m]; 0: half the tip module's radius.
        extra_clearance_m: clearance the tip path keeps beyond the tip module's radius and
            the problem's safety margin [m].
        centre_m: distance from the obstacles below which a path step costs more [m].
        centre_weight: how much more: a step at distance d costs its length times
            ``1 + centre_weight · max(0, 1 − d / centre_m)``.
        pad_m: the search box reaches this far beyond the start tip, the goal, its
            approach point and the arm's base [m] (and never beyond the arm's reach from
            its base); doubled while no path is found, up to the reach.
        approach_m: the path ends at ``p_d − approach_m · n_d``, the goal's approach point.
        subgoal_pos_tol_m, subgoal_angle_tol_deg: tolerances of the moving sub-goal.
        stride_m: spacing of the sub-goals along the path's segments after its first [m].
        track_approach: also sub-goals every ``stride_m`` from the approach point towards
            the goal, looking along the goal's normal (the finish then starts closer).
        escape: "none" or "detour" (the clearance descent's detour from a stall).
        random_grid: shift the grid by a random fraction of a voxel and scale
            ``centre_weight`` by a random factor in [0.5, 1.5] (the seed's draw).
        max_replans: (``random_grid``) new leader paths drawn from where a try ended.
        retract: when the tries from the start end in a stall, one more try from the
            start: the tip drawn back along the start's own body first
            (:meth:`FollowLeader.retract`), then the leader's path from there.

    The clearance descent's settings are its own (:class:`ClearanceSettings`), overridden
    as ``descent.<key>``.
    """

    voxel_m: float = 0.0
    extra_clearance_m: float = 0.05
    centre_m: float = 1.5
    centre_weight: float = 4.0
    pad_m: float = 3.0
    approach_m: float = 2.5
    subgoal_pos_tol_m: float = 0.5
    subgoal_angle_tol_deg: float = 45.0
    stride_m: float = 1.0
    track_approach: bool = False
    escape: str = "none"
    random_grid: bool = False
    max_replans: int = 3
    retract: bool = True

    def __post_init__(self) -> None:
        if not self.voxel_m >= 0:
            raise PlannerlabError(f"voxel_m must be >= 0, got {self.voxel_m}")
        if self.escape not in ("none", "detour"):
            raise PlannerlabError(f"escape setting: 'none' or 'detour', got {self.escape!r}")
        for key in ("stride_m", "subgoal_pos_tol_m", "centre_m"):
            if not getattr(self, key) > 0:
                raise PlannerlabError(f"{key} must be > 0, got {getattr(self, key)}")
        if self.max_replans < 0:
            raise PlannerlabError(f"max_replans must be >= 0, got {self.max_replans}")


# ---------------------------------------------------------------------- workspace search
def scene_distance_m(scene: Scene, points_m: Array) -> Array:
    """Signed distance [m] of points (k, 3) to the nearest obstacle (inf without any)."""
    p = np.asarray(points_m, dtype=float).reshape(-1, 3)
    d = np.full(len(p), np.inf)
    for o in scene.obstacles:
        T = o.T_world_obstacle
        local = (p - T[:3, 3]) @ T[:3, :3]
        if isinstance(o, Box):
            q = np.abs(local) - o.size_m / 2.0
            di = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
        elif isinstance(o, Cylinder):
            q = np.stack(
                [
                    np.hypot(local[:, 0], local[:, 1]) - o.radius_m,
                    np.abs(local[:, 2]) - o.length_m / 2,
                ],
                axis=1,
            )
            di = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
        elif isinstance(o, Sphere):
            di = np.linalg.norm(local, axis=1) - o.radius_m
        else:  # pragma: no cover - the scene's types are closed
            raise PlannerlabError(f"obstacle {o.name}: unknown kind {o.kind!r}")
        d = np.minimum(d, di)
    return d


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
) -> TipPath | None:
    """The leader's path from ``start_m`` to the approach point ``goal_m − approach_m ·
    goal_n`` on the free voxels (obstacle distance >= ``clearance_m``), then to ``goal_m``;
    None when the two are not connected. The start and the approach point are joined to
    their nearest free voxel (a tip that starts close to a wall). See the module docstring.
    ``stop()`` is asked between the stages (distances, graph, search): True gives None.
    """
    start = np.asarray(start_m, dtype=float)
    goal = np.asarray(goal_m, dtype=float)
    approach = goal - approach_m * np.asarray(goal_n, dtype=float)
    pts = np.vstack([start, approach, goal, reach_centre_m])
    lo = np.min(pts, axis=0) - pad_m
    hi = np.max(pts, axis=0) + pad_m
    lo = np.maximum(lo, np.asarray(reach_centre_m) - reach_m)
    hi = np.minimum(hi, np.asarray(reach_centre_m) + reach_m)
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
class FollowLeader(LegPlanner):
    """Follow-the-leader with the clearance descent (see the module docstring). The
    tracking, the finish and the detour are descents in the leg's context: one checker,
    one tracker."""

    def __init__(
        self,
        name: str,
        settings: FollowLeaderSettings,
        descent: ClearanceSettings,
        escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
    ) -> None:
        self.name = name
        self.settings = settings
        self.descent_settings = descent
        # the tracking descent: no approach of its own, done as soon as inside the sub-goal
        self._track = ClearanceDescent(
            name, replace(descent, approach_m=0.0, goal_depth=1.0, settle_iterations=0)
        )
        self._finish = ClearanceDescent(name, replace(descent, escape="none"))
        self._detour = ClearanceDescent(name, replace(descent, escape="detour"), escape_planner)

    def warm_up(self, problem, leg: int, q_start: Array) -> None:
        """The fields of the tracking and the finishing descents (their compiled kernels
        loaded), before the leg's tracker starts: one-off costs outside the limits."""
        goal = problem.goal(leg)
        for descent in (self._track, self._finish):
            descent.model(problem).warm_up(goal, q_start)

    def leader_path(
        self,
        problem,
        leg: int,
        q: Array,
        rng: np.random.Generator | None,
        stop: Callable[[], bool] | None = None,
        goal: GoalRegion | None = None,
    ) -> TipPath | None:
        """The leader's path from the tip of ``q`` into leg's goal, or into ``goal`` when
        given (randomised with rng; None when there is none, or ``stop()`` said so)."""
        s = self.settings
        robot = problem.robot
        goal = problem.goal(leg) if goal is None else goal
        p_tip, _ = robot.tip(q)
        F0 = robot.fk(q)
        base = F0[0, :3, 3]
        reach = float(np.sum(np.linalg.norm(np.diff(F0[:, :3, 3], axis=0), axis=1)))
        r_tip = float(np.asarray(robot.link_radii_m)[-1])
        voxel = s.voxel_m if s.voxel_m > 0 else 0.5 * r_tip
        offset = None
        weight = s.centre_weight
        if rng is not None:
            offset = rng.uniform(0.0, voxel, size=3)
            weight = s.centre_weight * float(rng.uniform(0.5, 1.5))
        pad = s.pad_m
        while True:
            leader = tip_path(
                problem.scene,
                p_tip,
                goal.p_world_m,
                goal.n_world,
                clearance_m=r_tip + problem.safety_margin_m + s.extra_clearance_m,
                approach_m=s.approach_m,
                voxel_m=voxel,
                centre_m=s.centre_m,
                centre_weight=weight,
                pad_m=pad,
                reach_centre_m=base,
                reach_m=reach,
                offset_m=offset,
                stop=stop,
            )
            if leader is not None or pad >= reach or (stop is not None and stop()):
                return leader
            pad = min(2.0 * pad, reach)

    def subgoals(self, leader: TipPath) -> list[tuple[Array, Array]]:
        """The sub-goals along the leader's path, up to its approach point: each corner of
        the path, looking along the segment after it, and points every ``stride_m`` along
        every segment after the first, looking along it (the tip goes to the first corner
        as the descent takes it, then advances along its own normal). The approach
        point looks along the goal's normal."""
        s = self.settings
        pts = leader.points_m
        out: list[tuple[Array, Array]] = []
        last = len(pts) - 2  # the approach point
        for i in range(1, last + 1):
            a, b = pts[i - 1], pts[i]
            d = b - a
            length = float(np.linalg.norm(d))
            if length < 1e-9:
                continue
            u = d / length
            if i > 1:
                n_mid = int(np.floor(length / s.stride_m))
                for k in range(1, n_mid + 1):
                    t = k * s.stride_m
                    if t < length - 0.5 * s.stride_m:
                        out.append((a + t * u, u))
            nxt = pts[i + 1] - b
            nn = float(np.linalg.norm(nxt))
            out.append((b, nxt / nn if nn > 1e-9 else u))
        if s.track_approach:
            a, b = pts[-2], pts[-1]
            length = float(np.linalg.norm(b - a))
            if length > 1e-9:
                u = (b - a) / length
                k = 1
                while k * s.stride_m < length - 0.5 * s.stride_m:
                    out.append((a + k * s.stride_m * u, u))
                    k += 1
        return out

    def _follow(
        self, ctx: PlanningContext, q0: Array, leader: TipPath, used: int
    ) -> tuple[Status, str, list[Array], int]:
        """Descend to each sub-goal along the leader's path in turn (:meth:`subgoals`); a
        sub-goal the descent stalls before is passed over, two in a row end the tracking."""
        s = self.settings
        path = [np.array(q0)]
        iterations = 0
        goals = self.subgoals(leader)
        stalls = 0
        for k, (p_sub, n_sub) in enumerate(goals):
            sub = GoalRegion(
                f"leader{k}", p_sub, n_sub, s.subgoal_pos_tol_m, s.subgoal_angle_tol_deg
            )
            st, reason, seg, _, it = self._track.descend(ctx, path[-1], sub, used + iterations)
            iterations += it
            path.extend(seg[1:])
            if st is Status.LOCAL_MINIMUM:
                stalls += 1
                if stalls >= 2:
                    return (
                        st,
                        f"tracking stalled at sub-goal {k + 1} of {len(goals)}: {reason}",
                        path,
                        iterations,
                    )
                continue
            if st is not Status.SOLVED:
                return st, reason, path, iterations
            stalls = 0
        return Status.SOLVED, f"followed {len(goals)} sub-goals", path, iterations

    def track(
        self,
        ctx: PlanningContext,
        q0: Array,
        goal: GoalRegion,
        rng: np.random.Generator | None,
        used: int = 0,
        leader: TipPath | None = None,
    ) -> Track:
        """:func:`plannerlab.planners.leader_moves.track` with this planner."""
        return leader_moves.track(self, ctx, q0, goal, rng, used, leader)

    def sees_approach(self, ctx: PlanningContext, q: Array) -> bool:
        """Whether the straight line from the tip of ``q`` to the leg goal's approach
        point keeps the leader's clearance from the scene (the retract has got the tip
        out)."""
        s = self.settings
        goal, robot = ctx.goal, ctx.robot
        p_tip, _ = robot.tip(q)
        approach = goal.p_world_m - s.approach_m * goal.n_world
        clearance = (
            float(np.asarray(robot.link_radii_m)[-1])
            + ctx.problem.safety_margin_m
            + s.extra_clearance_m
        )
        n = max(2, int(np.ceil(np.linalg.norm(approach - p_tip) / 0.1)) + 1)
        line = p_tip + np.linspace(0.0, 1.0, n)[:, None] * (approach - p_tip)
        return bool(scene_distance_m(ctx.scene, line).min() >= clearance)

    def retract(self, ctx: PlanningContext, q0: Array, used: int = 0) -> Track:
        """:func:`plannerlab.planners.leader_moves.retract` with this planner."""
        return leader_moves.retract(self, ctx, q0, used)

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leader's path, follow it, finish with the leg's descent."""
        s = self.settings
        problem, leg, robot, goal, tracker = ctx.problem, ctx.leg, ctx.robot, ctx.goal, ctx.tracker
        q0 = ctx.q_start
        leg_path = LegPath(ctx.run(self.name, s), q0)
        path = leg_path.path
        log: list[dict] = []

        def done(status: Status, reason: str) -> PlanResult:
            return leg_path.result(
                status,
                reason,
                extra={"leader": log, "descent_settings": settings_dict(self.descent_settings)},
            )

        if ctx.start_problem is not None:
            return done(Status.INVALID_START, ctx.start_problem)
        leg_path.note([q0])
        draw_rng = rng if s.random_grid else None
        attempts = 1 + (s.max_replans if s.random_grid else 0)
        reason = ""
        retracted = ""

        def retract_from_start() -> PlanResult | None:
            """The path reset to the start, then the tip drawn back along its own body."""
            nonlocal retracted
            del path[1:]
            tr = self.retract(ctx, q0, leg_path.iterations)
            leg_path.iterations += tr.iterations
            leg_path.add(tr.states)
            retracted = tr.reason
            log.append({"attempt": "retract", "retract": tr.reason})
            if tr.status is Status.BUDGET_EXHAUSTED:
                return done(tr.status, tr.reason)
            return None

        for attempt in range(attempts + (1 if s.retract else 0)):
            if attempt == attempts:
                # one more try: from the start, the tip drawn back along its own body
                if retracted or tracker.exhausted(leg_path.iterations) is not None:
                    break
                out = retract_from_start()
                if out is not None:
                    return out
            q = np.array(path[-1])
            if goal.contains(robot, q):
                return done(Status.SOLVED, "in the goal region")
            used = leg_path.iterations

            def stop(used: int = used) -> bool:
                return tracker.exhausted(used) is not None

            leader = self.leader_path(problem, leg, q, draw_rng, stop)
            if (
                s.retract
                and not retracted
                and attempt == 0
                and leader is not None
                and crosses_body(robot, q0, leader)
                and not self.sees_approach(ctx, q0)
            ):
                # the leader leads the tip back through its own body: retract first
                out = retract_from_start()
                if out is not None:
                    return out
                q = np.array(path[-1])
                if goal.contains(robot, q):
                    return done(Status.SOLVED, f"{retracted}; in the goal region")
                leader = self.leader_path(problem, leg, q, draw_rng, stop)
            if tracker.exhausted(leg_path.iterations) is not None:
                return done(Status.BUDGET_EXHAUSTED, str(tracker.exhausted(leg_path.iterations)))
            entry: dict = {
                "attempt": attempt,
                "from_leg_start_rad": float(
                    np.linalg.norm(joint_difference(q, q0, robot.continuous))
                ),
            }
            log.append(entry)
            if leader is None:
                # no way for the tip at that clearance: the descent alone, as
                # gradient.clearance would go
                entry["leader"] = "none"
                reason = "no path for the tip through free workspace"
            else:
                entry["leader_m"] = float(leader.arc_m[-1])
                entry["leader_clearance_m"] = leader.min_distance_m
                st, reason, seg, it = self._follow(ctx, q, leader, leg_path.iterations)
                leg_path.iterations += it
                leg_path.add(seg)
                entry["follow"] = st.value
                if st is Status.BUDGET_EXHAUSTED:
                    return done(st, reason)
            # finish: the clearance descent of the leg from here (approach point, goal)
            st2, reason2, seg2, _, it2 = self._finish.leg_descent(
                ctx, np.array(path[-1]), leg_path.iterations
            )
            leg_path.iterations += it2
            leg_path.add(seg2)
            entry["finish"] = st2.value
            if st2 is Status.SOLVED:
                first = f"{retracted}; " if retracted else ""
                return done(st2, f"{first}followed the leader ({reason}); {reason2}")
            if st2 is not Status.LOCAL_MINIMUM:
                return done(st2, reason2)
            leg_path.minima += 1
            reason = f"{reason}; finish: {reason2}"
            if s.escape == "detour":
                # the clearance descent's own plan from the stall, with its detour: a
                # sub-solve in the leg's context (its checks are the leg's)
                sub = tracker.remaining(limit_iterations=False)
                if sub is None:
                    return done(
                        Status.BUDGET_EXHAUSTED, str(tracker.exhausted(leg_path.iterations))
                    )
                b = tracker.budget
                if b.max_iterations is not None:
                    sub = sub.replace(max_iterations=max(b.max_iterations - leg_path.iterations, 1))
                r = self._detour.plan(ctx.sub(sub, np.array(path[-1])), rng)
                leg_path.iterations += r.iterations
                leg_path.minima += r.local_minima
                leg_path.escapes += r.escapes
                leg_path.add(r.path)
                entry["detour"] = r.extra.get("escapes", [])
                if r.status is Status.SOLVED:
                    return done(r.status, f"followed the leader; {r.reason}")
                if r.status is not Status.LOCAL_MINIMUM:
                    return done(r.status, r.reason)
                reason = f"{reason}; detour: {r.reason}"
        return done(Status.LOCAL_MINIMUM, reason)


VARIANTS: dict[str, dict[str, object]] = {
    "gradient.follow_leader": {},
    "gradient.follow_leader+detour": {"escape": "detour"},
    "gradient.follow_leader+random": {"random_grid": True},
}


def make(
    name: str,
    overrides: dict,
    *,
    escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
) -> FollowLeader:
    """Registry factory for the ``gradient.follow_leader`` family. Overrides of the
    clearance descent's settings are given as ``descent.<key>``."""
    if name not in VARIANTS:
        raise PlannerlabError(f"{name} is not a follow-the-leader planner ({', '.join(VARIANTS)})")
    own = {k: v for k, v in overrides.items() if not k.startswith("descent.")}
    sub = {k[len("descent.") :]: v for k, v in overrides.items() if k.startswith("descent.")}
    base = FollowLeaderSettings(**VARIANTS[name])  # type: ignore[arg-type]
    descent = with_overrides(ClearanceSettings(), sub, f"{name} (descent)")
    return FollowLeader(name, with_overrides(base, own, name), descent, escape_planner)

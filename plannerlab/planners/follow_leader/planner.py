"""Follow-the-leader: a path for the tip through free workspace, tracked by the clearance
descent, so the body follows the tip through a window.

The clearance descent (:mod:`plannerlab.planners.clearance.descent`) pulls the tip
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
   (:meth:`~plannerlab.planners.clearance.descent.ClearanceDescent.descend`, its public
   entry point) tracks a sub-goal that moves along the path (:meth:`FollowLeader.subgoals`):
   to the path's first corner (the tip turns there as the descent takes it), then along
   every later segment every ``stride_m``, looking along it, each within
   ``subgoal_pos_tol_m`` and ``subgoal_angle_tol_deg``: the tip advances along its own
   normal and the descent's clearance term keeps the body off the window's frame while
   the tip leads it in. A sub-goal the descent stalls before is passed over; two in a row
   end the tracking.
3. **The finish** is the clearance descent of the leg
   (:meth:`~plannerlab.planners.clearance.descent.ClearanceDescent.leg_descent`) from the
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
   so). What got the body in gets it out: the body lies on the curve its tip came in by,
   so it slides back out along that curve, every face inside at once, while the faces
   outside take up the length (:meth:`FollowLeader.retract`, the slide of
   :mod:`plannerlab.planners.clearance.slide`; the tip alone drawn back face by face, the
   retract before issue 33, is its fallback: it coils the body inside the room), until
   the tip sees the goal's approach point, then the leader's path from there. It comes
   first when the leader's path runs back through the body (:func:`crosses_body`) or the
   body is deep inside something the approach point is outside of
   (:func:`~plannerlab.planners.follow_leader.moves.leaves_from_inside`), else after the
   forward tries.

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

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    Planner,
    PlanResult,
    Status,
    settings_dict,
    with_overrides,
)
from plannerlab.planners.clearance import SetupStopped
from plannerlab.planners.clearance.descent import ClearanceDescent, ClearanceSettings, LegPath
from plannerlab.planners.clearance.settings import DERIVED, resolve_distances
from plannerlab.planners.clearance.slide import sees, sees_through
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.follow_leader import moves as leader_moves
from plannerlab.planners.follow_leader.grid import TipPath, joined, tip_path
from plannerlab.planners.follow_leader.moves import Track
from plannerlab.problem.goals import GoalRegion
from plannerlab.robots.base import Array, joint_difference

#: the default voxel is at least the reach over this (Arm-Z's 0.34 m < its 0.375 m)
VOXELS_PER_REACH = 50.0
#: the distance settings of :class:`FollowLeaderSettings` derived from the robot (see
#: :mod:`~plannerlab.planners.clearance.settings`): their values on Arm-Z [m]
DERIVED_DISTANCES: dict[str, float] = {
    "extra_clearance_m": 0.05,
    "centre_m": 1.5,
    "pad_m": 3.0,
    "approach_m": 2.5,
    "subgoal_pos_tol_m": 0.5,
    "stride_m": 1.0,
}


@dataclass(frozen=True)
class FollowLeaderSettings:
    """Settings of follow-the-leader.

    Distances marked *derived* default to None: Arm-Z's value (given) scaled to the
    robot's size (:mod:`~plannerlab.planners.clearance.settings`: the typical link length
    over Arm-Z's module); a value set wins. The clearance descent's settings are its own
    (:class:`ClearanceSettings`), overridden as ``descent.<key>``.

    Attributes:
        voxel_m: edge of the search grid's voxels [m]; 0: half the tip module's radius
            or a fiftieth of the arm's reach, the larger (0.375 on Arm-Z), but never so
            fine that the search box holds more than ``max_voxels`` voxels
            (then the finest edge that fits).
        max_voxels: the most voxels the search grid may hold [1]: the grid's memory and
            time cap (measured: about 400 bytes and 3 µs a voxel while it is built and
            searched, so 1e6 voxels take about 400 MB and 3 s; an Arm-Z's grid holds at
            most 0.78e6, bounded by its reach). A ``voxel_m`` set that would pass it is
            refused with an error naming both.
        extra_clearance_m: clearance the tip path keeps beyond the tip module's radius and
            the problem's safety margin [m]; derived, 0.05 on Arm-Z.
        centre_m: distance from the obstacles below which a path step costs more [m];
            derived, 1.5 on Arm-Z.
        centre_weight: how much more: a step at distance d costs its length times
            ``1 + centre_weight · max(0, 1 − d / centre_m)`` [1].
        pad_m: the search box reaches this far beyond the start tip, the goal, its
            approach point and the arm's base (and never beyond the arm's reach from its
            base); doubled while no path is found, up to the reach [m]; derived, 3 on
            Arm-Z.
        approach_m: the path ends at ``p_d − approach_m · n_d``, the goal's approach
            point, then goes in along the goal's normal [m]; derived, 2.5 on Arm-Z.
        subgoal_pos_tol_m: position tolerance of the moving sub-goal [m]; derived, 0.5
            on Arm-Z.
        subgoal_angle_tol_deg: angle tolerance of the moving sub-goal [deg].
        stride_m: spacing of the sub-goals along the path's segments after its first
            [m]; derived, 1 on Arm-Z.
        track_approach: also sub-goals every ``stride_m`` from the approach point towards
            the goal, looking along the goal's normal (the finish then starts closer).
        escape: "none" or "detour" (the clearance descent's detour from a stall).
        random_grid: shift the grid by a random fraction of a voxel and scale
            ``centre_weight`` by a random factor in [0.5, 1.5] (the seed's draw).
        max_replans: (``random_grid``) new leader paths drawn from where a try ended [1].
        retract: when the tries from the start end in a stall, one more try from the
            start: the tip drawn back along the start's own body first (sub-goals at
            its modules' faces, from the tip's towards the base), then the leader's path
            from there.

    The clearance descent's settings are its own (:class:`ClearanceSettings`), overridden
    as ``descent.<key>``.
    """

    voxel_m: float = 0.0
    max_voxels: int = 1_000_000
    extra_clearance_m: float = DERIVED
    centre_m: float = DERIVED
    centre_weight: float = 4.0
    pad_m: float = DERIVED
    approach_m: float = DERIVED
    subgoal_pos_tol_m: float = DERIVED
    subgoal_angle_tol_deg: float = 45.0
    stride_m: float = DERIVED
    track_approach: bool = False
    escape: str = "none"
    random_grid: bool = False
    max_replans: int = 3
    retract: bool = True

    def __post_init__(self) -> None:
        if not self.voxel_m >= 0:
            raise PlannerlabError(f"voxel_m must be >= 0, got {self.voxel_m}")
        if self.max_voxels < 8:
            raise PlannerlabError(f"max_voxels must be >= 8, got {self.max_voxels}")
        if self.escape not in ("none", "detour"):
            raise PlannerlabError(f"escape setting: 'none' or 'detour', got {self.escape!r}")
        for key in ("stride_m", "subgoal_pos_tol_m", "centre_m", "pad_m"):
            value = getattr(self, key)
            if value is not None and not value > 0:
                raise PlannerlabError(f"{key} must be > 0, got {value}")
        for key in ("extra_clearance_m", "approach_m"):
            value = getattr(self, key)
            if value is not None and not value >= 0:
                raise PlannerlabError(f"{key} must be >= 0, got {value}")
        if self.max_replans < 0:
            raise PlannerlabError(f"max_replans must be >= 0, got {self.max_replans}")

    @property
    def resolved(self) -> bool:
        """Whether every derived distance has a value."""
        return all(getattr(self, k) is not None for k in DERIVED_DISTANCES)

    def for_robot(self, robot: Any) -> FollowLeaderSettings:
        """These settings with every derived distance that is None set for ``robot``."""
        out: FollowLeaderSettings = resolve_distances(self, DERIVED_DISTANCES, robot)
        return out


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
        self.escape_planner = escape_planner
        #: (robot, this planner with its distances derived for it) (see :meth:`for_robot`)
        self._resolved: tuple[Any, FollowLeader] | None = None

    def for_robot(self, robot: Any) -> FollowLeader:
        """This planner with its derived distance settings (and its descents') set for
        ``robot``; itself when none is left to derive."""
        if self.settings.resolved and self.descent_settings.resolved:
            return self
        cached = self._resolved
        if cached is not None and cached[0] is robot:
            return cached[1]
        planner = FollowLeader(
            self.name,
            self.settings.for_robot(robot),
            self.descent_settings.for_robot(robot),
            self.escape_planner,
        )
        self._resolved = (robot, planner)
        return planner

    def warm_up(self, problem, leg: int, q_start: Array) -> None:
        """The descents' compiled kernels loaded before the leg's tracker starts (a
        one-off cost of the process, outside the limits). Their fields and the leader's
        grid are set-up, built in the solve's time."""
        self._track.warm_up(problem, leg, q_start)

    def leader_path(
        self,
        problem,
        leg: int,
        q: Array,
        rng: np.random.Generator | None,
        stop: Callable[[], bool] | None = None,
        goal: GoalRegion | None = None,
        via_m: Array | None = None,
    ) -> TipPath | None:
        """The leader's path from the tip of ``q`` into leg's goal, or into ``goal`` when
        given (randomised with rng; None when there is none, or ``stop()`` said so).
        ``via_m``: a waypoint the path must pass (the body's own opening when leaving
        from inside, :func:`~plannerlab.planners.follow_leader.moves.body_opening`): the
        path from the tip to it, then from it into the goal (two searches, one grid shift
        and centring weight)."""
        resolved = self.for_robot(problem.robot)
        if resolved is not self:
            return resolved.leader_path(problem, leg, q, rng, stop, goal, via_m)
        s = self.settings
        robot = problem.robot
        goal = problem.goal(leg) if goal is None else goal
        p_tip, _ = robot.tip(q)
        F0 = robot.fk(q)
        base = F0[0, :3, 3]
        reach = float(np.sum(np.linalg.norm(np.diff(F0[:, :3, 3], axis=0), axis=1)))
        r_tip = float(np.asarray(robot.link_radii_m)[-1])
        # a thin robot's grid need not resolve its own thickness (voxel_m's docstring)
        voxel = s.voxel_m if s.voxel_m > 0 else max(0.5 * r_tip, reach / VOXELS_PER_REACH)
        offset = None
        weight = s.centre_weight
        if rng is not None:
            offset = rng.uniform(0.0, voxel, size=3)
            weight = s.centre_weight * float(rng.uniform(0.5, 1.5))
        if via_m is not None:
            via = np.asarray(via_m, dtype=float)
            legs = ((p_tip, via, np.zeros(3), 0.0), (via, goal.p_world_m, goal.n_world, None))
            parts = []
            for a, b, n, appr in legs:
                part = self._tip_path(
                    problem, a, b, n, appr, base, reach, voxel, offset, weight, stop
                )
                if part is None:
                    return None
                parts.append(part)
            return joined(parts[0], parts[1])
        return self._tip_path(
            problem,
            p_tip,
            goal.p_world_m,
            goal.n_world,
            None,
            base,
            reach,
            voxel,
            offset,
            weight,
            stop,
        )

    def _tip_path(
        self,
        problem,
        p_from: Array,
        p_goal: Array,
        n_goal: Array,
        approach_m: float | None,
        base: Array,
        reach: float,
        voxel: float,
        offset: Array | None,
        weight: float,
        stop: Callable[[], bool] | None,
    ) -> TipPath | None:
        """One :func:`tip_path` of :meth:`leader_path` (``approach_m`` None: the setting's),
        its pad doubled up to the reach while none is found."""
        s = self.settings
        r_tip = float(np.asarray(problem.robot.link_radii_m)[-1])
        pad = s.pad_m
        while True:
            leader = tip_path(
                problem.scene,
                p_from,
                p_goal,
                n_goal,
                clearance_m=r_tip + problem.safety_margin_m + s.extra_clearance_m,
                approach_m=s.approach_m if approach_m is None else approach_m,
                voxel_m=voxel,
                centre_m=s.centre_m,
                centre_weight=weight,
                pad_m=pad,
                reach_centre_m=base,
                reach_m=reach,
                offset_m=offset,
                stop=stop,
                max_voxels=s.max_voxels,
                voxel_set=s.voxel_m > 0,
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
        via_m: Array | None = None,
    ) -> Track:
        """:func:`plannerlab.planners.follow_leader.moves.track` with this planner (its derived
        distances set for the leg's robot)."""
        fl = self.for_robot(ctx.robot)
        return leader_moves.track(fl, ctx, q0, goal, rng, used, leader, via_m)

    def detour_from(
        self, ctx: PlanningContext, q: Array, rng: np.random.Generator, used: int = 0
    ) -> Track:
        """The clearance descent's plan from ``q`` with its detour escape (the ``+detour``
        variant's escape from a stalled finish), a sub-solve in the leg's context with
        what the leg has left (``used``: its iterations so far)."""
        fl = self.for_robot(ctx.robot)
        tracker = ctx.tracker
        sub = tracker.remaining(limit_iterations=False)
        if sub is None:
            why = str(tracker.exhausted(used) or "no budget left")
            return Track(None, Status.BUDGET_EXHAUSTED, why, [np.array(q)], 0)
        b = tracker.budget
        if b.max_iterations is not None:
            sub = sub.replace(max_iterations=max(b.max_iterations - used, 1))
        r = fl._detour.plan(ctx.sub(sub, np.array(q)), rng)
        return Track(None, r.status, r.reason, list(r.path), r.iterations)

    def sees_approach(self, ctx: PlanningContext, q: Array, through_m: Array | None = None) -> bool:
        """Whether the straight line from the tip of ``q`` to the leg goal's approach
        point keeps the leader's clearance from the scene (the retract has got the tip
        out); with ``through_m``, by the opening that point lies in
        (:func:`~plannerlab.planners.clearance.slide.sees_through`)."""
        s = self.for_robot(ctx.robot).settings
        goal, robot = ctx.goal, ctx.robot
        p_tip, _ = robot.tip(q)
        approach = goal.p_world_m - s.approach_m * goal.n_world
        if through_m is not None:
            return sees_through(ctx.scene, p_tip, through_m, approach, self.leader_clearance_m(ctx))
        return sees(ctx.scene, p_tip, approach, self.leader_clearance_m(ctx))

    def leader_clearance_m(self, ctx: PlanningContext) -> float:
        """The clearance the leader's path keeps from the scene [m]: the tip module's
        radius, the problem's safety margin and ``extra_clearance_m``."""
        s = self.for_robot(ctx.robot).settings
        return (
            float(np.asarray(ctx.robot.link_radii_m)[-1])
            + ctx.problem.safety_margin_m
            + s.extra_clearance_m
        )

    def retract(
        self, ctx: PlanningContext, q0: Array, used: int = 0, through_m: Array | None = None
    ) -> Track:
        """:func:`plannerlab.planners.follow_leader.moves.retract` with this planner (its derived
        distances set for the leg's robot)."""
        return leader_moves.retract(self.for_robot(ctx.robot), ctx, q0, used, through_m)

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leader's path, follow it, finish with the leg's descent."""
        resolved = self.for_robot(ctx.robot)
        if resolved is not self:
            return resolved.plan(ctx, rng)
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
        try:  # the descents' fields: set-up, in the leg's time
            for descent in (self._track, self._finish):
                descent.model(problem, tracker.time_up)
        except SetupStopped as exc:
            return done(Status.BUDGET_EXHAUSTED, f"{tracker.exhausted() or 'time is up'}: {exc}")
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
                and leader_moves.leaves_from_inside(self, ctx, q0, leader)
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

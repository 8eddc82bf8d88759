"""Follow-the-leader's moves, reusable by other planners: the tracking from one state into
any tip goal region (:func:`track`, the body states it passes through), and the retract
for leaving from deep inside (:func:`retract`: the tip drawn back along the start's own
body until it sees the goal's approach point), with
:func:`crosses_body`, which says when the leader's path runs back through the body.
The planner itself is :class:`~plannerlab.planners.follow_leader.FollowLeader`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.planners.base import Status
from plannerlab.planners.context import PlanningContext
from plannerlab.problem.goals import GoalRegion
from plannerlab.robots.base import Array

#: a :class:`~plannerlab.planners.follow_leader.FollowLeader` (its tracking descent, its
#: settings, its leader's path) and a :class:`~plannerlab.planners.follow_leader.grid.TipPath`:
#: typed loosely so that this module and the planner's form no import cycle
FollowLeader = Any
TipPath = Any


@dataclass(frozen=True)
class Track:
    """Follow-the-leader from one state into one goal region (:meth:`FollowLeader.track`).

    Attributes:
        leader: the leader's path (None: none found).
        status: how the tracking and the final descent ended (SOLVED: in the region).
        reason: in words.
        states: the body states passed through, in order (consecutive ones are accepted
            steps of the descent: collision-free at the descent's resolution).
        iterations: descent iterations used.
    """

    leader: TipPath | None
    status: Status
    reason: str
    states: list[Array]
    iterations: int


def crosses_body(robot: Any, q: Array, leader: TipPath, step_m: float = 0.1) -> bool:
    """Whether the leader's path from the tip of ``q`` runs back through the body of
    ``q``: a point of the path where the tip module, whose axis follows the path, would
    touch a module more than a third of the body behind the tip (closer to that module's
    axis than the two radii). (Near the tip every path touches the body: the tip turns.)
    The voxel grid knows the scene, not the body: deep in a room, the way out for the
    tip leads back through the window its own body fills. (Until issue 33 a path point
    had to lie inside the module's capsule, which a path running beside the body through
    the window never does: ``armz_inspection_v29``, ``results/leave.md``.)"""
    F = robot.fk(q)
    faces = F[:, :3, 3]
    radii = np.asarray(robot.link_radii_m, dtype=float)
    n_links = len(faces) - 1
    behind = n_links - int(np.ceil(n_links / 3.0))  # links 0 .. behind-1
    if behind < 1:
        return False
    pts, arc = leader.points_m, leader.arc_m
    s_all = np.arange(0.0, float(arc[-1]), step_m)
    p = np.stack([np.interp(s_all, arc, pts[:, k]) for k in range(3)], axis=1)  # (m, 3)
    a, ab = faces[:behind], faces[1 : behind + 1] - faces[:behind]
    t = np.einsum("mkd,kd->mk", p[:, None, :] - a[None], ab) / np.maximum(
        np.einsum("kd,kd->k", ab, ab), 1e-12
    )
    closest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    d = np.linalg.norm(p[:, None, :] - closest, axis=2)  # (m, behind)
    r = np.resize(radii, behind) if len(radii) < behind else radii[:behind]
    return bool(np.any(d < r[None, :] + radii[-1]))


def leaves_from_inside(fl: FollowLeader, ctx: PlanningContext, q: Array, leader: Any) -> bool:
    """Whether leaving from ``q`` starts with the retract: the tip does not see the leg
    goal's approach point, and the leader's path runs back through the body
    (:func:`crosses_body`) or the body is deep inside something the approach point is
    outside of (:func:`~plannerlab.planners.clearance.slide.deep_inside`). Otherwise the
    forward tries come first (measured: on ``armz_inspection_v25``, ``v29`` and ``v44``
    the forward tracking spent 3-6 s before the retract got out)."""
    from plannerlab.planners.clearance.slide import deep_inside

    if fl.sees_approach(ctx, q):
        return False
    if leader is not None and crosses_body(ctx.robot, q, leader):
        return True
    s, goal = fl.settings, ctx.goal
    faces = np.asarray(ctx.robot.fk(q))[:, :3, 3]
    reach = float(np.sum(np.linalg.norm(np.diff(faces, axis=0), axis=1)))
    target = goal.p_world_m - s.approach_m * goal.n_world
    return deep_inside(ctx.scene, faces, target, fl.leader_clearance_m(ctx), reach / 3.0)


def body_opening(fl: FollowLeader, ctx: PlanningContext, q: Array) -> Array | None:
    """Where the body of ``q`` leaves the room, for leaving from inside: its pivot face
    (:func:`~plannerlab.planners.clearance.slide.pivot_face`: the last face of the first
    run from the base that sees the leg goal's approach point with the leader's
    clearance) [m], (3,); None when no face or the tip sees it. The leader's grid knows
    the scene, not the body: in a room with a second opening its shortest way out for
    the tip may take the other one, while the body fills this one; routed by this point
    (tip, pivot, approach point; backwards approach, pivot, tip) both trees keep to the
    body's way out, and the retract ends when the tip sees the approach point by it
    (:func:`~plannerlab.planners.clearance.slide.sees_through`)."""
    from plannerlab.planners.clearance.slide import pivot_face

    s, goal = fl.settings, ctx.goal
    faces = np.asarray(ctx.robot.fk(q))[:, :3, 3]
    target = goal.p_world_m - s.approach_m * goal.n_world
    k = pivot_face(ctx.scene, faces, target, fl.leader_clearance_m(ctx))
    return None if k < 0 else faces[k].copy()


def track(
    fl: FollowLeader,
    ctx: PlanningContext,
    q0: Array,
    goal: GoalRegion,
    rng: np.random.Generator | None,
    used: int = 0,
    leader: TipPath | None = None,
    via_m: Array | None = None,
) -> Track:
    """Follow-the-leader from ``q0`` into ``goal`` (any tip goal region): the leader's
    path from ``q0``'s tip (randomised with ``rng``, None: the deterministic grid), the
    tracking descent along it, then the descent into ``goal`` itself (no approach
    point). The body states it passed through come back whatever the outcome: the
    reusable part of follow-the-leader (guide states of a sampling planner, the
    backward branches). ``used``: iterations the leg has used already; ``leader``:
    the leader's path when the caller has it already; ``via_m``: a waypoint of the
    leader's path (:meth:`FollowLeader.leader_path`)."""
    tracker = ctx.tracker

    def stop() -> bool:
        return tracker.exhausted(used) is not None

    if leader is None:
        leader = fl.leader_path(ctx.problem, ctx.leg, q0, rng, stop, goal=goal, via_m=via_m)
    states = [np.array(q0, dtype=float)]
    if leader is None:
        why = tracker.exhausted(used) or "no path for the tip through free workspace"
        status = Status.BUDGET_EXHAUSTED if tracker.exhausted(used) else Status.FAILED
        return Track(None, status, why, states, 0)
    st, reason, seg, it = fl._follow(ctx, q0, leader, used)
    states.extend(seg[1:])
    if st is Status.BUDGET_EXHAUSTED:
        return Track(leader, st, reason, states, it)
    st2, reason2, seg2, _, it2 = fl._track.descend(ctx, states[-1], goal, used + it)
    states.extend(seg2[1:])
    return Track(leader, st2, f"{reason}; {reason2}", states, it + it2)


def retract(
    fl: FollowLeader,
    ctx: PlanningContext,
    q0: Array,
    used: int = 0,
    through_m: Array | None = None,
) -> Track:
    """Leaving from deep inside: the body drawn back along its own curve until the tip
    sees the leg goal's approach point. What got the body in gets it out: the body lies
    on the curve its tip came in by; the leader's path forwards would lead the tip back
    through the window its own body fills (measured on the far-ended variants: the
    tracking stalls at sub-goal 2).

    First the slide (:func:`~plannerlab.planners.clearance.slide.slide_out`): every face
    of the part inside slides back along the curve at once while the faces outside take
    up the length. When there is nothing to slide back to (no face sees the approach
    point) or the slide stalls, the tip alone is drawn back, from the start: sub-goals at
    the body's faces from the tip's towards the base's (each looking along the body,
    within the sub-goal tolerances), tracked by the descent, until the tip sees the
    approach point (``fl.sees_approach``); a sub-goal the descent stalls before is passed
    over, two in a row end it. (The tip alone leaves the body to the descent, which
    coils it inside the room: the window must then take two passes of the body,
    ``results/leave.md``.)

    ``through_m`` (:func:`body_opening`): both end only when the tip sees the approach
    point by the opening that point lies in (None: by any)."""
    sl = _slide(fl, ctx, q0, used, through_m)
    if sl.status in (Status.SOLVED, Status.BUDGET_EXHAUSTED):
        return Track(None, sl.status, sl.reason, sl.states, sl.iterations)
    tr = _retract_tip(fl, ctx, q0, used + sl.iterations, through_m)
    reason = f"{tr.reason} ({sl.reason})" if sl.iterations else tr.reason
    return Track(None, tr.status, reason, tr.states, tr.iterations + sl.iterations)


def _slide(
    fl: FollowLeader, ctx: PlanningContext, q0: Array, used: int, through_m: Array | None = None
):
    """The slide of :func:`retract`, towards the leg goal's approach point with the
    leader's clearance, at the tracking descent's step and clearance floor."""
    from plannerlab.planners.clearance.settings import robot_size
    from plannerlab.planners.clearance.slide import slide_out

    s = fl.settings
    robot, goal = ctx.robot, ctx.goal
    d = fl._track.for_robot(robot).settings
    return slide_out(
        ctx,
        q0,
        goal.p_world_m - s.approach_m * goal.n_world,
        fl.leader_clearance_m(ctx),
        used,
        clearance_floor_m=d.clearance_floor_m,
        max_step_rad=d.max_step_rad if d.max_step_rad > 0 else ctx.problem.joint_step / 2,
        link_m=robot_size(robot).pitch_m,
        through_m=through_m,
    )


def _retract_tip(
    fl: FollowLeader,
    ctx: PlanningContext,
    q0: Array,
    used: int = 0,
    through_m: Array | None = None,
) -> Track:
    """The tip alone drawn back along the start's body, face by face (see :func:`retract`)."""
    s = fl.settings
    F = ctx.robot.fk(q0)
    faces, normals = F[:, :3, 3], F[:, :3, 2]
    states = [np.array(q0, dtype=float)]
    it = 0
    stalls = 0
    reached = 0
    status, reason = Status.LOCAL_MINIMUM, "no face of the body reached"
    for k in range(len(faces) - 2, 0, -1):
        sub = GoalRegion(
            f"face{k}", faces[k], normals[k], s.subgoal_pos_tol_m, s.subgoal_angle_tol_deg
        )
        st, why, seg, _, i = fl._track.descend(ctx, states[-1], sub, used + it)
        it += i
        states.extend(seg[1:])
        if st is Status.BUDGET_EXHAUSTED:
            return Track(None, st, why, states, it)
        if st is Status.SOLVED:
            reached, stalls = reached + 1, 0
            status, reason = Status.SOLVED, f"retracted to face {k}"
            if fl.sees_approach(ctx, states[-1], through_m):
                break
            continue
        stalls += 1
        if stalls >= 2:
            break
    return Track(None, status, f"{reason} ({reached} faces reached)", states, it)

"""The slide: a body drawn back out along its own curve (follow-the-leader in reverse), for
leaving from deep inside a room; shared by the clearance descent's detour, follow-the-
leader's retract and the leader-guided sampler.

Why (measured on the far-ended room variants, ``results/leave.md``): leaving a room from
its far wall, the tip's way out runs back through the window its own body fills. The
retract of :mod:`plannerlab.planners.follow_leader.moves` drew the tip back along the
body, face by face, with the body left to the clearance descent: the descent moves the
tip at the least joint cost, which coils the body inside the room, and once the tip is
back at the window the window must take two passes of the body (``armz_inspection_v29``:
the tip stalls at the window's sill with 15 modules still inside). A fixed-base arm can
only leave by taking the length up *outside*.

What got the body in gets it out: the body lies on the curve its tip came in by, so
every face of the part that is inside slides back along that curve at once, while the
faces outside, free, take up the length (they bend out into free space, as they did on
the way in). The curve is the start state's chain of frame origins; the inside part is
the part beyond the **pivot**, the last face of the first run of faces (from the base)
that see the target (the goal's approach point: the straight line keeps ``clearance_m``
from the scene, :func:`sees`). At slide σ, face j is pulled to the point of the curve
σ metres behind where it started (when that point is beyond the pivot); σ grows while
the pulled faces are, by their median, within a fifth of a link of their points and none is
more than 1.5 links off (where the curve bends round an edge, the modules' chords
cut the corner and the clearance push holds them off it), and the slide ends once the
tip sees the target.

Each step is a damped least-squares step on the pulled faces' errors, with every pair of
the checker closer than ``clearance_floor_m`` plus two thirds of it pushed apart through
its points' Jacobians (as the room variants' witness IK,
:mod:`plannerlab.problem.variant_witness`), at most ``max_step_rad`` per joint; a step
is kept when the checker finds the state valid, as the clearance descent keeps its
steps. The Jacobians are finite differences of one batched forward kinematics, so any
chain slides.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from plannerlab.planners.base import Status
from plannerlab.planners.context import PlanningContext
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import Array, wrap_to_pi

#: a pulled face keeps within this many links of its point before σ grows
TRACK_TOL_LINKS = 0.2
#: no pulled face may be further off its point than this many links for σ to grow
OFF_CURVE_LINKS = 1.5
#: σ grows by this many links at a time
ADVANCE_LINKS = 0.07
#: the slide has stalled when σ has not grown in this many steps
STALL_STEPS = 150
#: damping of the least-squares step [m]
DAMPING_M = 0.1
#: weight of the pairs' push against the faces' pull
PUSH_WEIGHT = 3.0
#: the tip's line of sight is looked at every this many steps
SIGHT_EVERY = 8
#: the free part keeps this many links from the scene and itself, softly
SPREAD_LINKS = 0.42
#: the weight of that soft push against the faces' pull [1/m · m]
SPREAD_WEIGHT = 0.5
#: finite-difference step of the Jacobians [rad]
FD_RAD = 1e-6
#: a line of sight keeps the tip link's radius, the safety margin and this many links
SIGHT_EXTRA_LINKS = 0.07


def sight_clearance_m(robot, safety_margin_m: float, link_m: float) -> float:
    """The clearance a line of sight keeps [m]: the tip link's radius, the problem's
    safety margin and :data:`SIGHT_EXTRA_LINKS` links (0.05 m on Arm-Z, the leader's
    ``extra_clearance_m``)."""
    return float(np.asarray(robot.link_radii_m)[-1]) + safety_margin_m + SIGHT_EXTRA_LINKS * link_m


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
        else:  # a mesh: its bounding box (conservative: never closer than the mesh)
            half = o.half_extents_world()
            q = np.abs(p - T[:3, 3]) - half
            di = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
        d = np.minimum(d, di)
    return d


def sees(
    scene: Scene, p_m: Array, target_m: Array, clearance_m: float, step_m: float = 0.1
) -> bool:
    """Whether the straight line from ``p_m`` to ``target_m`` keeps ``clearance_m`` [m]
    from every obstacle (sampled every ``step_m``)."""
    p, t = np.asarray(p_m, dtype=float), np.asarray(target_m, dtype=float)
    n = max(2, int(np.ceil(np.linalg.norm(t - p) / step_m)) + 1)
    line = p + np.linspace(0.0, 1.0, n)[:, None] * (t - p)
    return bool(scene_distance_m(scene, line).min() >= clearance_m)


def sees_through(
    scene: Scene,
    p_m: Array,
    via_m: Array,
    target_m: Array,
    clearance_m: float,
    step_m: float = 0.1,
) -> bool:
    """Whether ``p_m`` sees ``target_m`` by the opening ``via_m`` lies in (a point that
    sees ``target_m``): every straight line from ``p_m`` to a point of the segment
    ``via_m`` – ``target_m`` (a fan, one line every ``step_m`` along it) keeps
    ``clearance_m`` [m] from the scene. The fan sweeps the triangle between the line of
    sight and the way by ``via_m``: free, the two are one way out; a room with a second
    opening the line of sight takes (a window in the ceiling while the body fills the
    near one) puts a wall inside the triangle. In a room with one (convex) opening and
    ``via_m`` at it, it is :func:`sees`."""
    p, v, t = (np.asarray(x, dtype=float) for x in (p_m, via_m, target_m))
    if not sees(scene, p, t, clearance_m, step_m):
        return False
    n = max(2, int(np.ceil(np.linalg.norm(t - v) / step_m)) + 1)
    ends = v + np.linspace(0.0, 1.0, n)[:, None] * (t - v)
    m = max(2, int(np.ceil(np.max(np.linalg.norm(ends - p, axis=1)) / step_m)) + 1)
    u = np.linspace(0.0, 1.0, m)[None, :, None]
    lines = p + u * (ends[:, None, :] - p)
    return bool(scene_distance_m(scene, lines.reshape(-1, 3)).min() >= clearance_m)


@dataclass(frozen=True)
class Slide:
    """How a slide ended.

    Attributes:
        status: SOLVED (the tip sees the target), LOCAL_MINIMUM (σ stopped growing, or no
            face sees the target: nothing to slide back to), BUDGET_EXHAUSTED.
        reason: in words.
        states: the accepted states from the start, in order.
        iterations: steps taken (one iteration each).
        pivot: the face the inside part slides back to (-1: none).
        slid_m: σ at the end [m].
    """

    status: Status
    reason: str
    states: list[Array]
    iterations: int
    pivot: int = -1
    slid_m: float = 0.0


def pivot_face(scene: Scene, faces_m: Array, target_m: Array, clearance_m: float) -> int:
    """The last face of the first run of faces (from the base) that see the target; -1
    when none does, or when the tip itself does (nothing to slide)."""
    see = [sees(scene, p, target_m, clearance_m) for p in faces_m]
    if see[-1] or not any(see):
        return -1
    k = see.index(True)
    while k + 1 < len(see) and see[k + 1]:
        k += 1
    return k


def openness(scene: Scene, p_m: Array, clearance_m: float, length_m: float) -> float:
    """The share of 26 directions (the grid's neighbours) in which a ray from ``p_m``
    keeps ``clearance_m`` from the scene for ``length_m`` [m]: near 1 in the open, small
    inside a room (its rays end on the walls, but for those through the window)."""
    d = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    d = d[np.any(d != 0, axis=1)] / np.linalg.norm(d[np.any(d != 0, axis=1)], axis=1)[:, None]
    steps = np.linspace(0.0, length_m, max(2, int(np.ceil(length_m / 0.1)) + 1))
    pts = np.asarray(p_m, dtype=float) + steps[None, :, None] * d[:, None, :]
    dist = scene_distance_m(scene, pts.reshape(-1, 3)).reshape(len(d), len(steps))
    return float(np.mean(dist.min(axis=1) >= clearance_m))


def deep_inside(
    scene: Scene, faces_m: Array, target_m: Array, clearance_m: float, length_m: float
) -> bool:
    """Whether the body is deep inside something the target is outside of: its tip is
    more enclosed than the target (:func:`openness`, rays of ``length_m``: a third of the
    body), and more than a third of the body lies beyond its pivot
    (:func:`pivot_face`; the rule of follow-the-leader's ``crosses_body``: a third of the
    body). A column standing before a room whose goal is inside is not: its tip is in the
    open. Measured: the clearance descent's tip retract leaves every far-wall variant with
    up to 0.46 of the body beyond the pivot and fails all six above it (0.50-0.56);
    ``results/leave.md``."""
    pivot = pivot_face(scene, faces_m, target_m, clearance_m)
    n = len(faces_m) - 1
    if pivot < 0 or (n - pivot) * 3 <= n:
        return False
    radius = clearance_m / 2.0
    return openness(scene, faces_m[-1], radius, length_m) < openness(
        scene, target_m, radius, length_m
    )


def _faces(robot, Q: Array) -> Array:
    """Frame origins (…, F, 3): the body's curve."""
    return np.asarray(robot.fk(Q))[..., :3, 3]


def _jacobians(robot, q: Array) -> tuple[Array, Array, Array, Array]:
    """Frame origins (F, 3), link segments (L, 2, 3) and their Jacobians (F, 3, dof),
    (L, 2, 3, dof): an Arm-Z's analytic (joint i turns about frame i's z axis, its links
    run between successive frames), any other chain's by finite differences of one
    batched forward kinematics."""
    dof = robot.dof
    if getattr(robot, "kind", "") == "armz":
        F = np.asarray(robot.fk(q))
        f, z, o = F[:, :3, 3], F[1:-1, :3, 2], F[1:-1, :3, 3]
        # d face_k / d θ_i = z_i × (face_k − o_i) for the joints before face k
        Jf = np.cross(z[None, :, :], f[:, None, :] - o[None, :, :])  # (F, dof, 3)
        Jf *= (np.arange(1, dof + 1)[None, :] < np.arange(len(f))[:, None])[..., None]
        Jf = np.transpose(Jf, (0, 2, 1))
        return f, np.stack([f[:-1], f[1:]], axis=1), Jf, np.stack([Jf[:-1], Jf[1:]], axis=1)
    Q = np.vstack([q[None], q[None] + FD_RAD * np.eye(dof)])
    f = _faces(robot, Q)
    s = np.asarray(robot.link_segments(Q))
    Jf = np.moveaxis((f[1:] - f[0]) / FD_RAD, 0, -1)
    Js = np.moveaxis((s[1:] - s[0]) / FD_RAD, 0, -1)
    return f[0], s[0], Jf, Js


def _push_rows(
    ctx: PlanningContext,
    q: Array,
    Js: Array,
    want_m: float,
    band_m: float,
    free_link: Array,
    spread_m: float,
):
    """Rows pushing apart every pair closer than ``want_m`` (its points' Jacobians along
    the checker's separating direction, the deficit in units of ``band_m``), and, softly
    (:data:`SPREAD_WEIGHT`, the deficit in metres), every pair of a free link closer than
    ``spread_m``: the free part takes up the length in free space, not along a wall or
    the ground. None when no pair is that close."""
    pd = ctx.checker.pair_distances(q, max(want_m, spread_m) + 0.05)
    hard = pd.d_m < want_m
    soft = ~hard & (pd.d_m < spread_m) & free_link[pd.link]
    close = hard | soft
    if not np.any(close):
        return None
    link, t = pd.link[close], pd.t_link[close]
    Ja = (1.0 - t)[:, None, None] * Js[link, 0] + t[:, None, None] * Js[link, 1]
    nrm = pd.n_world[close]
    G = np.einsum("mk,mkd->md", nrm, Ja)
    other = pd.other_is_link[close]
    if np.any(other):
        lo, to = pd.other[close][other], pd.t_other[close][other]
        Jb = (1.0 - to)[:, None, None] * Js[lo, 0] + to[:, None, None] * Js[lo, 1]
        G[other] -= np.einsum("mk,mkd->md", nrm[other], Jb)
    d = pd.d_m[close]
    w = np.where(hard[close], PUSH_WEIGHT / band_m, SPREAD_WEIGHT)
    deficit = np.where(hard[close], want_m, spread_m) - d
    return w[:, None] * G, w * deficit


def slide_out(
    ctx: PlanningContext,
    q0: Array,
    target_m: Array,
    clearance_m: float,
    used: int = 0,
    *,
    clearance_floor_m: float,
    max_step_rad: float,
    link_m: float,
    stop: Callable[[int], str | None] | None = None,
    through_m: Array | None = None,
) -> Slide:
    """Slide the body of ``q0`` back out along its own curve until its tip sees
    ``target_m`` with ``clearance_m`` (see the module docstring). ``used``: iterations
    the leg has used already (the leg's budget, ``ctx.tracker``, bounds the slide);
    ``link_m``: the robot's typical link length (the tolerances are fractions of it);
    ``stop(iterations)``: a reason to stop now, or None (default: the leg's budget);
    ``through_m``: the slide ends only when the tip sees the target by the opening this
    point lies in (:func:`sees_through`; None: by any)."""
    robot, tracker, scene = ctx.robot, ctx.tracker, ctx.scene
    q = wrap_to_pi(np.array(q0, dtype=float), robot.continuous)
    states = [q.copy()]
    curve = _faces(robot, q)
    pivot = pivot_face(scene, curve, target_m, clearance_m)
    if pivot < 0:
        words = (
            "the tip sees the target"
            if sees(scene, curve[-1], target_m, clearance_m)
            else ("no face of the body sees the target")
        )
        return Slide(Status.LOCAL_MINIMUM, f"no slide: {words}", states, 0)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))])
    keep = np.concatenate([[True], np.diff(arc) > 1e-9])  # frames on one point: one arc
    arc_u, curve_u = arc[keep], curve[keep]
    total = float(arc[-1] - arc[pivot])
    tol, advance = TRACK_TOL_LINKS * link_m, ADVANCE_LINKS * link_m
    band = 2.0 * clearance_floor_m / 3.0
    spread = SPREAD_LINKS * link_m
    want = clearance_floor_m + band
    dof = robot.dof

    def point_at(s: Array) -> Array:
        return np.stack([np.interp(s, arc_u, curve_u[:, k]) for k in range(3)], axis=-1)

    def budget(it: int) -> str | None:
        if stop is not None:
            return stop(it)
        why = tracker.exhausted(used + it)
        left = tracker.checks_left()
        if why is None and left is not None and left < 2:
            why = f"collision-check budget of {tracker.budget.max_collision_checks} used up"
        return why

    sigma, best_at, it = 0.0, 0, 0
    while True:
        why: str | None = budget(it)
        if why is not None:
            return Slide(Status.BUDGET_EXHAUSTED, why, states, it, pivot, sigma)
        f, _, Jf, Js = _jacobians(robot, q)
        # the line of sight costs a tenth of a step: looked at every SIGHT_EVERY steps
        if (it % SIGHT_EVERY == 0 or sigma >= total) and sigma > 0.0:
            if (
                sees(scene, f[-1], target_m, clearance_m)
                if through_m is None
                else sees_through(scene, f[-1], through_m, target_m, clearance_m)
            ):
                return Slide(
                    Status.SOLVED,
                    f"slid {sigma:.2f} m back along the body to face {pivot} in {it} steps",
                    states,
                    it,
                    pivot,
                    sigma,
                )
        if it - best_at >= STALL_STEPS:
            return Slide(
                Status.LOCAL_MINIMUM,
                f"the slide stalled after {sigma:.2f} of {total:.2f} m (pivot face {pivot})",
                states,
                it,
                pivot,
                sigma,
            )
        it += 1
        goal_arc = arc - sigma
        pulled = np.flatnonzero((goal_arc >= arc[pivot]) & (np.arange(len(arc)) > 0))
        targets = point_at(goal_arc[pulled])
        J = Jf[pulled].reshape(-1, dof)
        rows, rhs = [J], [(targets - f[pulled]).reshape(-1)]
        free = np.ones(len(Js), dtype=bool)
        if len(pulled):
            free[pulled[0] - 1 :] = False  # link l runs from face l to face l + 1
        push = _push_rows(ctx, q, Js, want, band, free, spread)
        if push is not None:
            rows.append(push[0])
            rhs.append(push[1])
        A, b = np.vstack(rows), np.concatenate(rhs)
        dq = np.linalg.solve(A.T @ A + DAMPING_M**2 * np.eye(dof), A.T @ b)
        big = float(np.max(np.abs(dq), initial=0.0))
        if big > max_step_rad:
            dq *= max_step_rad / big
        q_new = wrap_to_pi(q + dq, robot.continuous)
        moved = f[pulled]
        if ctx.checker.is_valid(q_new):
            q = q_new
            states.append(q.copy())
            moved = moved + (J @ dq).reshape(-1, 3)  # to first order: one kinematics a step
        gaps = np.linalg.norm(targets - moved, axis=1)
        # the faces by their median within the tolerance, none far off: where the curve
        # bends round an edge its chords cut the corner, and the push holds them off it
        if (
            len(gaps)
            and float(np.median(gaps)) < tol
            and gaps.max() < OFF_CURVE_LINKS * link_m
            and sigma < total
        ):
            sigma = min(sigma + advance, total)
            best_at = it

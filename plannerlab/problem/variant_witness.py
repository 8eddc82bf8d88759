"""The witnesses of a room variant (:mod:`plannerlab.problem.variants`): for every goal a
collision-free state inside its tolerances with at least ``min_clearance_m`` of clearance
to the scene and between modules (the collision checker's exact signed distances), from a
clearance-aware numeric IK (damped least squares on the tip error, with every pair closer
than the wanted clearance pushed apart through its point Jacobian), seeded from the
previous goal's witness and from noisy restarts: not from any planner."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Problem
from plannerlab.robots.base import Array, wrap_to_pi

__all__ = ["WitnessResult", "clearance_ik", "find_witness", "witness_states"]


@dataclass(frozen=True)
class WitnessResult:
    """One clearance-aware IK descent: the state reached and whether it is a witness."""

    q: Array
    success: bool
    clearance_m: float
    pos_err_m: float
    angle_err_deg: float
    iterations: int


def _point_jacobians(frames: Array, link: Array, t: Array) -> tuple[Array, Array]:
    """Points ``a + t (b − a)`` on Arm-Z links (m, 3) and their Jacobians (m, 3, dof).

    Link i runs from face frame i to i + 1; joint k (1-based) turns about frame k's z
    axis, and a point on link i moves with joints 1..i."""
    o = frames[:, :3, 3]
    p = o[link] + t[:, None] * (o[link + 1] - o[link])
    z = frames[1:-1, :3, 2]
    oj = frames[1:-1, :3, 3]
    dof = z.shape[0]
    J = np.cross(z[None, :, :], p[:, None, :] - oj[None, :, :])  # (m, dof, 3)
    mask = np.arange(1, dof + 1)[None, :] <= link[:, None]
    return p, np.transpose(J * mask[:, :, None], (0, 2, 1))


def clearance_ik(
    robot: Any,
    checker: CollisionChecker,
    goal: GoalRegion,
    q_seed: Array,
    min_clearance_m: float,
    *,
    target_fraction: float = 0.5,
    max_iterations: int = 400,
    max_step_rad: float = 0.08,
    damping: float = 0.1,
    push_weight: float = 3.0,
    max_tip_units: float = 4.0,
) -> WitnessResult:
    """A damped-least-squares IK descent that keeps clearance (Arm-Z).

    Each step solves one weighted least-squares problem: the tip's position and normal
    errors scaled by the goal's tolerances (clipped to ``max_tip_units`` so far targets
    are approached a little at a time) and, for every checked pair closer than
    ``min_clearance_m`` + 2 cm, the pair's closest points pushed apart along the
    checker's separating direction (``pair_distances``: link points' Jacobians, the
    deficit in units of 2 cm, times ``push_weight``). It stops once the tip is within
    ``target_fraction`` of both tolerances and every pair is at least
    ``min_clearance_m`` apart.
    """
    q = wrap_to_pi(np.asarray(q_seed, dtype=float).copy(), robot.continuous)
    pos_scale = 1.0 / goal.pos_tol_m
    ang_scale = 1.0 / math.radians(goal.angle_tol_deg)
    want = min_clearance_m + 0.02
    d_min = pos_e = ang_e = math.inf
    for it in range(max_iterations + 1):
        F = robot.fk(q)
        p, n = F[-1, :3, 3], F[-1, :3, 2]
        pos_e, ang_e = (float(v) for v in goal.errors_from_tip(p, n))
        pd = checker.pair_distances(q, want + 0.2)
        d_min = float(pd.d_m.min()) if len(pd.d_m) else math.inf
        inside = pos_e <= target_fraction * goal.pos_tol_m and ang_e <= (
            target_fraction * goal.angle_tol_deg
        )
        if inside and d_min >= min_clearance_m:
            return WitnessResult(q, True, d_min, pos_e, ang_e, it)
        if it == max_iterations:
            break
        e = np.concatenate([(goal.p_world_m - p) * pos_scale, (goal.n_world - n) * ang_scale])
        size = float(np.linalg.norm(e))
        if size > max_tip_units:
            e *= max_tip_units / size
        z = F[1:-1, :3, 2]
        oj = F[1:-1, :3, 3]
        J_tip = np.vstack([np.cross(z, p - oj).T * pos_scale, np.cross(z, n).T * ang_scale])
        rows, rhs = [J_tip], [e]
        close = pd.d_m < want
        if np.any(close):
            link = pd.link[close]
            _, Ja = _point_jacobians(F, link, pd.t_link[close])
            nrm = pd.n_world[close]
            G = np.einsum("mk,mkd->md", nrm, Ja)
            other_link = pd.other_is_link[close]
            if np.any(other_link):
                _, Jb = _point_jacobians(
                    F, pd.other[close][other_link], pd.t_other[close][other_link]
                )
                G[other_link] -= np.einsum("mk,mkd->md", nrm[other_link], Jb)
            deficit = (want - pd.d_m[close]) / 0.02
            rows.append(push_weight * G / 0.02)
            rhs.append(push_weight * deficit)
        A = np.vstack(rows)
        b = np.concatenate(rhs)
        dq = np.linalg.solve(A.T @ A + damping**2 * np.eye(robot.dof), A.T @ b)
        biggest = float(np.max(np.abs(dq)))
        if biggest > max_step_rad:
            dq *= max_step_rad / biggest
        q = wrap_to_pi(q + dq, robot.continuous)
    return WitnessResult(q, False, d_min, pos_e, ang_e, max_iterations)


def _approach(goal: GoalRegion, distance_m: float) -> GoalRegion:
    """A loose goal ``distance_m`` back from ``goal`` along its normal (the tip then comes
    in along the normal it must show)."""
    return GoalRegion(
        f"{goal.name}-approach",
        goal.p_world_m - distance_m * goal.n_world,
        goal.n_world,
        0.5,
        30.0,
    )


def find_witness(
    robot: Any,
    checker: CollisionChecker,
    goal: GoalRegion,
    seeds: Sequence[Array],
    rng: np.random.Generator,
    min_clearance_m: float,
    attempts: int = 12,
    interior: tuple[Array, Array] | None = None,
    step_m: float = 1.0,
) -> WitnessResult | None:
    """A witness state for ``goal``: collision-free, inside both tolerances, at least
    ``min_clearance_m`` from the scene and between modules; or None.

    Attempt k starts from seed ``k mod len(seeds)`` (plus Gaussian noise of 0.05 · 1.5^k
    rad, at most 1 rad, from the second round of seeds on), descends by
    :func:`clearance_ik` first to the approach point 2.5 m back along the goal's normal,
    then to the goal. A seed already inside the goal with the clearance is taken as is.

    With ``interior`` (a convex free box, lower and upper corners [m]: a room's inside)
    and the attempt's tip and the approach point both in it, the tip is first led to the
    approach point along the straight segment between them (free for the tip, the box
    being convex), a loose target (0.5 m, any normal) at most ``step_m`` ahead at a time
    (:func:`_route`): one descent across a room 8-14 m wide or deep pulls the body
    straight at a wall or out through the window it came in by, and stalls there.
    """
    for q0 in seeds:
        pos_e, ang_e = (float(v) for v in goal.errors(robot, q0))
        if pos_e <= goal.pos_tol_m and ang_e <= goal.angle_tol_deg:
            if checker.clearance(q0) >= min_clearance_m:
                return WitnessResult(
                    np.array(q0, dtype=float), True, checker.clearance(q0), pos_e, ang_e, 0
                )
    for k in range(attempts):
        q0 = np.array(seeds[k % len(seeds)], dtype=float)
        if k >= len(seeds):
            q0 = q0 + rng.normal(0.0, min(0.05 * 1.5**k, 1.0), robot.dof)
        approach = _approach(goal, 2.5)
        for target in _route(robot, q0, approach.p_world_m, interior, step_m):
            q0 = clearance_ik(robot, checker, target, q0, min_clearance_m).q
        first = clearance_ik(robot, checker, approach, q0, min_clearance_m)
        result = clearance_ik(robot, checker, goal, first.q, min_clearance_m)
        if result.success:
            # the final word is the checker's: collision-free and the clearance kept
            if checker.is_valid(result.q) and checker.clearance(result.q) >= min_clearance_m:
                return result
    return None


def _route(
    robot: Any,
    q: Array,
    to_m: Array,
    interior: tuple[Array, Array] | None,
    step_m: float,
) -> list[GoalRegion]:
    """Loose targets (0.5 m, any normal) every ``step_m`` or less along the straight
    segment from ``q``'s tip to ``to_m``, short of ``to_m``; none unless ``interior`` is
    given and holds both ends."""
    if interior is None:
        return []
    lo, hi = (np.asarray(c, dtype=float) for c in interior)
    a = np.asarray(robot.fk(q)[-1, :3, 3], dtype=float)
    b = np.asarray(to_m, dtype=float)
    if not all(bool(np.all((lo <= p) & (p <= hi))) for p in (a, b)):
        return []
    n = int(math.ceil(float(np.linalg.norm(b - a)) / step_m))
    return [GoalRegion("route", a + (i / n) * (b - a), b - a, 0.5, 360.0) for i in range(1, n)]


def witness_states(
    problem: Problem,
    rng: np.random.Generator,
    min_clearance_m: float,
    checker: CollisionChecker | None = None,
    interior: tuple[Array, Array] | None = None,
) -> tuple[list[Array], list[float]] | str:
    """One witness per goal (in leg order) and its clearance [m], or the reason there is
    none (a string naming the goal); ``interior``: as :func:`find_witness`'s."""
    robot = problem.robot
    checker = checker or CollisionChecker(robot, problem.scene)
    if checker.clearance(problem.q_start) < min_clearance_m:
        return f"the start state is closer than {min_clearance_m:g} m to the scene"
    found: list[Array] = []
    clear: list[float] = []
    for goal in problem.goals:
        previous = found[-1] if found else problem.q_start
        seeds = [previous, *found[:-1][::-1], problem.q_start]
        w = find_witness(robot, checker, goal, seeds, rng, min_clearance_m, interior=interior)
        if w is None:
            return f"no witness for goal {goal.name}"
        found.append(w.q)
        clear.append(float(checker.clearance(w.q)))
    return found, clear

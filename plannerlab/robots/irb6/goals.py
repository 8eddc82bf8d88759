"""Goal sampling for the IRb-6 on LP-1: a joint vector inside a tip goal region.

A goal region is a flange position with a tolerance ball and an approach vector with a
tolerance cone (world frame, as :meth:`IRb6.tip` reports them); the roll is free. Each
attempt draws a pose inside the region and solves it with :mod:`irb6_ik`:

* even attempts draw position, approach and roll directly; an ambiguous pose (e.g. an
  exactly vertical approach with zero tolerances) gets λ0 uniformly from its feasible
  interval set;
* odd attempts draw λ0 uniformly on the track first and turn the drawn approach into the
  vertical plane through the column and the flange point, which is how near-vertical
  targets (where λ0 = d_z − d_x·c_z/c_x swings wildly) are reached.

The result is checked with the forward kinematics before it is returned. Only numpy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array
from plannerlab.robots.irb6.ik import IKAnswer, solve_ik, solve_with_lambda0
from plannerlab.robots.irb6.model import IRb6


class GoalRegion(Protocol):
    """What the sampler reads of a goal region (a
    :class:`plannerlab.problem.goals.GoalRegion`; robots/ does not import problem/)."""

    @property
    def p_world_m(self) -> Array: ...

    @property
    def n_world(self) -> Array: ...

    @property
    def pos_tol_m(self) -> float: ...

    @property
    def angle_tol_deg(self) -> float: ...


def reach_from_track(robot: IRb6, p_world_m: Array) -> tuple[float, float, str]:
    """How far ``p_world_m`` is from the shoulder's line along the track, and the most the
    flange reaches from it (lower arm + upper arm + wrist-to-flange) [m]: the IRb-6's
    reach bound (:attr:`plannerlab.robots.registry.RobotFamily.reach`)."""
    T = np.asarray(robot.T_world_base, dtype=float)
    lo, hi = robot.track_range_m
    p_s = T[:3, :3].T @ (np.asarray(p_world_m, dtype=float) - T[:3, 3])
    h = robot.shoulder_height_m
    closest = np.array([0.0, h, min(max(p_s[2], lo), hi)])
    dist = float(np.linalg.norm(p_s - closest))
    reach = float(robot.lower_arm_m + robot.upper_arm_m + robot.wrist_to_flange_m)
    return dist, reach, f"the shoulder's line along the track (λ0 in [{lo:g}, {hi:g}] m)"


def _perpendicular_basis(c: Array) -> tuple[Array, Array]:
    helper = np.array([1.0, 0.0, 0.0]) if abs(c[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(c, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(c, e1)


def _sample_ball(center: Array, radius_m: float, rng: np.random.Generator) -> Array:
    if radius_m <= 0.0:
        return center.copy()
    v = rng.normal(size=3)
    v /= max(float(np.linalg.norm(v)), 1e-300)
    return center + v * radius_m * rng.random() ** (1.0 / 3.0)


def _sample_cone(c: Array, angle_rad: float, rng: np.random.Generator) -> Array:
    if angle_rad <= 0.0:
        return c.copy()
    cos_t = 1.0 - rng.random() * (1.0 - math.cos(angle_rad))  # uniform on the cap
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    phi = rng.uniform(-math.pi, math.pi)
    e1, e2 = _perpendicular_basis(c)
    out = cos_t * c + sin_t * (math.cos(phi) * e1 + math.sin(phi) * e2)
    return out / np.linalg.norm(out)


def _uniform_in_intervals(
    intervals: tuple[tuple[float, float], ...], rng: np.random.Generator
) -> float:
    lengths = np.array([hi - lo for lo, hi in intervals])
    if lengths.sum() <= 0.0:
        lo, _ = intervals[int(rng.integers(len(intervals)))]
        return lo
    i = int(rng.choice(len(intervals), p=lengths / lengths.sum()))
    lo, hi = intervals[i]
    return float(rng.uniform(lo, hi))


def sample_irb6_goal(
    robot: IRb6,
    p_world_m: Array,
    c_world: Array,
    pos_tol_m: float,
    angle_tol_deg: float,
    rng: np.random.Generator,
    previous_theta5_rad: float | None = None,
    max_attempts: int = 64,
) -> Array | None:
    """A joint vector whose flange lies in a goal region, or None.

    Args:
        robot: the model.
        p_world_m: (3,) target flange position in the world [m].
        c_world: (3,) target approach vector in the world (normalised here).
        pos_tol_m: radius of the position ball [m], ≥ 0.
        angle_tol_deg: half-angle of the approach cone [deg], in [0, 180].
        rng: the trial's generator (the only source of randomness).
        previous_theta5_rad: passed to the IK (θ5 continuity at the range ends).
        max_attempts: poses drawn before giving up.

    Returns:
        q (6,) within the joint ranges with ``tip(q)`` inside the region, or None when no
        attempt succeeded.

    Raises:
        PlannerlabError: bad tolerances, NaN input, zero approach vector or no Generator.
    """
    if not isinstance(rng, np.random.Generator):
        raise PlannerlabError("sample_irb6_goal: rng must be a numpy.random.Generator")
    p_w = np.asarray(p_world_m, dtype=float)
    c_w = np.asarray(c_world, dtype=float)
    if p_w.shape != (3,) or c_w.shape != (3,):
        raise PlannerlabError("sample_irb6_goal: p_world_m and c_world must have shape (3,)")
    if not (np.all(np.isfinite(p_w)) and np.all(np.isfinite(c_w))):
        raise PlannerlabError("sample_irb6_goal: p_world_m and c_world must be finite")
    norm = float(np.linalg.norm(c_w))
    if norm < 1e-12:
        raise PlannerlabError("sample_irb6_goal: c_world is a zero vector")
    c_w = c_w / norm
    if not (math.isfinite(pos_tol_m) and pos_tol_m >= 0.0):
        raise PlannerlabError(f"sample_irb6_goal: pos_tol_m must be ≥ 0, got {pos_tol_m!r}")
    if not (math.isfinite(angle_tol_deg) and 0.0 <= angle_tol_deg <= 180.0):
        raise PlannerlabError(
            f"sample_irb6_goal: angle_tol_deg must be in [0, 180], got {angle_tol_deg!r}"
        )
    T_base_world = np.linalg.inv(robot.T_world_base)
    p_s = T_base_world[:3, :3] @ p_w + T_base_world[:3, 3]
    c_s = T_base_world[:3, :3] @ c_w
    tol_rad = math.radians(angle_tol_deg)
    cos_tol = math.cos(tol_rad)
    track_lo, track_hi = robot.track_range_m

    for attempt in range(max_attempts):
        p_try = _sample_ball(p_s, pos_tol_m, rng)
        c_try = _sample_cone(c_s, tol_rad, rng)
        roll = float(rng.uniform(-math.pi, math.pi))
        answer: IKAnswer
        if attempt % 2 == 0:
            answer = solve_ik(robot, (p_try, c_try, roll), previous_theta5_rad)
            if answer.case != "unambiguous" and answer.lambda0_intervals_m:
                lam = _uniform_in_intervals(answer.lambda0_intervals_m, rng)
                answer = solve_with_lambda0(robot, (p_try, c_try, roll), lam, previous_theta5_rad)
        else:
            lam = float(rng.uniform(track_lo, track_hi))
            radial = np.array([p_try[0], 0.0, p_try[2] - lam])
            if np.linalg.norm(radial) < 1e-9:
                continue
            normal = np.cross(np.array([0.0, 1.0, 0.0]), radial)
            normal /= np.linalg.norm(normal)
            c_plane = c_try - (c_try @ normal) * normal
            if np.linalg.norm(c_plane) < 1e-9:
                continue
            c_plane /= np.linalg.norm(c_plane)
            if c_plane @ c_s < cos_tol - 1e-12:
                continue
            answer = solve_with_lambda0(robot, (p_try, c_plane, roll), lam, previous_theta5_rad)
        if not answer.solutions:
            continue
        q = answer.solutions[int(rng.integers(len(answer.solutions)))].copy()
        p_q, c_q = robot.tip(q)
        pos_err = float(np.linalg.norm(p_q - p_w))
        cos_err = float(np.clip(c_q @ c_w, -1.0, 1.0))
        if pos_err <= pos_tol_m + 1e-9 and math.acos(cos_err) <= tol_rad + 1e-9:
            return q
    return None


def sample_goal_state(
    robot: IRb6,
    goal: GoalRegion,
    rng: np.random.Generator,
    seeds: Sequence[Array] | None = None,
) -> Array | None:
    """One joint vector inside a goal region, drawn through the analytic IK, or None.

    The common goal sampler (:func:`plannerlab.problem.ik.sample_goal_state`) calls this
    for the IRb-6 (its analytic inverse kinematics instead of restarting a numeric
    descent): it wraps :func:`sample_irb6_goal`, which draws a flange pose
    inside the region (position ball, approach cone, free roll) and solves it; in the
    ambiguous cases λ0 is drawn uniformly from the pose's feasible λ0 set, so repeated
    calls spread over every interval of the track that reaches the goal.

    The collision check is the caller's job: the state returned is only guaranteed to
    be within the joint ranges with its flange inside the region.

    Args:
        robot: the IRb-6 model.
        goal: target flange position ``goal.p_world_m`` and approach vector
            ``goal.n_world`` in the WORLD frame, tolerances ``goal.pos_tol_m`` [m] and
            ``goal.angle_tol_deg`` [deg].
        rng: the trial's generator (the only source of randomness).
        seeds: states near which the goal is wanted (e.g. the leg's start); the first
            one's θ5 picks the θ5 branch at the ends of its 360° range. The analytic IK
            needs no other seed.

    Returns:
        q (6,) or None when no attempt of the sampler reached the region.
    """
    previous_theta5 = None
    if seeds is not None and len(seeds) > 0:
        first = np.asarray(seeds[0], dtype=float)
        if first.shape != (robot.dof,):
            raise PlannerlabError(f"IRb6: a seed must have shape (6,), got {first.shape}")
        previous_theta5 = float(first[5])
    return sample_irb6_goal(
        robot,
        goal.p_world_m,
        goal.n_world,
        float(goal.pos_tol_m),
        float(goal.angle_tol_deg),
        rng,
        previous_theta5_rad=previous_theta5,
    )

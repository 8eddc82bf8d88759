"""Goal regions: a target position and surface normal, each with a tolerance.

A state q is in the region when the robot's tip is within ``pos_tol_m`` of ``p_world_m``
and the tip normal is within ``angle_tol_deg`` of ``n_world``. The normalised goal
distance (position error / pos_tol + angle error / angle_tol) is what sampling planners
steer by: below 1 in both terms means inside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.robots.registry import reach_function


@dataclass(frozen=True, eq=False)
class GoalRegion:
    """A target position + normal with tolerances.

    Args:
        name: label of the leg's goal ("A", "enter", …).
        p_world_m: (3,) target tip position [m].
        n_world: (3,) target tip normal, unit length.
        pos_tol_m: position tolerance [m], > 0.
        angle_tol_deg: angle tolerance between tip normal and target normal [deg], > 0.
    """

    name: str
    p_world_m: Array
    n_world: Array
    pos_tol_m: float
    angle_tol_deg: float

    def __post_init__(self) -> None:
        p = np.array(self.p_world_m, dtype=float).reshape(3)
        n = np.array(self.n_world, dtype=float).reshape(3)
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(n))):
            raise ValueError("goal position and normal must be finite")
        norm = float(np.linalg.norm(n))
        if norm < 1e-9:
            raise ValueError("goal normal must not be zero")
        n = n / norm
        p.setflags(write=False)
        n.setflags(write=False)
        object.__setattr__(self, "p_world_m", p)
        object.__setattr__(self, "n_world", n)
        if not (self.pos_tol_m > 0 and np.isfinite(self.pos_tol_m)):
            raise ValueError("pos_tol_m must be a positive number")
        if not (self.angle_tol_deg > 0 and np.isfinite(self.angle_tol_deg)):
            raise ValueError("angle_tol_deg must be a positive number")

    def errors(self, robot: Robot, q: Array) -> tuple[Array, Array]:
        """Position error [m] and angle error [deg] of q (dof,) or (k, dof)."""
        p, n = robot.tip(q)
        return self.errors_from_tip(p, n)

    def errors_from_tip(self, p_world_m: Array, n_world: Array) -> tuple[Array, Array]:
        """Position error [m] and angle error [deg] of a tip pose (3,) or (k, 3)."""
        pos_err = np.linalg.norm(np.asarray(p_world_m) - self.p_world_m, axis=-1)
        cosang = np.clip(np.asarray(n_world) @ self.n_world, -1.0, 1.0)
        return pos_err, np.degrees(np.arccos(cosang))

    def contains(self, robot: Robot, q: Array) -> NDArray[np.bool_]:
        """True where q is inside both tolerances (scalar bool for one q)."""
        pos_err, ang_err = self.errors(robot, q)
        return (pos_err <= self.pos_tol_m) & (ang_err <= self.angle_tol_deg)

    def distance(self, robot: Robot, q: Array) -> Array:
        """Normalised goal distance: max(pos_err/pos_tol, angle_err/angle_tol) - 1 clipped at 0.

        Zero exactly inside the region; grows with the larger of the two scaled errors.
        """
        p, n = robot.tip(q)
        return self.distance_from_tip(p, n)

    def distance_from_tip(self, p_world_m: Array, n_world: Array) -> Array:
        """:meth:`distance` of a tip pose (3,) or (k, 3) (one pose in scalar arithmetic:
        a planner's goal heuristic asks for one at a time)."""
        if np.ndim(p_world_m) == 1 and np.ndim(n_world) == 1:
            px, py, pz = (float(v) for v in p_world_m)
            nx, ny, nz = (float(v) for v in n_world)
            gp, gn = self.p_world_m, self.n_world
            dx, dy, dz = px - float(gp[0]), py - float(gp[1]), pz - float(gp[2])
            pos = math.sqrt(dx * dx + dy * dy + dz * dz)
            c = nx * float(gn[0]) + ny * float(gn[1]) + nz * float(gn[2])
            ang = math.degrees(math.acos(min(max(c, -1.0), 1.0)))
            return np.asarray(max(max(pos / self.pos_tol_m, ang / self.angle_tol_deg) - 1.0, 0.0))
        pos_err, ang_err = self.errors_from_tip(p_world_m, n_world)
        scaled = np.maximum(pos_err / self.pos_tol_m, ang_err / self.angle_tol_deg)
        return np.maximum(scaled - 1.0, 0.0)


@dataclass(frozen=True, eq=False)
class JointGoal(GoalRegion):
    """A goal state (MotionBenchMaker's joint goals): inside when every joint is within
    ``tol_rad`` of ``q_rad`` (continuous joints wrapped).

    It is a :class:`GoalRegion` whose tip target is the tip at ``q_rad`` and whose tip
    tolerances are the ones ``tol_rad`` implies to first order (``pos_tol_m = tol_rad ·
    Σ_i |∂p/∂q_i|``, the angle likewise), so code that looks at the tip (tip errors in the
    records, the execution's goal verdict, tip-steering planners) sees the same target;
    :meth:`contains` and :meth:`distance`, which decide "solved" for every planner, are
    the joint distance's. Build it with :meth:`at`.

    Args:
        q_rad: (dof,) the goal state [rad, m for prismatic joints].
        tol_rad: the largest joint difference still inside, > 0.
        continuous: (dof,) which joints wrap.
    """

    q_rad: Array = field(default_factory=lambda: np.zeros(0))
    tol_rad: float = 1e-3
    continuous: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def __post_init__(self) -> None:
        super().__post_init__()
        q = np.array(self.q_rad, dtype=float).reshape(-1)
        if not np.all(np.isfinite(q)):
            raise ValueError("goal state must be finite")
        if not (self.tol_rad > 0 and np.isfinite(self.tol_rad)):
            raise ValueError("tol_rad must be a positive number")
        cont = np.array(self.continuous, dtype=bool).reshape(-1)
        if cont.shape != q.shape:
            raise ValueError("continuous must have one flag per joint")
        q.setflags(write=False)
        cont.setflags(write=False)
        object.__setattr__(self, "q_rad", q)
        object.__setattr__(self, "continuous", cont)

    @classmethod
    def at(cls, robot: Robot, name: str, q_rad: Array, tol_rad: float) -> JointGoal:
        """The goal state ``q_rad`` of ``robot`` with joint tolerance ``tol_rad``."""
        q = np.asarray(q_rad, dtype=float).reshape(robot.dof)
        p, n = robot.tip(q)
        J_p, J_n = robot.tip_jacobian(q)
        pos_tol_m = max(tol_rad * float(np.sum(np.linalg.norm(J_p, axis=0))), 1e-9)
        angle_tol_deg = float(np.degrees(tol_rad * np.sum(np.linalg.norm(J_n, axis=0))))
        return cls(
            name=name,
            p_world_m=p,
            n_world=n,
            pos_tol_m=pos_tol_m,
            angle_tol_deg=min(max(angle_tol_deg, 1e-9), 180.0),
            q_rad=q,
            tol_rad=float(tol_rad),
            continuous=np.asarray(robot.continuous, dtype=bool),
        )

    def joint_error(self, q: Array) -> Array:
        """Largest joint difference from the goal state [rad or m]: scalar or (k,)."""
        d = joint_difference(np.asarray(q, dtype=float), self.q_rad, self.continuous)
        return np.max(np.abs(d), axis=-1)

    def contains(self, robot: Robot, q: Array) -> NDArray[np.bool_]:
        """True where every joint of q is within ``tol_rad`` of the goal state."""
        return np.asarray(self.joint_error(q) <= self.tol_rad)

    def distance(self, robot: Robot, q: Array) -> Array:
        """Normalised joint distance: max |q_i − q_goal_i| / tol_rad − 1, clipped at 0."""
        return np.maximum(self.joint_error(q) / self.tol_rad - 1.0, 0.0)


def unreachable_reason(robot: Robot, goal: GoalRegion) -> str | None:
    """Why no state of ``robot`` can put its tip in ``goal``'s position ball, or None.

    A cheap necessary condition checked before planning: the tip cannot be farther from
    the base than the chain is long. Fixed-base chains (Arm-Z, continuum): the bound is the
    base-to-first-link offset plus every link's length plus the last link-to-tip offset.
    IRb-6 on its track: the flange is at most lower arm + upper arm + wrist-to-flange from
    the shoulder, which slides along the track at the shoulder's height.
    """
    p = np.asarray(goal.p_world_m, dtype=float)
    T = np.asarray(robot.T_world_base, dtype=float)
    reach_from = reach_function(robot.kind)
    if reach_from is not None:
        dist, reach, where = reach_from(robot, p)
    elif getattr(robot, "max_reach_m", None) is not None:
        # a robot that bounds its own reach (a URDF chain: its collision spheres are no
        # measure of its length)
        reach = float(robot.max_reach_m)  # type: ignore[attr-defined]
        dist = float(np.linalg.norm(p - T[:3, 3]))
        where = "the base"
    else:
        q = np.zeros(robot.dof)
        seg = np.asarray(robot.link_segments(q), dtype=float)
        tip, _ = robot.tip(q)
        reach = float(
            np.linalg.norm(seg[0, 0] - T[:3, 3])
            + np.sum(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1))
            + np.linalg.norm(np.asarray(tip) - seg[-1, 1])
        )
        dist = float(np.linalg.norm(p - T[:3, 3]))
        where = "the base"
    if dist - goal.pos_tol_m > reach * (1.0 + 1e-9):
        return (
            f"goal {goal.name!r} at {p.round(3).tolist()} m is {dist:.3g} m from {where}, "
            f"but the {robot.kind} reaches at most {reach:.3g} m (+ pos_tol {goal.pos_tol_m:g} m)"
        )
    return None

"""The Arm-Z paper's objective as an object you can evaluate, differentiate and test.

    f(S) = r1 · |p − p_d| + r2 · (1 − n·n_d)² + A(S)

(``000_a8ed938e94518caf.txt``, eq. 3). A(S) is a penalty about five orders of magnitude
above typical values of f when S collides with itself or the scene. For a goal state
(joint goal) the first two terms are the squared joint distance ``r1 · |q − q_goal|² / 2``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plannerlab.problem.goals import GoalRegion, JointGoal
from plannerlab.problem.ik import ValidityChecker
from plannerlab.robots.base import Array, Robot, joint_difference


@dataclass(eq=False)
class Objective:
    """f(S) for one goal. Counts its evaluations (``evaluations``) and the states it
    asked the checker about; holds no other state.

    Args:
        robot: the robot.
        goal: target position p_d and normal n_d.
        checker: something with ``is_valid(q)``; None leaves A(S) out.
        r1, r2: weights of the position and normal terms (paper: 1, 1).
        penalty: A(S) when S is in collision (paper: ~1e5).
    """

    robot: Robot
    goal: GoalRegion
    checker: ValidityChecker | None = None
    r1: float = 1.0
    r2: float = 1.0
    penalty: float = 1e5
    evaluations: int = field(default=0, init=False)

    def smooth(self, q: Array) -> Array:
        """f without A(S), for q (dof,) or a batch (k, dof).

        For a goal state (:class:`~plannerlab.problem.goals.JointGoal`) the tip terms give
        way to the joint distance: ``f = r1 · |q − q_goal|² / 2`` (continuous joints
        wrapped; squared, so that the step γ∇f = γ r1 (q − q_goal) shrinks near the goal
        instead of circling it at γ r1).
        """
        if isinstance(self.goal, JointGoal):
            self.evaluations += 1 if np.ndim(q) == 1 else len(q)
            dq = joint_difference(q, self.goal.q_rad, self.goal.continuous)
            return 0.5 * self.r1 * np.sum(dq * dq, axis=-1)
        p, n = self.robot.tip(q)
        d = np.linalg.norm(p - self.goal.p_world_m, axis=-1)
        c = 1.0 - n @ self.goal.n_world
        self.evaluations += 1 if np.ndim(q) == 1 else len(q)
        return self.r1 * d + self.r2 * c**2

    def __call__(self, q: Array) -> float:
        value = float(self.smooth(q))
        if self.checker is not None and not self.checker.is_valid(q):
            value += self.penalty
        return value

    def smooth_gradient(self, q: Array) -> Array:
        """Analytic ∇ of the smooth part (dof,): chain rule through the tip Jacobians."""
        q = np.asarray(q, dtype=float)
        if isinstance(self.goal, JointGoal):
            self.evaluations += 1
            return self.r1 * joint_difference(q, self.goal.q_rad, self.goal.continuous)
        p, n = self.robot.tip(q)
        J_p, J_n = self.robot.tip_jacobian(q)
        self.evaluations += 1
        diff = p - self.goal.p_world_m
        dist = float(np.linalg.norm(diff))
        g_pos = (diff / dist) @ J_p if dist > 1e-12 else np.zeros(self.robot.dof)
        c = 1.0 - float(n @ self.goal.n_world)
        g_n = -2.0 * c * (self.goal.n_world @ J_n)
        return self.r1 * g_pos + self.r2 * g_n

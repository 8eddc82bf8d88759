"""The clearance descent's step in numpy: its direction (steepest descent or damped
Gauss-Newton on the tip residuals, or the joint residual towards a goal state, and the
clearance residuals), the metric of its quadratic model, and the hold that slides a step
along the clearance floor (see :mod:`plannerlab.planners.clearance.descent`). The
reference of the compiled step (:mod:`plannerlab.planners.clearance.compiled`)."""

from __future__ import annotations

import numpy as np

from plannerlab.planners.clearance.field import Clearance, ClearanceField
from plannerlab.planners.clearance.settings import ClearanceSettings
from plannerlab.problem.goals import JointGoal
from plannerlab.robots.base import Array, joint_difference


class DescentStep:
    """The step of the clearance descent on its ``settings`` (a base of
    :class:`~plannerlab.planners.clearance.descent.ClearanceDescent`)."""

    settings: ClearanceSettings

    def _f(self, robot, goal, q: Array) -> float:
        s = self.settings
        if isinstance(goal, JointGoal):
            return float(s.r1 * np.linalg.norm(joint_difference(q, goal.q_rad, goal.continuous)))
        p, n = robot.tip(q)
        return float(
            s.r1 * np.linalg.norm(p - goal.p_world_m) + s.r2 * (1.0 - n @ goal.n_world) ** 2
        )

    def _direction(self, robot, goal, field: ClearanceField, q: Array) -> tuple[Array, float]:
        """Descent direction (dof,) and F at q."""
        s = self.settings
        c = field(q)
        if isinstance(goal, JointGoal):
            return self._joint_direction(goal, field, q, c)
        p, n = robot.tip(q)
        J_p, J_n = robot.tip_jacobian(q)
        diff = p - goal.p_world_m
        dist = float(np.linalg.norm(diff))
        cn = 1.0 - float(n @ goal.n_world)
        F = s.r1 * dist + s.r2 * cn**2 + s.clearance_weight * c.cost
        if s.direction == "gradient":
            g_pos = (diff / dist) @ J_p if dist > 1e-12 else np.zeros(robot.dof)
            g = s.r1 * g_pos - 2.0 * s.r2 * cn * (goal.n_world @ J_n)
            g = g + s.clearance_weight * c.gradient
            return -g, F
        # Gauss-Newton on scaled tip residuals + clearance residuals
        pos_scale = 1.0 / goal.pos_tol_m
        ang_scale = 1.0 / np.deg2rad(goal.angle_tol_deg)
        e = np.concatenate([(goal.p_world_m - p) * pos_scale, (goal.n_world - n) * ang_scale])
        # aim only as deep as goal_depth of the tolerances: no pull once well inside
        pos_err = dist / goal.pos_tol_m
        ang_err = np.arccos(np.clip(1.0 - cn, -1.0, 1.0)) * ang_scale
        if pos_err < s.goal_depth:
            e[:3] = 0.0
        if ang_err < s.goal_depth:
            e[3:] = 0.0
        J = np.vstack([J_p * pos_scale, J_n * ang_scale])
        A = J.T @ J
        b = J.T @ e
        if c.close_pairs:
            # residual r = k (m − d), k = √(w/m); J_r = −k ∇d; Gauss-Newton uses −J_r^T r
            # = k² (m − d) ∇d = −(w/2) ∇cost, and J_r^T J_r = k² ∇d ∇d^T
            dd = self._distance_gradients(field, q)
            k2 = s.clearance_weight / s.influence_m
            A = A + k2 * dd.T @ dd
            b = b - 0.5 * s.clearance_weight * c.gradient
        A = A + s.damping**2 * np.eye(robot.dof)
        return np.linalg.solve(A, b), F

    def _metric(self, robot, goal, field: ClearanceField, q: Array) -> Array:
        """The matrix A (dof, dof) of the quadratic model :meth:`_direction` minimises at q
        (Gauss-Newton: JᵀJ of the scaled tip residuals, or of the joint residuals towards a
        goal state, plus the clearance residuals',
        plus the damping; the identity for ``direction = "gradient"``)."""
        s = self.settings
        if s.direction == "gradient":
            return np.eye(robot.dof)
        if isinstance(goal, JointGoal):  # the joint residual's Jacobian I / tol_rad
            A = np.eye(robot.dof) / goal.tol_rad**2
        else:
            J_p, J_n = robot.tip_jacobian(q)
            J = np.vstack([J_p / goal.pos_tol_m, J_n / np.deg2rad(goal.angle_tol_deg)])
            A = J.T @ J
        if field(q).close_pairs:
            dd = self._distance_gradients(field, q)
            A = A + (s.clearance_weight / s.influence_m) * dd.T @ dd
        return A + s.damping**2 * np.eye(robot.dof)

    def _joint_direction(
        self, goal: JointGoal, field: ClearanceField, q: Array, c: Clearance
    ) -> tuple[Array, float]:
        """:meth:`_direction` towards a goal state: F = |(q − q_goal) / tol_rad|² + w · cost
        (continuous joints wrapped), the sum of squares whose Gauss-Newton step is taken:
        the joint residual (q_goal − q) / tol_rad (its Jacobian I / tol_rad) and the
        clearance residuals; or −∇F."""
        s = self.settings
        dq = joint_difference(q, goal.q_rad, goal.continuous)
        F = joint_residual_sq(goal, q) + s.clearance_weight * c.cost
        if s.direction == "gradient":
            g = 2.0 * dq / goal.tol_rad**2
            return -(g + s.clearance_weight * c.gradient), F
        scale = 1.0 / goal.tol_rad
        e = -dq * scale
        # aim only as deep as goal_depth of the tolerance: no pull once well inside
        if float(np.max(np.abs(dq), initial=0.0)) * scale < s.goal_depth:
            e[:] = 0.0
        A = scale**2 * np.eye(len(q))
        b = scale * e
        if c.close_pairs:
            dd = self._distance_gradients(field, q)
            k2 = s.clearance_weight / s.influence_m
            A = A + k2 * dd.T @ dd
            b = b - 0.5 * s.clearance_weight * c.gradient
        A = A + s.damping**2 * np.eye(len(q))
        direction: Array = np.asarray(np.linalg.solve(A, b), dtype=float)
        return direction, F

    @staticmethod
    def _distance_gradients(field: ClearanceField, q: Array) -> Array:
        """∇d (c, dof) of the pairs inside the margin."""
        p, J = field._centres_and_jacobians(q)
        d, n, a, b = field._pairs(p)
        close = d < field.influence_m
        n, a, b = n[close], a[close], b[close]
        g = np.einsum("ck,ckj->cj", n, J[a])
        is_self = b >= 0
        if is_self.any():
            g[is_self] -= np.einsum("ck,ckj->cj", n[is_self], J[b[is_self]])
        return g

    def _hold_clearance(
        self, field: ClearanceField, q: Array, direction: Array, metric: Array | None = None
    ) -> Array:
        """The step ``direction`` (dof,) changed as little as possible so that no sphere
        pair within ``hold_band_m`` (1 cm on Arm-Z) of ``clearance_floor_m`` comes closer
        (to first order: it moves away at a small angle, 0.1 of its gradient's full
        rate), so the descent slides along the clearance floor instead of stalling
        against it (a step that would take such a pair closer is refused, and the
        descent otherwise only shrinks its step).
        Active-set projection, at most 10 rounds.

        "As little as possible" is measured in ``metric`` (A, the quadratic model's
        matrix, :meth:`_metric`): ``dq = direction + A⁻¹ Gᵀ λ``, the minimiser of the
        model under the pairs' constraints, so the held step still lowers the model the
        direction came from. (The Euclidean projection, ``metric`` None, is not: on a
        room variant, v14 leg A, it raised F at every radius and the descent stalled with
        the trust radius collapsing; projected in A it solved the leg.)"""
        s = self.settings
        p, J = field._centres_and_jacobians(q)
        d, n, a, b = field._pairs(p)
        active = np.flatnonzero(d < s.clearance_floor_m + s.hold_band_m)
        if active.size == 0:
            return direction
        G = np.einsum("ck,ckj->cj", n[active], J[a[active]])
        is_self = b[active] >= 0
        if is_self.any():
            G[is_self] -= np.einsum("ck,ckj->cj", n[active][is_self], J[b[active][is_self]])
        norms = np.linalg.norm(G, axis=1)
        want = 0.1 * norms * float(np.linalg.norm(direction))
        chosen = np.zeros(len(active), dtype=bool)
        dq = direction
        # A⁻¹ Gᵀ (columns: each pair's gradient in the model's metric)
        AiGt = G.T if metric is None else np.linalg.solve(metric, G.T)
        for _ in range(10):
            short = (G @ dq) < want - 1e-12
            if not short.any():
                break
            chosen |= short
            K = G[chosen] @ AiGt[:, chosen]
            reg = 1e-9 * max(float(np.trace(K)) / len(K), 1e-12) * np.eye(len(K))
            lam = np.linalg.solve(K + reg, want[chosen] - G[chosen] @ direction)
            dq = direction + AiGt[:, chosen] @ lam
        return dq

    def _F(self, robot, goal, field: ClearanceField, q: Array) -> float:
        return self._f(robot, goal, q) + self.settings.clearance_weight * field(q).cost


def joint_residual_sq(goal: JointGoal, q: Array) -> float:
    """|(q − q_goal) / tol_rad|², continuous joints wrapped: the goal part of F towards a
    goal state."""
    e = joint_difference(q, goal.q_rad, goal.continuous) / goal.tol_rad
    return float(e @ e)


__all__ = ["DescentStep", "joint_residual_sq"]

"""Compiled inverse kinematics of a serial chain (a URDF robot) for position + normal goals.

The descent of :func:`plannerlab.problem.ik.solve_ik` (damped least squares on the tip
position error scaled by ``pos_tol_m`` and the tip normal error scaled by the angle
tolerance in radians; each step scaled so that no joint moves more than ``max_step_rad``;
bounded joints clipped, continuous ones wrapped into [-π, π); stop once both errors are
below ``target_fraction`` of the tolerances) in one numba call per descent, on the chain
of ``robot.chain_data()`` folded as the compiled model folds it
(:func:`~plannerlab.collision.model.folded_chain`: every joint's axis turned onto its
frame's z axis) and its tip (``robot.tip_data()``: the body, the tip point and normal in
its frame), on the one forward kinematics
(:func:`~plannerlab.collision.kinematics.chain_frames`). The Jacobian is the chain's own:
joint ``i`` turns (or slides) about its world axis ``w_i`` (its body's folded z) through
its body's origin ``o_i``, so
``dp/dv_i = w_i × (p − o_i)`` (``w_i``) and ``dn/dv_i = w_i × n`` (0), and through the
coupling ``dv/dq``.

A family opts in through the flag of its registry entry
(:attr:`plannerlab.robots.registry.RobotFamily.compiled_ik`: the URDF family);
:func:`descent_for_robot` gives its descent, which the planners' goal sampling hands to
:func:`plannerlab.problem.ik.sample_goal_state` to restart instead of the numpy one. The
goal states it returns are checked there as before (the region test in numpy, one
collision check).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.kinematics import chain_frames, chain_values
from plannerlab.collision.model import folded_chain
from plannerlab.robots.registry import compiled_ik


class IkChain(NamedTuple):
    """A robot's chain folded (:func:`~plannerlab.collision.model.folded_chain`: the
    compiled model's kinematic fields) and its tip, for :func:`descend_kernel`."""

    T0: np.ndarray  # (12,)
    parent: np.ndarray  # (n,)
    pre: np.ndarray  # (n, 12) the axes folded onto z
    slide: np.ndarray  # (n,) bool
    cpl_start: np.ndarray  # the coupling, sparse (empty: v = q)
    cpl_idx: np.ndarray
    cpl_val: np.ndarray
    path: np.ndarray  # the chain joints that move the tip body, root first
    tip_body: int
    tip_p: np.ndarray  # (3,) the tip point and normal in the tip body's folded frame
    tip_n: np.ndarray


class IkGoal(NamedTuple):
    """The goal region: tip point p_d and normal n_d, tolerances [m] and [rad]."""

    p_d: np.ndarray
    n_d: np.ndarray
    pos_tol: float
    ang_tol: float


class IkBounds(NamedTuple):
    lower: np.ndarray
    upper: np.ndarray
    continuous: np.ndarray


class IkSteps(NamedTuple):
    """The descent's settings (:func:`plannerlab.problem.ik.solve_ik`'s)."""

    max_iterations: int
    damping: float
    max_step: float
    target_fraction: float


@njit(cache=True, nogil=True)
def _frames(q, ch, F, v):
    """Body frames F (flat, (n + 1) x 12: 3 x 4 rows) of state q by the one kinematics
    (:func:`~plannerlab.collision.kinematics.chain_frames`); v (n,) the coupling's
    joint values."""
    if ch.cpl_start.shape[0] == 0:
        chain_frames(F, q, ch.T0, ch.pre, ch.parent, ch.slide)
    else:
        chain_values(q, (ch.cpl_start, ch.cpl_idx, ch.cpl_val), v)
        chain_frames(F, v, ch.T0, ch.pre, ch.parent, ch.slide)


@njit(cache=True, nogil=True)
def _tip(B, tip_body, p_bt, n_bt, p, nv):
    """Tip position p and normal nv in the world from the body frames."""
    F = B[tip_body]
    for a in range(3):
        p[a] = F[a, 0] * p_bt[0] + F[a, 1] * p_bt[1] + F[a, 2] * p_bt[2] + F[a, 3]
        nv[a] = F[a, 0] * n_bt[0] + F[a, 1] * n_bt[1] + F[a, 2] * n_bt[2]


@njit(cache=True, nogil=True)
def _errors(p, nv, p_d, n_d):
    """Position error [m] and angle error [rad] (``GoalRegion.errors_from_tip``)."""
    dx, dy, dz = p[0] - p_d[0], p[1] - p_d[1], p[2] - p_d[2]
    c = nv[0] * n_d[0] + nv[1] * n_d[1] + nv[2] * n_d[2]
    c = min(1.0, max(-1.0, c))
    return math.sqrt(dx * dx + dy * dy + dz * dz), math.acos(c)


@njit(cache=True, nogil=True)
def _solve6(A, e, x):
    """x = A⁻¹ e for a symmetric positive definite A (6, 6), by Cholesky (A overwritten)."""
    n = 6
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        d = math.sqrt(max(s, 1e-300))
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(n):
        s = e[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= A[k, i] * x[k]
        x[i] = s / A[i, i]


@njit(cache=True, nogil=True)
def descend_kernel(q0, ch, goal, bounds, steps_of, q):
    """One descent from q0 (dof,) into q (dof,): returns (steps, pos_err_m, ang_err_rad)
    at q, on the chain ``ch`` (:class:`IkChain`) towards ``goal`` (:class:`IkGoal`) within
    ``bounds`` (:class:`IkBounds`) by the settings ``steps_of`` (:class:`IkSteps`)."""
    p_d, n_d, pos_tol, ang_tol = goal
    lower, upper, continuous = bounds
    max_iterations, damping, max_step, target_fraction = steps_of
    path, slide, cpl_start, cpl_idx, cpl_val = (
        ch.path,
        ch.slide,
        ch.cpl_start,
        ch.cpl_idx,
        ch.cpl_val,
    )
    dof = q0.shape[0]
    n = ch.parent.shape[0]
    F = np.empty(12 * (n + 1))
    B = F.reshape((n + 1, 3, 4))
    v = np.empty(n)
    p = np.empty(3)
    nv = np.empty(3)
    Jv = np.zeros((6, n))
    J = np.zeros((6, dof))
    A = np.empty((6, 6))
    e = np.empty(6)
    x = np.empty(6)
    dq = np.empty(dof)
    two_pi = 2.0 * math.pi
    for i in range(dof):
        qi = q0[i]
        if continuous[i]:
            qi = (qi + math.pi) % two_pi - math.pi
        else:
            qi = min(max(qi, lower[i]), upper[i])
        q[i] = qi
    ps = 1.0 / pos_tol
    an = 1.0 / ang_tol
    lam2 = damping * damping
    steps = 0
    for it in range(max_iterations + 1):
        _frames(q, ch, F, v)
        _tip(B, ch.tip_body, ch.tip_p, ch.tip_n, p, nv)
        pe, ae = _errors(p, nv, p_d, n_d)
        if (pe <= target_fraction * pos_tol and ae <= target_fraction * ang_tol) or (
            it == max_iterations
        ):
            return steps, pe, ae
        steps += 1
        for a in range(3):
            e[a] = (p_d[a] - p[a]) * ps
            e[3 + a] = (n_d[a] - nv[a]) * an
        # the chain's Jacobian (6, n) in its joint values
        for a in range(6):
            for i in range(n):
                Jv[a, i] = 0.0
        for k in range(path.shape[0]):
            i = path[k]
            Fi = B[i + 1]  # the joint's axis: its body's folded z
            wx, wy, wz = Fi[0, 2], Fi[1, 2], Fi[2, 2]
            if slide[i]:
                Jv[0, i], Jv[1, i], Jv[2, i] = wx * ps, wy * ps, wz * ps
            else:
                rx, ry, rz = p[0] - Fi[0, 3], p[1] - Fi[1, 3], p[2] - Fi[2, 3]
                Jv[0, i] = (wy * rz - wz * ry) * ps
                Jv[1, i] = (wz * rx - wx * rz) * ps
                Jv[2, i] = (wx * ry - wy * rx) * ps
                Jv[3, i] = (wy * nv[2] - wz * nv[1]) * an
                Jv[4, i] = (wz * nv[0] - wx * nv[2]) * an
                Jv[5, i] = (wx * nv[1] - wy * nv[0]) * an
        if cpl_start.shape[0] > 0:  # J = Jv · dv/dq, the coupling sparse
            for a in range(6):
                for j in range(dof):
                    J[a, j] = 0.0
                for i in range(n):
                    for k in range(cpl_start[i], cpl_start[i + 1]):
                        J[a, cpl_idx[k]] += Jv[a, i] * cpl_val[k]
        else:
            for a in range(6):
                for j in range(dof):
                    J[a, j] = Jv[a, j]
        # dq = Jᵀ (J Jᵀ + λ² I)⁻¹ e
        for a in range(6):
            for b in range(a, 6):
                acc = 0.0
                for j in range(dof):
                    acc += J[a, j] * J[b, j]
                A[a, b] = acc
                A[b, a] = acc
            A[a, a] += lam2
        _solve6(A, e, x)
        big = 0.0
        for j in range(dof):
            acc = 0.0
            for a in range(6):
                acc += J[a, j] * x[a]
            dq[j] = acc
            big = max(big, abs(acc))
        scale = max_step / big if big > max_step else 1.0
        for j in range(dof):
            qj = q[j] + dq[j] * scale
            if continuous[j]:
                qj = (qj + math.pi) % two_pi - math.pi
            else:
                qj = min(max(qj, lower[j]), upper[j])
            q[j] = qj
    return steps, 0.0, 0.0  # not reached


def ik_arrays(robot: Any) -> IkChain:
    """The chain and tip of a robot as :func:`descend_kernel` takes them (folded as the
    compiled model folds it)."""
    ch = folded_chain(robot)
    tip_body, p_bt, n_bt = robot.tip_data()
    path = []
    b = int(tip_body)
    while b > 0:
        path.append(b - 1)
        b = int(ch.parent[b - 1])
    A = np.asarray(ch.fold[int(tip_body)], dtype=float)
    f = np.ascontiguousarray
    return IkChain(
        T0=ch.T0,
        parent=ch.parent,
        pre=ch.pre,
        slide=ch.slide,
        cpl_start=ch.cpl_start,
        cpl_idx=ch.cpl_idx,
        cpl_val=ch.cpl_val,
        path=np.array(path[::-1], dtype=np.int64),
        tip_body=int(tip_body),
        tip_p=f(A.T @ np.asarray(p_bt, dtype=np.float64)),
        tip_n=f(A.T @ np.asarray(n_bt, dtype=np.float64)),
    )


class ChainDescent:
    """The compiled descent of one robot (its arrays made once; the kernel compiled or
    loaded from numba's cache when this is built, not inside a search), called as
    ``descent(goal, q_seed, max_iterations, damping, max_step_rad, target_fraction)`` ->
    (q (dof,), steps) for a :class:`~plannerlab.problem.goals.GoalRegion` ``goal``: the
    signature :func:`plannerlab.problem.ik.solve_ik` runs a family's descent with."""

    def __init__(self, robot: Any) -> None:
        self.dof = int(robot.dof)
        self._arrays = ik_arrays(robot)
        f = np.ascontiguousarray
        self._bounds = IkBounds(
            f(robot.lower, dtype=np.float64),
            f(robot.upper, dtype=np.float64),
            f(robot.continuous, dtype=np.bool_),
        )
        kernel: Any = descend_kernel  # a numba dispatcher
        if not kernel.signatures:  # compile (first run on the machine) or load it here
            q = np.clip(np.zeros(self.dof), robot.lower, robot.upper)
            kernel(
                q,
                self._arrays,
                IkGoal(np.zeros(3), np.ones(3) / 3**0.5, 1.0, 1.0),
                self._bounds,
                IkSteps(0, 0.05, 0.25, 0.3),
                np.empty(self.dof),
            )

    def __call__(
        self,
        goal: Any,
        q_seed: Any,
        max_iterations: int,
        damping: float,
        max_step_rad: float,
        target_fraction: float,
    ) -> tuple[np.ndarray, int]:
        q = np.empty(self.dof)
        kernel: Any = descend_kernel  # a numba dispatcher
        steps, _, _ = kernel(
            np.ascontiguousarray(q_seed, dtype=np.float64).reshape(self.dof),
            self._arrays,
            IkGoal(  # fresh writable copies: a goal's read-only arrays would be another
                # signature than the warm-up's, compiled again (~2 s on a cold cache)
                np.array(goal.p_world_m, dtype=np.float64),
                np.array(goal.n_world, dtype=np.float64),
                float(goal.pos_tol_m),
                math.radians(float(goal.angle_tol_deg)),
            ),
            self._bounds,
            IkSteps(
                int(max_iterations), float(damping), float(max_step_rad), float(target_fraction)
            ),
            q,
        )
        return q, int(steps)


def descent_for(robot: Any) -> ChainDescent:
    """The compiled descent of a robot with a chain and a tip (``tip_data()``)."""
    return ChainDescent(robot)


def descent_for_robot(robot: Any) -> ChainDescent | None:
    """The compiled descent of ``robot`` when its family opts in
    (:attr:`~plannerlab.robots.registry.RobotFamily.compiled_ik`: URDF chains), else None
    (the numpy descent; also for a robot built in code whose kind is not registered)."""
    return descent_for(robot) if compiled_ik(str(getattr(robot, "kind", ""))) else None


__all__ = [
    "ChainDescent",
    "IkBounds",
    "IkChain",
    "IkGoal",
    "IkSteps",
    "descend_kernel",
    "descent_for",
    "descent_for_robot",
    "ik_arrays",
]

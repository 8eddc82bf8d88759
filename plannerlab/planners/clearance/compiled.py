"""The clearance descent's compiled inner loop (numba, cached): the clearance field of
:mod:`plannerlab.planners.clearance` and the step of
:class:`~plannerlab.planners.clearance.descent.ClearanceDescent`.

One call, :func:`evaluate`, gives everything the descent asks at a state: the objective
``f`` and ``F = f + w · cost``, the tip's position and angle errors, every sphere pair's
distance (the ``spacious`` test compares them between states) and, when asked, the step
direction (steepest descent or damped Gauss-Newton on the tip residuals plus one residual
per close pair; towards a goal state, on the joint residual instead of the tip's).
:func:`hold_clearance` is the active-set projection of
``ClearanceDescent._hold_clearance``. Both are the numpy code's arithmetic written as
loops (same spheres, same pairs in the same order, same formulas), so the compiled descent
takes the numpy descent's steps to rounding (``tests/planners/test_descent_core.py`` holds the two
paths to 1e-9 rad on a fixed problem).

No geometry of its own: the chain's frames, the tip, the sphere centres, the pairs and
their gradients are the compiled robot–scene model's kinematics
(:mod:`plannerlab.collision.spheres` on a :class:`~plannerlab.collision.model.
CompiledModel`). :class:`CompiledField` packs a :class:`~plannerlab.planners.clearance.
ClearanceField`'s spheres and pairs, the scene and the chain once into one
:class:`SphereField` (named tuples of arrays: one argument, loaded from numba's cache).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.spheres import (
    BOX,
    CYLINDER,
    SPHERE,
    SphereChain,
    centres,
    frames,
    kin,
    model_sphere_chain,
    pair_gradient,
    pair_spheres,
    pairs,
    sphere_chain,
    tip_jacobians,
    tip_pose,
)
from plannerlab.planners.clearance.field import ClearanceField
from plannerlab.problem.scene import Box, Cylinder, Sphere, touch_mask
from plannerlab.robots.base import Array


class SphereField(NamedTuple):
    """A :class:`ClearanceField` packed for the kernels: the chain, the spheres (each one's
    link, place ``t`` on it and radius), the pairs (the scene's spheres, the self pairs,
    every pair's spheres ``A``, ``B`` and :func:`~plannerlab.collision.spheres.
    pair_spheres`' culls), the obstacles and the margin."""

    ch: SphereChain
    link: np.ndarray
    t: np.ndarray
    r: np.ndarray
    scene_idx: np.ndarray
    self_a: np.ndarray
    self_b: np.ndarray
    scene: tuple  # (kinds, Rs, cs, pars, bound, touch: (n, s) declared contacts)
    A: np.ndarray
    B: np.ndarray
    lp_of_row: np.ndarray
    lp_links: np.ndarray
    ends: np.ndarray
    margin: float


class DescentGoal(NamedTuple):
    """A goal for :func:`evaluate`: the tip target (p, n) and tolerances, or a goal state
    (``joint``: q, its continuous joints and tolerance; empty arrays for a tip goal)."""

    p: np.ndarray
    n: np.ndarray
    pos_tol: float
    angle_tol_deg: float
    joint: bool
    q: np.ndarray
    continuous: np.ndarray
    tol_rad: float


class StepRule(NamedTuple):
    """The step's settings: objective weights, clearance weight, the rule, damping and
    how deep into the goal region the tip residuals count."""

    r1: float
    r2: float
    weight: float
    gauss_newton: bool
    damping: float
    goal_depth: float


@njit(cache=True, nogil=True, inline="always")
def _pairs_of(P, fld, far_m):
    """Every pair's distance and direction at the centres P (:func:`pairs`)."""
    return pairs(
        P,
        fld.r,
        fld.scene_idx,
        (fld.self_a, fld.self_b),
        fld.scene,
        far_m,
        (fld.lp_of_row, fld.lp_links, fld.ends),
    )


# ---------------------------------------------------------------------- the descent
@njit(cache=True, nogil=True)
def evaluate(q, fld, far_m, goal, rule, want_direction, d_ref, floor_m):
    """The descent's view of state q: (F, f, pos_err_m, ang_err_deg, cost, gradient (dof,),
    distances (m,), direction (dof,); zeros unless ``want_direction``, spacious, metric,
    joint_err). Spacious: every pair is at least ``floor_m`` apart or no closer than in
    ``d_ref`` (the distances at the state the step starts from; empty: True). Towards a
    goal state (``goal.joint``) with tolerance ``tol_rad``: f = r1 |q − q_goal|,
    F = |(q − q_goal) / tol_rad|² + w · cost, the Gauss-Newton residual
    (q_goal − q) / tol_rad, and joint_err the largest joint difference (else 0).

    The steps, each its own compiled function: the chain's frames and tip
    (:func:`~plannerlab.collision.spheres.frames`, :func:`_tip_errors`) or the joint
    errors (:func:`_joint_errors`), the sphere centres and pairs, the clearance cost and
    its gradient (:func:`_clearance_cost`), the spacious test (:func:`_spacious`), and
    the step direction: towards a goal state :func:`_joint_direction`, else the tip's
    Jacobians and :func:`_tip_steepest` or :func:`_tip_gauss_newton`. The steps of this
    module and the kinematics are inlined into it (``inline="always"``: numba's IR); the
    pairs are called."""
    dof = q.shape[0]
    ch = fld.ch
    Bf = frames(q, ch)
    p, n, diff, dist, cn, ang_err_deg = _tip_errors(Bf, ch, goal.p, goal.n)
    r1, r2, weight = rule.r1, rule.r2, rule.weight
    f = r1 * dist + r2 * cn**2
    dq = np.zeros(dof)
    joint_err = 0.0
    e_sq = 0.0  # |dq / tol_rad|²
    if goal.joint:
        dq, sq, e_sq, joint_err = _joint_errors(q, goal.q, goal.continuous, goal.tol_rad)
        f = r1 * math.sqrt(sq)

    P = centres(Bf, ch, fld.link, fld.t)
    d, nrm = _pairs_of(P, fld, far_m)
    margin = fld.margin
    cost, grad, n_close, close = _clearance_cost(Bf, fld, P, nrm, d, dof)
    if goal.joint:
        F = e_sq + weight * cost
    else:
        F = r1 * dist + r2 * cn**2 + weight * cost
    spacious = _spacious(d, d_ref, floor_m)
    direction = np.zeros(dof)
    metric = np.eye(dof)  # the step's quadratic model (the identity for plain gradients)
    if not want_direction:
        return F, f, dist, ang_err_deg, cost, grad, d, direction, spacious, metric, joint_err
    close_pairs = (Bf, fld, P, nrm, n_close, close, margin)
    if goal.joint:
        direction, metric = _joint_direction(dq, joint_err, close_pairs, grad, rule, goal.tol_rad)
        return F, f, dist, ang_err_deg, cost, grad, d, direction, spacious, metric, joint_err

    Jp, Jn = tip_jacobians(Bf, ch, p, n, dof)
    if not rule.gauss_newton:
        direction = _tip_steepest(diff, dist, cn, goal.n, (Jp, Jn), grad, rule)
        return F, f, dist, ang_err_deg, cost, grad, d, direction, spacious, metric, joint_err
    direction, A = _tip_gauss_newton(
        (p, n, dist, cn),
        (goal.p, goal.n, goal.pos_tol, goal.angle_tol_deg),
        Jp,
        Jn,
        rule,
        close_pairs,
        grad,
    )
    return F, f, dist, ang_err_deg, cost, grad, d, direction, spacious, A, joint_err


# ---------------------------------------------------------------------- its steps
@njit(cache=True, nogil=True, inline="always")
def _tip_errors(Bf, ch, p_goal, n_goal):
    """The tip (of the body frames ``Bf``) against the tip target (p_goal, n_goal): its
    position p (3,), normal n (3,), p − p_goal (3,), |p − p_goal| [m], 1 − n · n_goal
    and the angle between n and n_goal [deg]."""
    p, n = tip_pose(Bf, ch)
    diff = p - p_goal
    dist = math.sqrt(diff[0] ** 2 + diff[1] ** 2 + diff[2] ** 2)
    dot = n[0] * n_goal[0] + n[1] * n_goal[1] + n[2] * n_goal[2]
    cn = 1.0 - dot
    ang_err_deg = math.degrees(math.acos(min(max(dot, -1.0), 1.0)))
    return p, n, diff, dist, cn, ang_err_deg


@njit(cache=True, nogil=True, inline="always")
def _joint_errors(q, q_goal, continuous, tol_rad):
    """q (dof,) against the goal state q_goal (dof,) (``continuous`` joints wrapped to
    [−π, π)): dq = q − q_goal (dof,), |dq|², |dq / tol_rad|² and the largest |dq_j| [rad]."""
    dof = q.shape[0]
    dq = np.zeros(dof)
    joint_err = 0.0
    e_sq = 0.0
    sq = 0.0
    for j in range(dof):
        dj = q[j] - q_goal[j]
        if continuous[j]:
            dj = (dj + math.pi) % (2.0 * math.pi) - math.pi
        dq[j] = dj
        sq += dj * dj
        e_sq += (dj / tol_rad) ** 2
        joint_err = max(joint_err, abs(dj))
    return dq, sq, e_sq, joint_err


@njit(cache=True, nogil=True, inline="always")
def _clearance_cost(Bf, fld, P, nrm, d, dof):
    """The clearance cost Σ (margin − d)² / margin over the pairs closer than the margin,
    its gradient (dof,), how many pairs are that close and their rows (n_close,)."""
    margin = fld.margin
    kn, link, A_idx, B_idx = kin(fld.ch), fld.link, fld.A, fld.B
    cost = 0.0
    grad = np.zeros(dof)
    n_close = 0
    for i in range(d.shape[0]):
        if d[i] < margin:
            n_close += 1
            gap = margin - d[i]
            cost += gap * gap
    cost = cost / margin
    gi = np.empty(dof)
    close = np.empty(n_close, dtype=np.int64)
    k = 0
    for i in range(d.shape[0]):
        if d[i] < margin:
            close[k] = i
            k += 1
            wgt = -2.0 * (margin - d[i]) / margin
            pair_gradient(Bf, kn, P, link, nrm, (A_idx[i], B_idx[i], i), gi)
            for j in range(dof):
                grad[j] += wgt * gi[j]
    return cost, grad, n_close, close


@njit(cache=True, nogil=True, inline="always")
def _spacious(d, d_ref, floor_m):
    """No pair closer than ``floor_m`` that came closer than in ``d_ref`` (empty: True)."""
    if d_ref.shape[0] == d.shape[0]:
        for i in range(d.shape[0]):
            if d[i] < floor_m and d[i] < d_ref[i] - 1e-9:
                return False
    return True


@njit(cache=True, nogil=True, inline="always")
def _tip_steepest(diff, dist, cn, n_goal, J, grad, rule):
    """Steepest descent on F = r1 |p − p_goal| + r2 (1 − n · n_goal)² + w · cost (dof,);
    J = (Jp, Jn) the tip's Jacobians, ``rule`` the :class:`StepRule` (scalars only)."""
    Jp, Jn = J
    r1, r2, weight = rule.r1, rule.r2, rule.weight
    dof = Jp.shape[1]
    direction = np.zeros(dof)
    for j in range(dof):
        g = 0.0
        if dist > 1e-12:
            g = (diff[0] * Jp[0, j] + diff[1] * Jp[1, j] + diff[2] * Jp[2, j]) / dist
        gn = n_goal[0] * Jn[0, j] + n_goal[1] * Jn[1, j] + n_goal[2] * Jn[2, j]
        direction[j] = -(r1 * g - 2.0 * r2 * cn * gn + weight * grad[j])
    return direction


@njit(cache=True, nogil=True, inline="always")
def _tip_gauss_newton(tip, target, Jp, Jn, rule, pairs, grad):
    """Damped Gauss-Newton on the tip residuals (p_goal − p) / pos_tol and
    (n_goal − n) / angle_tol (each zero once deeper than ``goal_depth`` tolerances in the
    goal) plus one residual per close pair (``pairs``, see :func:`_with_close_pairs`):
    the step (dof,) and the matrix of its quadratic model (dof, dof). ``tip`` = (p, n,
    dist, cn), ``target`` = (p_goal, n_goal, pos_tol, angle_tol_deg), ``rule`` the
    :class:`StepRule` (scalars only)."""
    p, n, dist, cn = tip
    p_goal, n_goal, pos_tol, angle_tol_deg = target
    goal_depth, weight, damping = rule.goal_depth, rule.weight, rule.damping
    dof = Jp.shape[1]
    pos_scale = 1.0 / pos_tol
    ang_scale = 1.0 / math.radians(angle_tol_deg)
    e = np.empty(6)
    for k in range(3):
        e[k] = (p_goal[k] - p[k]) * pos_scale
        e[3 + k] = (n_goal[k] - n[k]) * ang_scale
    if dist / pos_tol < goal_depth:
        e[:3] = 0.0
    if math.acos(min(max(1.0 - cn, -1.0), 1.0)) * ang_scale < goal_depth:
        e[3:] = 0.0
    Jt = np.empty((6, dof))
    for k in range(3):
        for j in range(dof):
            Jt[k, j] = Jp[k, j] * pos_scale
            Jt[3 + k, j] = Jn[k, j] * ang_scale
    A = Jt.T @ Jt
    b = Jt.T @ e
    return _damped_solve(_with_close_pairs(A, b, pairs, grad, weight), b, damping)


@njit(cache=True, nogil=True, inline="always")
def _with_close_pairs(A, b, pairs, grad, weight):
    """The Gauss-Newton system (A, b) with one residual per close pair added:
    A + (w / margin) D^T D (a new matrix; D (n_close, dof): the close pairs' distance
    gradients) and b − w/2 · gradient (in place). ``pairs``: the body frames, the field,
    the centres, the pairs' directions, how many pairs are close, their rows and the
    margin."""
    Bf, fld, P, nrm, n_close, close, margin = pairs
    kn, link, A_idx, B_idx = kin(fld.ch), fld.link, fld.A, fld.B
    dof = b.shape[0]
    if n_close > 0:
        gi = np.empty(dof)
        dd = np.empty((n_close, dof))
        for c in range(n_close):
            i = close[c]
            pair_gradient(Bf, kn, P, link, nrm, (A_idx[i], B_idx[i], i), gi)
            dd[c] = gi
        k2 = weight / margin
        A = A + k2 * (dd.T @ dd)
        for j in range(dof):
            b[j] = b[j] - 0.5 * weight * grad[j]
    return A


@njit(cache=True, nogil=True, inline="always")
def _damped_solve(A, b, damping):
    """A + damping² I (A changed in place) and the solution of (A + damping² I) x = b:
    (x, A)."""
    for j in range(b.shape[0]):
        A[j, j] += damping**2
    return np.linalg.solve(A, b), A


@njit(cache=True, nogil=True, inline="always")
def _joint_direction(dq, joint_err, pairs, grad, rule, tol_rad):
    """The step towards a goal state (``ClearanceDescent._joint_direction``): steepest
    descent on F = |dq / tol|² + w · cost, or damped Gauss-Newton on the joint residual
    −dq / tol (Jacobian I / tol) plus one residual per close pair (``pairs``, see
    :func:`_with_close_pairs`); dq = q − q_goal. Returns the step and the matrix of its
    quadratic model (the hold's metric). ``rule``: the :class:`StepRule` (scalars only)."""
    weight, gauss_newton, damping, goal_depth = (
        rule.weight,
        rule.gauss_newton,
        rule.damping,
        rule.goal_depth,
    )
    dof = dq.shape[0]
    direction = np.zeros(dof)
    if not gauss_newton:
        for j in range(dof):
            direction[j] = -(2.0 * dq[j] / tol_rad**2 + weight * grad[j])
        return direction, np.eye(dof)
    scale = 1.0 / tol_rad
    A = np.zeros((dof, dof))
    b = np.empty(dof)
    deep = joint_err * scale < goal_depth
    for j in range(dof):
        A[j, j] = scale * scale
        b[j] = 0.0 if deep else scale * (-dq[j] * scale)
    return _damped_solve(_with_close_pairs(A, b, pairs, grad, weight), b, damping)


@njit(cache=True, nogil=True)
def hold_clearance(q, direction, fld, floor_m, metric):
    """``ClearanceDescent._hold_clearance``: ``direction`` changed as little as possible so
    that no pair closer than ``floor_m`` comes closer (to first order, it moves away at
    0.1 of its gradient's rate); active-set projection, at most 10 rounds. "As little as
    possible" in ``metric`` (A, dof x dof, the step's quadratic model):
    ``dq = direction + A^-1 G^T lambda``."""
    dof = q.shape[0]
    ch = fld.ch
    Bf = frames(q, ch)
    P = centres(Bf, ch, fld.link, fld.t)
    d, nrm = _pairs_of(P, fld, floor_m)
    kn, link, A_idx, B_idx = kin(ch), fld.link, fld.A, fld.B
    n_act = 0
    for i in range(d.shape[0]):
        if d[i] < floor_m:
            n_act += 1
    if n_act == 0:
        return direction.copy()
    G = np.empty((n_act, dof))
    gi = np.empty(dof)
    k = 0
    for i in range(d.shape[0]):
        if d[i] < floor_m:
            pair_gradient(Bf, kn, P, link, nrm, (A_idx[i], B_idx[i], i), gi)
            G[k] = gi
            k += 1
    dnorm = math.sqrt(np.sum(direction * direction))
    want = np.empty(n_act)
    for c in range(n_act):
        want[c] = 0.1 * math.sqrt(np.sum(G[c] * G[c])) * dnorm
    chosen = np.zeros(n_act, dtype=np.bool_)
    dq = direction.copy()
    AiGt = np.linalg.solve(metric, np.ascontiguousarray(G.T))  # (dof, n_act)
    for _ in range(10):
        rate = G @ dq
        any_short = False
        for c in range(n_act):
            if rate[c] < want[c] - 1e-12:
                chosen[c] = True
                any_short = True
        if not any_short:
            break
        idx = np.flatnonzero(chosen)
        Gs = G[idx]
        Ai = np.ascontiguousarray(AiGt[:, idx])
        K = Gs @ Ai
        tr = 0.0
        for c in range(idx.shape[0]):
            tr += K[c, c]
        reg = 1e-9 * max(tr / idx.shape[0], 1e-12)
        for c in range(idx.shape[0]):
            K[c, c] += reg
        lam = np.linalg.solve(K, want[idx] - Gs @ direction)
        dq = direction + Ai @ lam
    return dq


# ---------------------------------------------------------------------- entries
# numba types a named tuple passed from Python at every call (some 5 µs for the field,
# the goal and the rule; plain tuples: their types by fingerprint, ~1 µs): the wrapper
# passes plain tuples and these entries name them again, free in compiled code
@njit(cache=True, nogil=True, inline="always")
def _named(fld_t, goal_t, rule_t):
    """The field, goal and rule named again from their plain tuples."""
    fld = SphereField(SphereChain(*fld_t[0]), *fld_t[1:])
    return fld, DescentGoal(*goal_t), StepRule(*rule_t)


@njit(cache=True, nogil=True)
def evaluate_at(q, fld_t, far_m, goal_t, rule_t, want_direction, d_ref, floor_m):
    """:func:`evaluate` on the plain tuples of a :class:`SphereField`, a
    :class:`DescentGoal` and a :class:`StepRule` (:meth:`CompiledField.evaluate`)."""
    fld, goal, rule = _named(fld_t, goal_t, rule_t)
    return evaluate(q, fld, far_m, goal, rule, want_direction, d_ref, floor_m)


@njit(cache=True, nogil=True)
def hold_at(q, direction, fld_t, floor_m, metric):
    """:func:`hold_clearance` on the plain tuple of a :class:`SphereField`."""
    fld = SphereField(SphereChain(*fld_t[0]), *fld_t[1:])
    return hold_clearance(q, direction, fld, floor_m, metric)


# ---------------------------------------------------------------------- the wrapper
@dataclass(frozen=True)
class Evaluation:
    """The descent's view of one state (see :func:`evaluate`)."""

    F: float
    f: float
    pos_err_m: float
    ang_err_deg: float
    cost: float
    gradient: Array
    #: every sphere pair's distance, those at least ``far_m`` apart reported as ``far_m``
    distances_m: Array
    direction: Array
    #: no pair below the clearance floor that came closer than in ``d_ref``
    spacious: bool
    #: the step's quadratic model at q (dof, dof): Gauss-Newton's A, or the identity
    metric: Array
    #: the largest joint difference from a goal state (0 for a tip goal)
    joint_err: float = 0.0


class CompiledField:
    """The compiled field and step for one robot in one scene: the spheres and pairs of a
    :class:`ClearanceField` (so both backends see the same field), the scene and the
    robot's chain from the compiled robot–scene model (``model``: a checker's
    :class:`~plannerlab.collision.model.CompiledModel`, or None: the robot's chain
    folded alone, :func:`~plannerlab.collision.model.folded_chain`), packed once.

    Raises:
        ModelError: the robot gives no serial chain.
        ValueError: its chain's capsules are not its links one to one, or it gives no
            tip (``tip_data()``).
    """

    def __init__(self, field: ClearanceField, far_m: float, model: Any = None) -> None:
        robot = field.robot
        if not callable(getattr(robot, "tip_data", None)):
            raise ValueError(
                f"the compiled descent needs the robot's tip (tip_data()); "
                f"robot {getattr(robot, 'kind', '?')!r} gives none"
            )
        chain = sphere_chain(robot) if model is None else model_sphere_chain(model, robot)
        link = np.array(field._link, dtype=np.int64)
        scene_idx = np.array(field._scene_spheres, dtype=np.int64)
        self_a = np.array(field._self_a, dtype=np.int64)
        self_b = np.array(field._self_b, dtype=np.int64)
        obstacles = field.scene.obstacles
        k = len(obstacles)
        kinds = np.zeros(k, dtype=np.int64)
        Rs = np.zeros((k, 3, 3))
        cs = np.zeros((k, 3))
        pars = np.zeros((k, 3))
        bound = np.zeros(k)  # bounding sphere radius round the obstacle's centre
        for i, o in enumerate(obstacles):
            T = np.asarray(o.T_world_obstacle, dtype=float)
            Rs[i], cs[i] = T[:3, :3], T[:3, 3]
            if isinstance(o, Box):
                kinds[i] = BOX
                pars[i] = np.asarray(o.size_m, dtype=float) / 2.0
                bound[i] = float(np.linalg.norm(pars[i]))
            elif isinstance(o, Cylinder):
                kinds[i] = CYLINDER
                pars[i, 0], pars[i, 1] = float(o.radius_m), float(o.length_m) / 2.0
                bound[i] = float(np.hypot(pars[i, 0], pars[i, 1]))
            elif isinstance(o, Sphere):
                kinds[i] = SPHERE
                pars[i, 0] = float(o.radius_m)
                bound[i] = pars[i, 0]
            else:  # pragma: no cover - scene types are closed
                raise TypeError(f"unknown obstacle {o!r}")
        # the declared contacts (an obstacle's touch_links) per obstacle and scene sphere
        touch = np.ascontiguousarray(
            touch_mask(robot, field.scene)[link[scene_idx]].T.reshape(k, len(scene_idx)),
            dtype=np.bool_,
        )
        A, B, lp_of_row, lp_links, ends = pair_spheres(scene_idx, k, self_a, self_b, link)
        self.influence_m = float(field.influence_m)
        # fresh (writeable, contiguous) arrays everywhere: numba compiles one version
        self._field = SphereField(
            ch=chain,
            link=link,
            t=np.array(field._t, dtype=float),
            r=np.array(field._r, dtype=float),
            scene_idx=scene_idx,
            self_a=self_a,
            self_b=self_b,
            scene=(kinds, Rs, cs, pars, bound, touch),
            A=A,
            B=B,
            lp_of_row=lp_of_row,
            lp_links=lp_links,
            ends=ends,
            margin=self.influence_m,
        )
        #: the field as plain tuples (see :func:`evaluate_at`)
        self._plain = (tuple(chain), *self._field[1:])
        #: pairs at least this far apart are reported at this distance (see pairs)
        self.far_m = max(float(far_m), self.influence_m)
        self._no_ref = np.zeros(0)
        #: the last goal asked about and its arrays (fresh, writeable: one numba version;
        #: see :func:`_goal_arrays`)
        self._goal: tuple[Any, tuple] = (None, ())

    def evaluate(
        self,
        q: Array,
        goal,
        rule: tuple,
        want_direction: bool,
        d_ref: Array | None = None,
        floor_m: float = 0.0,
    ) -> Evaluation:
        """F, f, tip errors, clearance cost and gradient, distances and (when asked) the
        step direction at q (dof,) towards ``goal`` (a GoalRegion) by the step ``rule``
        (a :class:`StepRule`'s values, made once: :func:`step_rule`); ``spacious``
        against the distances ``d_ref`` (see :func:`evaluate`)."""
        if goal is not self._goal[0]:
            self._goal = (goal, tuple(_goal_arrays(goal)))
        out = evaluate_at(
            np.array(q, dtype=float),
            self._plain,
            self.far_m,
            self._goal[1],
            rule,
            bool(want_direction),
            self._no_ref if d_ref is None else d_ref,
            float(floor_m),
        )
        F, f, pos_err, ang_err, cost, grad, d, direction, spacious, metric, joint_err = out
        return Evaluation(
            float(F),
            float(f),
            float(pos_err),
            float(ang_err),
            float(cost),
            grad,
            d,
            direction,
            bool(spacious),
            metric,
            float(joint_err),
        )

    def hold_clearance(
        self, q: Array, direction: Array, floor_m: float, metric: Array | None = None
    ) -> Array:
        """:func:`hold_clearance` at q (dof,) for ``direction`` (dof,), projected in
        ``metric`` (dof, dof; None: the identity)."""
        dof = len(direction)
        return hold_at(
            np.array(q, dtype=float),
            np.array(direction, dtype=float),
            self._plain,
            float(floor_m),
            np.eye(dof) if metric is None else np.ascontiguousarray(metric, dtype=float),
        )


def step_rule(
    r1: float, r2: float, weight: float, gauss_newton: bool, damping: float, goal_depth: float
) -> tuple:
    """The values of a :class:`StepRule`, a plain tuple (floats and a bool: one numba
    version; see :func:`evaluate_at`)."""
    return tuple(
        StepRule(
            float(r1),
            float(r2),
            float(weight),
            bool(gauss_newton),
            float(damping),
            float(goal_depth),
        )
    )


def _goal_arrays(goal) -> DescentGoal:
    """A goal as :func:`evaluate` takes it: the tip target (p, n) and tolerances, then
    whether it is a goal state, the state, its continuous joints and its tolerance (empty
    arrays for a tip goal: one numba version for both)."""
    from plannerlab.problem.goals import JointGoal

    p = np.array(goal.p_world_m, dtype=float)
    n = np.array(goal.n_world, dtype=float)
    pos_tol, angle_tol = float(goal.pos_tol_m), float(goal.angle_tol_deg)
    if isinstance(goal, JointGoal):
        q = np.array(goal.q_rad, dtype=float)
        cont = np.array(goal.continuous, dtype=np.bool_)
        return DescentGoal(p, n, pos_tol, angle_tol, True, q, cont, float(goal.tol_rad))
    return DescentGoal(
        p, n, pos_tol, angle_tol, False, np.zeros(0), np.zeros(0, dtype=np.bool_), 1.0
    )


def warm_up() -> None:
    """Load (or compile) both kernels once in this process, on a small arm beside a box:
    callers that time a solve from outside (tests, benches) do this before their clock,
    as they build a collision checker to load the collision core. The planners do not
    need it: they load the kernels before their tracker starts."""
    from plannerlab.problem.goals import GoalRegion
    from plannerlab.problem.scene import Scene
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans

    robot = ArmZ(n_modules=8)
    scene = Scene((Box("box", trans(2.0, 0.0, 2.0), np.array([0.5, 0.5, 0.5])),))
    core = CompiledField(ClearanceField(robot, scene, 0.3), far_m=0.3)  # type: ignore[arg-type]
    goal = GoalRegion("warm_up", np.array([1.0, 0.0, 3.0]), np.array([0.0, 0.0, 1.0]), 0.1, 10.0)
    q = np.zeros(robot.dof)
    rule = step_rule(1.0, 1.0, 0.2, True, 0.1, 0.3)
    e = core.evaluate(q, goal, rule, True)
    core.evaluate(q, goal, rule, True, e.distances_m, 0.03)
    core.hold_clearance(q, e.direction, 0.04)

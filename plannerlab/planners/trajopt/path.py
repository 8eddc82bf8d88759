"""The optimisation problem over a whole path: K waypoints from the fixed start, the
merit the solvers lower and its derivatives.

Variables: the waypoints X (K, dof), ``X[0]`` the start (fixed) and ``X[K−1]`` the goal
state (fixed) or free in a tip goal region. Continuous joints are kept unwrapped (the
path is a curve in the joint space's cover; it is wrapped once it is returned). The
merit of a path, for a penalty weight μ::

    M(X) = S(X) + μ (C(X) + w_g G(X))

* **Smoothness** ``S = w_s (K−1)³ Σ_k |X[k+1] − 2 X[k] + X[k−1]|²``: the squared joint
  accelerations of the path parameterised on [0, 1] (``∫ |q''(s)|² ds`` to second order,
  the same value for the same curve at any K).
* **Collision** ``C = Σ_states Σ_pairs max(0, d_safe − d)² / δ²``, the hinge on the
  signed distance of every sphere pair (:mod:`~plannerlab.planners.trajopt.geometry`),
  ``d_safe = margin + δ`` (the checker's margin and the optimiser's buffer δ),
  evaluated at every waypoint and at ``substeps`` states on every edge
  (``(1 − t) X[k] + t X[k+1]``), whose gradients go to both ends.
* **Goal** (a tip region only; a goal state is the fixed last waypoint), a constraint
  held by the same penalty weight as the collision hinge
  ``G = max(0, |p − p_g| / tol_p − ρ)² + max(0, θ / tol_θ − ρ)²``: the last waypoint's
  tip within ρ (``goal_depth``) of both tolerances.

Joint limits are box bounds on X (the solvers keep the iterates inside them).

**The structure.** Every term couples a waypoint with at most its two neighbours on
either side (smoothness), or one (an edge's states): the Gauss-Newton matrix is banded
with ``2 · dof`` sub-diagonals in waypoint-major order, so a step costs
``O(K · dof³)`` (LAPACK's banded Cholesky, :func:`scipy.linalg.solveh_banded`), not
``O((K · dof)³)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from plannerlab.problem.goals import JointGoal
from plannerlab.robots.base import Array

__all__ = ["Evaluation", "PathProblem", "second_difference", "warm_up"]


def second_difference(K: int) -> Array:
    """The (K − 2, K) second-difference matrix (rows ``X[k−1] − 2 X[k] + X[k+1]``)."""
    D = np.zeros((max(K - 2, 0), K))
    for r in range(K - 2):
        D[r, r : r + 3] = (1.0, -2.0, 1.0)
    return D


@dataclass(frozen=True)
class Evaluation:
    """The merit and its parts at one path, with what the solvers need.

    Attributes:
        merit: ``S + μ (C + w_g G)``; ``smooth``, ``collision``, ``goal`` its parts
            (``collision`` and ``goal`` before their weights).
        gradient: (n,) ∇M over the free variables (waypoint-major).
        band: (2 dof + 1, n) the Gauss-Newton matrix of M in LAPACK's lower banded form
            (empty unless asked for).
        d_min_m: (m,) the smallest pair distance at each evaluated state (clipped at
            ``d_safe``).
        goal_ok: the last waypoint is within the goal region (a goal state: always).
        hinge: (m,) each evaluated state's hinge over δ² (the collision part's terms).
    """

    merit: float
    smooth: float
    collision: float
    goal: float
    gradient: Array
    band: Array
    d_min_m: Array
    goal_ok: bool
    hinge: Array


class PathProblem:
    """The merit of K-waypoint paths for one leg (see the module docstring).

    Args:
        geometry: the leg's :class:`~plannerlab.planners.trajopt.geometry.PathGeometry`.
        robot: the robot (joint limits, continuous joints).
        goal: the leg's goal (a :class:`JointGoal`: the last waypoint is fixed).
        K: waypoints (≥ 3).
        substeps: states evaluated inside every edge.
        margin_m: the checker's clearance margin; ``buffer_m`` δ above it.
        smooth_weight: w_s; ``goal_weight`` w_g; ``goal_depth`` ρ.
    """

    def __init__(
        self,
        geometry: Any,
        robot: Any,
        goal: Any,
        K: int,
        substeps: int,
        margin_m: float,
        buffer_m: float,
        smooth_weight: float,
        goal_weight: float,
        goal_depth: float,
    ) -> None:
        if K < 3:
            raise ValueError(f"a path needs at least 3 waypoints, got {K}")
        self.geometry, self.robot, self.goal = geometry, robot, goal
        self.K, self.dof = int(K), int(robot.dof)
        self.joint_goal = isinstance(goal, JointGoal)
        self.substeps = int(substeps)
        self.margin_m, self.buffer_m = float(margin_m), float(buffer_m)
        self.d_safe_m = self.margin_m + self.buffer_m
        self.smooth_weight, self.goal_weight = float(smooth_weight), float(goal_weight)
        self.goal_depth = float(goal_depth)
        cont = np.asarray(robot.continuous, dtype=bool)
        self.lower = np.where(cont, -np.inf, np.asarray(robot.lower, dtype=float))
        self.upper = np.where(cont, np.inf, np.asarray(robot.upper, dtype=float))
        K, dof = self.K, self.dof
        #: the free waypoints: 1 … K−1 (a tip region) or 1 … K−2 (a goal state)
        self.last_free = K - 2 if self.joint_goal else K - 1
        self.n_free = self.last_free
        self.n = self.n_free * dof
        # the evaluated states: every free waypoint, then `substeps` states on each edge
        ts = np.arange(1, self.substeps + 1) / (self.substeps + 1)
        k_w = np.arange(1, self.last_free + 1)
        k_e = np.repeat(np.arange(K - 1), len(ts))
        self.state_k = np.concatenate([k_w, k_e]).astype(np.int64)
        self.state_t = np.concatenate([np.zeros(len(k_w)), np.tile(ts, K - 1)])
        # smoothness: (K−1)³ w_s |D X|², its Hessian 2 c DᵀD (⊗ I)
        D = second_difference(K)
        self._coef = self.smooth_weight * float(K - 1) ** 3
        self._DtD = D.T @ D
        self._band_index()

    # ------------------------------------------------------------------ layout
    def _band_index(self) -> None:
        """The smoothness term's banded matrix (lower form, 2 dof + 1 rows): 2c DᵀD[k, l]
        on the diagonal of block (k, l) of the free waypoints, l ≤ k ≤ l + 2."""
        dof, nf = self.dof, self.n_free
        band = np.zeros((2 * dof + 1, nf * dof))
        for off in range(3):
            for i in range(nf - off):
                k, l_ = i + 1 + off, i + 1
                band[off * dof, i * dof : (i + 1) * dof] = 2.0 * self._coef * self._DtD[k, l_]
        self._smooth_band = band

    def free(self, X: Array) -> Array:
        """The free variables of the path X (K, dof), flat (waypoint-major)."""
        return np.ascontiguousarray(X[1 : self.last_free + 1]).reshape(-1)

    def with_free(self, X: Array, x: Array) -> Array:
        """A copy of X with the free variables x."""
        Y = np.array(X, dtype=float, copy=True)
        Y[1 : self.last_free + 1] = np.asarray(x).reshape(self.n_free, self.dof)
        return Y

    def clip(self, x: Array) -> Array:
        """x with every joint inside its limits."""
        Xf = np.asarray(x).reshape(self.n_free, self.dof)
        return np.clip(Xf, self.lower, self.upper).reshape(-1)

    def bounds(self) -> tuple[Array, Array]:
        """Lower and upper bounds of the free variables (n,) each (±inf: continuous)."""
        return np.tile(self.lower, self.n_free), np.tile(self.upper, self.n_free)

    def states(self, X: Array) -> Array:
        """The evaluated states (m, dof): the free waypoints, then each edge's."""
        k, t = self.state_k, self.state_t[:, None]
        return (1.0 - t) * X[k] + t * X[np.minimum(k + 1, self.K - 1)]

    @property
    def evaluated_states(self) -> int:
        """States evaluated per merit (the checks one evaluation is charged)."""
        return len(self.state_k)

    # ------------------------------------------------------------------ the merit
    def evaluate(
        self,
        X: Array,
        mu: float,
        want_matrix: bool = True,
        multipliers: Array | None = None,
    ) -> Evaluation:
        """The merit at X (K, dof) with penalty weight ``mu`` (see the module
        docstring), its gradient and (``want_matrix``) its banded Gauss-Newton matrix.

        With ``multipliers`` λ (m,), one per evaluated state, the collision part is the
        augmented Lagrangian of the constraints ``c_s = 0`` (``c_s ≥ 0`` each state's
        hinge, over δ²): ``Σ_s λ_s c_s + μ/2 c_s²``, its gradient weighted by
        ``λ_s + μ c_s`` per state (its matrix likewise, the rank-one part left out)."""
        K = self.K
        coef = self._coef
        smooth = coef * float(np.sum((X[:-2] - 2.0 * X[1:-1] + X[2:]) ** 2))
        G_full = 2.0 * coef * (self._DtD @ X)  # ∇S per waypoint
        c, g, H, dmin = self.geometry.hinge(self.states(X), self.d_safe_m, want_matrix)
        inv = 1.0 / self.buffer_m**2
        c_n = c * inv
        if multipliers is None:
            collision = float(np.sum(c_n))
            weights = np.full(len(c), mu * inv)
            collision_merit = mu * collision
        else:
            collision = float(np.sum(c_n))
            weights = (multipliers + mu * c_n) * inv
            collision_merit = float(np.sum(multipliers * c_n + 0.5 * mu * c_n * c_n))
        band = self._smooth_band.copy() if want_matrix else np.zeros((0, 0))
        _accumulate(
            G_full,
            band,
            (self.state_k, self.state_t),
            (g, H, weights),
            self.last_free,
            bool(want_matrix),
        )
        goal_val, goal_ok = 0.0, True
        if not self.joint_goal:
            goal_val, g_goal, B_goal, goal_ok = self._goal_terms(X[K - 1])
            wg = mu * self.goal_weight
            G_full[K - 1] += wg * g_goal
            if want_matrix:
                _add_block(band, wg * B_goal, self.n_free - 1)
        grad = G_full[1 : self.last_free + 1].reshape(-1)
        merit = smooth + collision_merit + mu * self.goal_weight * goal_val
        return Evaluation(merit, smooth, collision, goal_val, grad, band, dmin, goal_ok, c_n)

    def _goal_terms(self, q: Array) -> tuple[float, Array, Array, bool]:
        """G at the last waypoint q (a tip region), its gradient (dof,), its
        Gauss-Newton matrix (dof, dof) and whether q's tip is inside the region."""
        goal = self.goal
        p, n, Jp, Jn = self.geometry.tip(q)
        rho = self.goal_depth
        tol_p = float(goal.pos_tol_m)
        tol_a = math.radians(float(goal.angle_tol_deg))
        diff = p - np.asarray(goal.p_world_m)
        dist = float(np.linalg.norm(diff))
        cosang = float(np.clip(n @ np.asarray(goal.n_world), -1.0, 1.0))
        ang = math.acos(cosang)
        value, grad = 0.0, np.zeros(self.dof)
        B = np.zeros((self.dof, self.dof))
        r_p = dist / tol_p - rho
        if r_p > 0.0 and dist > 1e-12:
            j = (diff / dist) @ Jp / tol_p
            value += r_p * r_p
            grad += 2.0 * r_p * j
            B += 2.0 * np.outer(j, j)
        r_a = ang / tol_a - rho
        sin = math.sqrt(max(1.0 - cosang * cosang, 0.0))
        if r_a > 0.0 and sin > 1e-12:
            j = -(np.asarray(goal.n_world) @ Jn) / (sin * tol_a)
            value += r_a * r_a
            grad += 2.0 * r_a * j
            B += 2.0 * np.outer(j, j)
        inside = dist <= tol_p and math.degrees(ang) <= float(goal.angle_tol_deg)
        return value, grad, B, inside


@njit(cache=True, nogil=True)
def _accumulate(G, band, states, terms, last_free, want_matrix):
    """Add the states' hinge terms (``terms`` = (g, H, w): gradients g (m, dof), matrices H
    (m, dof, dof)), state s's times ``w[s]``, state s at ``states`` = (state_k, state_t),
    into the waypoints' gradient G (K, dof) and the banded matrix of the free
    waypoints 1 … ``last_free`` (lower form; waypoint k is free index k − 1): a state at
    ``(1 − t) X[k] + t X[k+1]`` gives (1 − t) of its gradient to k and t to k + 1, and
    (1 − t)², t² and t (1 − t) of its matrix to the blocks (k, k), (k+1, k+1), (k+1, k)."""
    state_k, state_t = states
    g, H, w = terms
    dof = G.shape[1]
    for s in range(state_k.shape[0]):
        k = state_k[s]
        t = state_t[s]
        scale = w[s]
        w0 = 1.0 - t
        for j in range(dof):
            G[k, j] += scale * w0 * g[s, j]
            if t > 0.0:
                G[k + 1, j] += scale * t * g[s, j]
        if not want_matrix:
            continue
        k_free = 1 <= k <= last_free
        k1_free = t > 0.0 and k + 1 <= last_free
        for a in range(dof):
            for b in range(a + 1):
                h = scale * H[s, a, b]
                if h == 0.0:
                    continue
                if k_free:
                    band[a - b, (k - 1) * dof + b] += w0 * w0 * h
                if k1_free:
                    band[a - b, k * dof + b] += t * t * h
        if k_free and k1_free:
            for a in range(dof):
                for b in range(dof):
                    band[dof + a - b, (k - 1) * dof + b] += scale * w0 * t * H[s, a, b]


@njit(cache=True, nogil=True)
def _add_block(band, B, i):
    """Add the symmetric block B (dof, dof) on the diagonal at free waypoint index i."""
    dof = B.shape[0]
    for a in range(dof):
        for b in range(a + 1):
            band[a - b, i * dof + b] += B[a, b]


def warm_up(geometry: Any, robot: Any, goal: Any) -> None:
    """Run every compiled path of :meth:`PathProblem.evaluate` once (the hinge with and
    without its matrix, the tip, the accumulation): their kernels are loaded."""
    q = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
    X = np.repeat(q[None], 4, axis=0) + np.linspace(0.0, 0.1, 4)[:, None]
    problem = PathProblem(geometry, robot, goal, 4, 1, 0.0, 0.01, 1.0, 1.0, 0.5)
    problem.evaluate(X, 1.0, True)
    problem.evaluate(X, 1.0, False, np.zeros(problem.evaluated_states))

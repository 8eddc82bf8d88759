"""The solvers of the path problem (:class:`~plannerlab.planners.trajopt.path.
PathProblem`), each inside the same penalty loop.

**The penalty loop** (TrajOpt's, Schulman et al. 2014, with squared hinges): the merit
``S + μ (C + w_g G)`` is lowered at a penalty weight μ until the solver converges; if the
path is then not feasible (a state closer than ``margin + feasible_fraction · δ``, or the
goal not reached) μ grows by ``penalty_growth`` and the solver goes on from there, up to
``max_penalty``.

**The solvers** (``solver`` setting; ``bench/trajopt_bench.py`` measures them, the
choice is argued in ``docs/planners.md``):

``gauss_newton``
    Levenberg–Marquardt on the merit written as a sum of squares (an inner solve ends
    when M falls by less than ``rel_tol`` in a step, or by less than
    ``feasible_rel_tol`` once the path is feasible): the step solves
    ``(H + λ diag H) Δ = −∇M`` with H the Gauss-Newton matrix (smoothness exact, one
    rank-one term per close pair and per goal residual), banded in waypoint-major
    order, by LAPACK's banded Cholesky (:func:`scipy.linalg.solveh_banded`); the step is
    projected into the joint limits; λ shrinks after a step that lowers M and grows
    after one that does not. An SQP whose quadratic model is the Gauss-Newton one and
    whose constraints are held by the penalty.
``lbfgs``
    scipy's L-BFGS-B on the same merit (its bounds are the joint limits): no matrix,
    cheaper steps, more of them.
``auglag``
    The augmented Lagrangian of the constraints "each evaluated state's hinge is zero"
    (``c_s = 0``, ``c_s ≥ 0``): ``μ C`` becomes ``Σ_s λ_s c_s + μ/2 c_s²``
    (:meth:`~plannerlab.planners.trajopt.path.PathProblem.evaluate`), lowered by
    L-BFGS-B at fixed λ; then ``λ_s ← λ_s + μ c_s``, and μ grows only when the largest
    ``c_s`` did not fall to a quarter. The multipliers hold the path off the obstacles
    at a finite μ, where the plain penalty needs μ to grow.

Each solver stops when its budget says so (``Work.stop``): every merit evaluation is an
iteration and charges the evaluated states as collision checks.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import LinAlgError, solveh_banded
from scipy.optimize import minimize

from plannerlab.planners.trajopt.path import Evaluation, PathProblem
from plannerlab.robots.base import Array

__all__ = ["SOLVERS", "BudgetStop", "Outcome", "PenaltySettings", "Work", "optimise"]

#: the solvers by setting value
SOLVERS = ("gauss_newton", "lbfgs", "auglag")


class BudgetStop(Exception):
    """The budget does not pay for the next evaluation (the message says which limit)."""


@dataclass
class Work:
    """The budget of one optimisation: ``stop(states)`` says why not to evaluate that many
    states (None: go on), ``charge(states)`` counts one evaluation of them."""

    stop: Callable[[int], str | None]
    charge: Callable[[int], None]
    evaluations: int = 0

    def evaluate(
        self,
        problem: PathProblem,
        X: Array,
        mu: float,
        want: bool,
        multipliers: Array | None = None,
    ) -> Evaluation:
        """``problem.evaluate`` when the budget pays for it, else :class:`BudgetStop`."""
        why = self.stop(problem.evaluated_states)
        if why:
            raise BudgetStop(why)
        self.evaluations += 1
        self.charge(problem.evaluated_states)
        return problem.evaluate(X, mu, want, multipliers)


@dataclass(frozen=True)
class PenaltySettings:
    """The penalty loop's and the solvers' numbers (see the module docstring)."""

    solver: str = "gauss_newton"
    penalty_start: float = 10.0
    penalty_growth: float = 10.0
    max_penalty: float = 1e6
    feasible_fraction: float = 0.5
    #: an inner solve converged when M fell by less than this fraction in a step
    rel_tol: float = 1e-4
    #: ... or by less than this fraction once the path is feasible (0: rel_tol only)
    feasible_rel_tol: float = 0.0
    max_inner: int = 60


@dataclass
class Outcome:
    """How an optimisation ended: the path, feasible or not, why it stopped, the
    evaluations, the last penalty weight and the smallest distance."""

    X: Array
    feasible: bool
    reason: str
    evaluations: int
    penalty: float
    d_min_m: float
    smooth: float
    stats: dict[str, Any] = field(default_factory=dict)


def feasible(problem: PathProblem, ev: Evaluation, fraction: float) -> bool:
    """Every evaluated state at least ``margin + fraction · δ`` from everything, and the
    goal reached."""
    floor = problem.margin_m + fraction * problem.buffer_m
    return bool(ev.goal_ok and (len(ev.d_min_m) == 0 or float(ev.d_min_m.min()) >= floor))


def optimise(
    problem: PathProblem, X0: Array, s: PenaltySettings, work: Work, mu0: float | None = None
) -> Outcome:
    """The penalty loop with the solver ``s.solver`` from the path X0 (K, dof), from the
    penalty weight ``mu0`` (default ``s.penalty_start``).

    Raises:
        BudgetStop: the budget ran out (the path so far is dropped).
    """
    if s.solver not in SOLVERS:
        raise ValueError(f"solver must be one of {', '.join(SOLVERS)}, got {s.solver!r}")
    gn = s.solver == "gauss_newton"
    x = problem.clip(problem.free(X0))
    X = problem.with_free(X0, x)
    mu = s.penalty_start if mu0 is None else float(mu0)
    lam: Array | None = np.zeros(problem.evaluated_states) if s.solver == "auglag" else None
    reason = ""
    ev = work.evaluate(problem, X, mu, gn, lam)
    while True:
        worst = float(ev.hinge.max(initial=0.0))
        if gn:
            X, ev = _gauss_newton(problem, X, ev, mu, s, work)
        else:
            X, ev = _lbfgs(problem, X, ev, mu, s, work, lam)
        if feasible(problem, ev, s.feasible_fraction):
            reason = "feasible"
            break
        if lam is not None:
            lam = lam + mu * ev.hinge
            if float(ev.hinge.max(initial=0.0)) > 0.25 * worst:
                mu *= s.penalty_growth
        else:
            mu *= s.penalty_growth
        if mu > s.max_penalty:
            reason = f"not feasible at the largest penalty weight {s.max_penalty:g}"
            break
        ev = work.evaluate(problem, X, mu, gn, lam)
    return Outcome(
        X=X,
        feasible=feasible(problem, ev, s.feasible_fraction),
        reason=reason,
        evaluations=work.evaluations,
        penalty=mu,
        d_min_m=float(ev.d_min_m.min()) if len(ev.d_min_m) else math.inf,
        smooth=ev.smooth,
    )


def _gauss_newton(
    problem: PathProblem, X: Array, ev: Evaluation, mu: float, s: PenaltySettings, work: Work
) -> tuple[Array, Evaluation]:
    """Levenberg–Marquardt at penalty weight ``mu`` from X (``ev``: its evaluation)."""
    lam = 1e-3
    x = problem.free(X)
    for _ in range(s.max_inner):
        ab = ev.band.copy()
        d = ab[0].copy()
        ab[0] += lam * (d + 1e-9 * (float(d.mean()) + 1.0))
        try:
            step = solveh_banded(ab, -ev.gradient, lower=True, check_finite=False)
        except (LinAlgError, ValueError):
            lam *= 10.0
            continue
        x_new = problem.clip(x + step)
        X_new = problem.with_free(X, x_new)
        ev_new = work.evaluate(problem, X_new, mu, True)
        if ev_new.merit < ev.merit:
            drop = (ev.merit - ev_new.merit) / max(ev.merit, 1e-300)
            X, x, ev = X_new, x_new, ev_new
            lam = max(lam / 3.0, 1e-9)
            if drop < s.rel_tol:
                break
            # early stop: feasible, and the smoothing has slowed down
            if drop < s.feasible_rel_tol and feasible(problem, ev, s.feasible_fraction):
                break
        else:
            lam *= 5.0
            if lam > 1e8:
                break
    return X, ev


def _lbfgs(
    problem: PathProblem,
    X: Array,
    ev: Evaluation,
    mu: float,
    s: PenaltySettings,
    work: Work,
    multipliers: Array | None,
) -> tuple[Array, Evaluation]:
    """scipy's L-BFGS-B at penalty weight ``mu`` (and ``multipliers``) from X."""
    best: list[Any] = [X, ev]

    def fun(x: Array) -> tuple[float, Array]:
        Xn = problem.with_free(X, x)
        e = work.evaluate(problem, Xn, mu, False, multipliers)
        if e.merit < best[1].merit:
            best[0], best[1] = Xn, e
        return e.merit, e.gradient

    lo, hi = problem.bounds()
    minimize(
        fun,
        problem.free(X),
        jac=True,
        method="L-BFGS-B",
        bounds=list(zip(lo, hi, strict=True)),
        options={"maxfun": 10 * s.max_inner, "ftol": s.rel_tol * 1e-2, "gtol": 1e-9},
    )
    return best[0], best[1]

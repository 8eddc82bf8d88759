"""The core against FCL (and against an independent 1-D minimisation) on sampled states.

Used by ``bench/core_agreement.py`` (≥ 100 000 states per scene) and by the tests (a small
sample of the same kinds). Three kinds of states:

* ``"uniform"``: uniform in the joint bounds;
* ``"coiled"``: every joint within ±0.3 rad of 0 (clipped to the bounds): Arm-Z's ring
  closes on itself near θ = 0, so self-collision is dense there;
* ``"contact"``: within ~1 mm of contact: an edge from a valid to an invalid state is
  bisected to its first contact, then moved along the edge by a random offset of at most
  1 mm of link motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from plannerlab.collision.core import Core, PairDistances
from plannerlab.robots.base import Array

KINDS = ("uniform", "coiled", "contact")


def sample_states(core: Core, kind: str, n: int, rng: np.random.Generator) -> Array:
    """``n`` states (n, dof) of one kind (see the module docstring)."""
    robot = core.robot
    lo, hi = robot.lower, robot.upper
    if kind == "uniform":
        return rng.uniform(lo, hi, (n, robot.dof))
    if kind == "coiled":
        return np.clip(rng.uniform(-0.3, 0.3, (n, robot.dof)), lo, hi)
    if kind != "contact":
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    out = np.empty((0, robot.dof))
    while len(out) < n:
        m = 4 * (n - len(out)) + 64
        A = rng.uniform(lo, hi, (m, robot.dof))
        B = np.clip(A + rng.normal(0.0, 0.5, A.shape), lo, hi)
        ok = core.valid(A) & ~core.valid(B)
        A, B = A[ok], B[ok]
        t_lo, t_hi = np.zeros(len(A)), np.ones(len(A))
        for _ in range(40):  # bisection on the verdict: t_lo valid, t_hi invalid
            t = 0.5 * (t_lo + t_hi)
            v = core.valid(A + t[:, None] * (B - A))
            t_lo = np.where(v, t, t_lo)
            t_hi = np.where(v, t_hi, t)
        # metres of link motion per unit t along each edge, then a random offset ≤ 1 mm
        eps = 1e-6
        s0 = core.segments(A + t_lo[:, None] * (B - A))
        s1 = core.segments(A + (t_lo + eps)[:, None] * (B - A))
        speed = np.linalg.norm(s1 - s0, axis=-1).max(axis=(1, 2)) / eps
        dt = rng.uniform(-1e-3, 1e-3, len(A)) / np.maximum(speed, 1e-9)
        t = np.clip(t_lo + dt, 0.0, 1.0)
        out = np.concatenate([out, A + t[:, None] * (B - A)])
    return out[:n]


def reference_distance(core: Core, q: Array, pd: PairDistances, k: int) -> float:
    """Signed distance of pair k of ``pd`` at q by an independent route (non-negative only).

    Link pairs: dense minimisation over both axis parameters is not needed, the segment
    distance is checked by a bounded 1-D minimisation of the distance from the link's axis
    point to the other axis segment. Obstacles: bounded 1-D minimisation (scipy) of the
    distance from the axis point to the shape. Both are convex in t, so the bounded
    search finds the minimum to its tolerance (1e-12 in t).
    """
    seg = core.segments(q)[0]
    a, b = seg[pd.link[k]]
    r = core.radii[pd.link[k]]
    oi = pd.other[k]
    if pd.other_is_link[k]:
        c, e = seg[oi]
        r2 = core.radii[oi]

        def f(t: float) -> float:
            p = a + t * (b - a)
            u = e - c
            s = np.clip(np.dot(p - c, u) / max(np.dot(u, u), 1e-300), 0.0, 1.0)
            return float(np.linalg.norm(p - (c + s * u)))

        extra = r + r2
    else:
        kind, R, ctr, h = core.kinds[oi], core.Rs[oi], core.cs[oi], core.hs[oi]

        def f(t: float) -> float:
            x = R.T @ (a + t * (b - a) - ctr)
            if kind == 0:
                return float(np.linalg.norm(np.maximum(np.abs(x) - h, 0.0)))
            if kind == 1:
                rad = max(np.hypot(x[0], x[1]) - h[0], 0.0)
                ax = max(abs(x[2]) - h[1], 0.0)
                return float(np.hypot(rad, ax))
            return float(max(np.linalg.norm(x) - h[0], 0.0))

        extra = r
    res = minimize_scalar(f, bounds=(0.0, 1.0), method="bounded", options={"xatol": 1e-12})
    return float(min(res.fun, f(0.0), f(1.0))) - extra


@dataclass
class Agreement:
    """Outcome of comparing the core with FCL on a set of states."""

    states: int = 0
    verdict_mismatches: int = 0
    pairs_compared: int = 0
    max_err_fcl_m: float = 0.0  # |core − FCL| over separated pairs
    max_err_ref_m: float = 0.0  # |core − independent minimisation| over separated pairs
    pen_pairs: int = 0
    max_pen_err_m: float = 0.0  # |core − FCL| over penetrating pairs
    median_pen_err_m: float = 0.0


def compare(
    core: Core,
    fcl_checker,  # CollisionChecker(backend="fcl")
    Q: Array,
    margin_m: float = 0.05,
    distance_states: int | None = None,
    reference_pairs: int = 0,
    rng: np.random.Generator | None = None,
) -> Agreement:
    """Verdicts on every state; pair distances below ``margin_m`` on ``distance_states``.

    ``reference_pairs`` separated pairs (chosen with ``rng``) are also checked against
    :func:`reference_distance`.
    """
    out = Agreement(states=len(Q))
    v_core = core.valid(Q)
    v_fcl = fcl_checker.valid_batch(Q)
    out.verdict_mismatches = int(np.sum(v_core != v_fcl))
    idx = np.arange(len(Q)) if distance_states is None else np.arange(min(distance_states, len(Q)))
    pos_err: list[float] = []
    pen_err: list[float] = []
    chosen: list[tuple[int, int]] = []
    for s in idx:
        pd = core.pair_distances(Q[s], margin_m)
        if not len(pd.d_m):
            continue
        d_fcl = fcl_checker.fcl_pair_distances(Q[s], pd.link, pd.other, pd.other_is_link)
        for k in range(len(pd.d_m)):
            if pd.d_m[k] > 0.0 and d_fcl[k] > 0.0:
                pos_err.append(abs(pd.d_m[k] - d_fcl[k]))
                chosen.append((int(s), k))
            elif pd.d_m[k] < 0.0 and d_fcl[k] < 0.0:
                pen_err.append(abs(pd.d_m[k] - d_fcl[k]))
    out.pairs_compared = len(pos_err)
    out.max_err_fcl_m = float(max(pos_err, default=0.0))
    out.pen_pairs = len(pen_err)
    out.max_pen_err_m = float(max(pen_err, default=0.0))
    out.median_pen_err_m = float(np.median(pen_err)) if pen_err else 0.0
    if reference_pairs and chosen:
        rng = rng or np.random.default_rng(0)
        pick = rng.choice(len(chosen), size=min(reference_pairs, len(chosen)), replace=False)
        errs = []
        for i in pick:
            s, k = chosen[i]
            pd = core.pair_distances(Q[s], margin_m)
            errs.append(abs(pd.d_m[k] - reference_distance(core, Q[s], pd, k)))
        out.max_err_ref_m = float(max(errs))
    return out

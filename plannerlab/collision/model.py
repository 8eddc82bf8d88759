"""The compiled robot–scene model: one typed object that compiled consumers share.

A :class:`CompiledModel` is a named tuple of arrays (numba passes it as one argument and
loads kernels that take it from its cache) built once per (robot, scene, margin) from a
robot's serial chain (``robot.chain_data()``: per joint its parent body, fixed transform,
axis and kind; per capsule its body and end points) and the scene's obstacles. It holds
what a compiled planner needs without calling back into Python:

* ``P``, ``M``, ``idat``: the chain, its capsules (inflated by the margin against the
  scene, by half of it between links), the checked link pairs and the scene, packed as
  :mod:`plannerlab.collision.chain_valid` packs them (its fused validity test is the
  model's state test);
* ``lower``, ``upper``, ``continuous``: the joint bounds and which joints wrap;
* ``edge_weights``: per joint how far [m] the robot's points move per radian (or metre),
  divided by the margin (zeros without a margin): an edge ``Δq`` is cut into at least
  ``ceil(Σ |Δq_i| · edge_weights_i)`` steps, so no point moves more than the margin
  between two checked states (the checker's grid, :meth:`~plannerlab.collision.
  fcl_checker.CollisionChecker.densify`);
* ``margin_m``.

The kernels below are the model's queries in compiled code: one state, a batch, and an
edge checked on the checker's grid (the very states of ``densify``, bit for bit) in an
order that finds a collision early (coarse to fine, the way VAMP checks a whole edge).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.chain_valid import _pack, _scratch, _state_ok, _unpack


class CompiledModel(NamedTuple):
    """One robot in one scene with a margin, as arrays (see the module docstring)."""

    P: np.ndarray
    M: np.ndarray
    idat: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    continuous: np.ndarray
    edge_weights: np.ndarray
    margin_m: float


def has_chain(robot: Any) -> bool:
    """True when the robot gives its serial chain (``chain_data()``) to compile."""
    return callable(getattr(robot, "chain_data", None))


def model_of_core(core: Any) -> CompiledModel:
    """The model of a built :class:`~plannerlab.collision.core.Core` (its capsules with
    the margin, checked pairs, scene arrays and edge weights)."""
    robot = core.robot
    if not has_chain(robot):
        raise ValueError(f"robot {getattr(robot, 'kind', type(robot).__name__)} gives no chain")
    P, M, idat, _ = _pack(
        robot,
        core.radii,
        core.radii_self,
        core.moving,
        core.allowed,
        core.kinds,
        core.Rs,
        core.cs,
        core.hs,
        None,
    )
    f = np.ascontiguousarray
    return CompiledModel(
        P=P,
        M=M,
        idat=idat,
        lower=f(robot.lower, dtype=np.float64),
        upper=f(robot.upper, dtype=np.float64),
        continuous=f(robot.continuous, dtype=np.bool_),
        edge_weights=f(core.edge_weights, dtype=np.float64),
        margin_m=float(core.margin_m),
    )


# ---------------------------------------------------------------------- compiled queries
@njit(cache=True, nogil=True)
def views(m):
    """The model's views and a scratch for :func:`state_ok` (made once per search)."""
    return _unpack(m.P, m.M, m.idat), _scratch(m.idat)


@njit(cache=True, nogil=True)
def state_ok(q, V, S):
    """One state q (dof,) is valid (``V``, ``S`` from :func:`views`)."""
    return _state_ok(q, V, S)


@njit(cache=True, nogil=True)
def valid_states(Q, m, out):
    """Validity of a batch Q (k, dof) -> out (k,) bool."""
    V, S = views(m)
    for s in range(Q.shape[0]):
        out[s] = _state_ok(Q[s], V, S)
    return out


@njit(cache=True, nogil=True)
def edge_delta(q_a, q_b, continuous, d):
    """d = q_b - q_a, continuous joints the short way round (``joint_difference``)."""
    for i in range(q_a.shape[0]):
        x = q_b[i] - q_a[i]
        if continuous[i]:
            x = (x + np.pi) % (2.0 * np.pi) - np.pi
        d[i] = x


@njit(cache=True, nogil=True)
def edge_count(d, joint_step, edge_weights):
    """The grid's number of steps of an edge ``d``: at most ``joint_step`` per joint and
    ``ceil(Σ |d_i| · w_i)`` (``robots.paths.edge_counts``)."""
    span = 0.0
    metric = 0.0
    for i in range(d.shape[0]):
        a = abs(d[i])
        span = max(span, a)
        metric += edge_weights[i] * a
    return int(max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12)))


@njit(cache=True, nogil=True)
def edge_state(q_a, d, j, n, out):
    """State ``j`` (1..n) of the edge's grid: ``q_a + t d``, ``t = j · (1 / n)`` (exactly
    1 at ``j = n``), the floats of ``densify``."""
    t = 1.0 if j == n else j * (1.0 / n)
    for i in range(q_a.shape[0]):
        out[i] = q_a[i] + t * d[i]


@njit(cache=True, nogil=True)
def edge_ok(q_a, q_b, joint_step, m, V, S, d, q, limit):
    """Check the grid states 1..n of edge q_a -> q_b, coarse to fine (the end state, then
    the midpoints of ever finer halvings), stopping at the first invalid one or after
    ``limit`` checks. Returns (status, checks): status 0 all valid, 1 a state is invalid,
    2 the limit came first (nothing proved), 3 the edge has more than ``limit`` states
    and was not checked (``checks`` = 0)."""
    edge_delta(q_a, q_b, m.continuous, d)
    n = edge_count(d, joint_step, m.edge_weights)
    checks = 0
    # j = n first (the state the edge reaches), then j in van der Corput order over 1..n-1
    edge_state(q_a, d, n, n, q)
    checks += 1
    if not _state_ok(q, V, S):
        return 1, checks
    if n == 1:
        return 0, checks
    step = 1
    while step < n:
        step *= 2
    # visit j = step/2, step/4, 3 step/4, ... (skipping j >= n): every j in 1..n-1 once
    h = step // 2
    while h >= 1:
        j = h
        while j < n:
            if checks >= limit:
                return 2, checks
            edge_state(q_a, d, j, n, q)
            checks += 1
            if not _state_ok(q, V, S):
                return 1, checks
            j += 2 * h
        h //= 2
    return 0, checks

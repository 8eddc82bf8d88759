"""The compiled robot–scene model: one typed object that compiled consumers share.

A :class:`ChainModel` is a named tuple of arrays (numba passes it as one argument and
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
* ``margin_m``;
* ``perm``: the capsules' packed order (capsule ``perm[k]`` of the robot is the ``k``-th
  packed one; :func:`segments` gives them back in the robot's order).

Every robot's model is built by the generic serial-chain builder :func:`model_of_core`
from the robot's own data, its ``chain_data()`` (:mod:`plannerlab.collision.chain`:
parents, fixed transforms, axes, sliding joints, capsules, and an optional linear coupling
of the joints), so a new family takes the compiled road without a special case and without
naming this module in its registry entry; a robot without a chain gets a
:class:`ModelError` naming its kind.

The kernels below are the model's queries in compiled code: one state, a batch, and an
edge checked on the checker's grid (the very states of ``densify``, bit for bit) in an
order that finds a collision early (coarse to fine, the way VAMP checks a whole edge).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.chain_pack import _pack
from plannerlab.collision.chain_valid import (
    _body_frames,
    _place_body,
    _scratch,
    _state_ok,
    _unpack,
)
from plannerlab.collision.lanes import valid_states_lanes
from plannerlab.errors import PlannerlabError


class ModelError(PlannerlabError):
    """A compiled consumer asked for the model of a robot that cannot give one."""


class ChainModel(NamedTuple):
    """One robot in one scene with a margin, as arrays (see the module docstring)."""

    P: np.ndarray
    M: np.ndarray
    idat: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    continuous: np.ndarray
    edge_weights: np.ndarray
    margin_m: float
    perm: np.ndarray


def has_chain(robot: Any) -> bool:
    """True when the robot gives its serial chain (``chain_data()``) to compile."""
    return callable(getattr(robot, "chain_data", None))


def model_of_core(core: Any) -> ChainModel:
    """The model of a built :class:`~plannerlab.collision.core.Core` (its capsules with
    the margin, checked pairs, scene arrays and edge weights)."""
    robot = core.robot
    if not has_chain(robot):
        raise ModelError(
            f"robot type {getattr(robot, 'kind', type(robot).__name__)!r} gives no serial "
            "chain (chain_data()) and its family registers no model builder: a compiled "
            "consumer (native planners, the fused checks) cannot run it; give the robot a "
            "chain_data() (docs/extending.md)"
        )
    P, M, idat, perm = core.packed()  # the fused validity's arrays, packed once

    def f(a: Any, dtype: Any) -> np.ndarray:
        # a writable C-ordered copy: numba types read-only arrays (a robot's bounds may
        # be read-only views) apart, and every kernel taking the model would be compiled
        # and cached twice
        return np.array(a, dtype=dtype, order="C", copy=True)

    return ChainModel(
        P=P,
        M=M,
        idat=idat,
        lower=f(robot.lower, dtype=np.float64),
        upper=f(robot.upper, dtype=np.float64),
        continuous=f(robot.continuous, dtype=np.bool_),
        edge_weights=f(core.edge_weights, dtype=np.float64),
        margin_m=float(core.margin_m),
        perm=f(perm, dtype=np.int64),
    )


def chain_model(robot: Any) -> ChainModel:
    """The model of a robot's chain alone (no scene, no margin, no checked pairs): its
    kinematics and capsules packed as :func:`model_of_core` packs them, for a consumer
    that needs only those (the clearance field's spheres,
    :mod:`plannerlab.collision.spheres`) when no checker's model is at hand.

    Raises:
        ModelError: the robot gives no serial chain (``chain_data()``).
    """
    if not has_chain(robot):
        raise ModelError(
            f"robot type {getattr(robot, 'kind', type(robot).__name__)!r} gives no serial "
            "chain (chain_data()): its kinematics cannot be compiled"
        )
    L = len(np.asarray(robot.link_radii_m))
    zeros = np.zeros(L)
    P, M, idat, perm = _pack(
        robot,
        zeros,
        zeros,
        np.ones(L, dtype=bool),
        np.zeros((L, L), dtype=bool),
        np.zeros(0, dtype=np.int64),
        np.zeros((0, 3, 3)),
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        None,
    )
    dof = int(robot.dof)
    return ChainModel(
        P=P,
        M=M,
        idat=idat,
        lower=np.array(robot.lower, dtype=np.float64, order="C", copy=True),
        upper=np.array(robot.upper, dtype=np.float64, order="C", copy=True),
        continuous=np.array(robot.continuous, dtype=np.bool_, order="C", copy=True),
        edge_weights=np.zeros(dof),
        margin_m=0.0,
        perm=np.array(perm, dtype=np.int64, order="C", copy=True),
    )


def build_model(core: Any) -> ChainModel:
    """The model of a built core: the generic serial-chain :func:`model_of_core`, from the
    robot's ``chain_data()``.

    Raises:
        ModelError: the robot gives no chain.
    """
    return model_of_core(core)


# ---------------------------------------------------------------------- compiled queries
@njit(cache=True, nogil=True)
def views(m):
    """The model's views and a scratch for :func:`state_ok` (made once per search)."""
    return _unpack(m.P, m.M, m.idat), _scratch(m.idat)


#: One state q (dof,) is valid (``V``, ``S`` from :func:`views`): chain_valid's own
#: kernel under the model's name (a wrapper that passes ``V`` and ``S`` on, even inlined
#: at numba's level, costs ~0.35 µs a call: ``bench/model_bench.py``)
state_ok = _state_ok


@njit(cache=True, nogil=True)
def segments(Q, m, out):
    """Capsule axes of a batch in the robot's capsule order, the model's kinematics:
    Q (k, dof) -> out (k, L, 2, 3) (``robot.link_segments``' numbers to rounding)."""
    V, S = views(m)
    (parent, prism, body_cl, cl_start, _, _, issph) = V[0][:7]
    (T0, pre, cap_a, cap_b) = V[1][:4]
    cl_c = V[1][9]
    Bf, _, Kw, X, Y, v, _ = S
    for s in range(Q.shape[0]):
        _body_frames(Q[s], T0, parent, prism, pre, Bf, V[2], v)
        for b in range(Bf.shape[0]):
            _place_body(Bf, cap_a, cap_b, issph, body_cl, cl_start, cl_c, b, X, Y, Kw)
        for k in range(X.shape[0]):
            l = m.perm[k]
            for a in range(3):
                out[s, l, 0, a] = X[k, a]
                out[s, l, 1, a] = X[k, a] if issph[k] else Y[k, a]
    return out


def valid_states(Q: np.ndarray, m: ChainModel, out: np.ndarray) -> np.ndarray:
    """Validity of a batch Q (k, dof) -> out (k,) bool, in vector lanes (the verdicts of
    :func:`state_ok`, state by state)."""
    return valid_states_lanes(Q, m, out)


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

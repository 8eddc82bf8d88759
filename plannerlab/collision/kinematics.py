"""The one compiled forward kinematics of every chain: eight float32 lanes or one float64
state, from the same code.

Every robot family that compiles gives its serial chain (``robot.chain_data()``,
:mod:`plannerlab.collision.chain`); :mod:`plannerlab.collision.model` folds each joint's
axis onto its frame's z axis, so a joint is one affine product and a turn (or a slide)
about z. :func:`chain_frames` computes every body's frame from the chain's joint values,
written on the operations of :mod:`plannerlab.collision.simd`: given float32 arrays it
runs eight states at once as lane vectors (the state test's filter,
:mod:`plannerlab.collision.state_test`), given float64 arrays one state in float64 (the
state test's confirmation, the sphere field and its gradients, the IK, segments for the
re-check and the viewer). Only the turn's sine and cosine differ by kind: ``math`` in
float64; in float32 a polynomial in plain vector arithmetic (numba ≥ 0.62 calls the
scalar library for ``math.sin``), whose error the filter's float32 bound covers.

Layout (flat arrays; ``w`` = 8 lanes for float32, 1 for float64): the chain's joint
values ``V[i w : (i + 1) w]``; frames as 3 x 4 rows, entry ``(a, c)`` of body ``b`` at
``F[(12 b + 4 a + c) w]``. Body 0 is the base (``T0``); joint ``i`` moves body ``i + 1``
and hangs from body ``parent[i]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.extending import overload

from plannerlab.collision.simd import (
    f8,
    fma,
    kernel,
    like,
    load,
    select,
    splat,
    store,
    vfloor,
    width,
)

_F4 = np.float32
#: a bound of the float32 polynomial's error [1] on the angles the filter meets (states
#: wrapped into [-π, π] first, the range reduction's rounding then ~4e-7): the model's
#: float32 bound takes it per joint
SINCOS32_ABS_ERR = 1e-6


def sincos(x):
    """(sin x, cos x): a lane vector in float32 arithmetic, or a float64 by ``math``."""
    raise NotImplementedError("numba only")


@overload(sincos)
def _ov_sincos(x):
    if isinstance(x, types.UniTuple):  # (sine, cosine) given: see angle()
        return lambda x: (x[0], x[1])
    if x == f8:

        def vec(x):
            # reduce to [-π, π], fold onto [-π/2, π/2], two Taylor polynomials (the terms
            # left out are below 6e-8 and 7e-9 there, under float32's rounding)
            k = vfloor(x * splat(1.0 / (2.0 * math.pi)) + splat(0.5))
            y = fma(k, splat(-2.0 * math.pi), x)
            big = y > splat(0.5 * math.pi)
            small = y < splat(-0.5 * math.pi)
            z = select(big, splat(math.pi) - y, y)
            z = select(small, splat(-math.pi) - z, z)
            z2 = z * z
            s = fma(z2, splat(-1.0 / 39916800.0), splat(1.0 / 362880.0))
            s = fma(z2, s, splat(-1.0 / 5040.0))
            s = fma(z2, s, splat(1.0 / 120.0))
            s = fma(z2, s, splat(-1.0 / 6.0))
            s = fma(z2 * z, s, z)
            c = fma(z2, splat(1.0 / 479001600.0), splat(-1.0 / 3628800.0))
            c = fma(z2, c, splat(1.0 / 40320.0))
            c = fma(z2, c, splat(-1.0 / 720.0))
            c = fma(z2, c, splat(1.0 / 24.0))
            c = fma(z2, c, splat(-0.5))
            c = fma(z2, c, splat(1.0))
            return s, select(big | small, -c, c)

        return vec

    def scalar(x):
        return math.sin(x), math.cos(x)

    return scalar


def value(V, i, w):
    """Joint i's value: ``V[i w]`` (flat, ``w`` lanes a joint) or, V a float64 table (m, 3)
    of each joint's value, sine and cosine (the one-state road's, computed by the
    caller), ``V[i, 0]``."""
    raise NotImplementedError("numba only")


def angle(V, i, w):
    """What :func:`sincos` takes for joint i: its value (flat V), or, V a table (see
    :func:`value`), its sine and cosine as given."""
    raise NotImplementedError("numba only")


@overload(value)
def _ov_value(V, i, w):
    if isinstance(V, types.Array) and V.ndim == 2:
        return lambda V, i, w: V[i, 0]
    return lambda V, i, w: load(V, i * w)


@overload(angle)
def _ov_angle(V, i, w):
    if isinstance(V, types.Array) and V.ndim == 2:
        return lambda V, i, w: (V[i, 1], V[i, 2])
    return lambda V, i, w: load(V, i * w)


@kernel
def chain_values(Q, cpl, V):
    """The chain's joint values V (flat, ``w`` lanes a joint) of the states Q (the same
    layout, ``dof`` joints): ``v_i = Σ cpl_val[k] · q[cpl_idx[k]]`` over ``cpl_start[i] :
    cpl_start[i + 1]`` (IRb-6's relative angles); ``cpl = (cpl_start, cpl_idx, cpl_val)``,
    its start empty for none (then V is not written: the caller uses Q)."""
    start, idx, val = cpl
    w = width(V)
    for i in range(start.shape[0] - 1):
        acc = like(V, 0.0)
        for j in range(start[i], start[i + 1]):
            acc = fma(like(V, val[j]), load(Q, idx[j] * w), acc)
        store(V, i * w, acc)


@kernel
def chain_frames(F, V, T0, pre, parent, slide):
    """Every body's frame F (flat, see the module) from the chain's joint values V: the
    base's pose T0 (12,), then per joint ``F[parent] · pre · Rz(v)`` (a turn) or ``F[parent]
    · pre · Tz(v)`` (a slide), ``pre`` (m, 12) the fixed transforms with the axes folded
    onto z. Float32 arrays: eight lanes; float64: one state."""
    w = width(F)
    for r in range(12):
        store(F, r * w, like(F, T0[r]))
    for i in range(parent.shape[0]):
        v = value(V, i, w)
        if slide[i]:
            s, c = like(F, 0.0), like(F, 1.0)
        else:
            s, c = sincos(angle(V, i, w))
        fb = 12 * parent[i] * w
        ob = 12 * (i + 1) * w
        p00, p01, p02, p03 = (
            like(F, pre[i, 0]),
            like(F, pre[i, 1]),
            like(F, pre[i, 2]),
            like(F, pre[i, 3]),
        )
        p10, p11, p12, p13 = (
            like(F, pre[i, 4]),
            like(F, pre[i, 5]),
            like(F, pre[i, 6]),
            like(F, pre[i, 7]),
        )
        p20, p21, p22, p23 = (
            like(F, pre[i, 8]),
            like(F, pre[i, 9]),
            like(F, pre[i, 10]),
            like(F, pre[i, 11]),
        )
        for a in range(3):
            r = fb + 4 * a * w
            f0 = load(F, r)
            f1 = load(F, r + w)
            f2 = load(F, r + 2 * w)
            f3 = load(F, r + 3 * w)
            g0 = fma(f2, p20, fma(f1, p10, f0 * p00))
            g1 = fma(f2, p21, fma(f1, p11, f0 * p01))
            g2 = fma(f2, p22, fma(f1, p12, f0 * p02))
            g3 = fma(f2, p23, fma(f1, p13, fma(f0, p03, f3)))
            o = ob + 4 * a * w
            if slide[i]:
                store(F, o, g0)
                store(F, o + w, g1)
                store(F, o + 3 * w, fma(v, g2, g3))
            else:
                store(F, o, fma(s, g1, c * g0))
                store(F, o + w, fma(c, g1, -(s * g0)))
                store(F, o + 3 * w, g3)
            store(F, o + 2 * w, g2)


@kernel
def place(F, b, P, row, col):
    """The body-frame point ``P[row, col:col + 3]`` of body b in the world: (x, y, z),
    values of F's kind (lane vectors of float32, or float64 scalars)."""
    w = width(F)
    px, py, pz = like(F, P[row, col]), like(F, P[row, col + 1]), like(F, P[row, col + 2])
    o = 12 * b * w
    x = fma(
        load(F, o), px, fma(load(F, o + w), py, fma(load(F, o + 2 * w), pz, load(F, o + 3 * w)))
    )
    o += 4 * w
    y = fma(
        load(F, o), px, fma(load(F, o + w), py, fma(load(F, o + 2 * w), pz, load(F, o + 3 * w)))
    )
    o += 4 * w
    z = fma(
        load(F, o), px, fma(load(F, o + w), py, fma(load(F, o + 2 * w), pz, load(F, o + 3 * w)))
    )
    return x, y, z


__all__ = ["SINCOS32_ABS_ERR", "chain_frames", "chain_values", "place", "sincos", "value", "angle"]

"""Compiled kinematics of a generic serial chain (a ``type = "urdf"`` robot) for the core.

:class:`~plannerlab.robots.urdf.model.UrdfChain` keeps its chain as plain arrays: per
movable joint its parent body, the fixed transform from that body to the joint frame,
the unit axis and whether it slides; per capsule its body and its two end points in the
body's frame. :func:`chain_segments` turns a batch of states into capsule axes in the world
in one numba call (``cache=True``), the same numbers as ``UrdfChain.link_segments`` (to
rounding), so that :class:`~plannerlab.collision.core.Core` checks a URDF robot without a
numpy detour per state. Validity in one fused call per query:
:mod:`plannerlab.collision.chain_valid`.

**The chain format** (``robot.chain_data()``, every robot family that compiles gives it):
``(parent, pre, axes, prismatic, cap_body, cap_a, cap_b[, coupling])`` with, per chain
joint ``i`` (``n`` of them), ``parent[i]`` the body it hangs from (body 0 is the base at
``T_world_base``, joint ``i`` moves body ``i + 1``), ``pre[i]`` (4, 4) the fixed transform
from that body to the joint frame, ``axes[i]`` the unit axis in the joint frame and
``prismatic[i]``; per capsule ``cap_body[l]`` and its two end points in that body's frame.
The optional ``coupling`` (n, dof) makes the chain's joint values a linear map of the
state, ``v = coupling @ q`` (IRb-6's relative angles from its absolute ones); without it
(or None) ``v = q`` (``n = dof``). :func:`chain_parts` reads the tuple with the default.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def chain_segments(Q, T0, parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling, out):
    """Capsule axes for a batch: Q (k, dof) -> out (k, L, 2, 3) (see ``link_segments``);
    ``coupling`` (n, dof) the chain's joint values from a state, or (0, 0): ``v = q``."""
    k = Q.shape[0]
    n = parent.shape[0]
    coupled = coupling.shape[0] > 0
    L = cap_body.shape[0]
    B = np.empty((n + 1, 4, 4))
    M = np.empty((4, 4))
    P = np.empty((4, 4))
    for s in range(k):
        B[0] = T0
        for i in range(n):
            # M: the joint's motion
            x, y, z = axes[i, 0], axes[i, 1], axes[i, 2]
            if coupled:
                q = 0.0
                for j in range(Q.shape[1]):
                    q += coupling[i, j] * Q[s, j]
            else:
                q = Q[s, i]
            for a in range(4):
                for b in range(4):
                    M[a, b] = 1.0 if a == b else 0.0
            if prismatic[i]:
                M[0, 3] = q * x
                M[1, 3] = q * y
                M[2, 3] = q * z
            else:
                c = np.cos(q)
                sn = np.sin(q)
                t = 1.0 - c
                M[0, 0] = c + t * x * x
                M[0, 1] = t * x * y - sn * z
                M[0, 2] = t * x * z + sn * y
                M[1, 0] = t * x * y + sn * z
                M[1, 1] = c + t * y * y
                M[1, 2] = t * y * z - sn * x
                M[2, 0] = t * x * z - sn * y
                M[2, 1] = t * y * z + sn * x
                M[2, 2] = c + t * z * z
            F = B[parent[i]]
            # P = F @ pre[i]; B[i + 1] = P @ M
            for a in range(4):
                for b in range(4):
                    acc = 0.0
                    for m in range(4):
                        acc += F[a, m] * pre[i, m, b]
                    P[a, b] = acc
            for a in range(4):
                for b in range(4):
                    acc = 0.0
                    for m in range(4):
                        acc += P[a, m] * M[m, b]
                    B[i + 1, a, b] = acc
        for l in range(L):
            F = B[cap_body[l]]
            for a in range(3):
                out[s, l, 0, a] = (
                    F[a, 0] * cap_a[l, 0] + F[a, 1] * cap_a[l, 1] + F[a, 2] * cap_a[l, 2] + F[a, 3]
                )
                out[s, l, 1, a] = (
                    F[a, 0] * cap_b[l, 0] + F[a, 1] * cap_b[l, 1] + F[a, 2] * cap_b[l, 2] + F[a, 3]
                )
    return out


def chain_parts(robot: Any) -> tuple[Any, ...]:
    """``robot.chain_data()`` as eight parts (the module's chain format), the coupling
    checked: (n, dof) floats, or None when the chain's joint values are the state.

    Raises:
        ValueError: a chain of other than 7 or 8 parts, or a coupling of the wrong shape.
    """
    data = tuple(robot.chain_data())
    if len(data) not in (7, 8):
        raise ValueError(f"chain_data() gives {len(data)} parts; expected 7 or 8 (see chain.py)")
    coupling = data[7] if len(data) == 8 else None
    n = len(data[0])
    if coupling is not None:
        coupling = np.asarray(coupling, dtype=np.float64)
        if coupling.shape != (n, int(robot.dof)):
            raise ValueError(
                f"chain_data() coupling has shape {coupling.shape}; expected ({n}, {robot.dof})"
            )
        if n == int(robot.dof) and np.array_equal(coupling, np.eye(n)):
            coupling = None
    elif n != int(robot.dof):
        raise ValueError(f"chain_data() has {n} joints for {robot.dof} without a coupling")
    return (*data[:7], coupling)


def chain_arrays(robot: Any) -> tuple[np.ndarray, ...]:
    """The chain's arrays in the kernel's order, after ``Q`` and before ``out``."""
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling = chain_parts(robot)
    return (
        np.ascontiguousarray(robot.T_world_base, dtype=np.float64),
        np.ascontiguousarray(parent, dtype=np.int64),
        np.ascontiguousarray(pre, dtype=np.float64),
        np.ascontiguousarray(axes, dtype=np.float64),
        np.ascontiguousarray(prismatic, dtype=np.bool_),
        np.ascontiguousarray(cap_body, dtype=np.int64),
        np.ascontiguousarray(cap_a, dtype=np.float64),
        np.ascontiguousarray(cap_b, dtype=np.float64),
        np.zeros((0, 0)) if coupling is None else np.ascontiguousarray(coupling),
    )


__all__ = ["chain_arrays", "chain_parts", "chain_segments"]

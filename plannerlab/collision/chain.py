"""Compiled kinematics of a generic serial chain (a ``type = "urdf"`` robot) for the core.

:class:`~plannerlab.robots.urdf.model.UrdfChain` keeps its chain as plain arrays: per
movable joint its parent body, the fixed transform from that body to the joint frame,
the unit axis and whether it slides; per capsule its body and its two end points in the
body's frame. :func:`chain_segments` turns a batch of states into capsule axes in the world
in one numba call (``cache=True``), the same numbers as ``UrdfChain.link_segments`` (to
rounding), so that :class:`~plannerlab.collision.core.Core` checks a URDF robot without a
numpy detour per state. Validity in one fused call per query:
:mod:`plannerlab.collision.chain_valid`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def chain_segments(Q, T0, parent, pre, axes, prismatic, cap_body, cap_a, cap_b, out):
    """Capsule axes for a batch: Q (k, dof) -> out (k, L, 2, 3) (see ``link_segments``)."""
    k, dof = Q.shape
    L = cap_body.shape[0]
    B = np.empty((dof + 1, 4, 4))
    M = np.empty((4, 4))
    P = np.empty((4, 4))
    for s in range(k):
        B[0] = T0
        for i in range(dof):
            # M: the joint's motion
            x, y, z = axes[i, 0], axes[i, 1], axes[i, 2]
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


def chain_arrays(robot: Any) -> tuple[np.ndarray, ...]:
    """The chain's arrays in the kernel's order, after ``Q`` and before ``out``."""
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b = robot.chain_data()
    return (
        np.ascontiguousarray(robot.T_world_base, dtype=np.float64),
        np.ascontiguousarray(parent, dtype=np.int64),
        np.ascontiguousarray(pre, dtype=np.float64),
        np.ascontiguousarray(axes, dtype=np.float64),
        np.ascontiguousarray(prismatic, dtype=np.bool_),
        np.ascontiguousarray(cap_body, dtype=np.int64),
        np.ascontiguousarray(cap_a, dtype=np.float64),
        np.ascontiguousarray(cap_b, dtype=np.float64),
    )


__all__ = ["chain_arrays", "chain_segments"]

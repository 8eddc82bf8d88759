"""Compiled kinematics of a generic serial chain (a ``type = "urdf"`` robot) for the core.

:class:`~plannerlab.robots.urdf.model.UrdfChain` keeps its chain as plain arrays: per
movable joint its parent body, the fixed transform from that body to the joint frame,
the unit axis and whether it slides; per capsule its body and its two end points in the
body's frame. The compiled model (:mod:`plannerlab.collision.model`) folds it, and the one forward
kinematics (:mod:`plannerlab.collision.kinematics`) runs it.

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


__all__ = ["chain_parts"]

"""A chain's validity from Python (:class:`ChainValidity`): the compiled model's fused
test (:mod:`plannerlab.collision.chain_valid`) for one state, and its batches in vector
lanes (:mod:`plannerlab.collision.lanes`), on the chain packed once. The core
(:class:`~plannerlab.collision.core.Core`) answers every chain's validity with it."""

from __future__ import annotations

from typing import Any

import numpy as np

from plannerlab.collision.chain_pack import _pack
from plannerlab.collision.chain_valid import _F64, chain_points, chain_state_valid
from plannerlab.collision.lanes import chain_batch_lanes


class ChainValidity:
    """Validity of a URDF chain's states in one compiled call each (:func:`chain_valid`,
    :func:`chain_first_bad`, :func:`chain_state_valid`): the same pairs and tests as the
    core's (``core.py``: moving capsules against every obstacle, the ``allowed`` link
    pairs), with the core's arrays (:class:`~plannerlab.collision.core.Core` ``radii``,
    ``radii_self``, ``moving``, ``allowed``, ``kinds``, ``Rs``, ``cs``, ``hs``).

    ``body_order``: the order in which bodies are tested against the scene (the first hit
    ends a test, so bodies that collide most often go first); default the last body first.
    """

    def __init__(
        self,
        robot: Any,
        radii: np.ndarray,
        radii_self: np.ndarray,
        moving: np.ndarray,
        allowed: np.ndarray,
        kinds: np.ndarray,
        Rs: np.ndarray,
        cs: np.ndarray,
        hs: np.ndarray,
        body_order: np.ndarray | None = None,
    ) -> None:
        self.dof = int(robot.dof)
        self._one = (self.dof,)
        # batches in vector lanes (the same verdicts, state by state), one state scalar
        self._batch: Any = chain_batch_lanes  # a numba dispatcher
        self._state_valid: Any = chain_state_valid  # a numba dispatcher
        self._P, self._M, self._idat, self.perm = _pack(
            robot, radii, radii_self, moving, allowed, kinds, Rs, cs, hs, body_order
        )
        #: the kernels' arguments after the states: ``chain_state_valid(q, *args)``
        self.args = (self._P, self._M, self._idat)
        kernels: tuple[Any, ...] = (self._batch, chain_state_valid)
        if not all(k.signatures for k in kernels):  # compile or load them here, not later
            q = np.clip(np.zeros(self.dof), robot.lower, robot.upper)
            self.valid(np.vstack([q, q]))
            self.first_invalid(np.vstack([q, q]))
            self.is_valid(q)

    @classmethod
    def of(cls, core: Any, body_order: np.ndarray | None = None) -> ChainValidity:
        """From a built :class:`~plannerlab.collision.core.Core` of a URDF chain."""
        c = core
        geo = (c.radii, c.radii_self, c.moving, c.allowed, c.kinds, c.Rs, c.cs, c.hs)
        return cls(c.robot, *geo, body_order)

    def _Q(self, Q: Any) -> np.ndarray:
        Qc = np.ascontiguousarray(np.atleast_2d(np.asarray(Q, dtype=np.float64)))
        if Qc.ndim != 2 or Qc.shape[1] != self.dof:
            raise ValueError(f"q must have {self.dof} joints, got shape {np.shape(Q)}")
        return Qc

    def segments(self, Q: Any) -> np.ndarray:
        """Capsule axes (k, L, 2, 3) of Q (k, dof) from this kinematics (axes folded onto
        z), in the robot's capsule order: ``link_segments``' numbers to rounding."""
        Qc = self._Q(Q)
        kernel: Any = chain_points
        out = np.empty((len(Qc), len(self.perm), 2, 3))
        kernel(Qc, self._P, self._M, self._idat, out)
        return out[:, np.argsort(self.perm)]

    def valid(self, Q: Any) -> np.ndarray:
        """(k,) bool validity of Q (k, dof)."""
        Qc = self._Q(Q)
        out = np.empty(len(Qc), dtype=np.bool_)
        self._batch(Qc, self._P, self._M, self._idat, out, False)
        return out

    def first_invalid(self, Q: Any) -> int:
        """Index of the first invalid state of Q (k, dof) in order, -1 if all are valid."""
        Qc = self._Q(Q)
        out = np.empty(len(Qc), dtype=np.bool_)
        return int(self._batch(Qc, self._P, self._M, self._idat, out, True))

    def is_valid(self, q: Any) -> bool:
        """Validity of one state q (dof,): a float64 array of that shape goes straight to
        the kernel (numba takes any memory layout), anything else through ``_Q``."""
        if type(q) is not np.ndarray or q.shape != self._one or q.dtype is not _F64:
            q = self._Q(q)
            if len(q) != 1:
                raise ValueError(f"q must be one state ({self.dof},), got shape {q.shape}")
            q = q[0]
        return self._state_valid(q, *self.args)


__all__ = ["ChainValidity"]

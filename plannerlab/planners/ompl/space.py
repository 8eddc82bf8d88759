"""OMPL's state space for one robot (joint vectors <-> OMPL states, OMPL's metric), the
tip-position projection of the KPIECE family, and reading a planner's tree."""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import Any

import numpy as np
import ompl.base as ob

from plannerlab.robots.base import Array, Robot, joint_difference, wrap_to_pi

#: the capsule name nanobind reads a ``void *`` argument from (see ``Space._fast_reader``)
_NB_HANDLE = b"nb_handle"


class Space:
    """Conversion between joint vectors and OMPL states for one robot (one solve).

    ``lifted=False``: SO2 subspaces for continuous joints (+ one RealVector block for the
    bounded ones). ``lifted=True``: a single RealVectorStateSpace in which each continuous
    joint ranges over ``[c - 2 pi, c + 2 pi]`` around the start ``c`` (a double cover of
    the circle: every path in it is a valid path of the robot, and every path that turns a
    joint by less than ±pi net from the start is in it). Used by planners whose informed
    samplers only accept real-vector spaces (InformedRRT*, SORRT*, BIT*, AORRTC).
    """

    def __init__(self, robot: Robot, lifted: bool = False, center: Array | None = None) -> None:
        self.robot = robot
        self.dof = robot.dof
        self.lifted = lifted
        cont = np.asarray(robot.continuous, dtype=bool)
        self.center = (
            np.zeros(self.dof) if center is None else np.asarray(center, dtype=float).copy()
        )
        if lifted:
            self.cont_idx: list[int] = []
            self.bound_idx = list(range(self.dof))
            lo = np.where(cont, self.center - 2.0 * np.pi, robot.lower)
            hi = np.where(cont, self.center + 2.0 * np.pi, robot.upper)
            self.space = self._real_vector(lo, hi)
            self.compound = False
            self._use_fast_reader()
            return
        self.cont_idx = [int(i) for i in np.flatnonzero(cont)]
        self.bound_idx = [int(i) for i in np.flatnonzero(~cont)]
        self.compound = bool(self.cont_idx)
        if self.compound:
            space = ob.CompoundStateSpace()
            for _ in self.cont_idx:
                space.addSubspace(ob.SO2StateSpace(), 1.0)
            if self.bound_idx:
                space.addSubspace(
                    self._real_vector(robot.lower[self.bound_idx], robot.upper[self.bound_idx]), 1.0
                )
        else:
            space = self._real_vector(robot.lower, robot.upper)
        self.space = space
        self._use_fast_reader()

    def _use_fast_reader(self) -> None:
        reader = self._fast_reader()
        if reader is not None:
            self.to_q = reader  # type: ignore[method-assign, assignment]

    def _fast_reader(self) -> Callable[[Any], Array] | None:
        """One-call reading of a state, or None: OMPL's ``StateSpace::serialize`` writes
        the state's reals (SO2 values, then the RealVector block: :meth:`to_q`'s order)
        into a buffer this space owns, passed as the ``void *`` capsule nanobind accepts;
        one binding call instead of two per joint. Used only if the layout is confirmed on
        a test state (else None, and :meth:`to_q` reads joint by joint)."""
        buf = np.zeros(self.dof)
        try:
            if int(self.space.getSerializationLength()) != buf.nbytes:
                return None
            new = ctypes.pythonapi.PyCapsule_New
            new.restype = ctypes.py_object
            new.argtypes = (ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p)
            capsule = new(buf.ctypes.data, _NB_HANDLE, None)
            serialize = self.space.serialize
            probe = self.space.allocState()  # freed with its Python object
            q = wrap_to_pi(self.center + 0.1 + 0.01 * np.arange(self.dof), self.robot.continuous)
            self.set_state(probe, q)
            serialize(capsule, probe)
            order = self.cont_idx + self.bound_idx  # the joint of each serialized real
            ok = np.array_equal(buf[np.argsort(order)], self._read(probe))
        except (TypeError, AttributeError, ValueError):
            return None
        if not ok:
            return None
        self._buf = buf  # the capsule points into it: kept alive with this space
        if order == list(range(self.dof)):

            def read(state: Any) -> Array:
                serialize(capsule, state)
                return buf.copy()

            return read
        joint_of = np.argsort(order)  # q = buf[joint_of] (a new array)

        def read_permuted(state: Any) -> Array:
            serialize(capsule, state)
            return buf[joint_of]

        return read_permuted

    @staticmethod
    def _real_vector(lower: Array, upper: Array) -> Any:
        n = len(lower)
        rv = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for j in range(n):
            bounds.setLow(j, float(lower[j]))
            bounds.setHigh(j, float(upper[j]))
        rv.setBounds(bounds)
        return rv

    def to_q(self, state: Any) -> Array:
        """The joint vector (dof,) of an OMPL state (a new array)."""
        return self._read(state)

    def _read(self, state: Any) -> Array:
        """:meth:`to_q` joint by joint (two binding calls per joint)."""
        q = np.empty(self.dof)
        if self.compound:
            for k, i in enumerate(self.cont_idx):
                q[i] = state[k].value
            if self.bound_idx:
                rv = state[len(self.cont_idx)]
                for j, i in enumerate(self.bound_idx):
                    q[i] = rv[j]
        else:
            for j, i in enumerate(self.bound_idx):
                q[i] = state[j]
        return q

    def set_state(self, state: Any, q: Array) -> None:
        q = np.asarray(q, dtype=float)
        if self.lifted:  # the lift of q nearest to the centre
            q = self.center + joint_difference(q, self.center, self.robot.continuous)
        else:
            q = wrap_to_pi(q, self.robot.continuous)
        if self.compound:
            for k, i in enumerate(self.cont_idx):
                state[k].value = float(q[i])
            if self.bound_idx:
                rv = state[len(self.cont_idx)]
                for j, i in enumerate(self.bound_idx):
                    rv[j] = float(q[i])
        else:
            for j, i in enumerate(self.bound_idx):
                state[j] = float(q[i])

    def pair_metric(self, A: Array, B: Array) -> Array:
        """OMPL's distance between the rows of A and B (k, dof) pairwise."""
        d = np.abs(joint_difference(A, B, self.robot.continuous)).reshape(len(A), -1)
        out = d[:, self.cont_idx].sum(axis=1) if self.cont_idx else np.zeros(len(A))
        if self.bound_idx:
            out = out + np.linalg.norm(d[:, self.bound_idx], axis=1)
        return out

    def metric(self, Q: Array, q: Array) -> Array:
        """OMPL's distance from each row of Q (k, dof) to q: L1 continuous + L2 bounded."""
        d = np.abs(joint_difference(Q, q[None, :], self.robot.continuous))
        out = d[:, self.cont_idx].sum(axis=1) if self.cont_idx else np.zeros(len(Q))
        if self.bound_idx:
            out = out + np.linalg.norm(d[:, self.bound_idx], axis=1)
        return out


def tip_projection(
    space: Space, cell_m: float, center: Array, reach: float, counter: list[int]
) -> Any:
    """Tip-position projection (3-D, metres) for the KPIECE family."""

    class TipProjection(ob.ProjectionEvaluator):
        def getDimension(self) -> int:  # noqa: N802
            return 3

        def project(self, state: Any, projection: Any) -> None:
            counter[0] += 1
            p, _ = space.robot.tip(space.to_q(state))
            projection[:] = p

    proj = TipProjection(space.space)
    bounds = ob.RealVectorBounds(3)
    for d in range(3):
        bounds.setLow(d, float(center[d] - reach))
        bounds.setHigh(d, float(center[d] + reach))
    proj.setBounds(bounds)
    proj.inferCellSizes()  # sizes the cell vector; then set the real sizes
    for d in range(3):
        proj.setCellSizes(d, float(cell_m))
    return proj


def goal_chain(data: Any, space: Space) -> Array | None:
    """The chain of parents from the first goal vertex of OMPL planner data to a start
    vertex, as joint vectors (start first); None if there is none."""
    if data.numGoalVertices() == 0 or data.numStartVertices() == 0:
        return None
    v = int(data.getGoalIndex(0))
    chain = [v]
    seen = {v}
    while not data.isStartVertex(v):
        parents = data.getIncomingEdges(v)
        if not parents or parents[0] in seen:
            return None  # not a tree chain
        v = int(parents[0])
        seen.add(v)
        chain.append(v)
    return np.array([space.to_q(data.getVertex(i).getState()) for i in reversed(chain)])


def reach_m(robot: Robot, q: Array) -> float:
    """An upper bound of the tip's distance from the base [m]: the sum of link lengths."""
    seg = robot.link_segments(np.asarray(q, dtype=float))
    return float(np.sum(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)))

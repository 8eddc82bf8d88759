"""The public checker: the collision core for people who check states themselves.

``pl.checker(problem)`` gives a :class:`Checker` of the problem's robot in its scene with
its safety margin, as VAMP's ``validate`` and MPlib's ``check_for_collision`` give one::

    import plannerlab as pl

    check = pl.checker(pl.load_problem("armz_window"))
    check.valid(q)                 # one state (dof,) -> bool
    check.valid(Q)                 # a batch (n, dof) -> (n,) bool, eight states a call
    check.clearance(q)             # [m] smallest distance of the robot's own geometry
    check.edge_valid(q_a, q_b)     # the straight motion, on the re-check's grid
    check.lower, check.upper       # the joint bounds [rad or m]

Its answers are every planner's: the compiled state test (a float32 filter in vector
lanes, confirmed in float64: :mod:`plannerlab.collision.state_test` for a batch, eight
states a call; :mod:`plannerlab.collision.one_state` for one state, eight of its capsules
a vector) with the capsules grown by the problem's margin, and certified edges
(:mod:`plannerlab.collision.edges`) at the problem's re-check resolution (``[checking]
joint_step / 4``, and with a margin no point moving more than the margin between two
checked states).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.one_lanes import checker_tables
from plannerlab.collision.one_state import valid_state
from plannerlab.collision.queries import kernel_states
from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array


class Checker:
    """Validity, clearance and edges of one problem's robot in its scene (see the module).

    Attributes:
        dof: the robot's joints.
        lower, upper: (dof,) the joint bounds [rad, or m for a sliding joint]; a continuous
            joint's are ±π (any value is accepted, wrapped).
        margin_m: the problem's safety margin [m] (``[planning] safety_margin_m``): the
            robot counts as colliding closer than that to the scene.
        joint_step_rad: the edges' resolution (the problem's ``[checking] joint_step / 4``).
        checks: states tested so far.
    """

    def __init__(self, problem: Any, checker: CollisionChecker | None = None) -> None:
        self._checker = checker if checker is not None else problem_checker(problem)
        robot = problem.robot
        self.dof = int(robot.dof)
        self.lower = np.where(robot.continuous, -np.pi, robot.lower).astype(float)
        self.upper = np.where(robot.continuous, np.pi, robot.upper).astype(float)
        self.margin_m = float(self._checker.margin_m)
        self.joint_step_rad = float(problem.joint_step) / 4.0
        # the one-state road's inputs (None: no compiled core, the checker answers)
        self._one: tuple[Any, Any] | None = None
        if self._checker.backend == "core":
            self._one = (self._checker.packed_model, checker_tables(self._checker))

    @property
    def checks(self) -> int:
        return int(self._checker.checks)

    def _states(self, q: Array) -> tuple[np.ndarray, bool]:
        a = np.asarray(q, dtype=float)
        one = a.ndim == 1
        Q = np.atleast_2d(a)
        if Q.ndim != 2 or Q.shape[1] != self.dof:
            raise PlannerlabError(
                f"states must have shape ({self.dof},) or (n, {self.dof}), got {a.shape}"
            )
        if not np.all(np.isfinite(Q)):
            raise PlannerlabError("states must be finite numbers")
        return kernel_states(Q), one

    def valid(self, q: Array) -> Any:
        """One state (dof,) -> bool; states (n, dof) -> (n,) bool array."""
        a = np.asarray(q, dtype=float)
        if self._one is not None and a.ndim == 1 and a.shape[0] == self.dof:
            # one state: the one-state road, which also refuses a value that is not finite
            t32, t64i, t64 = self._one[1]
            ok = valid_state(self._one[0], t32, t64i, t64, kernel_states(a))
            if ok >= 0:
                self._checker.checks += 1
                return bool(ok)
        Q, one = self._states(a)  # bad input: a clear error
        if not one:
            return self._checker.valid_batch(Q)
        return bool(self._checker.is_valid(Q[0]))

    def clearance(self, q: Array) -> float:
        """The smallest signed distance [m] between the robot's own geometry (not grown
        by the margin) and the scene or itself (checked link pairs only) at one state;
        negative: penetration (exact while the capsule axes stay outside)."""
        Q, one = self._states(q)
        if not one:
            raise PlannerlabError(f"clearance takes one state ({self.dof},), got {Q.shape}")
        d = self._checker.clearance(Q[0])
        # the core's capsules carry the margin against the scene, half of it each between
        # links: either way the pair's distance is the margin short of the real one
        return float(d + self.margin_m)

    def edge_valid(self, q_a: Array, q_b: Array) -> bool:
        """The straight joint-space motion q_a -> q_b is free (q_a itself included)."""
        A, one_a = self._states(q_a)
        B, one_b = self._states(q_b)
        if not (one_a and one_b):
            raise PlannerlabError(f"edge_valid takes two states ({self.dof},) each")
        if not self._checker.is_valid(A[0]):
            return False
        _, bad = self._checker.check_edge(A[0], B[0], self.joint_step_rad)
        return bad is None


def checker(problem: Any) -> Checker:
    """The public checker of a problem (:class:`Checker`)."""
    return Checker(problem)


__all__ = ["Checker", "checker"]

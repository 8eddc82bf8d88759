"""One solve's guarded checker and termination condition, on the leg's budget tracker."""

from __future__ import annotations

from collections.abc import Callable

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners.base import BudgetTracker
from plannerlab.robots.base import Array


class TimeUp(Exception):
    """Raised by a validity callback past the time limit: it unwinds OMPL's C++ loop."""


class Guard:
    """One solve's collision checker and termination condition, behind its
    :class:`~plannerlab.planners.base.BudgetTracker`: the checker refuses (reports
    invalid, without checking) once the checks are spent or the time limit is reached;
    the termination condition counts its polls, which are the iterations of planners that
    expose no count of their own (``iteration_source``)."""

    def __init__(self, checker: CollisionChecker, tracker: BudgetTracker) -> None:
        self.checker = checker
        self.tracker = tracker
        self.polls = 0
        self.refused = 0
        self.iteration_source: Callable[[], int] | None = None
        #: raise TimeUp past the time limit (set while an OMPL solve runs, for planners
        #: with loops that poll nothing, see HARD_STOP)
        self.hard_stop = False
        #: checks held back for the re-check of the best path found so far: the checker
        #: refuses to spend them, so that path's re-check always fits the budget
        self.reserve = 0
        #: the time limit was seen reached (time only goes on)
        self._time_up = False

    def iterations(self) -> int:
        return self.iteration_source() if self.iteration_source is not None else self.polls

    def exhausted(self) -> str | None:
        return self.tracker.exhausted(self.iterations())

    def poll(self) -> bool:
        """The termination condition: True once any limit is reached."""
        self.polls += 1
        if self.hard_stop and self.out_of_time():
            raise TimeUp()
        return self.exhausted() is not None

    def out_of_time(self) -> bool:
        """The time limit is reached (once it is, the clock is not read again: the
        validity callbacks that refuse past it cost no look at the clock)."""
        if self._time_up:
            return True
        tl = self.tracker.budget.time_limit_s
        self._time_up = tl is not None and self.tracker.elapsed_s >= tl
        return self._time_up

    def _out_of_time(self) -> bool:
        """Past the time limit: refuse, so that loops which do not poll the termination
        condition (the goal pool's IK) end quickly too; with ``hard_stop``, raise
        :class:`TimeUp` instead, out through OMPL's C++ to the solve."""
        if self.out_of_time():
            self.refused += 1
            if self.hard_stop:
                raise TimeUp()
            return True
        return False

    def checks_left(self) -> int | None:
        """Checks the planning may still spend: the budget's, less the reserve."""
        left = self.tracker.checks_left()
        return None if left is None else max(left - self.reserve, 0)

    def is_valid(self, q: Array) -> bool:
        left = self.checks_left()
        if left is not None and left <= 0:
            self.refused += 1
            return False
        if self._out_of_time():
            return False
        return self.checker.is_valid(q)

    def edge_valid(self, q_a: Array, q_b: Array, joint_step: float) -> bool:
        """Every state of the edge after q_a (q_b included) is valid, checked in order.

        One call to the checker for the whole edge (interpolation included); with too
        little budget left for the whole edge, checks what it may, then refuses.
        """
        if self._out_of_time():
            return False
        left = self.checks_left()
        n, bad = self.checker.check_edge(q_a, q_b, joint_step, left)
        if left is not None and left < n:
            self.refused += 1
            return False
        return bad is None

    def path_valid(self, Q: Array, joint_step: float) -> bool:
        """Every state ``checker.check_path(Q, joint_step)`` checks is valid (the re-check's
        own states of a motion, for the repair); refused without checking when they do not
        all fit the checks left."""
        if self._out_of_time():
            return False
        left = self.checks_left()
        if left is not None and self.checker.grid_states(Q, joint_step) > left:
            self.refused += 1
            return False
        return bool(self.checker.check_path(Q, joint_step).valid)

"""The clearance family's result: a leg's path built from segments (descents, escapes, a
leader's tracking) and the counts the planner keeps on it (:class:`LegPath`), shared by
``gradient.clearance*`` and ``gradient.follow_leader*``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from plannerlab.planners.base import LegRun, PlanResult, Status
from plannerlab.robots.base import Array
from plannerlab.robots.paths import path_length

__all__ = ["LegPath"]


class LegPath:
    """A leg's path built from segments (descents, escapes, a leader's tracking), the
    counts the planner keeps on it, and its result: the one home of the result of the
    clearance family (``gradient.clearance*``, ``gradient.follow_leader*``).

    Progress is noted after each segment (the best goal distance it reached); the result
    adds ``extra["path_rad"]`` (the path's joint-space length) and, at a local minimum,
    ``extra["q_stall"]`` (the state it stalled at) to the planner's own ``extra``.

    Args:
        run: the leg's :class:`~plannerlab.planners.base.LegRun`.
        q0: (dof,) the leg's start, the path's first state.
    """

    def __init__(self, run: LegRun, q0: Array) -> None:
        self.run = run
        self.path: list[Array] = [q0]
        #: the planner's counts, reported in the result
        self.iterations = 0
        self.minima = 0
        self.escapes = 0

    def note(self, states: Any) -> None:
        """Progress after a segment: the best goal distance its states reach."""
        if len(states):
            run = self.run
            run.progress.note(float(np.min(run.goal.distance(run.robot, np.asarray(states)))))

    def add(self, segment: Any) -> None:
        """Append a segment that starts at the path's last state (its first state is
        dropped) and note its progress."""
        self.note(list(segment))
        self.path.extend(list(segment[1:]))

    def result(
        self,
        status: Status,
        reason: str,
        *,
        trace: Any = None,
        extra: Mapping[str, Any] | None = None,
    ) -> PlanResult:
        """The leg's result: the path, the counts, the planner's ``extra`` with the
        path's length and, at a local minimum, the stall state."""
        robot = self.run.robot
        out: dict[str, Any] = {
            **(extra or {}),
            "path_rad": path_length(np.array(self.path), robot.continuous),
        }
        if status is Status.LOCAL_MINIMUM:
            out["q_stall"] = np.asarray(self.path[-1], dtype=float).tolist()
        return self.run.result(
            status,
            reason,
            self.path,
            iterations=self.iterations,
            trace=trace,
            local_minima=self.minima,
            escapes=self.escapes,
            extra=out,
        )

"""The record of one planned leg: :class:`Status` and :class:`PlanResult`.

Every pipeline (``solve``, ``execute``, ``compare``, ``continuum``) produces these; plan
files and trial stores hold them in the form :meth:`PlanResult.to_dict` writes, through the
one codec (:mod:`plannerlab.record.codec`).
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.errors import PlanFileError
from plannerlab.record.codec import read_float, to_data
from plannerlab.record.contact_plan import ContactPlan, as_contact_plan
from plannerlab.robots.base import Array


class Status(enum.StrEnum):
    """How a planning call ended."""

    SOLVED = "solved"  #: the path ends inside the goal region and was checked collision-free
    APPROXIMATE = "approximate"  #: ended outside the goal region but as close as it got
    LOCAL_MINIMUM = "local_minimum"  #: descent stalled (objective flat while above epsilon)
    BUDGET_EXHAUSTED = "budget_exhausted"  #: ran out of iterations, checks or time
    INVALID_START = "invalid_start"  #: the start state is in collision
    INVALID_GOAL = "invalid_goal"  #: no valid goal state could be found
    INVALID_PATH = "invalid_path"  #: a path was found but failed the fine re-check
    FAILED = "failed"  #: any other failure, see ``reason``
    UNREACHABLE = "unreachable"  #: the goal is farther than the robot reaches (not planned)


def settings_dict(settings: Any) -> dict[str, Any]:
    """A frozen settings dataclass as plain JSON-able data."""
    if dataclasses.is_dataclass(settings) and not isinstance(settings, type):
        return to_data(dataclasses.asdict(settings))
    return {}


#: the columns of :attr:`PlanResult.progress`, in order
PROGRESS_COLUMNS = ("time_s", "collision_checks", "best_goal_dist", "best_cost")

#: float fields of :class:`PlanResult` (``null`` in a file reads back as NaN)
_FLOAT_FIELDS = (
    "time_s",
    "pos_err_m",
    "angle_err_deg",
    "min_clearance_m",
    "pos_tol_m",
    "angle_tol_deg",
    "path_clearance_m",
    "roughness_rad2",
)


@dataclass(frozen=True, eq=False)
class PlanResult:
    """What a planner returns for one leg.

    Attributes:
        planner: registry name.
        problem: problem name.
        leg: leg index; ``goal`` is the goal's name.
        status: see :class:`Status`; ``reason`` says why in words.
        path: (m, dof) joint path from the start; m >= 1.
        time_s: wall time of ``solve`` [s].
        iterations: planner iterations (descent steps, tree expansions, …).
        collision_checks: states checked for collision during planning.
        fk_calls: forward-kinematics evaluations (states), where the planner counts them.
        pos_err_m, angle_err_deg: tip errors of the path's last state.
        min_clearance_m: smallest planned clearance [m]: the least signed distance of the
            robot's true capsules (no margin) to the scene and between its checked link
            pairs over the states of the returned path (NaN when not computed). A plan
            that passed with ``[planning] safety_margin_m`` keeps at least that margin.
        trace: objective (or best goal distance) per iteration, for plots.
        progress: (k, 4) rows ``(time_s, collision_checks, best_goal_dist, best_cost)``
            (:data:`PROGRESS_COLUMNS`), one whenever the best goal distance or the best
            cost improved, plus one at the end: how the planner got there over time
            (OMPL's benchmark "progress properties"; see
            :class:`plannerlab.planners.base.Progress`).
        local_minima, escapes: local minima met, and how many of them were left.
        seed: the trial's seed (None if not seeded by a trial).
        settings: the planner's settings as data.
        extra: planner-specific numbers (path length before/after simplification, …).
        pos_tol_m, angle_tol_deg: the goal's tolerances the tip errors are judged against
            (NaN when not recorded); set by :func:`plannerlab.run.pipeline.solve_legs`.
        path_clearance_m: smallest clearance along the whole path [m]: every state of the
            final re-check's grid (``joint_step / 4``, the checker's edge cuts), the true
            capsules (no margin) to the scene and between checked link pairs, in one
            compiled call; measured by :func:`~plannerlab.run.pipeline.solve_legs` after
            the solve (outside the planner's clock) for a solved leg (NaN otherwise, and
            for a contact-permitting plan, which touches by design).
        roughness_rad2: how much the path turns [rad²]
            (:func:`~plannerlab.robots.paths.roughness`; lower is smoother), set with
            ``path_clearance_m``.
        contact_plan: a contact-permitting plan's record of its contacts (the continuum's
            ``chord_arc``: :class:`~plannerlab.record.contact_plan.ContactPlan`), which the
            executor, the figures and the CLI read; None for every other planner. A leg
            with one is executed by the contact executor, without the FCL re-check.
    """

    planner: str
    problem: str
    leg: int
    goal: str
    status: Status
    reason: str
    path: Array
    time_s: float = 0.0
    iterations: int = 0
    collision_checks: int = 0
    fk_calls: int = 0
    pos_err_m: float = math.nan
    angle_err_deg: float = math.nan
    min_clearance_m: float = math.nan
    pos_tol_m: float = math.nan
    angle_tol_deg: float = math.nan
    path_clearance_m: float = math.nan
    roughness_rad2: float = math.nan
    trace: Array = field(default_factory=lambda: np.zeros(0))
    progress: Array = field(default_factory=lambda: np.zeros((0, 4)))
    local_minima: int = 0
    escapes: int = 0
    seed: int | None = None
    settings: Mapping[str, Any] = field(default_factory=dict)
    extra: Mapping[str, Any] = field(default_factory=dict)
    contact_plan: ContactPlan | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status(self.status))
        object.__setattr__(self, "contact_plan", as_contact_plan(self.contact_plan))
        path = np.atleast_2d(np.array(self.path, dtype=float))
        path.setflags(write=False)
        object.__setattr__(self, "path", path)
        trace = np.array(self.trace, dtype=float).reshape(-1)
        trace.setflags(write=False)
        object.__setattr__(self, "trace", trace)
        progress = np.array(self.progress, dtype=float).reshape(-1, len(PROGRESS_COLUMNS))
        progress.setflags(write=False)
        object.__setattr__(self, "progress", progress)

    @property
    def solved(self) -> bool:
        return self.status is Status.SOLVED

    @property
    def q_final(self) -> Array:
        return self.path[-1]

    def path_sha256(self) -> str:
        """First 16 hex digits of the SHA-256 of the path's float64 bytes (C order)."""
        path = np.ascontiguousarray(self.path, dtype=np.float64)
        return hashlib.sha256(path.tobytes()).hexdigest()[:16]

    def to_dict(self, *, include_path: bool = True) -> dict[str, Any]:
        """The record as plain data (the codec's convention for non-finite numbers).

        Args:
            include_path: False leaves out ``path`` and ``trace`` (a trial store keeps
                hundreds of legs) and writes ``path_points`` and ``path_sha256`` instead.
        """
        d: dict[str, Any] = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        if self.contact_plan is None:
            del d["contact_plan"]
        else:
            d["contact_plan"] = self.contact_plan.to_dict()
        if not include_path:
            del d["path"], d["trace"]
            d["path_points"] = len(self.path)
            d["path_sha256"] = self.path_sha256()
        return to_data(d)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> PlanResult:
        """Read back what :meth:`to_dict` wrote (with its path).

        Raises:
            PlanFileError: ``data`` is not a plan result.
        """
        try:
            values = dict(data)
            for k in _FLOAT_FIELDS:
                if k in values:
                    values[k] = read_float(values[k])
            if "trace" in values:
                values["trace"] = [read_float(v) for v in values["trace"]]
            if values.get("progress") is not None:
                values["progress"] = [[read_float(v) for v in row] for row in values["progress"]]
            return cls(**values)
        except (TypeError, ValueError) as exc:
            raise PlanFileError(f"not a plan result: {exc}") from None

    def replace(self, **changes: Any) -> PlanResult:
        return dataclasses.replace(self, **changes)

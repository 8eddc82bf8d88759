"""The planner contract: one call signature, one result type, frozen settings.

Every planner is ``solve(problem, leg, budget, rng, q_start=None, stepper=None) ->
PlanResult``. Failure is a status with a reason, never ``None`` or an exception (bad
*input* still raises a :class:`~plannerlab.errors.PlannerlabError`).
"""

from __future__ import annotations

import dataclasses
import enum
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np

from plannerlab.errors import PlanFileError, PlannerlabError
from plannerlab.robots.base import Array


class Status(enum.StrEnum):
    """How a planning call ended."""

    SOLVED = "solved"  #: the path ends inside the goal region and was checked collision-free
    APPROXIMATE = "approximate"  #: ended outside the goal region but as close as it got
    LOCAL_MINIMUM = "local_minimum"  #: descent stalled (objective flat while above epsilon)
    BUDGET_EXHAUSTED = "budget_exhausted"  #: ran out of iterations, checks or time
    INVALID_START = "invalid_start"  #: the start state is in collision
    INVALID_GOAL = "invalid_goal"  #: no valid goal state could be found
    UNREACHABLE = "unreachable"  #: the goal is farther than the robot reaches (not planned)
    INVALID_PATH = "invalid_path"  #: a path was found but failed the fine re-check
    FAILED = "failed"  #: any other failure, see ``reason``


@runtime_checkable
class Stepper(Protocol):
    """Something that moves the robot for real (a simulator): closed-loop planners use it."""

    def move_towards(self, q_target: Array, steps: int) -> Array:
        """Drive towards q_target for ``steps`` control steps; return the state reached."""
        ...

    def reset(self, q: Array) -> None:
        """Put the robot at q, at rest."""
        ...


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
            return _jsonable(value.tolist())  # NaN/inf are not JSON
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, enum.Enum):
        return value.value
    return value


def settings_dict(settings: Any) -> dict[str, Any]:
    """A frozen settings dataclass as plain JSON-able data."""
    return _jsonable(dataclasses.asdict(settings)) if dataclasses.is_dataclass(settings) else {}


#: the columns of :attr:`PlanResult.progress`, in order
PROGRESS_COLUMNS = ("time_s", "collision_checks", "best_goal_dist", "best_cost")


class Progress:
    """Records a planner's progress: a row ``(time_s, collision_checks, best_goal_dist,
    best_cost)`` whenever the best normalised goal distance
    (:meth:`~plannerlab.problem.goals.GoalRegion.distance`, 0 inside the region) or the
    best cost (joint-space length of the best solution [rad], NaN until one is found)
    improves, and one at the end. Times are strictly increasing: a row at the same time as
    the last one replaces it. The shared helper behind :attr:`PlanResult.progress`.

    Args:
        clock: seconds since the solve started (e.g. ``Deadline.elapsed_s``).
        checks: collision checks used so far in this solve.
    """

    def __init__(self, clock: Any, checks: Any) -> None:
        self._clock = clock
        self._checks = checks
        self.best_goal_dist = math.inf
        self.best_cost = math.inf
        self._rows: list[list[float]] = []

    def _row(self, time_s: float, checks: int) -> None:
        d, c = self.best_goal_dist, self.best_cost
        row = [
            float(time_s),
            float(checks),
            d if d < math.inf else math.nan,
            c if c < math.inf else math.nan,
        ]
        if self._rows and row[0] <= self._rows[-1][0]:
            row[0] = self._rows[-1][0]
            self._rows[-1] = row
        else:
            self._rows.append(row)

    def note(
        self,
        goal_dist: float = math.nan,
        cost: float = math.nan,
        time_s: float | None = None,
        checks: int | None = None,
    ) -> bool:
        """Take a state's goal distance and/or a solution's cost; a row when either best
        improves (True then)."""
        better = False
        if goal_dist < self.best_goal_dist:  # False for NaN
            self.best_goal_dist = float(goal_dist)
            better = True
        if cost < self.best_cost:
            self.best_cost = float(cost)
            better = True
        if better:
            self._row(
                self._clock() if time_s is None else time_s,
                self._checks() if checks is None else checks,
            )
        return better

    def extend(self, rows: Array, time_offset_s: float, checks_offset: int) -> None:
        """Take a sub-solve's progress rows (a hybrid's descent or escape), shifted by when
        it started; its costs are of a part of the path, so only goal distances count."""
        for t, c, d, _cost in np.asarray(rows, dtype=float).reshape(-1, 4):
            self.note(goal_dist=d, time_s=time_offset_s + t, checks=int(checks_offset + c))

    def finish(self, goal_dist: float = math.nan, cost: float = math.nan) -> Array:
        """The rows, closed by one at the end (the last state's distance, the path's cost)."""
        if not self.note(goal_dist, cost):
            self._row(self._clock(), self._checks())
        return self.rows()

    def rows(self) -> Array:
        return np.array(self._rows, dtype=float).reshape(-1, len(PROGRESS_COLUMNS)).copy()

    @staticmethod
    def of_series(
        times_s: Any, checks: Any, goal_dists: Any, final_cost: float = math.nan
    ) -> Array:
        """Rows from per-iteration series (a descent's), keeping the improvements and the
        last iteration; ``final_cost`` is the path's cost when it solved."""
        times_s = np.asarray(times_s, dtype=float)
        series = list(zip(times_s, checks, goal_dists, strict=True))
        if not series:
            return np.zeros((0, len(PROGRESS_COLUMNS)))
        last = series[-1]
        p = Progress(lambda: last[0], lambda: last[1])
        for t, c, d in series:
            p.note(goal_dist=float(d), time_s=float(t), checks=int(c))
        return p.finish(cost=final_cost)


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
        trace: objective (or best goal distance) per iteration, for plots.
        progress: (k, 4) rows ``(time_s, collision_checks, best_goal_dist, best_cost)``
            (:data:`PROGRESS_COLUMNS`), one whenever the best goal distance or the best
            cost improved, plus one at the end: how the planner got there over time
            (OMPL's benchmark "progress properties"; see :class:`Progress`).
        local_minima, escapes: local minima met, and how many of them were left.
        seed: the trial's seed (None if not seeded by a trial).
        settings: the planner's settings as data.
        extra: planner-specific numbers (path length before/after simplification, …).
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
    trace: Array = field(default_factory=lambda: np.zeros(0))
    progress: Array = field(default_factory=lambda: np.zeros((0, 4)))
    local_minima: int = 0
    escapes: int = 0
    seed: int | None = None
    settings: Mapping[str, Any] = field(default_factory=dict)
    extra: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status(self.status))
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

    def to_dict(self) -> dict[str, Any]:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return _jsonable(d)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> PlanResult:
        try:
            values = dict(data)
            for k in ("pos_err_m", "angle_err_deg", "time_s"):
                if values.get(k) is None:
                    values[k] = math.nan
            if values.get("progress") is not None:  # JSON has no NaN: None stands for it
                values["progress"] = [
                    [math.nan if v is None else v for v in row] for row in values["progress"]
                ]
            return cls(**values)
        except (TypeError, ValueError) as exc:
            raise PlanFileError(f"not a plan result: {exc}") from None

    def replace(self, **changes: Any) -> PlanResult:
        return dataclasses.replace(self, **changes)


class Planner(Protocol):
    """A planner instance: a registry name and frozen settings."""

    name: str
    settings: Any

    def solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None = None,
        stepper: Stepper | None = None,
    ) -> PlanResult: ...


class Deadline:
    """Budget bookkeeping shared by planners: iterations, collision checks, time."""

    def __init__(self, budget: Any, checker: Any | None = None) -> None:
        self.budget = budget
        self.checker = checker
        self._checks0 = checker.checks if checker is not None else 0
        self._t0 = time.perf_counter()

    @property
    def elapsed_s(self) -> float:
        return time.perf_counter() - self._t0

    @property
    def checks_used(self) -> int:
        return (self.checker.checks - self._checks0) if self.checker is not None else 0

    def checks_left(self) -> int | None:
        """Collision checks still allowed (None: no such limit)."""
        b = self.budget
        if b.max_collision_checks is None:
            return None
        return max(b.max_collision_checks - self.checks_used, 0)

    def exhausted(self, iterations: int) -> str | None:
        """None while within budget, else which limit was hit, in words."""
        b = self.budget
        if b.max_iterations is not None and iterations >= b.max_iterations:
            return f"iteration budget of {b.max_iterations} used up"
        if b.max_collision_checks is not None and self.checks_used >= b.max_collision_checks:
            return f"collision-check budget of {b.max_collision_checks} used up"
        if b.time_limit_s is not None and self.elapsed_s >= b.time_limit_s:
            return f"time limit of {b.time_limit_s:g} s reached"
        return None


def with_overrides(settings: Any, overrides: Mapping[str, Any], planner: str) -> Any:
    """A copy of frozen ``settings`` with some fields changed; strings are coerced to the
    field's type (so CLI ``--set key=value`` works). Unknown keys raise with the known ones.
    """
    if not overrides:
        return settings
    fields = {f.name: f for f in dataclasses.fields(settings)}
    changes: dict[str, Any] = {}
    for key, value in overrides.items():
        if key not in fields:
            from plannerlab.errors import UnknownNameError

            raise UnknownNameError(f"setting of {planner}", key, fields)
        current = getattr(settings, key)
        if isinstance(value, str) and not isinstance(current, str):
            try:
                if isinstance(current, bool):
                    if value.lower() not in ("true", "false", "1", "0", "yes", "no"):
                        raise ValueError(value)
                    value = value.lower() in ("true", "1", "yes")
                elif isinstance(current, int):
                    value = int(value)
                elif isinstance(current, float) or current is None:
                    value = float(value)
            except ValueError:
                raise PlannerlabError(
                    f"setting {key} of {planner}: expected {type(current).__name__}, got {value!r}"
                ) from None
        changes[key] = value
    return dataclasses.replace(settings, **changes)

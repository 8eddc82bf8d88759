"""The planner contract: one call signature, one result type, frozen settings.

Every planner is ``solve(problem, leg, budget, rng, q_start=None, stepper=None) ->
PlanResult``. Failure is a status with a reason, never ``None`` or an exception (bad
*input* still raises a :class:`~plannerlab.errors.PlannerlabError`).

The pieces every planner shares: :class:`BudgetTracker` (the budget of one solve, its
sub-solves charged to it), :class:`LegRun` (the one way to build a :class:`PlanResult`),
:class:`Progress` (its progress rows) and :func:`start_collision` (the start-state check).
plannerlab's planners are :class:`~plannerlab.planners.context.LegPlanner` subclasses: ``solve``
builds the leg's :class:`~plannerlab.planners.context.PlanningContext` (checker, tracker,
the start checked once) and plans in it with ``plan(ctx, rng)``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from plannerlab.errors import PlannerlabError, warn_renamed
from plannerlab.problem.load import Budget
from plannerlab.record.leg import PROGRESS_COLUMNS, PlanResult, Status, settings_dict
from plannerlab.robots.base import Array
from plannerlab.robots.paths import path_length

__all__ = [
    "PROGRESS_COLUMNS",
    "BudgetTracker",
    "LegRun",
    "Progress",
    "PlanResult",
    "StepClock",
    "Planner",
    "Status",
    "Stepper",
    "settings_dict",
    "start_collision",
    "with_overrides",
]


@runtime_checkable
class Stepper(Protocol):
    """Something that moves the robot for real (a simulator): closed-loop planners use it."""

    def move_towards(self, q_target: Array, steps: int) -> Array:
        """Drive towards q_target for ``steps`` control steps; return the state reached."""
        ...

    def reset(self, q: Array) -> None:
        """Put the robot at q, at rest."""
        ...


class Planner(Protocol):
    """A planner instance: a registry name and frozen settings."""

    @property
    def name(self) -> str: ...

    @property
    def settings(self) -> Any: ...

    def solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None = None,
        stepper: Stepper | None = None,
    ) -> PlanResult: ...


class Progress:
    """Records a planner's progress: a row ``(time_s, collision_checks, best_goal_dist,
    best_cost)`` whenever the best normalised goal distance
    (:meth:`~plannerlab.problem.goals.GoalRegion.distance`, 0 inside the region) or the
    best cost (joint-space length of the best solution [rad], NaN until one is found)
    improves, and one at the end. Times are strictly increasing: a row at the same time as
    the last one replaces it. The shared helper behind :attr:`PlanResult.progress`.

    Args:
        clock: seconds since the solve started (e.g. ``BudgetTracker.elapsed_s``).
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


def start_collision(checker: Any, q_start: Array) -> str | None:
    """Why a leg cannot start at ``q_start``: its colliding pairs in words, or None when it
    is collision-free. The one start-state check (one collision check when valid).

    Pairs are named by the robot's links as its file names them: the capsules of a
    mesh's cover (``panda_link1#40``) by their URDF link (``panda_link1``), each pair once.
    """
    if checker.is_valid(q_start):
        return None
    robot = getattr(checker, "robot", None)
    urdf_of = dict(
        zip(
            getattr(robot, "link_names", ()),
            getattr(robot, "link_urdf_names", getattr(robot, "link_names", ())),
            strict=True,
        )
    )
    named = ((urdf_of.get(a, a), urdf_of.get(b, b)) for a, b in checker.colliding_pairs(q_start))
    pairs = ", ".join(f"{a} x {b}" for a, b in dict.fromkeys(named))
    return f"the start state collides: {pairs}"


def planned_clearance_m(checker: Any, path: Array) -> float:
    """Smallest clearance [m] of the robot's true capsules (the checker's margin added
    back) over the states of ``path``: to the scene and between checked link pairs.
    Not counted as collision checks (a measurement of the result, not planning); NaN
    without a checker that measures clearance."""
    if checker is None or not hasattr(checker, "clearance"):
        return math.nan
    checks = checker.checks
    try:
        P = np.atleast_2d(path)
        if hasattr(checker, "min_clearance"):  # one call for the whole path
            inflated = checker.min_clearance(P)
        else:
            inflated = min(checker.clearance(q) for q in P)
    finally:
        checker.checks = checks
    return float(inflated + getattr(checker, "margin_m", 0.0))


class BudgetTracker:
    """The budget bookkeeping of one solve: time, collision checks and iterations used,
    against a :class:`~plannerlab.problem.load.Budget`. The one tracker every planner uses.

    Checks used are those of ``checker`` since the tracker was made plus those charged
    (:meth:`charge` takes a sub-solve's result, :meth:`charge_checks` a count checked
    elsewhere). Iterations are the planner's own count, passed to :meth:`exhausted`, or
    else :attr:`iterations`, the count charged from sub-solves.

    A sub-solve on the same checker (a hybrid's descent, an escape) gets a
    :meth:`child`: its own limits and clock; its checks are this tracker's too (they are
    the shared checker's), and what it is charged is charged here as well.

    Time is read on :attr:`clock`, a callable giving seconds: ``clock`` if given, else
    the budget's (``Budget.clock``), else the parent's, else :func:`time.perf_counter`.
    Every look at the time of a solve (its limit, its progress rows, its result's
    ``time_s``, OMPL's termination condition, a set-up's stop) goes through it, so a
    test that gives its own clock (:class:`StepClock`) checks a time limit without the
    wall clock. Sub-budgets (:meth:`remaining`) carry the clock.

    Args:
        budget: the limits (a field None: no limit of that kind).
        checker: the collision checker whose ``checks`` count (None: charged checks only).
        parent: the tracker of the solve this one is a sub-solve of (:meth:`child`).
        clock: the clock (default: as above).
    """

    def __init__(
        self,
        budget: Any,
        checker: Any | None = None,
        parent: BudgetTracker | None = None,
        clock: Callable[[], float] | None = None,
    ) -> None:
        self.budget = budget
        self.checker = checker
        self.parent = parent
        if clock is None:
            clock = getattr(budget, "clock", None)
        if clock is None:
            clock = parent.clock if parent is not None else time.perf_counter
        #: the clock time is read on [s]
        self.clock: Callable[[], float] = clock
        self._checks0 = checker.checks if checker is not None else 0
        self._t0 = float(clock())
        #: iterations charged from sub-solves
        self.iterations = 0
        #: collision checks charged (sub-solves, checks made elsewhere)
        self.charged_checks = 0
        #: forward-kinematics evaluations charged from sub-solves (not a limit; a count)
        self.fk_calls = 0

    @property
    def elapsed_s(self) -> float:
        """Seconds since the tracker was made, on :attr:`clock`."""
        return float(self.clock()) - self._t0

    @property
    def checks_used(self) -> int:
        """Collision checks used: the checker's since the start, plus those charged."""
        own = (self.checker.checks - self._checks0) if self.checker is not None else 0
        return own + self.charged_checks

    def time_up(self) -> bool:
        """Whether the time limit is reached (False without one): the poll of a set-up
        (a field, a grid, a pool) that is not counted in iterations or checks."""
        tl = self.budget.time_limit_s
        return tl is not None and self.elapsed_s >= tl

    def checks_left(self) -> int | None:
        """Collision checks still allowed (None: no such limit)."""
        b = self.budget
        if b.max_collision_checks is None:
            return None
        return max(b.max_collision_checks - self.checks_used, 0)

    def exhausted(self, iterations: int | None = None) -> str | None:
        """None while within budget, else which limit was hit, in words.

        Args:
            iterations: the planner's iterations so far (default: :attr:`iterations`).
        """
        b = self.budget
        used = self.iterations if iterations is None else iterations
        if b.max_iterations is not None and used >= b.max_iterations:
            return f"iteration budget of {b.max_iterations} used up"
        if b.max_collision_checks is not None and self.checks_used >= b.max_collision_checks:
            return f"collision-check budget of {b.max_collision_checks} used up"
        if b.time_limit_s is not None and self.elapsed_s >= b.time_limit_s:
            return f"time limit of {b.time_limit_s:g} s reached"
        return None

    def remaining(
        self, checks_cap: int | None = None, *, limit_iterations: bool = True
    ) -> Budget | None:
        """The budget left for a sub-solve, or None when a limit is used up.

        Args:
            checks_cap: at most this many collision checks (an escape's slice).
            limit_iterations: False gives the sub-solve no iteration limit (a planner
                that counts its own iterations against the leg's, and the sub-solve's
                after it returns).
        """
        b = self.budget
        it = None
        if limit_iterations and b.max_iterations is not None:
            it = b.max_iterations - self.iterations
        ch = None if b.max_collision_checks is None else b.max_collision_checks - self.checks_used
        tl = None if b.time_limit_s is None else b.time_limit_s - self.elapsed_s
        if (
            (it is not None and it <= 0)
            or (ch is not None and ch <= 0)
            or (tl is not None and tl <= 0)
        ):
            return None
        if checks_cap is not None:
            ch = checks_cap if ch is None else min(ch, checks_cap)
        return Budget(max_iterations=it, max_collision_checks=ch, time_limit_s=tl, clock=self.clock)

    def child(self, budget: Any) -> BudgetTracker:
        """The tracker of a sub-solve on this tracker's checker within ``budget`` (a slice
        of :meth:`remaining`): its clock and checks count from now; its checks are seen
        here through the shared checker, and its charged checks are charged here too."""
        return BudgetTracker(budget, self.checker, parent=self, clock=self.clock)

    def charge(self, sub: PlanResult, *, checks: bool = True) -> None:
        """Count a sub-solve's iterations, collision checks and FK calls as this solve's.

        Args:
            sub: the sub-solve's result.
            checks: False for a sub-solve on a :meth:`child` of this tracker, whose
                checks this tracker already counts (they are its checker's).
        """
        self.iterations += sub.iterations
        if checks:
            self.charge_checks(sub.collision_checks)
        self.fk_calls += sub.fk_calls

    def charge_checks(self, checks: int) -> None:
        """Count collision checks made outside ``checker`` (another checker, a count);
        a child's are its parent's too."""
        self.charged_checks += int(checks)
        if self.parent is not None:
            self.parent.charge_checks(checks)


class StepClock:
    """A clock a test controls: it advances ``read_s`` at every read and ``check_s`` per
    unit of ``work()`` (for example a checker's collision checks), from 0. Given as
    ``Budget(time_limit_s=..., clock=StepClock(...))``, a planner's time limit is checked
    on the planner's own work rather than on the machine's load: the same verdict on any
    machine. ``reads`` counts the reads.

    Args:
        read_s: seconds each read advances the clock (> 0, so a loop that polls it ends).
        check_s: seconds per unit of ``work()``.
        work: a non-decreasing count of work done (None: none).
    """

    def __init__(
        self, read_s: float, check_s: float = 0.0, work: Callable[[], int] | None = None
    ) -> None:
        if not read_s > 0:
            raise PlannerlabError(f"StepClock: read_s must be > 0, got {read_s}")
        self.read_s = float(read_s)
        self.check_s = float(check_s)
        self.work = work
        self.reads = 0

    def now(self) -> float:
        """The time without a read [s]."""
        done = self.work() if self.work is not None else 0
        return self.reads * self.read_s + done * self.check_s

    def __call__(self) -> float:
        t = self.now()
        self.reads += 1
        return t


class LegRun:
    """One planner's run on one leg, and the one way to build its :class:`PlanResult`.

    It knows the planner (registry name, settings), the problem, the leg (its goal, the
    robot), the solve's :class:`BudgetTracker` and a :class:`Progress` on the tracker's
    clock and checks (:attr:`progress`, for the planner to note improvements on).
    :meth:`result` adds what every result has: the tip errors of the path's last state,
    the path's cost (joint-space length [rad]) when solved, the progress closed by a last
    row, the time and the checks used.

    Args:
        planner: registry name.
        settings: the planner's frozen settings (None: none, a leg that is not planned).
        problem: the problem; ``leg`` the leg index.
        tracker: the solve's budget tracker (None: a leg that is not planned: no time,
            no checks, no progress rows).
    """

    def __init__(
        self,
        planner: str,
        settings: Any,
        problem: Any,
        leg: int,
        tracker: BudgetTracker | None = None,
    ) -> None:
        self.planner = planner
        self.settings = settings
        self.problem = problem
        self.leg = leg
        self.robot = problem.robot
        self.goal = problem.goal(leg)
        self.tracker = tracker
        self.progress = (
            Progress(lambda: tracker.elapsed_s, lambda: tracker.checks_used)
            if tracker is not None
            else Progress(lambda: 0.0, lambda: 0)
        )

    def cost(self, status: Status, path: Array) -> float:
        """The cost of a result's path: its joint-space length [rad] when solved, else NaN."""
        if status is not Status.SOLVED:
            return math.nan
        return path_length(np.asarray(path, dtype=float), self.robot.continuous)

    def result(
        self,
        status: Status,
        reason: str,
        path: Any,
        *,
        iterations: int = 0,
        fk_calls: int = 0,
        trace: Any = None,
        progress_rows: Array | None = None,
        local_minima: int = 0,
        escapes: int = 0,
        extra: Mapping[str, Any] | None = None,
    ) -> PlanResult:
        """The leg's result.

        Args:
            status, reason: how it ended, in words.
            path: (m, dof) states from the start (m >= 1).
            iterations, fk_calls, local_minima, escapes: the planner's counts.
            trace: objective or best goal distance per iteration (default: none).
            progress_rows: the progress rows when the planner made them itself (default:
                :attr:`progress` closed by the last state's goal distance and the cost).
            extra: planner-specific numbers (copied).
        """
        P = np.atleast_2d(np.asarray(path, dtype=float))
        pos_err, ang_err = self.goal.errors(self.robot, P[-1])
        if progress_rows is None and self.tracker is not None:
            progress_rows = self.progress.finish(
                float(self.goal.distance(self.robot, P[-1])), self.cost(status, P)
            )
        t = self.tracker
        elapsed_s = t.elapsed_s if t is not None else 0.0
        checks_used = t.checks_used if t is not None else 0
        clearance = math.nan
        if status in (Status.SOLVED, Status.APPROXIMATE) and t is not None:
            clearance = planned_clearance_m(t.checker, P)
        return PlanResult(
            planner=self.planner,
            problem=self.problem.name,
            leg=self.leg,
            goal=self.goal.name,
            status=status,
            reason=reason,
            path=P,
            time_s=elapsed_s,
            iterations=iterations,
            collision_checks=checks_used,
            fk_calls=fk_calls,
            pos_err_m=float(pos_err),
            angle_err_deg=float(ang_err),
            min_clearance_m=clearance,
            trace=np.zeros(0) if trace is None else np.asarray(trace, dtype=float),
            progress=(
                np.zeros((0, len(PROGRESS_COLUMNS))) if progress_rows is None else progress_rows
            ),
            local_minima=local_minima,
            escapes=escapes,
            settings=settings_dict(self.settings),
            extra=dict(extra or {}),
        )


def with_overrides(settings: Any, overrides: Mapping[str, Any], planner: str) -> Any:
    """A copy of frozen ``settings`` with some fields changed; strings are coerced to the
    field's type (so CLI ``--set key=value`` works). Unknown keys raise with the known ones.
    A key the settings class renamed (its ``RENAMED_KEYS``: old -> new) is read as the new
    one, with a :class:`~plannerlab.errors.RenamedWarning` naming it.
    """
    if not overrides:
        return settings
    fields = {f.name: f for f in dataclasses.fields(settings)}
    renamed: Mapping[str, str] = getattr(type(settings), "RENAMED_KEYS", {})
    changes: dict[str, Any] = {}
    for key, value in overrides.items():
        if key in renamed:  # an old name, read as the new one for one release
            if renamed[key] in overrides:
                raise PlannerlabError(
                    f"settings of {planner}: {key!r} is the old name of {renamed[key]!r}; "
                    f"give {renamed[key]!r} only"
                )
            warn_renamed(f"settings of {planner}", key, renamed[key])
            key = renamed[key]
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
        changes[key] = _typed(value, current, key, planner)
    return dataclasses.replace(settings, **changes)


def _typed(value: Any, current: Any, key: str, planner: str) -> Any:
    """``value`` as the type of the setting's default ``current``, or a clear error: a
    flag takes only true/false, a count only a whole number, a length or time only a
    number, a name only a string (a TOML file's ``route_escape = "maybe"`` or
    ``max_checks = 2.5`` must not pass silently). A default of ``None`` is a number."""
    if isinstance(current, bool):
        ok = isinstance(value, bool)
        expected = "true or false"
    elif isinstance(current, int):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        ok = isinstance(value, int) and not isinstance(value, bool)
        expected = "a whole number"
    elif isinstance(current, float) or current is None:
        if value is None and current is None:
            return None
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        value = float(value) if ok else value
        expected = "a number"
    elif isinstance(current, str):
        ok = isinstance(value, str)
        expected = "a string"
    else:
        return value
    if not ok:
        raise PlannerlabError(f"setting {key} of {planner}: expected {expected}, got {value!r}")
    return value

"""One trial: (problem, planner, seed, overrides, legs, execute), run in its own process
into a JSON-able record (:func:`run_trial`), and the seeds of a grid (:func:`parse_seeds`).
See :mod:`plannerlab.comparison.runner` for how trials are run."""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
import traceback
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from plannerlab.errors import PlannerlabError
from plannerlab.record.leg import Status
from plannerlab.record.trial import (
    DIED_STATUS,
    ERROR_STATUS,
    TIMEOUT_STATUS,
    TRIAL_FORMAT,
    ExecutionRecord,
    LegRecord,
    TrialRecord,
)

LOGGER = logging.getLogger(__name__)

#: kept for readers of the old name
RECORD_FORMAT = TRIAL_FORMAT
__all__ = [
    "DIED_STATUS",
    "ERROR_STATUS",
    "MAX_SEEDS",
    "RECORD_FORMAT",
    "TIMEOUT_STATUS",
    "Trial",
    "error_record",
    "parse_seeds",
    "run_trial",
]

Scalar = int | float | str | bool | None


# ---------------------------------------------------------------------- trials
def _frozen_items(d: Mapping[str, Any] | Iterable[tuple[str, Any]] | None) -> tuple:
    items = dict(d or {}).items()
    return tuple(sorted((str(k), v) for k, v in items if v is not None))


@dataclass(frozen=True)
class Trial:
    """One run of one planner on one problem with one seed.

    Build with :meth:`make` (it normalises the mappings into sorted tuples, so trials are
    hashable and picklable).

    Attributes:
        problem: problem name (as reported by the problem file).
        problem_file: path of the problem file the child process loads.
        planner: registry name.
        seed: the trial's seed (numpy streams per leg, and OMPL's global seed).
        budget: overrides of the problem's budget, sorted ``(key, value)`` pairs with keys
            of :class:`~plannerlab.problem.load.Budget` (``max_iterations``,
            ``max_collision_checks``, ``time_limit_s``).
        settings: planner settings overrides, sorted ``(key, value)`` pairs.
        legs: leg indices to solve, in order (None: every leg).
        execute: also execute the planned legs in PyBullet.
        loaded: the problem already parsed (the comparison's, checked before any trial
            started): the trial's process takes it instead of parsing ``problem_file``
            again (a mesh robot's problem takes seconds to parse). Not part of the key.
        planner_obj: the planner already built with the settings (the comparison's, built
            to check them): the trial's process takes it instead of building it again.
            Not part of the key.
    """

    problem: str
    problem_file: str
    planner: str
    seed: int
    budget: tuple[tuple[str, Scalar], ...] = ()
    settings: tuple[tuple[str, Scalar], ...] = ()
    legs: tuple[int, ...] | None = None
    execute: bool = False
    loaded: Any = field(default=None, compare=False, hash=False, repr=False)
    planner_obj: Any = field(default=None, compare=False, hash=False, repr=False)

    @classmethod
    def make(
        cls,
        problem: str,
        problem_file: str | Path,
        planner: str,
        seed: int,
        *,
        budget: Mapping[str, Scalar] | None = None,
        settings: Mapping[str, Scalar] | None = None,
        legs: Sequence[int] | None = None,
        execute: bool = False,
        loaded: Any = None,
        planner_obj: Any = None,
    ) -> Trial:
        return cls(
            problem=str(problem),
            problem_file=str(problem_file),
            planner=str(planner),
            seed=int(seed),
            budget=_frozen_items(budget),
            settings=_frozen_items(settings),
            legs=None if legs is None else tuple(int(i) for i in legs),
            execute=bool(execute),
            loaded=loaded,
            planner_obj=planner_obj,
        )

    @property
    def config(self) -> dict[str, Any]:
        """Everything but problem, planner and seed, as plain data."""
        return {
            "budget": dict(self.budget),
            "settings": dict(self.settings),
            "legs": None if self.legs is None else list(self.legs),
            "execute": self.execute,
        }

    @property
    def key(self) -> str:
        """Stable identifier: ``problem/planner/s<seed>/<10 hex of the config>``."""
        blob = json.dumps(self.config, sort_keys=True, separators=(",", ":"))
        h = hashlib.sha256(blob.encode()).hexdigest()[:10]
        return f"{self.problem}/{self.planner}/s{self.seed}/{h}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "problem": self.problem,
            "problem_file": self.problem_file,
            "planner": self.planner,
            "seed": self.seed,
            **self.config,
        }


#: most seeds one comparison may ask for (each is one trial per planner and problem)
MAX_SEEDS = 100_000


def parse_seeds(spec: str) -> list[int]:
    """``"0-19"``, ``"0,3,5-7"`` or ``"4"`` -> sorted unique seeds.

    Raises:
        PlannerlabError: malformed spec or a negative/empty range.
    """
    seeds: set[int] = set()
    for part in str(spec).split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part:
                a, b = part.split("-", 1)
                lo, hi = int(a), int(b)
                if hi < lo:
                    raise ValueError
                if hi - lo >= MAX_SEEDS:
                    raise PlannerlabError(f"--seeds: at most {MAX_SEEDS} seeds, got {part!r}")
                seeds.update(range(lo, hi + 1))
            else:
                seeds.add(int(part))
        except ValueError:
            raise PlannerlabError(
                f"--seeds: expected integers and ranges like 0-19 or 0,3,5-7, got {part!r}"
            ) from None
    if not seeds:
        raise PlannerlabError(f"--seeds: no seed in {spec!r}")
    if min(seeds) < 0:
        raise PlannerlabError(f"--seeds: must be >= 0, got {min(seeds)}")
    return sorted(seeds)


# ---------------------------------------------------------------------- one trial
def _seed_ompl(seed: int) -> bool:
    """Seed OMPL's process-global RNG if the OMPL adapter imports; False when it cannot."""
    try:
        from plannerlab.planners import ompl as ompl_adapter
    except ImportError as exc:
        LOGGER.debug("OMPL adapter not importable (%s): OMPL not seeded", exc)
        return False
    seed_fn = getattr(ompl_adapter, "seed_ompl", None)
    if seed_fn is None:
        LOGGER.warning("plannerlab.planners.ompl has no seed_ompl(): OMPL not seeded")
        return False
    seed_fn(int(seed))
    return True


def _trial_status(legs: Sequence[LegRecord]) -> str:
    for leg in legs:
        if leg.status is not Status.SOLVED:
            return str(leg.status.value)
    return Status.SOLVED.value if legs else Status.FAILED.value


def _base(trial: Trial) -> dict[str, Any]:
    d = trial.to_dict()
    d["legs"] = None if trial.legs is None else tuple(trial.legs)
    return {"format": TRIAL_FORMAT, "key": trial.key, **d}


def run_trial(trial: Trial) -> TrialRecord:
    """Run one trial and return its record. Never raises (except KeyboardInterrupt/
    SystemExit): an exception becomes status ``error``.

    Meant to run in a fresh process: OMPL is seeded first, before any OMPL object exists.
    The problem file is parsed once, the planner built once and one collision checker
    serves the solve, the path measurements and the execution's re-check. The legs are
    solved in order and the trial stops at the first leg that is not solved (the task has
    failed there; ``legs_run`` shows how far it got).
    """
    t0 = time.perf_counter()
    cpu0 = time.process_time()
    ompl_seeded = _seed_ompl(trial.seed)  # first: before any OMPL object exists
    from plannerlab.record.files import versions

    fields: dict[str, Any] = {**_base(trial), "ompl_seeded": ompl_seeded}
    try:
        from plannerlab.problem.catalog import load_problem
        from plannerlab.run.pipeline import SharedChecker, solve_legs

        # parsed once: by the comparison that made the trial, or here
        problem = trial.loaded if trial.loaded is not None else load_problem(trial.problem_file)
        budget = problem.budget.replace(**dict(trial.budget))
        # one checker (and compiled model) per trial: the solve and the execution's
        # re-check share it
        shared = SharedChecker(problem)
        plan = solve_legs(
            problem,
            trial.planner,
            trial.seed,
            legs=trial.legs,
            budget=budget,
            overrides=dict(trial.settings),
            stop_on_failure=True,  # a task fails at its first failed leg
            shared=shared,
            planner=trial.planner_obj,  # built once: by the comparison, or by solve_legs
        )
        legs = tuple(LegRecord.of(r, problem.robot.continuous) for r in plan.legs)
        fields.update(
            budget_used=budget.to_dict(),
            settings_used=dict(plan.legs[0].settings) if plan.legs else {},
            legs_run=legs,
            status=_trial_status(legs),
            success=bool(legs) and all(x.solved for x in legs),
        )
        # Execution runs what the planner claims: the solved legs up to the first that is
        # not solved. A failed plan's path (thousands of flailing descent steps, say) is
        # not executed; ``executed_legs`` says how many legs were.
        solved_prefix = 0
        while solved_prefix < len(plan.legs) and plan.legs[solved_prefix].solved:
            solved_prefix += 1
        fields["executed_legs"] = solved_prefix if trial.execute else 0
        if trial.execute and solved_prefix:
            from plannerlab.run.pipeline import execute_results

            executions = execute_results(problem, plan.legs[:solved_prefix], shared=shared)
            fields["executions"] = tuple(ExecutionRecord.of(e) for e in executions)
    except Exception as exc:  # a crashing trial is a record, never the end of the run
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        LOGGER.debug("trial %s raised", trial.key, exc_info=True)
        fields.update(status=ERROR_STATUS, success=False, error=last, legs_run=(), executions=None)
    fields["versions"] = versions()
    fields["pid"] = os.getpid()
    fields["wall_s"] = time.perf_counter() - t0
    # the trial's own CPU time: its wall time on a machine with a core to spare for it
    fields["cpu_s"] = time.process_time() - cpu0
    fields["finished_at"] = datetime.now(UTC).isoformat(timespec="seconds")
    return TrialRecord(**fields)


def error_record(trial: Trial, error: str, status: str = ERROR_STATUS, **more: Any) -> TrialRecord:
    """The record of a trial that did not report (it died, timed out, or could not run):
    ``status`` with ``error`` saying why; ``more``: the other fields known (``exit_code``,
    ``signal``, ``output``, ``wall_s``)."""
    return TrialRecord(
        **_base(trial),
        status=status,
        success=False,
        error=error,
        finished_at=datetime.now(UTC).isoformat(timespec="seconds"),
        **more,
    )

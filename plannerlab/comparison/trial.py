"""One trial: (problem, planner, seed, overrides, legs, execute), run in its own process
into a JSON-able record (:func:`run_trial`), and the seeds of a grid (:func:`parse_seeds`).
See :mod:`plannerlab.comparison.runner` for how trials are run."""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import time
import traceback
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.record.codec import to_data
from plannerlab.record.execution import Execution
from plannerlab.record.leg import PlanResult, Status

LOGGER = logging.getLogger(__name__)

RECORD_FORMAT = "plannerlab.trial/1"
#: statuses of a trial record: the planner statuses plus "error" (the trial raised)
ERROR_STATUS = "error"
#: status of a trial killed for running past its wall-clock limit
TIMEOUT_STATUS = "timeout"

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
    """

    problem: str
    problem_file: str
    planner: str
    seed: int
    budget: tuple[tuple[str, Scalar], ...] = ()
    settings: tuple[tuple[str, Scalar], ...] = ()
    legs: tuple[int, ...] | None = None
    execute: bool = False

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


#: most progress rows a leg record keeps (evenly picked, the first and last always)
MAX_PROGRESS_ROWS = 200


def _thinned(rows: np.ndarray, most: int = MAX_PROGRESS_ROWS) -> np.ndarray:
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    if len(rows) <= most:
        return rows
    return rows[np.unique(np.linspace(0, len(rows) - 1, most).round().astype(int))]


def _leg_record(r: PlanResult, continuous: np.ndarray) -> dict[str, Any]:
    """The leg's :class:`PlanResult` record without its path and trace (a store holds
    hundreds of legs; ``path_sha256`` identifies the path), plus its joint-space length."""
    from plannerlab.robots.paths import path_length

    return {
        **r.to_dict(include_path=False),
        "path_length": to_data(path_length(r.path, continuous)),
        "progress": to_data(_thinned(r.progress)),
    }


def _execution_record(executions: Sequence[Execution]) -> dict[str, Any]:
    """The trial's executions: each leg's :class:`Execution` record without its
    per-waypoint log, and the verdict over the legs."""
    legs = [e.to_dict(include_log=False) for e in executions]
    last = executions[-1] if executions else None
    return {
        "success": bool(executions) and all(e.success for e in executions),
        "path_valid": all(e.path_valid is not False for e in executions),
        "max_track_err_rad": to_data(max((e.max_track_err_rad for e in executions), default=0.0)),
        "max_deviation_m": to_data(
            max((e.max_deviation_m for e in executions), default=math.nan)
            if all(math.isfinite(e.max_deviation_m) for e in executions)
            else math.nan
        ),
        "min_clearance_m": to_data(
            min(
                (e.min_clearance_m for e in executions if math.isfinite(e.min_clearance_m)),
                default=math.nan,
            )
        ),
        "contacts": sum(len(e.unexpected_contacts) for e in executions),
        "final_pos_err_m": to_data(last.final_pos_err_m) if last else None,
        "final_angle_err_deg": to_data(last.final_angle_err_deg) if last else None,
        "legs": legs,
    }


def _trial_status(legs: Sequence[Mapping[str, Any]]) -> str:
    for leg in legs:
        if leg["status"] != Status.SOLVED:
            return str(leg["status"])
    return Status.SOLVED.value if legs else Status.FAILED.value


#: per-leg numbers summed into a trial's ``totals``
TOTAL_KEYS = (
    "time_s",
    "iterations",
    "collision_checks",
    "fk_calls",
    "path_length",
    "local_minima",
    "escapes",
)


def run_trial(trial: Trial) -> dict[str, Any]:
    """Run one trial and return its record (plain JSON-able data). Never raises
    (except KeyboardInterrupt/SystemExit): an exception becomes status ``error``.

    Meant to run in a fresh process: OMPL is seeded first, before any OMPL object exists.
    The legs are solved in order and the trial stops at the first leg that is not solved
    (the task has failed there; ``legs_run`` shows how far it got).
    """
    t0 = time.perf_counter()
    cpu0 = time.process_time()
    ompl_seeded = _seed_ompl(trial.seed)  # first: before any OMPL object exists
    from plannerlab.record.files import versions

    rec: dict[str, Any] = {
        "format": RECORD_FORMAT,
        "key": trial.key,
        **trial.to_dict(),
        "ompl_seeded": ompl_seeded,
    }
    try:
        from plannerlab.problem.catalog import load_problem
        from plannerlab.run.pipeline import SharedChecker, solve_legs

        problem = load_problem(trial.problem_file)
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
        )
        legs = [_leg_record(r, problem.robot.continuous) for r in plan.legs]
        rec["budget_used"] = budget.to_dict()
        rec["settings_used"] = dict(plan.legs[0].settings) if plan.legs else {}
        rec["legs_run"] = legs
        rec["status"] = _trial_status(legs)
        rec["success"] = bool(legs) and all(x["status"] == "solved" for x in legs)
        rec["error"] = None
        rec["totals"] = {k: to_data(sum((x[k] or 0) for x in legs)) for k in TOTAL_KEYS}
        rec["final_pos_err_m"] = legs[-1]["pos_err_m"] if legs else None
        rec["final_angle_err_deg"] = legs[-1]["angle_err_deg"] if legs else None
        rec["execution"] = None
        # Execution runs what the planner claims: the solved legs up to the first that is
        # not solved. A failed plan's path (thousands of flailing descent steps, say) is
        # not executed; ``executed_legs`` says how many legs were.
        solved_prefix = 0
        while solved_prefix < len(plan.legs) and plan.legs[solved_prefix].solved:
            solved_prefix += 1
        rec["executed_legs"] = solved_prefix if trial.execute else 0
        if trial.execute and solved_prefix:
            from plannerlab.run.pipeline import execute_results

            executions = execute_results(problem, plan.legs[:solved_prefix], shared=shared)
            rec["execution"] = _execution_record(executions)
    except Exception as exc:  # a crashing trial is a record, never the end of the run
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        LOGGER.debug("trial %s raised", trial.key, exc_info=True)
        rec.update(
            status=ERROR_STATUS,
            success=False,
            error=last,
            legs_run=[],
            totals={},
            execution=None,
            final_pos_err_m=None,
            final_angle_err_deg=None,
        )
    rec["versions"] = versions()
    rec["pid"] = os.getpid()
    rec["wall_s"] = time.perf_counter() - t0
    # the trial's own CPU time: its wall time on a machine with a core to spare for it
    rec["cpu_s"] = time.process_time() - cpu0
    rec["finished_at"] = datetime.now(UTC).isoformat(timespec="seconds")
    return rec


def _error_record(trial: Trial, error: str) -> dict[str, Any]:
    return {
        "format": RECORD_FORMAT,
        "key": trial.key,
        **trial.to_dict(),
        "status": ERROR_STATUS,
        "success": False,
        "error": error,
        "legs_run": [],
        "totals": {},
        "execution": None,
        "final_pos_err_m": None,
        "final_angle_err_deg": None,
        "finished_at": datetime.now(UTC).isoformat(timespec="seconds"),
    }

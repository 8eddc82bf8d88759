"""Grids of trials (problems × planners × seeds), each trial in its own process.

A :class:`Trial` is (problem, planner, seed, budget overrides, settings overrides, legs,
execute). :func:`run_trial` runs one and returns a JSON-able record; it is meant to run in
a *fresh* process, because OMPL's random generator is process-global and its seed only
takes effect before OMPL's first generator exists (see :mod:`plannerlab.planners.ompl`).
:func:`run_comparison` runs many, ``jobs`` at a time, one spawned process per trial, and
appends every finished record to a :class:`TrialStore` (JSON lines, flushed and fsynced
line by line), so that rerunning the same comparison skips the trials already finished
and an interrupted run loses only the trials that were still running.
:func:`summarise` turns records into one row per (problem, planner).

Decisions:

* **One fresh process per trial**, at most ``jobs`` running, on a *backend*:
  :mod:`plannerlab.comparison.local` (default: children forked from a fork server that has
  imported numpy, FCL, PyBullet and OMPL's modules but created no OMPL object) or
  :mod:`plannerlab.comparison.ray_backend` (Ray tasks, one fresh worker process each). A
  trial whose process dies is recorded as an ``error`` for *that* trial; a trial past
  its wall-clock limit (``trial_timeout_s``; :func:`default_trial_timeout_s` derives one
  from the budget) is killed and recorded as ``timeout``; on Ctrl-C the running trials
  are stopped at once. A record is appended by the parent only, so there is a single
  writer, and the store, resuming and ``on_done`` are the same whatever the backend.
* **Seeding.** The child seeds OMPL (``seed_ompl(seed)``) before anything else whenever
  :mod:`plannerlab.planners.ompl` imports, whatever the planner (a planner may use OMPL
  inside); numpy generators come from :func:`plannerlab.run.pipeline.leg_rng`.
* **Trial key.** ``problem/planner/s<seed>/<hash>`` where the hash (sha256, 10 hex) covers
  the budget and settings overrides, the legs and the execute flag, so one store can hold
  runs of the same grid under different budgets without mixing them.
* **Errors.** A trial that raises is recorded with status ``error`` and the exception's
  last line (never kills the run); it and a ``timeout`` are "finished" for resuming
  unless ``retry_errors``.
* **Statistics** (:func:`summarise`): success = every leg SOLVED; a trial with status
  ``error`` or ``timeout`` counts in ``n`` as a failure and in ``errors``. Times (sum
  over legs of ``time_s``) and final tip errors are over every trial that did not error
  or time out; path length over successful trials only; 95 % Wilson score interval for
  the success rate.
* **Deterministic planners.** Seeds mean something only if they change the trial. A row
  is ``deterministic`` when it has two or more trials and all of them are the same trial:
  the same :func:`trial_fingerprint` (every leg's status, path hash, counts and tip
  errors, and the execution's verdict; clocks left out). Its seeds are one run repeated,
  so it gets no interval (``ci95_low``/``ci95_high`` NaN) and the tables say
  "deterministic" where the interval would be. This is detected from what the trials did,
  not read from the registry's ``uses_rng``: a planner that draws from its generator only
  at a stall (``gradient.clearance+rrtconnect``) runs one trial on every seed of a
  problem where it never stalls, and its interval would mean as little there.
  ``distinct_trials`` counts the different trials of a row.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import os
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.record.codec import dumps, to_data
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
        from plannerlab.run.pipeline import solve_legs

        problem = load_problem(trial.problem_file)
        budget = problem.budget.replace(**dict(trial.budget))
        plan = solve_legs(
            problem,
            trial.planner,
            trial.seed,
            legs=trial.legs,
            budget=budget,
            overrides=dict(trial.settings),
            stop_on_failure=True,  # a task fails at its first failed leg
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

            executions = execute_results(problem, plan.legs[:solved_prefix])
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


# ---------------------------------------------------------------------- the store
class TrialStore:
    """Append-only JSON-lines file of finished trial records (one line per trial).

    Every line is flushed and fsynced when written. On reading, a line that is not valid
    JSON is ignored: the last one may be half-written by a kill (it is cut off before the
    next append, so new lines never glue onto it); any other is logged. A key that occurs
    twice keeps its last record.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)

    def load(self) -> dict[str, dict[str, Any]]:
        """Records by trial key."""
        out: dict[str, dict[str, Any]] = {}
        if not self.path.exists():
            return out
        lines = self.path.read_bytes().split(b"\n")
        for i, line in enumerate(lines):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
            except (json.JSONDecodeError, UnicodeDecodeError):
                if i < len(lines) - 1:
                    LOGGER.warning("%s: line %d is not JSON; ignored", self.path, i + 1)
                continue
            if isinstance(rec, dict) and "key" in rec:
                out[str(rec["key"])] = rec
        return out

    def _cut_partial_tail(self) -> None:
        """Drop a last line without its newline (a write interrupted by a kill)."""
        if not self.path.exists():
            return
        with open(self.path, "r+b") as fh:
            size = fh.seek(0, os.SEEK_END)
            if size == 0:
                return
            fh.seek(size - 1)
            if fh.read(1) == b"\n":
                return
            data = self.path.read_bytes()
            cut = data.rfind(b"\n") + 1
            LOGGER.info("%s: dropping a half-written last line (%d bytes)", self.path, size - cut)
            fh.truncate(cut)
            fh.flush()
            os.fsync(fh.fileno())

    @contextlib.contextmanager
    def writer(self) -> Iterator[Callable[[Mapping[str, Any]], None]]:
        """Exclusive appender: ``with store.writer() as append: append(record)``.

        Raises:
            PlannerlabError: another process holds the store (a comparison already running
                into the same folder).
        """
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        lock_path = self.path.with_name(self.path.name + ".lock")
        with open(lock_path, "a") as lock:
            try:
                fcntl.flock(lock.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise PlannerlabError(
                    f"{self.path} is in use by another comparison (lock {lock_path})"
                ) from None
            self._cut_partial_tail()
            with open(self.path, "a", encoding="utf-8") as fh:

                def append(rec: Mapping[str, Any]) -> None:
                    fh.write(dumps(rec) + "\n")
                    fh.flush()
                    os.fsync(fh.fileno())

                yield append


def store_path(out_dir: str | Path, name: str) -> Path:
    """``<out_dir>/<name>/trials.jsonl``."""
    return Path(out_dir) / name / "trials.jsonl"


def default_name(problems: Sequence[str], planners: Sequence[str]) -> str:
    """A folder name from the problems and planners (filesystem-safe, at most ~80 chars)."""
    import re

    raw = "__".join(["+".join(problems), "+".join(planners)])
    safe = re.sub(r"[^A-Za-z0-9._+-]", "_", raw)
    if len(safe) <= 80:
        return safe
    h = hashlib.sha256(raw.encode()).hexdigest()[:8]
    return f"{safe[:70]}-{h}"


# ---------------------------------------------------------------------- comparisons
@dataclass
class ComparisonRun:
    """What :func:`run_comparison` did.

    Attributes:
        records: one record per requested trial that is finished (in the trials' order).
        ran: trials run by this call; skipped: trials already in the store.
        missing: trials without a record (only after an interruption).
    """

    records: list[dict[str, Any]]
    ran: int
    skipped: int
    missing: list[Trial] = field(default_factory=list)


#: the backends :func:`run_comparison` knows by name
BACKENDS = ("local", "ray")
#: wall-clock allowance per leg when the budget has no time limit [s]
LEG_ALLOWANCE_S = 600.0
#: wall-clock allowance per executed leg [s]
EXECUTE_ALLOWANCE_S = 120.0
#: start-up allowance per trial [s]
STARTUP_ALLOWANCE_S = 60.0


def default_trial_timeout_s(time_limit_s: float | None, n_legs: int, execute: bool) -> float:
    """A trial's wall-clock limit derived from its budget: per leg twice the time limit
    plus 30 s (or :data:`LEG_ALLOWANCE_S` when only checks or iterations are budgeted, which
    have no clock), plus :data:`EXECUTE_ALLOWANCE_S` per executed leg, plus
    :data:`STARTUP_ALLOWANCE_S`."""
    per_leg = 2.0 * float(time_limit_s) + 30.0 if time_limit_s else LEG_ALLOWANCE_S
    if execute:
        per_leg += EXECUTE_ALLOWANCE_S
    return STARTUP_ALLOWANCE_S + max(1, int(n_legs)) * per_leg


def _timeout_record(trial: Trial, limit_s: float, elapsed_s: float) -> dict[str, Any]:
    rec = _error_record(
        trial, f"killed after {elapsed_s:.1f} s: past the per-trial limit of {limit_s:g} s"
    )
    rec["status"] = TIMEOUT_STATUS
    rec["wall_s"] = elapsed_s
    return rec


def make_backend(name: str, work_dir: str | Path, *, address: str | None = None) -> Any:
    """A trial backend by name: ``"local"`` (:class:`plannerlab.comparison.local.LocalBackend`,
    fork server) or ``"ray"`` (:class:`plannerlab.comparison.ray_backend.RayBackend`).

    Raises:
        PlannerlabError: unknown name, ``address`` without Ray, or Ray not installed.
    """
    if name == "local":
        if address is not None:
            raise PlannerlabError("--address is for --backend ray")
        from plannerlab.comparison.local import LocalBackend

        return LocalBackend(work_dir, run_trial)
    if name == "ray":
        from plannerlab.comparison.ray_backend import RayBackend

        return RayBackend(run_trial, address=address)
    raise PlannerlabError(f"backend: expected one of {', '.join(BACKENDS)}, got {name!r}")


def run_comparison(
    trials: Sequence[Trial],
    store: TrialStore | str | Path,
    jobs: int = 1,
    on_done: Callable[[dict[str, Any], bool], None] | None = None,
    *,
    retry_errors: bool = False,
    poll_s: float = 0.5,
    trial_timeout_s: float | Callable[[Trial], float | None] | None = None,
    backend: Any = None,
) -> ComparisonRun:
    """Run the trials not yet in ``store``, ``jobs`` at a time, each in its own process.

    Args:
        trials: the grid; duplicates (same key) run once.
        store: where finished records are appended (a :class:`TrialStore` or its path).
        jobs: trials running at once (>= 1).
        on_done: called in this process as ``on_done(record, skipped)`` for every trial
            already in the store (``skipped=True``, first) and every trial as it finishes.
        retry_errors: rerun trials whose stored record has status ``error`` or
            ``timeout``.
        poll_s: how often to look at the running trials [s] (responsiveness, and the
            resolution of the time limit).
        trial_timeout_s: wall-clock limit per trial [s], or a function of the trial
            (None: no limit). A trial past it is killed and recorded with status
            ``timeout``; the comparison goes on.
        backend: where trials run: a backend object (see :mod:`plannerlab.comparison.local`,
            :mod:`plannerlab.comparison.ray_backend`), or None for the local fork-server
            backend. A backend made here is closed here.

    Returns:
        the records of every requested trial (see :class:`ComparisonRun`).

    Raises:
        KeyboardInterrupt: after stopping the running trials; every trial finished
            before is in the store, so rerunning resumes.
    """
    if jobs < 1:
        raise PlannerlabError(f"jobs: expected >= 1, got {jobs}")
    store = store if isinstance(store, TrialStore) else TrialStore(store)
    unique: dict[str, Trial] = {}
    for t in trials:
        unique.setdefault(t.key, t)
    stored = store.load()
    results: dict[str, dict[str, Any]] = {}
    todo: list[Trial] = []
    retry = (ERROR_STATUS, TIMEOUT_STATUS)
    for key, t in unique.items():
        rec = stored.get(key)
        if rec is not None and not (retry_errors and rec.get("status") in retry):
            results[key] = rec
        else:
            todo.append(t)
    skipped = len(results)
    if on_done is not None:
        for key in unique:
            if key in results:
                on_done(results[key], True)

    def limit_of(trial: Trial) -> float | None:
        if trial_timeout_s is None:
            return None
        v = trial_timeout_s(trial) if callable(trial_timeout_s) else trial_timeout_s
        return None if v is None else float(v)

    ran = 0
    if todo:
        queue = list(reversed(todo))
        own_backend = backend is None
        with store.writer() as append:
            if own_backend:
                backend = make_backend("local", store.path.parent / ".running")

            def finish(rec: dict[str, Any]) -> None:
                nonlocal ran
                append(rec)
                results[rec["key"]] = rec
                ran += 1
                if on_done is not None:
                    on_done(rec, False)

            running: dict[Any, tuple[Trial, float, float | None]] = {}
            try:
                while queue or running:
                    while queue and len(running) < jobs:
                        trial = queue.pop()
                        started = time.monotonic()
                        handle = backend.start(trial)
                        running[handle] = (trial, started, limit_of(trial))
                    for handle, rec, why in backend.wait(list(running), poll_s):
                        trial, _started, _limit = running.pop(handle)
                        finish(rec if rec is not None else _error_record(trial, why))
                    now = time.monotonic()
                    for handle, (trial, started, limit) in list(running.items()):
                        if limit is not None and now - started > limit:
                            backend.kill(handle)
                            del running[handle]
                            finish(_timeout_record(trial, limit, now - started))
            except KeyboardInterrupt:
                for rec in backend.salvage():  # sent but not yet read
                    if rec.get("key") in unique and rec["key"] not in results:
                        finish(rec)
                raise
            finally:
                if own_backend:
                    backend.close()
                else:
                    for handle in list(running):
                        backend.kill(handle)
    records = [results[k] for k in unique if k in results]
    missing = [t for k, t in unique.items() if k not in results]
    return ComparisonRun(records=records, ran=ran, skipped=skipped, missing=missing)


def compare(
    problems: Sequence[str | Path],
    planners: Sequence[str],
    seeds: Iterable[int],
    store: TrialStore | str | Path,
    *,
    budget: Mapping[str, Scalar] | None = None,
    settings: Mapping[str, Mapping[str, Scalar]] | None = None,
    execute: bool = False,
    jobs: int = 1,
    on_done: Callable[[dict[str, Any], bool], None] | None = None,
) -> ComparisonRun:
    """Every planner on every problem with every seed, each trial in its own process,
    resumable from ``store`` (what ``plannerlab compare`` runs).

    Args:
        problems: bundled problem names or problem file paths.
        planners: registry names.
        seeds: one trial per seed (seeds outermost within a problem, so that an
            interrupted run stays balanced over the planners).
        store: the trial store (JSON lines) to append to and resume from.
        budget: budget overrides for every trial (``max_collision_checks``, …).
        settings: per planner, settings overrides.
        execute: execute each trial's solved legs in PyBullet.
        jobs: trial processes alive at once.
        on_done: see :func:`run_comparison`.
    """
    from plannerlab.problem.catalog import load_problem, resolve_problem_path

    seeds = list(seeds)
    trials = []
    for p in problems:
        path = resolve_problem_path(p)
        name = load_problem(path).name
        trials += [
            Trial.make(
                name,
                path,
                planner,
                seed,
                budget=budget,
                settings=(settings or {}).get(planner),
                execute=execute,
            )
            for seed in seeds
            for planner in planners
        ]
    return run_comparison(trials, store, jobs, on_done)


# ---------------------------------------------------------------------- statistics
def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (95 % by default), from
    ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``.

    ``(nan, nan)`` for ``n == 0``. 0/20 gives (0, 0.161); 20/20 gives (0.839, 1).
    """
    if n <= 0:
        return (math.nan, math.nan)
    if not 0 <= successes <= n:
        raise ValueError(f"successes must be in [0, {n}], got {successes}")
    from scipy.stats import binomtest  # here: scipy.stats takes a while to import

    ci = binomtest(int(successes), int(n)).proportion_ci(
        confidence_level=confidence, method="wilson"
    )
    return (float(ci.low), float(ci.high))


#: per-leg fields of a trial record that say what the leg did (no clocks)
_FINGERPRINT_LEG_KEYS = (
    "leg",
    "status",
    "path_points",
    "path_sha256",
    "iterations",
    "collision_checks",
    "fk_calls",
    "local_minima",
    "escapes",
    "pos_err_m",
    "angle_err_deg",
)


def trial_fingerprint(rec: Mapping[str, Any]) -> str:
    """What a trial did, as a string: two trials with the same fingerprint are the same
    trial (seeds that changed nothing). Its status and error, every leg's
    :data:`_FINGERPRINT_LEG_KEYS` and the execution's verdict; clocks are left out."""
    ex = rec.get("execution") or {}
    return dumps(
        {
            "status": rec.get("status"),
            "error": rec.get("error"),
            "legs": [
                {k: leg.get(k) for k in _FINGERPRINT_LEG_KEYS} for leg in rec.get("legs_run") or []
            ],
            "execution": {k: ex.get(k) for k in ("success", "max_track_err_rad", "contacts")},
        }
    )


def _vals(xs: Iterable[Any]) -> np.ndarray:
    return np.array([float(x) for x in xs if x is not None and math.isfinite(float(x))])


def _pct(xs: np.ndarray, q: float) -> float:
    return float(np.percentile(xs, q)) if xs.size else math.nan


#: the columns of a summary row, in order
SUMMARY_COLUMNS = (
    "problem",
    "planner",
    "n",
    "successes",
    "errors",
    "success_rate",
    "ci95_low",
    "ci95_high",
    "deterministic",
    "distinct_trials",
    "time_median_s",
    "time_p75_s",
    "time_p95_s",
    "path_length_median",
    "pos_err_median_m",
    "angle_err_median_deg",
    "checks_median",
    "iterations_median",
    "local_minima",
    "escapes",
    "executed",
    "exec_successes",
    "exec_success_rate",
    "exec_track_err_median_rad",
    "exec_deviation_median_m",
    "exec_clearance_min_m",
    "exec_contacts",
)


def summarise(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One row per (problem, planner), in order of first appearance; keys
    :data:`SUMMARY_COLUMNS` (NaN where there is nothing to measure)."""
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for r in records:
        groups.setdefault((str(r["problem"]), str(r["planner"])), []).append(r)
    rows = []
    for (problem, planner), recs in groups.items():
        n = len(recs)
        ok = [r for r in recs if r.get("success")]
        ran = [r for r in recs if r.get("status") not in (ERROR_STATUS, TIMEOUT_STATUS)]
        distinct = len({trial_fingerprint(r) for r in recs})
        deterministic = n >= 2 and distinct == 1
        # the seeds of a deterministic row are one trial: no interval over copies of it
        lo, hi = (math.nan, math.nan) if deterministic else wilson_interval(len(ok), n)
        t = _vals(r["totals"].get("time_s") for r in ran)
        ex = [r["execution"] for r in recs if r.get("execution")]
        rows.append(
            {
                "problem": problem,
                "planner": planner,
                "n": n,
                "successes": len(ok),
                "errors": n - len(ran),
                "success_rate": len(ok) / n if n else math.nan,
                "ci95_low": lo,
                "ci95_high": hi,
                "deterministic": deterministic,
                "distinct_trials": distinct,
                "time_median_s": _pct(t, 50),
                "time_p75_s": _pct(t, 75),
                "time_p95_s": _pct(t, 95),
                "path_length_median": _pct(_vals(r["totals"].get("path_length") for r in ok), 50),
                "pos_err_median_m": _pct(_vals(r.get("final_pos_err_m") for r in ran), 50),
                "angle_err_median_deg": _pct(_vals(r.get("final_angle_err_deg") for r in ran), 50),
                "checks_median": _pct(_vals(r["totals"].get("collision_checks") for r in ran), 50),
                "iterations_median": _pct(_vals(r["totals"].get("iterations") for r in ran), 50),
                "local_minima": int(sum(r["totals"].get("local_minima") or 0 for r in ran)),
                "escapes": int(sum(r["totals"].get("escapes") or 0 for r in ran)),
                "executed": len(ex),
                "exec_successes": sum(1 for e in ex if e.get("success")),
                "exec_success_rate": (
                    sum(1 for e in ex if e.get("success")) / len(ex) if ex else math.nan
                ),
                "exec_track_err_median_rad": _pct(
                    _vals(e.get("max_track_err_rad") for e in ex), 50
                ),
                "exec_deviation_median_m": _pct(_vals(e.get("max_deviation_m") for e in ex), 50),
                "exec_clearance_min_m": _pct(_vals(e.get("min_clearance_m") for e in ex), 0),
                "exec_contacts": int(sum(e.get("contacts") or 0 for e in ex)),
            }
        )
    return rows


__all__ = [
    "BACKENDS",
    "ERROR_STATUS",
    "TIMEOUT_STATUS",
    "SUMMARY_COLUMNS",
    "ComparisonRun",
    "Trial",
    "compare",
    "TrialStore",
    "default_name",
    "default_trial_timeout_s",
    "make_backend",
    "parse_seeds",
    "run_comparison",
    "run_trial",
    "store_path",
    "summarise",
    "trial_fingerprint",
    "wilson_interval",
]

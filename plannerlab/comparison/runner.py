"""Grids of trials (problems × planners × seeds), each trial in its own process.

A :class:`~plannerlab.comparison.trial.Trial` is (problem, planner, seed, budget
overrides, settings overrides, legs, execute). :func:`~plannerlab.comparison.trial.
run_trial` runs one and returns a JSON-able record; it is meant to run in a *fresh*
process, because OMPL's random generator is process-global and its seed only takes effect
before OMPL's first generator exists (see :mod:`plannerlab.planners.ompl`). A
:class:`~plannerlab.comparison.spec.ComparisonSpec` is a whole grid, checked before the
first process starts; :func:`compare` runs one (``plannerlab compare`` and
``plannerlab.compare`` alike). :func:`run_comparison` runs many trials, ``jobs`` at a
time, one spawned process per trial, and appends every finished record to a
:class:`~plannerlab.comparison.store.TrialStore` (JSON lines, flushed and fsynced line by
line), so that rerunning the same comparison skips the trials already finished
and an interrupted run loses only the trials that were still running.
:func:`~plannerlab.comparison.statistics.summarise` turns records into one row per
(problem, planner).

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
* **Seeding.** numpy generators come from :func:`plannerlab.run.pipeline.leg_rng`. The
  child calls ``seed_ompl(seed)`` before anything else whenever
  :mod:`plannerlab.planners.ompl` imports; every OMPL solve then reseeds OMPL from its
  leg's generator before it builds any OMPL object, and every leg records that seed,
  the one in effect (``extra["ompl_seed"]``; see :mod:`plannerlab.planners.ompl`).
* **Trial key.** ``problem/planner/s<seed>/<hash>`` where the hash (sha256, 10 hex) covers
  the budget and settings overrides, the legs and the execute flag, so one store can hold
  runs of the same grid under different budgets without mixing them.
* **Errors.** A trial that raises is recorded with status ``error`` and the exception's
  last line (never kills the run); it and a ``timeout`` are "finished" for resuming
  unless ``retry_errors``. A trial that ``died`` is never finished: its record says why
  (in the store, and in this run's records), and the next run tries it again.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from plannerlab.comparison.spec import BACKENDS, ComparisonSpec
from plannerlab.comparison.store import TrialStore
from plannerlab.comparison.trial import (
    DIED_STATUS,
    ERROR_STATUS,
    TIMEOUT_STATUS,
    Scalar,
    Trial,
    error_record,
    run_trial,
)
from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import TrialRecord

LOGGER = logging.getLogger(__name__)


# ---------------------------------------------------------------------- comparisons
@dataclass
class ComparisonRun:
    """What :func:`run_comparison` did.

    Attributes:
        records: one record per requested trial that is finished (in the trials' order).
        ran: trials run by this call; skipped: trials already in the store.
        missing: trials without a record (only after an interruption).
    """

    records: list[TrialRecord]
    ran: int
    skipped: int
    missing: list[Trial] = field(default_factory=list)


def _timeout_record(trial: Trial, limit_s: float, elapsed_s: float) -> TrialRecord:
    return error_record(
        trial,
        f"killed after {elapsed_s:.1f} s: past the per-trial limit of {limit_s:g} s",
        TIMEOUT_STATUS,
        wall_s=elapsed_s,
    )


def _died_record(trial: Trial, why: dict[str, Any], elapsed_s: float) -> TrialRecord:
    """A trial whose process ended without reporting: why, from the backend."""
    fields = dict(why)
    error = str(fields.pop("error", "") or "trial process died before reporting a result")
    return error_record(trial, error, DIED_STATUS, wall_s=elapsed_s, **fields)


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
    on_done: Callable[[TrialRecord, bool], None] | None = None,
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
            ``timeout`` (a trial that ``died`` is always run again).
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
    results: dict[str, TrialRecord] = {}
    todo: list[Trial] = []
    retry = (DIED_STATUS, ERROR_STATUS, TIMEOUT_STATUS) if retry_errors else (DIED_STATUS,)
    for key, t in unique.items():
        rec = stored.get(key)
        if rec is not None and rec.status not in retry:
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

            def finish(rec: TrialRecord) -> None:
                nonlocal ran
                append(rec)
                results[rec.key] = rec
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
                        trial, started, _limit = running.pop(handle)
                        elapsed = time.monotonic() - started
                        finish(rec if rec is not None else _died_record(trial, why, elapsed))
                    now = time.monotonic()
                    for handle, (trial, started, limit) in list(running.items()):
                        if limit is not None and now - started > limit:
                            backend.kill(handle)
                            del running[handle]
                            finish(_timeout_record(trial, limit, now - started))
            except KeyboardInterrupt:
                for rec in backend.salvage():  # sent but not yet read
                    if rec.key in unique and rec.key not in results:
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


def run_spec(
    spec: ComparisonSpec,
    store: TrialStore | str | Path,
    on_done: Callable[[TrialRecord, bool], None] | None = None,
) -> ComparisonRun:
    """Run a checked specification's trials on its backend, resuming from ``store``.

    Args:
        spec: the comparison (:meth:`ComparisonSpec.build`).
        store: the trial store (JSON lines) to append to and resume from.
        on_done: see :func:`run_comparison`.
    """
    store = store if isinstance(store, TrialStore) else TrialStore(store)
    backend = make_backend(spec.backend, store.path.parent / ".running", address=spec.address)
    try:
        return run_comparison(
            spec.trials,
            store,
            jobs=spec.jobs,
            on_done=on_done,
            retry_errors=spec.retry_errors,
            trial_timeout_s=spec.trial_timeout,
            backend=backend,
        )
    finally:
        backend.close()


def compare(
    problems: Sequence[str | Path],
    planners: Sequence[str],
    seeds: Iterable[int],
    store: TrialStore | str | Path,
    *,
    budget: Mapping[str, Scalar] | None = None,
    settings: Mapping[str, Mapping[str, Scalar]] | None = None,
    legs: str | None = None,
    execute: bool = False,
    jobs: int = 1,
    backend: str = "local",
    address: str | None = None,
    trial_timeout_s: float | None = None,
    retry_errors: bool = False,
    on_done: Callable[[TrialRecord, bool], None] | None = None,
) -> ComparisonRun:
    """Every planner on every problem with every seed, each trial in its own process,
    resumable from ``store``: what ``plannerlab compare`` runs, with the same checks
    (:meth:`ComparisonSpec.build`: the arguments are described there).

    Raises:
        PlannerlabError: a bad argument, before any trial starts.
    """
    spec = ComparisonSpec.build(
        problems,
        planners,
        seeds,
        budget=budget,
        settings=settings,
        legs=legs,
        execute=execute,
        jobs=jobs,
        backend=backend,
        address=address,
        trial_timeout_s=trial_timeout_s,
        retry_errors=retry_errors,
    )
    return run_spec(spec, store, on_done)


__all__ = ["ComparisonRun", "compare", "make_backend", "run_comparison", "run_spec"]

"""A comparison's OMPL benchmark log: one *experiment* per problem, planners as OMPL
planners, trials as runs (:func:`ompl_log`, written by
:func:`plannerlab.comparison.report.write_reports`).

The log follows "The benchmark logfile format" of OMPL's documentation
(``doc/markdown/benchmark.md``) as parsed by ``readBenchmarkLog`` in the ``ompl`` wheel
(``ompl/_benchmark_statistics.py``). What that parser requires, and this module keeps to:

* the experiment name is the last whitespace-separated token of its line (problem names
  have no spaces; spaces are replaced);
* run properties are ``name TYPE`` lines (the name may hold spaces: they become ``_`` in
  the SQL column, so ``collision checks INTEGER`` is column ``collision_checks``); types
  are REAL, INTEGER, BOOLEAN (``0``/``1``) or ENUM (an index into the ``status`` enum,
  declared in the preamble as ``status|solved|approximate|...``);
* every run line is ``value; `` repeated, the last one included; an empty value, ``nan``
  or ``inf`` becomes NULL;
* ``runs per planner`` is written only when every planner has the same number of runs
  (it is optional); the time limit is ``inf`` when there is none, the memory limit 0.

Run properties: ``seed``, ``time`` (planning time summed over legs [s]), ``solved``
(every leg SOLVED), ``status`` (the first unsolved leg's status, or ``error``),
``approximate solution``, ``legs solved``, ``iterations``, ``collision checks``,
``fk calls``, ``solution length`` (joint-space path length [rad], solved trials only),
``path length`` (every trial), ``final position error`` [m], ``final angle error``
[deg], ``local minima``, ``escapes``, ``wall time`` (the trial's process [s]) and, for
executed comparisons, ``execution success``, ``execution max tracking error`` [rad],
``execution contacts``, ``execution max deviation`` [m] and ``execution min clearance``
[m] (empty otherwise), then ``smoothness`` (the roughness summed over legs [rad²]) and
``path clearance`` (the smallest clearance along the whole path [m]), solved trials only.
The ``status`` enum ends with ``timeout`` and ``died``.

Progress properties (OMPL's ``N progress properties`` block after the runs, one line of
``v1,v2,…,;`` samples per run; Planner Arena's "Progress" tab plots them): ``time`` [s],
``best goal distance`` (normalised, 0 inside the goal region), ``best cost`` (joint-space
length of the best solution [rad], empty until one), ``collision checks`` and ``leg``,
from each leg's :attr:`~plannerlab.planners.base.PlanResult.progress`; legs follow one
another, times and checks counted from the trial's start. An escape from a local minimum
shows as a drop of the best goal distance.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from plannerlab.comparison.meta import ReportMeta
from plannerlab.problem.load import Budget
from plannerlab.record.leg import Status
from plannerlab.record.trial import DIED_STATUS, ERROR_STATUS, TIMEOUT_STATUS, TrialRecord

#: values of the ``status ENUM`` run property (index = stored value): the planner statuses
#: in :class:`Status` order, with ``error`` (the trial raised) at index 8, where it stood
#: before statuses were added to :class:`Status`; those follow it, so that a stored index
#: keeps its meaning
_STATUSES = [s.value for s in Status]
STATUS_ENUM: tuple[str, ...] = (
    *_STATUSES[:8],
    ERROR_STATUS,
    *_STATUSES[8:],
    TIMEOUT_STATUS,
    DIED_STATUS,
)


_RUN_PROPERTIES: tuple[tuple[str, str], ...] = (
    ("seed", "INTEGER"),
    ("time", "REAL"),
    ("solved", "BOOLEAN"),
    ("status", "ENUM"),
    ("approximate solution", "BOOLEAN"),
    ("legs solved", "INTEGER"),
    ("iterations", "INTEGER"),
    ("collision checks", "INTEGER"),
    ("fk calls", "INTEGER"),
    ("solution length", "REAL"),
    ("path length", "REAL"),
    ("final position error", "REAL"),
    ("final angle error", "REAL"),
    ("local minima", "INTEGER"),
    ("escapes", "INTEGER"),
    ("wall time", "REAL"),
    ("execution success", "BOOLEAN"),
    ("execution max tracking error", "REAL"),
    ("execution contacts", "INTEGER"),
    ("execution max deviation", "REAL"),
    ("execution min clearance", "REAL"),
    ("smoothness", "REAL"),
    ("path clearance", "REAL"),
)


#: progress properties of a run: its legs one after another, times and checks counted
#: from the trial's start; the best goal distance is the current leg's
_PROGRESS_PROPERTIES: tuple[tuple[str, str], ...] = (
    ("time", "REAL"),
    ("best goal distance", "REAL"),
    ("best cost", "REAL"),
    ("collision checks", "INTEGER"),
    ("leg", "INTEGER"),
)


def _run_progress(r: TrialRecord) -> list[list[Any]]:
    """A trial's progress rows (see :data:`_PROGRESS_PROPERTIES`), times strictly
    increasing (OMPL's table keys progress on (run, time))."""
    rows: list[list[Any]] = []
    t_off = 0.0
    c_off = 0
    for leg in r.legs_run:
        for t, checks, dist, cost in leg.progress:
            if t is None:
                continue
            time_s = t_off + float(t)
            c = None if checks is None else c_off + int(checks)
            row = [time_s, dist, cost, c, leg.leg]
            if rows and time_s <= rows[-1][0]:
                rows[-1] = [rows[-1][0], *row[1:]]  # same instant: the later values
            else:
                rows.append(row)
        t_off += leg.time_s
        c_off += leg.collision_checks
    return rows


def _log_value(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    return str(v)


def _run_values(r: TrialRecord) -> list[str]:
    status = r.status
    ok = r.success
    last = r.last_leg if ok else None
    values: list[Any] = [
        r.seed,
        r.time_s if r.ran else None,
        ok,
        STATUS_ENUM.index(status) if status in STATUS_ENUM else STATUS_ENUM.index("failed"),
        status == "approximate",
        r.legs_solved,
        r.iterations,
        r.collision_checks,
        r.fk_calls,
        r.path_length if ok else None,
        r.path_length,
        last.pos_err_m if last else None,
        last.angle_err_deg if last else None,
        r.local_minima,
        r.escapes,
        r.wall_s,
        r.exec_success,
        r.exec_max_track_err_rad,
        r.exec_contacts,
        r.exec_max_deviation_m,
        r.exec_min_clearance_m,
        r.roughness_rad2 if ok else None,
        r.path_clearance_m if ok else None,
    ]
    return [_log_value(v) for v in values]


def _one_line(s: str) -> str:
    return " ".join(str(s).split())


#: the machine's line in an OMPL log, from :func:`machine_info`'s fields
_MACHINE_LINE = "{cpu_model}, {cpu_count} CPUs, {memory_gb} GB, {platform}"
_MACHINE_UNKNOWN = {"cpu_model": "unknown", "cpu_count": "?", "memory_gb": "?", "platform": ""}


def ompl_log(
    problem: str, records: Sequence[TrialRecord], meta: Mapping[str, Any] | ReportMeta
) -> str:
    """One OMPL benchmark log (one experiment) for the records of ``problem``."""
    m = ReportMeta.of(meta)
    recs = [r for r in records if r.problem == problem]
    planners = list(dict.fromkeys(r.planner for r in recs))
    by_planner = {p: [r for r in recs if r.planner == p] for p in planners}
    budget = m.budgets_used.get(problem, Budget())
    exp_props = [
        ("max_iterations", "INTEGER", budget.max_iterations),
        ("max_collision_checks", "INTEGER", budget.max_collision_checks),
        ("time_limit_s", "REAL", budget.time_limit_s),
        ("executed", "BOOLEAN", m.execute),
    ]
    exp_props = [(n, t, v) for n, t, v in exp_props if v is not None]
    time_limit = budget.time_limit_s
    seeds = sorted({r.seed for r in recs})
    machine = {**_MACHINE_UNKNOWN, "hostname": "unknown"} | dict(m.machine)
    host = "{hostname}".format_map(machine)
    version = "{plannerlab}".format_map({"plannerlab": "0", **m.versions})
    lines = [
        f"plannerlab version {version}",
        f"Experiment {'_'.join(problem.split()) or 'problem'}",
        f"{len(exp_props)} experiment properties",
        *[f"{n} {t} = {_log_value(v)}" for n, t, v in exp_props],
        f"Running on {'_'.join(host.split())}",
        f"Starting at {m.started_at.replace('T', ' ')}",
        "<<<|",
        f"command: {_one_line(m.command)}",
        f"problem file: {recs[0].problem_file if recs else ''}",
        f"seeds: {m.seeds_spec} (each run's seed is its 'seed' property)",
        f"budget: {json.dumps(budget.to_dict(), sort_keys=True)}",
        f"legs: {m.legs or 'all'}",
        "versions: " + ", ".join(f"{k} {v}" for k, v in m.versions.items()),
        "|>>>",
        "<<<|",
        _MACHINE_LINE.format_map(machine),
        "|>>>",
        f"{seeds[0] if seeds else 0} is the random seed",
        f"{float(time_limit) if time_limit is not None else math.inf!r} seconds per run",
        "0 MB per run",
    ]
    counts = {len(v) for v in by_planner.values()}
    if len(counts) == 1:
        lines.append(f"{counts.pop()} runs per planner")
    total = float(sum(r.wall_s or 0.0 for r in recs))
    lines += [
        f"{total!r} seconds spent to collect the data",
        "1 enum type",
        "status|" + "|".join(STATUS_ENUM),
        f"{len(planners)} planners",
    ]
    for p in planners:
        runs = by_planner[p]
        settings: dict[str, Any] = next((r.settings_used for r in runs if r.settings_used), {})
        common = [f"{k} = {_one_line(json.dumps(v))}" for k, v in sorted(settings.items())]
        lines += [p, f"{len(common)} common properties", *common]
        lines.append(f"{len(_RUN_PROPERTIES)} properties for each run")
        lines += [f"{n} {t}" for n, t in _RUN_PROPERTIES]
        lines.append(f"{len(runs)} runs")
        lines += ["".join(f"{v}; " for v in _run_values(r)) for r in runs]
        lines.append(f"{len(_PROGRESS_PROPERTIES)} progress properties")
        lines += [f"{n} {t}" for n, t in _PROGRESS_PROPERTIES]
        lines.append(f"{len(runs)} runs")
        lines += [
            "".join("".join(f"{_log_value(v)}," for v in row) + ";" for row in _run_progress(r))
            for r in runs
        ]
        lines.append(".")
    return "\n".join(lines) + "\n"


def log_paths(folder: str | Path, name: str, problems: Sequence[str]) -> dict[str, Path]:
    """Where each problem's OMPL log goes: ``<name>.log`` for one problem, else
    ``<name>.<problem>.log``."""
    folder = Path(folder)
    if len(problems) == 1:
        return {problems[0]: folder / f"{name}.log"}
    return {p: folder / f"{name}.{p}.log" for p in problems}


__all__ = ["STATUS_ENUM", "log_paths", "ompl_log"]

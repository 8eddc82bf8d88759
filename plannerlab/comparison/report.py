"""Tables backed by files: a comparison's CSV, Markdown and OMPL benchmark log.

Everything here turns trial records (:func:`plannerlab.comparison.trial.run_trial`) and
summary rows (:func:`plannerlab.comparison.statistics.summarise`) into text, and
:func:`write_reports` writes them atomically (:func:`plannerlab.record.files.write_text_atomic`)
into the comparison's folder:

* ``trials.csv``: one row per trial; ``legs.csv``: one row per leg of every trial;
  ``summary.csv``: one row per (problem, planner), columns
  :data:`plannerlab.comparison.statistics.SUMMARY_COLUMNS`;
* ``report.md``: a table per problem, with the exact command, seeds, budget, settings,
  package versions and the machine;
* ``meta.json``: the same metadata as data;
* ``<name>.log`` (one problem) or ``<name>.<problem>.log`` (several): OMPL benchmark logs,
  one *experiment* per problem (OMPL's parser reads one experiment per file), planners as
  OMPL planners, trials as runs. ``ompl_benchmark_statistics *.log -d results.db`` loads
  them into SQLite (and Planner Arena reads that database).

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
executed comparisons, ``execution success``, ``execution max tracking error`` [rad] and
``execution contacts`` (empty otherwise).

Progress properties (OMPL's ``N progress properties`` block after the runs, one line of
``v1,v2,…,;`` samples per run; Planner Arena's "Progress" tab plots them): ``time`` [s],
``best goal distance`` (normalised, 0 inside the goal region), ``best cost`` (joint-space
length of the best solution [rad], empty until one), ``collision checks`` and ``leg``,
from each leg's :attr:`~plannerlab.planners.base.PlanResult.progress`; legs follow one
another, times and checks counted from the trial's start. An escape from a local minimum
shows as a drop of the best goal distance.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
import platform
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from plannerlab.comparison.statistics import SUMMARY_COLUMNS, SummaryRow
from plannerlab.problem.load import Budget
from plannerlab.record.cells import err_of_tol, fmt, mm, rough
from plannerlab.record.files import write_json_atomic, write_text_atomic
from plannerlab.record.leg import Status
from plannerlab.record.trial import (
    DIED_STATUS,
    ERROR_STATUS,
    TIMEOUT_STATUS,
    ExecutionRecord,
    LegRecord,
    TrialRecord,
)

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

TRIAL_COLUMNS = (
    "key",
    "problem",
    "planner",
    "seed",
    "status",
    "success",
    "error",
    "legs",
    "legs_solved",
    "time_s",
    "iterations",
    "collision_checks",
    "fk_calls",
    "path_length",
    "smoothness_rad2",
    "path_clearance_m",
    "final_pos_err_m",
    "final_pos_tol_m",
    "final_angle_err_deg",
    "final_angle_tol_deg",
    "local_minima",
    "escapes",
    "exec_success",
    "exec_path_valid",
    "exec_max_deviation_m",
    "exec_min_clearance_m",
    "exec_max_track_err_rad",
    "exec_contacts",
    "exec_final_pos_err_m",
    "exec_final_angle_err_deg",
    "wall_s",
    "exit_code",
    "signal",
    "budget",
    "settings",
)

LEG_COLUMNS = (
    "key",
    "problem",
    "planner",
    "seed",
    "leg",
    "goal",
    "status",
    "time_s",
    "iterations",
    "collision_checks",
    "fk_calls",
    "pos_err_m",
    "pos_tol_m",
    "angle_err_deg",
    "angle_tol_deg",
    "tip_state",
    "local_minima",
    "escapes",
    "path_length",
    "smoothness_rad2",
    "path_clearance_m",
    "path_points",
    "extra_lengths",
    "exec_success",
    "exec_path_valid",
    "exec_max_deviation_m",
    "exec_min_clearance_m",
    "exec_max_track_err_rad",
    "exec_contacts",
    "exec_final_pos_err_m",
    "exec_final_angle_err_deg",
    "reason",
    "exec_reason",
)


# ---------------------------------------------------------------------- metadata
@dataclass(frozen=True)
class ReportMeta:
    """What a report says about its comparison besides the records (``meta.json``).

    Build it with :meth:`of` from the mapping ``plannerlab compare`` writes (any subset of
    these keys; others are kept in ``meta.json`` and not read here).

    Attributes:
        name, command: the comparison's name and the command that reproduces it.
        problems, planners, seeds: what was compared; ``seeds_spec`` as given.
        budget: the budget overrides; ``budgets_used``: per problem, the budget its
            trials ran with (a :class:`~plannerlab.problem.load.Budget`).
        settings: per planner, the settings overrides; ``legs``: the legs asked for.
        execute, jobs: executed in PyBullet; trials run at once.
        trials, ran, skipped, errors: trials asked for, run now, reused from the store,
            and those that did not run to their end.
        started_at, wall_s, store: this invocation's start, wall time [s] and the store.
        versions, machine: package versions and the machine (:func:`machine_info`).
    """

    name: str = ""
    command: str = ""
    problems: tuple[str, ...] = ()
    planners: tuple[str, ...] = ()
    seeds: tuple[int, ...] = ()
    seeds_spec: str = ""
    budget: Mapping[str, Any] = field(default_factory=dict)
    budgets_used: Mapping[str, Budget] = field(default_factory=dict)
    settings: Mapping[str, Any] = field(default_factory=dict)
    legs: str | None = None
    execute: bool = False
    jobs: int | str = ""
    trials: int | None = None
    ran: int | str = "?"
    skipped: int | str = "?"
    errors: int = 0
    started_at: str = ""
    wall_s: float | None = None
    store: str = ""
    versions: Mapping[str, str] = field(default_factory=dict)
    machine: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def of(cls, meta: Mapping[str, Any] | ReportMeta) -> ReportMeta:
        """The metadata from a mapping (its keys among the fields)."""
        if isinstance(meta, ReportMeta):
            return meta
        known = {f.name for f in dataclasses.fields(cls)}
        values = {k: v for k, v in meta.items() if k in known and v is not None}
        for k in ("problems", "planners", "seeds"):
            if k in values:
                values[k] = tuple(values[k])
        budgets = values.pop("budgets_used", {})
        values["budgets_used"] = {
            p: b if isinstance(b, Budget) else Budget().replace(**b) for p, b in budgets.items()
        }
        return cls(**values)


# ---------------------------------------------------------------------- machine
def machine_info() -> dict[str, Any]:
    """Where the numbers were measured: host, OS, CPU model and count, memory."""
    info: dict[str, Any] = {
        "hostname": platform.node() or "unknown",
        "platform": platform.platform(),
        "machine": platform.machine(),
        "cpu_count": os.cpu_count(),
        "cpu_model": platform.processor() or "unknown",
    }
    try:
        info["cpu_affinity"] = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        pass
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                info["cpu_model"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                info["memory_gb"] = round(int(line.split()[1]) / 1024**2, 1)
                break
    except (OSError, ValueError, IndexError):
        pass
    return info


# ---------------------------------------------------------------------- CSV
def _cell(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if not math.isfinite(v) else repr(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, Mapping | list | tuple):
        return json.dumps(v, sort_keys=True, separators=(",", ":"))
    return v


def _csv(columns: Sequence[str], rows: Iterable[Mapping[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_cell(r.get(c)) for c in columns])
    return buf.getvalue()


def _exec_cells(e: ExecutionRecord | None, prefix: str = "exec_") -> dict[str, Any]:
    if e is None:
        return {}
    return {
        f"{prefix}success": e.success,
        f"{prefix}path_valid": e.path_valid,
        f"{prefix}max_deviation_m": e.max_deviation_m,
        f"{prefix}min_clearance_m": e.min_clearance_m,
        f"{prefix}max_track_err_rad": e.max_track_err_rad,
        f"{prefix}contacts": e.contact_count,
        f"{prefix}final_pos_err_m": e.final_pos_err_m,
        f"{prefix}final_angle_err_deg": e.final_angle_err_deg,
    }


def trial_rows(records: Iterable[TrialRecord]) -> list[dict[str, Any]]:
    """One flat row per trial (keys :data:`TRIAL_COLUMNS`). The final tip errors are
    those of a successful trial's last leg (a failed trial's last state is no result:
    its legs are in ``legs.csv``)."""
    rows = []
    for r in records:
        last = r.last_leg if r.success else None
        ex = r.exec_last
        rows.append(
            {
                "key": r.key,
                "problem": r.problem,
                "planner": r.planner,
                "seed": r.seed,
                "status": r.status,
                "success": r.success,
                "error": r.error,
                "legs": len(r.legs_run),
                "legs_solved": r.legs_solved,
                "time_s": r.time_s if r.ran else None,
                "iterations": r.iterations,
                "collision_checks": r.collision_checks,
                "fk_calls": r.fk_calls,
                "path_length": r.path_length,
                "smoothness_rad2": r.roughness_rad2,
                "path_clearance_m": r.path_clearance_m,
                "final_pos_err_m": last.pos_err_m if last else None,
                "final_pos_tol_m": last.pos_tol_m if last else None,
                "final_angle_err_deg": last.angle_err_deg if last else None,
                "final_angle_tol_deg": last.angle_tol_deg if last else None,
                "local_minima": r.local_minima,
                "escapes": r.escapes,
                **_exec_cells(ex),
                "exec_success": r.exec_success,
                "exec_path_valid": r.exec_path_valid,
                "exec_max_deviation_m": r.exec_max_deviation_m,
                "exec_min_clearance_m": r.exec_min_clearance_m,
                "exec_max_track_err_rad": r.exec_max_track_err_rad,
                "exec_contacts": r.exec_contacts,
                "wall_s": r.wall_s,
                "exit_code": r.exit_code,
                "signal": r.signal,
                "budget": r.budget_used or r.budget,
                "settings": r.settings,
            }
        )
    return rows


def _lengths(extra: Mapping[str, Any]) -> dict[str, Any]:
    """The path lengths a planner reports in ``extra`` (before/after simplification, …)."""
    return {
        str(k): v
        for k, v in extra.items()
        if "length" in str(k)
        and (v is None or (isinstance(v, int | float) and not isinstance(v, bool)))
    }


def tip_state(leg: LegRecord) -> str:
    """What a leg's tip errors describe: ``goal`` (a solved leg's last state),
    ``best reached`` (the state it ended at, as close as it got or stalled there), or
    ``none`` (it planned nothing or gave up: its errors are blank)."""
    if leg.solved:
        return "goal"
    return "best reached" if leg.reached_best else "none"


def leg_rows(records: Iterable[TrialRecord]) -> list[dict[str, Any]]:
    """One flat row per leg of every trial (keys :data:`LEG_COLUMNS`). A leg that has no
    best state (:func:`tip_state` ``none``) has blank tip errors: its reason says why."""
    rows = []
    for r in records:
        executed = {e.leg: e for e in r.executions or ()}
        for x in r.legs_run:
            e = executed.get(x.leg)
            has_tip = x.reached_best
            rows.append(
                {
                    "key": r.key,
                    "problem": r.problem,
                    "planner": r.planner,
                    "seed": r.seed,
                    "leg": x.leg,
                    "goal": x.goal,
                    "status": x.status.value,
                    "time_s": x.time_s,
                    "iterations": x.iterations,
                    "collision_checks": x.collision_checks,
                    "fk_calls": x.fk_calls,
                    "pos_err_m": x.pos_err_m if has_tip else None,
                    "pos_tol_m": x.pos_tol_m,
                    "angle_err_deg": x.angle_err_deg if has_tip else None,
                    "angle_tol_deg": x.angle_tol_deg,
                    "tip_state": tip_state(x),
                    "local_minima": x.local_minima,
                    "escapes": x.escapes,
                    "path_length": x.path_length,
                    "smoothness_rad2": x.roughness_rad2,
                    "path_clearance_m": x.path_clearance_m,
                    "path_points": x.path_points,
                    "extra_lengths": _lengths(x.extra),
                    **_exec_cells(e),
                    "reason": x.reason,
                    "exec_reason": e.reason if e else None,
                }
            )
    return rows


def trials_csv(records: Iterable[TrialRecord]) -> str:
    return _csv(TRIAL_COLUMNS, trial_rows(records))


def legs_csv(records: Iterable[TrialRecord]) -> str:
    return _csv(LEG_COLUMNS, leg_rows(records))


def summary_csv(rows: Iterable[SummaryRow]) -> str:
    return _csv(SUMMARY_COLUMNS, (r.to_dict() for r in rows))


# ---------------------------------------------------------------------- Markdown
def summary_cells(row: SummaryRow, executed: bool) -> list[str]:
    """The cells of one planner's line in a per-problem table (see :data:`TABLE_HEADERS`)."""
    cells = [
        row.planner,
        f"{row.successes}/{row.n}" + (f" ({row.errors} err)" if row.errors else ""),
        (
            f"{fmt(100 * row.success_rate, 3)}% [deterministic: {row.n} seeds, one trial]"
            if row.deterministic
            else f"{fmt(100 * row.success_rate, 3)}% [{fmt(100 * row.ci95_low, 3)}, "
            f"{fmt(100 * row.ci95_high, 3)}]"
        ),
        f"{fmt(row.time_median_s)} / {fmt(row.time_p75_s)} / {fmt(row.time_p95_s)}",
        fmt(row.path_length_median),
        rough(row.smoothness_median_rad2),
        fmt(mm(row.path_clearance_min_m)),
        err_of_tol(row.pos_err_median_m, row.pos_tol_m),
        err_of_tol(row.angle_err_median_deg, row.angle_tol_deg),
        fmt(row.checks_median),
        f"{row.local_minima} / {row.escapes}",
    ]
    if executed:
        rate = row.exec_success_rate
        cells += [
            f"{row.exec_successes}/{row.executed}"
            + (f" ({fmt(100 * rate)}%)" if row.executed else ""),
            fmt(mm(row.exec_deviation_median_m)),
            fmt(mm(row.exec_clearance_min_m)),
            fmt(row.exec_track_err_median_rad),
        ]
    return cells


TABLE_HEADERS = (
    "planner",
    "solved",
    "success % [95% CI]",
    "time s med / p75 / p95",
    "path len rad",
    "smoothness rad²",
    "path clearance mm",
    "pos err / tol m",
    "ang err / tol °",
    "checks",
    "minima met / escaped",
)
EXEC_HEADERS = ("PyBullet ok", "deviation mm", "clearance mm", "track err rad")

TABLE_NOTES = (
    "solved: trials whose every leg is SOLVED (an `error` trial counts as a failure); "
    "95% CI: Wilson score interval; deterministic: every seed gave the identical trial "
    "(same statuses, path hashes, counts, tip errors and execution verdict), so the seeds "
    "are one run and no interval is given. time: planning time summed over legs, over trials "
    "that ran (median / 75th / 95th percentile). path len: joint-space length summed "
    "over legs, median over solved trials; smoothness: the paths' roughness (squared "
    "turning angles of each leg's path resampled at 200 states of equal joint-space arc "
    "length, summed over legs; lower is smoother), median over solved trials; path "
    "clearance: the smallest clearance along the whole planned paths (every state of the "
    "final re-check's grid, true geometry, scene and links) over solved trials. pos/ang "
    "err / tol: the last leg's final tip error, median over solved trials, beside that "
    "leg's goal tolerance (a failed trial's last state is no result; see legs.csv). "
    "checks: collision checks per trial, median. "
    "minima met / escaped: totals over trials. PyBullet ok: of the trials whose plan "
    "solved (only those are executed, solved legs up to the first failure), executions "
    "with a valid FCL re-check, no contact, simulated clearance >= 0, deviation within "
    "the problem's max_deviation_m and the goal reached; deviation: median over executed "
    "trials of the largest deviation of any point of the robot's collision geometry from "
    "the commanded state; clearance: the smallest simulated clearance (PyBullet's closest "
    "points, scene and links) over executed trials; track err: median over executed "
    "trials of the largest joint tracking error (informational)."
)

#: how far a planner may go past its budget, said under every comparison table
BUDGET_NOTE = (
    "Budgets: a planner stops within its iteration, collision-check and time limits; the "
    "final fine re-check of a found path may add at most 1 % to the checks and to the time "
    "(a path whose re-check does not fit is budget_exhausted, not trusted); a time limit is "
    "looked at once per planner loop, so a trial may end one loop late; a trial running "
    "past --trial-timeout is killed and recorded as timeout."
)


def _md_table(headers: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    def esc(s: str) -> str:
        return str(s).replace("|", "\\|").replace("\n", " ")

    lines = [
        "| " + " | ".join(esc(h) for h in headers) + " |",
        "|" + "|".join("---" for _ in headers) + "|",
    ]
    lines += ["| " + " | ".join(esc(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def _finished_span(records: Sequence[TrialRecord]) -> str:
    times = sorted(r.finished_at for r in records if r.finished_at)
    return f"{times[0]} to {times[-1]}" if times else "-"


def markdown(
    rows: Sequence[SummaryRow],
    records: Sequence[TrialRecord],
    meta: Mapping[str, Any] | ReportMeta,
) -> str:
    """The report: a table per problem, the command, seeds, budget, versions, machine."""
    m = ReportMeta.of(meta)
    out = [f"# Comparison `{m.name}`", ""]
    out += ["Command:", "", "```", m.command, "```", ""]
    problems = list(dict.fromkeys(r.problem for r in rows))
    headers = TABLE_HEADERS + (EXEC_HEADERS if m.execute else ())
    for p in problems:
        out += [f"## {p}", ""]
        out.append(
            _md_table(headers, [summary_cells(r, m.execute) for r in rows if r.problem == p])
        )
        out.append("")
    out += [TABLE_NOTES, "", BUDGET_NOTE, ""]
    errors = [r for r in records if not r.ran]
    if errors:
        out += ["## Errors", ""]
        out += [f"- `{r.key}` ({r.status}): {r.error}" for r in errors]
        out.append("")
    out += ["## Set-up", ""]
    used = {p: b.to_dict() for p, b in m.budgets_used.items()}
    setup = [
        ("problems", ", ".join(m.problems)),
        ("planners", ", ".join(m.planners)),
        ("seeds", m.seeds_spec),
        ("budget overrides", json.dumps(dict(m.budget))),
        ("budgets used", json.dumps(used)),
        ("settings overrides", json.dumps(dict(m.settings))),
        ("legs", m.legs or "all"),
        ("executed in PyBullet", "yes" if m.execute else "no"),
        (
            "trials",
            f"{len(records)} finished of {m.trials if m.trials is not None else len(records)} "
            f"(ran {m.ran}, reused {m.skipped})",
        ),
        ("jobs", m.jobs),
        ("trials finished", _finished_span(records)),
        ("trial processes, total s", fmt(sum(r.wall_s or 0.0 for r in records))),
        ("this invocation started", m.started_at),
        ("this invocation's wall time s", fmt(m.wall_s)),
        ("trial store", m.store),
    ]
    out.append(_md_table(("item", "value"), [(k, str(v)) for k, v in setup]))
    out += ["", "## Versions", ""]
    seen = {json.dumps(r.versions, sort_keys=True) for r in records if r.versions}
    if len(seen) > 1:
        out += [
            f"**The trials ran under {len(seen)} different sets of versions** (the store "
            "holds each trial's own `versions`); below: this invocation's.",
            "",
        ]
    out.append(_md_table(("package", "version"), [(k, str(v)) for k, v in m.versions.items()]))
    out += ["", "## Machine", ""]
    out.append(_md_table(("item", "value"), [(k, str(v)) for k, v in m.machine.items()]))
    out.append("")
    return "\n".join(out)


# ---------------------------------------------------------------------- OMPL log
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


# ---------------------------------------------------------------------- writing
def write_reports(
    folder: str | Path,
    name: str,
    records: Sequence[TrialRecord],
    rows: Sequence[SummaryRow],
    meta: Mapping[str, Any],
) -> list[Path]:
    """Write CSVs, Markdown, metadata and OMPL logs atomically into ``folder``.

    Returns:
        the files written, in that order.
    """
    folder = Path(folder)
    meta = {"name": name, **meta}
    files = [
        write_text_atomic(folder / "summary.csv", summary_csv(rows)),
        write_text_atomic(folder / "trials.csv", trials_csv(records)),
        write_text_atomic(folder / "legs.csv", legs_csv(records)),
        write_text_atomic(folder / "report.md", markdown(rows, records, meta)),
        write_json_atomic(folder / "meta.json", meta),
    ]
    problems = list(dict.fromkeys(r.problem for r in records))
    for problem, path in log_paths(folder, name, problems).items():
        files.append(write_text_atomic(path, ompl_log(problem, records, meta)))
    return files


__all__ = [
    "EXEC_HEADERS",
    "ReportMeta",
    "LEG_COLUMNS",
    "STATUS_ENUM",
    "TABLE_HEADERS",
    "TABLE_NOTES",
    "TRIAL_COLUMNS",
    "fmt",
    "mm",
    "leg_rows",
    "legs_csv",
    "log_paths",
    "machine_info",
    "markdown",
    "ompl_log",
    "summary_cells",
    "summary_csv",
    "tip_state",
    "trial_rows",
    "trials_csv",
    "write_reports",
]

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

The OMPL log is :mod:`plannerlab.comparison.ompl_log`; the metadata a report is given,
:class:`~plannerlab.comparison.meta.ReportMeta`.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from plannerlab.comparison.meta import ReportMeta, machine_info
from plannerlab.comparison.ompl_log import STATUS_ENUM, log_paths, ompl_log
from plannerlab.comparison.statistics import SUMMARY_COLUMNS, SummaryRow
from plannerlab.record.cells import err_of_tol, fmt, mm, rough
from plannerlab.record.files import write_json_atomic, write_text_atomic
from plannerlab.record.trial import ExecutionRecord, LegRecord, TrialRecord

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

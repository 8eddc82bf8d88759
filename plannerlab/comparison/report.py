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
import io
import json
import math
import os
import platform
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from plannerlab.comparison.statistics import SUMMARY_COLUMNS
from plannerlab.comparison.trial import ERROR_STATUS, TOTAL_KEYS
from plannerlab.record.cells import fmt, mm
from plannerlab.record.files import write_json_atomic, write_text_atomic
from plannerlab.record.leg import Status

#: values of the ``status ENUM`` run property (index = stored value): the planner statuses
#: in :class:`Status` order, with ``error`` (the trial raised) at index 8, where it stood
#: before statuses were added to :class:`Status`; those follow it, so that a stored index
#: keeps its meaning
_STATUSES = [s.value for s in Status]
STATUS_ENUM: tuple[str, ...] = (*_STATUSES[:8], ERROR_STATUS, *_STATUSES[8:])

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
    "final_pos_err_m",
    "final_angle_err_deg",
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
    "angle_err_deg",
    "local_minima",
    "escapes",
    "path_length",
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


def _exec_legs(rec: Mapping[str, Any]) -> dict[int, Mapping[str, Any]]:
    ex = rec.get("execution") or {}
    return {int(e["leg"]): e for e in ex.get("legs", []) if e.get("leg") is not None}


def trial_rows(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One flat row per trial (keys :data:`TRIAL_COLUMNS`)."""
    rows = []
    for r in records:
        tot = r.get("totals") or {}
        ex = r.get("execution") or {}
        legs = r.get("legs_run") or []
        rows.append(
            {
                "key": r["key"],
                "problem": r["problem"],
                "planner": r["planner"],
                "seed": r["seed"],
                "status": r.get("status"),
                "success": bool(r.get("success")),
                "error": r.get("error"),
                "legs": len(legs),
                "legs_solved": sum(1 for x in legs if x["status"] == "solved"),
                **{k: tot.get(k) for k in TOTAL_KEYS},
                "final_pos_err_m": r.get("final_pos_err_m"),
                "final_angle_err_deg": r.get("final_angle_err_deg"),
                "exec_success": ex.get("success"),
                "exec_path_valid": ex.get("path_valid"),
                "exec_max_deviation_m": ex.get("max_deviation_m"),
                "exec_min_clearance_m": ex.get("min_clearance_m"),
                "exec_max_track_err_rad": ex.get("max_track_err_rad"),
                "exec_contacts": ex.get("contacts"),
                "exec_final_pos_err_m": ex.get("final_pos_err_m"),
                "exec_final_angle_err_deg": ex.get("final_angle_err_deg"),
                "wall_s": r.get("wall_s"),
                "budget": r.get("budget_used") or r.get("budget"),
                "settings": r.get("settings"),
            }
        )
    return rows


def _n_contacts(contacts: Any) -> int | None:
    """Contacts of an executed leg: its list of contact records (a count in stores written
    before the trial legs were Execution records)."""
    return len(contacts) if isinstance(contacts, list) else contacts


def _lengths(extra: Mapping[str, Any]) -> dict[str, Any]:
    """The path lengths a planner reports in ``extra`` (before/after simplification, …)."""
    return {
        str(k): v
        for k, v in extra.items()
        if "length" in str(k)
        and (v is None or (isinstance(v, int | float) and not isinstance(v, bool)))
    }


def leg_rows(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One flat row per leg of every trial (keys :data:`LEG_COLUMNS`)."""
    rows = []
    for r in records:
        exl = _exec_legs(r)
        for x in r.get("legs_run") or []:
            e = exl.get(int(x["leg"]), {})
            rows.append(
                {
                    "key": r["key"],
                    "problem": r["problem"],
                    "planner": r["planner"],
                    "seed": r["seed"],
                    **{k: x.get(k) for k in LEG_COLUMNS if k in x},
                    "path_points": x.get("path_points"),
                    "extra_lengths": _lengths(x.get("extra") or {}),
                    "exec_success": e.get("success"),
                    "exec_path_valid": e.get("path_valid"),
                    "exec_max_deviation_m": e.get("max_deviation_m"),
                    "exec_min_clearance_m": e.get("min_clearance_m"),
                    "exec_max_track_err_rad": e.get("max_track_err_rad"),
                    "exec_contacts": _n_contacts(e.get("contacts")),
                    "exec_final_pos_err_m": e.get("final_pos_err_m"),
                    "exec_final_angle_err_deg": e.get("final_angle_err_deg"),
                    "exec_reason": e.get("reason"),
                }
            )
    return rows


def trials_csv(records: Iterable[Mapping[str, Any]]) -> str:
    return _csv(TRIAL_COLUMNS, trial_rows(records))


def legs_csv(records: Iterable[Mapping[str, Any]]) -> str:
    return _csv(LEG_COLUMNS, leg_rows(records))


def summary_csv(rows: Iterable[Mapping[str, Any]]) -> str:
    return _csv(SUMMARY_COLUMNS, rows)


# ---------------------------------------------------------------------- Markdown
def summary_cells(row: Mapping[str, Any], executed: bool) -> list[str]:
    """The cells of one planner's line in a per-problem table (see :data:`TABLE_HEADERS`)."""
    cells = [
        str(row["planner"]),
        f"{row['successes']}/{row['n']}" + (f" ({row['errors']} err)" if row["errors"] else ""),
        (
            f"{fmt(100 * row['success_rate'], 3)}% [deterministic: {row['n']} seeds, one trial]"
            if row.get("deterministic") is True
            else f"{fmt(100 * row['success_rate'], 3)}% [{fmt(100 * row['ci95_low'], 3)}, "
            f"{fmt(100 * row['ci95_high'], 3)}]"
        ),
        f"{fmt(row['time_median_s'])} / {fmt(row['time_p75_s'])} / {fmt(row['time_p95_s'])}",
        fmt(row["path_length_median"]),
        fmt(row["pos_err_median_m"]),
        fmt(row["angle_err_median_deg"]),
        fmt(row["checks_median"]),
        f"{row['local_minima']} / {row['escapes']}",
    ]
    if executed:
        rate = row["exec_success_rate"]
        cells += [
            f"{row['exec_successes']}/{row['executed']}"
            + (f" ({fmt(100 * rate)}%)" if row["executed"] else ""),
            fmt(mm(row.get("exec_deviation_median_m"))),
            fmt(mm(row.get("exec_clearance_min_m"))),
            fmt(row["exec_track_err_median_rad"]),
        ]
    return cells


TABLE_HEADERS = (
    "planner",
    "solved",
    "success % [95% CI]",
    "time s med / p75 / p95",
    "path len rad",
    "pos err m",
    "ang err °",
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
    "over legs, median over solved trials. pos/ang err: final tip error of the last "
    "leg, median over trials that ran. checks: collision checks per trial, median. "
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


def _finished_span(records: Sequence[Mapping[str, Any]]) -> str:
    times = sorted(str(r["finished_at"]) for r in records if r.get("finished_at"))
    return f"{times[0]} to {times[-1]}" if times else "-"


def markdown(
    rows: Sequence[Mapping[str, Any]], records: Sequence[Mapping[str, Any]], meta: Mapping[str, Any]
) -> str:
    """The report: a table per problem, the command, seeds, budget, versions, machine."""
    executed = bool(meta.get("execute"))
    out = [f"# Comparison `{meta.get('name', '')}`", ""]
    out += ["Command:", "", "```", str(meta.get("command", "")), "```", ""]
    problems = list(dict.fromkeys(str(r["problem"]) for r in rows))
    headers = TABLE_HEADERS + (EXEC_HEADERS if executed else ())
    for p in problems:
        out += [f"## {p}", ""]
        out.append(
            _md_table(headers, [summary_cells(r, executed) for r in rows if r["problem"] == p])
        )
        out.append("")
    out += [TABLE_NOTES, "", BUDGET_NOTE, ""]
    errors = [r for r in records if r.get("status") == ERROR_STATUS]
    if errors:
        out += ["## Errors", ""]
        out += [f"- `{r['key']}`: {r.get('error')}" for r in errors]
        out.append("")
    out += ["## Set-up", ""]
    setup = [
        ("problems", ", ".join(meta.get("problems", []))),
        ("planners", ", ".join(meta.get("planners", []))),
        ("seeds", meta.get("seeds_spec", "")),
        ("budget overrides", json.dumps(meta.get("budget", {})) or "{}"),
        ("budgets used", json.dumps(meta.get("budgets_used", {}))),
        ("settings overrides", json.dumps(meta.get("settings", {}))),
        ("legs", meta.get("legs") or "all"),
        ("executed in PyBullet", "yes" if executed else "no"),
        (
            "trials",
            f"{len(records)} finished of {meta.get('trials', len(records))} "
            f"(ran {meta.get('ran', '?')}, reused {meta.get('skipped', '?')})",
        ),
        ("jobs", meta.get("jobs", "")),
        ("trials finished", _finished_span(records)),
        ("trial processes, total s", fmt(sum(float(r.get("wall_s") or 0.0) for r in records))),
        ("this invocation started", meta.get("started_at", "")),
        ("this invocation's wall time s", fmt(meta.get("wall_s"))),
        ("trial store", meta.get("store", "")),
    ]
    out.append(_md_table(("item", "value"), [(k, str(v)) for k, v in setup]))
    out += ["", "## Versions", ""]
    seen = {json.dumps(r.get("versions"), sort_keys=True) for r in records if r.get("versions")}
    if len(seen) > 1:
        out += [
            f"**The trials ran under {len(seen)} different sets of versions** (the store "
            "holds each trial's own `versions`); below: this invocation's.",
            "",
        ]
    out.append(
        _md_table(
            ("package", "version"), [(k, str(v)) for k, v in (meta.get("versions") or {}).items()]
        )
    )
    out += ["", "## Machine", ""]
    out.append(
        _md_table(("item", "value"), [(k, str(v)) for k, v in (meta.get("machine") or {}).items()])
    )
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


def _run_progress(r: Mapping[str, Any]) -> list[list[Any]]:
    """A trial's progress rows (see :data:`_PROGRESS_PROPERTIES`), times strictly
    increasing (OMPL's table keys progress on (run, time))."""
    rows: list[list[Any]] = []
    t_off = 0.0
    c_off = 0
    for leg in r.get("legs_run") or []:
        for t, checks, dist, cost in leg.get("progress") or []:
            if t is None:
                continue
            time_s = t_off + float(t)
            c = None if checks is None else c_off + int(checks)
            row = [time_s, dist, cost, c, int(leg["leg"])]
            if rows and time_s <= rows[-1][0]:
                rows[-1] = [rows[-1][0], *row[1:]]  # same instant: the later values
            else:
                rows.append(row)
        t_off += float(leg.get("time_s") or 0.0)
        c_off += int(leg.get("collision_checks") or 0)
    return rows


def _log_value(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    return str(v)


def _run_values(r: Mapping[str, Any]) -> list[str]:
    tot = r.get("totals") or {}
    ex = r.get("execution")
    legs = r.get("legs_run") or []
    status = str(r.get("status"))
    ok = bool(r.get("success"))
    values: list[Any] = [
        int(r["seed"]),
        tot.get("time_s"),
        ok,
        STATUS_ENUM.index(status) if status in STATUS_ENUM else STATUS_ENUM.index("failed"),
        status == "approximate",
        sum(1 for x in legs if x["status"] == "solved"),
        tot.get("iterations"),
        tot.get("collision_checks"),
        tot.get("fk_calls"),
        tot.get("path_length") if ok else None,
        tot.get("path_length"),
        r.get("final_pos_err_m"),
        r.get("final_angle_err_deg"),
        tot.get("local_minima"),
        tot.get("escapes"),
        r.get("wall_s"),
        ex.get("success") if ex else None,
        ex.get("max_track_err_rad") if ex else None,
        ex.get("contacts") if ex else None,
        ex.get("max_deviation_m") if ex else None,
        ex.get("min_clearance_m") if ex else None,
    ]
    return [_log_value(v) for v in values]


def _one_line(s: str) -> str:
    return " ".join(str(s).split())


def ompl_log(problem: str, records: Sequence[Mapping[str, Any]], meta: Mapping[str, Any]) -> str:
    """One OMPL benchmark log (one experiment) for the records of ``problem``."""
    recs = [r for r in records if r["problem"] == problem]
    planners = list(dict.fromkeys(str(r["planner"]) for r in recs))
    by_planner = {p: [r for r in recs if r["planner"] == p] for p in planners}
    versions = meta.get("versions") or {}
    machine = meta.get("machine") or {}
    budget = (meta.get("budgets_used") or {}).get(problem, {})
    exp_props = [
        ("max_iterations", "INTEGER", budget.get("max_iterations")),
        ("max_collision_checks", "INTEGER", budget.get("max_collision_checks")),
        ("time_limit_s", "REAL", budget.get("time_limit_s")),
        ("executed", "BOOLEAN", bool(meta.get("execute"))),
    ]
    exp_props = [(n, t, v) for n, t, v in exp_props if v is not None]
    time_limit = budget.get("time_limit_s")
    seeds = sorted({int(r["seed"]) for r in recs})
    lines = [
        f"plannerlab version {versions.get('plannerlab', '0')}",
        f"Experiment {'_'.join(problem.split()) or 'problem'}",
        f"{len(exp_props)} experiment properties",
        *[f"{n} {t} = {_log_value(v)}" for n, t, v in exp_props],
        f"Running on {'_'.join(str(machine.get('hostname', 'unknown')).split())}",
        f"Starting at {str(meta.get('started_at', '')).replace('T', ' ')}",
        "<<<|",
        f"command: {_one_line(meta.get('command', ''))}",
        f"problem file: {recs[0].get('problem_file', '') if recs else ''}",
        f"seeds: {meta.get('seeds_spec', '')} (each run's seed is its 'seed' property)",
        f"budget: {json.dumps(budget, sort_keys=True)}",
        f"legs: {meta.get('legs') or 'all'}",
        "versions: " + ", ".join(f"{k} {v}" for k, v in versions.items()),
        "|>>>",
        "<<<|",
        f"{machine.get('cpu_model', 'unknown')}, {machine.get('cpu_count', '?')} CPUs, "
        f"{machine.get('memory_gb', '?')} GB, {machine.get('platform', '')}",
        "|>>>",
        f"{seeds[0] if seeds else 0} is the random seed",
        f"{float(time_limit) if time_limit is not None else math.inf!r} seconds per run",
        "0 MB per run",
    ]
    counts = {len(v) for v in by_planner.values()}
    if len(counts) == 1:
        lines.append(f"{counts.pop()} runs per planner")
    total = sum(float(r.get("wall_s") or 0.0) for r in recs)
    lines += [
        f"{total!r} seconds spent to collect the data",
        "1 enum type",
        "status|" + "|".join(STATUS_ENUM),
        f"{len(planners)} planners",
    ]
    for p in planners:
        runs = by_planner[p]
        settings: dict[str, Any] = next(
            (r["settings_used"] for r in runs if r.get("settings_used")), {}
        )
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
    records: Sequence[Mapping[str, Any]],
    rows: Sequence[Mapping[str, Any]],
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
    problems = list(dict.fromkeys(str(r["problem"]) for r in records))
    for problem, path in log_paths(folder, name, problems).items():
        files.append(write_text_atomic(path, ompl_log(problem, records, meta)))
    return files


__all__ = [
    "EXEC_HEADERS",
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
    "trial_rows",
    "trials_csv",
    "write_reports",
]

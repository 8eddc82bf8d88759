"""``plannerlab compare``: planners × problems × seeds, each trial in its own process.

    plannerlab compare PROBLEM... --planners a,b,c --seeds 0-19
                       [--time-limit S | --max-checks N | --max-iterations N]
                       [--legs L1,L2] [--set PLANNER:KEY=VALUE ...] [--execute]
                       [--jobs J] [--name NAME] [--out DIR] [--retry-errors] [--json]
                       [--trial-timeout S] [--backend local|ray [--address ADDR]]
                       [--wide | --columns A,B,C]

Every (problem, planner, seed) is a trial run in a fresh process (OMPL's generator is
process-global and must be seeded before any OMPL object exists): forked from a warm
fork server on this machine (``--backend local``, the default), or a Ray task in a fresh
worker (``--backend ray``, on a local instance or a cluster at ``--address``). A trial
past ``--trial-timeout`` is killed and recorded as ``timeout``. Finished trials are
appended to ``DIR/NAME/trials.jsonl`` as they finish, so rerunning the same command skips
them and an interrupted comparison resumes where it stopped. At the end: a table per
problem (success rate with a 95 % Wilson interval, time median/p75/p95, path length,
final tip errors, collision checks, local minima met/escaped, PyBullet execution), and
CSV, Markdown and OMPL benchmark logs in ``DIR/NAME/`` (load a log with
``ompl_benchmark_statistics LOG -d results.db``).

Budgets are per leg; use ``--max-checks`` or ``--max-iterations`` for reproducible
numbers, ``--time-limit`` for benchmarks. The same from Python: ``plannerlab.compare``.
"""

# Argument parsing and printing only: the work is plannerlab.extras.ComparisonSpec (the
# checks, shared with plannerlab.compare), plannerlab.extras.run_spec and the reports of
# plannerlab.write_reports. The docstring above is the command's help: no internal names.

from __future__ import annotations

import argparse
import json
import math
import re
import shlex
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    SpinnerColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.text import Text

from plannerlab import extras as px
from plannerlab.cli.common import (
    add_budget_args,
    leg_spec,
    parse_scoped_overrides,
    positive_int,
    positive_seconds,
)
from plannerlab.cli.tables import (
    SUMMARY_COLUMNS,
    column_notes,
    pick_columns,
    print_summary_tables,
)
from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import DIED_STATUS, ERROR_STATUS

DEFAULT_OUT = Path("results") / "compare"


def add_compare_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``compare`` subcommand on the ``plannerlab`` parser's subparsers."""
    p = subparsers.add_parser(
        "compare",
        help="run planners × problems × seeds (one process per trial), tables + CSV/MD/OMPL log",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("problems", nargs="+", metavar="PROBLEM", help="problem names or .toml paths")
    p.add_argument(
        "--planners", required=True, help="comma-separated registry names (plannerlab planners)"
    )
    p.add_argument(
        "--seeds", default="0-19", help="seeds: a range 0-19, a list 0,3,5-7 (default 0-19)"
    )
    add_budget_args(p)
    p.add_argument(
        "--legs", type=leg_spec, help="comma-separated leg names or indices (default: all)"
    )
    p.add_argument(
        "--set",
        action="append",
        metavar="PLANNER:KEY=VALUE",
        help="override a setting of one planner (repeatable)",
    )
    p.add_argument(
        "--execute",
        action="store_true",
        help="also execute every plan in PyBullet (success, tracking error)",
    )
    p.add_argument("--jobs", type=positive_int, default=1, help="trials run at once (default 1)")
    p.add_argument(
        "--trial-timeout",
        type=positive_seconds,
        metavar="S",
        help="wall-clock limit per trial [s]; a trial past it is killed and recorded as "
        "timeout (default: from the budget: 60 s + per leg 2 x the time limit + 30 s, or "
        "600 s without a time limit, + 120 s with --execute)",
    )
    p.add_argument(
        "--backend",
        choices=("local", "ray"),
        default="local",
        help="where trials run: local processes (default) or Ray tasks (pip install .[ray])",
    )
    p.add_argument(
        "--address",
        metavar="ADDR",
        help="Ray cluster address for --backend ray (e.g. HOST:6379 or auto; default: a "
        "running local instance, else a private one)",
    )
    p.add_argument("--name", help="comparison name (default: from problems and planners)")
    p.add_argument(
        "--out",
        default=str(DEFAULT_OUT),
        help=f"parent folder of the comparison's folder (default {DEFAULT_OUT})",
    )
    p.add_argument(
        "--retry-errors", action="store_true", help="rerun trials whose stored record is an error"
    )
    p.add_argument(
        "--json", action="store_true", help="print the summary rows and file paths as JSON"
    )
    p.add_argument(
        "--wide",
        action="store_true",
        help="every column (percentiles, path length, tip errors, tracking error); "
        "the default is a compact table that fits 80 columns",
    )
    p.add_argument(
        "--columns",
        metavar="A,B,C",
        help="the table's columns, in order: " + ", ".join(SUMMARY_COLUMNS),
    )
    p.add_argument(
        "--minima",
        action="store_true",
        help="end with which planner escaped which local minimum: the legs the paper's "
        "gradient (else the first planner) stalled on, who solved them, and the minima each "
        "planner met and escaped itself (from the trial records)",
    )
    p.set_defaults(func=cmd_compare)
    return p


# ---------------------------------------------------------------------- arguments
def _split(spec: str) -> list[str]:
    return [x.strip() for x in spec.split(",") if x.strip()]


def _command(args: argparse.Namespace) -> str:
    """The command that reproduces (and resumes) this comparison, canonically spelled."""
    parts = [
        "plannerlab",
        "compare",
        *args.problems,
        "--planners",
        args.planners,
        "--seeds",
        args.seeds,
    ]
    for flag, value in (
        ("--time-limit", args.time_limit),
        ("--max-checks", args.max_checks),
        ("--max-iterations", args.max_iterations),
        ("--legs", args.legs),
    ):
        if value is not None:
            parts += [flag, str(value)]
    for item in args.set or []:
        parts += ["--set", item]
    if args.execute:
        parts.append("--execute")
    parts += ["--jobs", str(args.jobs)]
    if args.trial_timeout is not None:
        parts += ["--trial-timeout", f"{args.trial_timeout:g}"]
    if args.backend != "local":
        parts += ["--backend", args.backend]
    if args.address:
        parts += ["--address", args.address]
    if args.name:
        parts += ["--name", args.name]
    if Path(args.out) != DEFAULT_OUT:
        parts += ["--out", args.out]
    return shlex.join(parts)


def _json_safe(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json_safe(v) for v in x]
    return x


# ---------------------------------------------------------------------- command
def cmd_compare(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl
    from plannerlab.record.files import versions

    # -- validate everything before the first process starts
    columns = pick_columns(args.columns, args.wide, args.execute)
    for flag, v in (
        ("--max-checks", args.max_checks),
        ("--max-iterations", args.max_iterations),
        ("--time-limit", args.time_limit),
    ):
        if v is not None and v <= 0:
            raise PlannerlabError(f"{flag}: expected > 0, got {v}")
    planners = list(dict.fromkeys(_split(args.planners)))
    spec = px.ComparisonSpec.build(
        args.problems,
        planners,
        px.parse_seeds(args.seeds),
        budget={
            "max_iterations": args.max_iterations,
            "max_collision_checks": args.max_checks,
            "time_limit_s": args.time_limit,
        },
        settings=parse_scoped_overrides(args.set, planners),
        legs=args.legs,
        execute=args.execute,
        jobs=args.jobs,
        backend=args.backend,
        address=args.address,
        trial_timeout_s=args.trial_timeout,
        retry_errors=args.retry_errors,
    )
    name = args.name or px.default_store_name(spec.problem_names, list(spec.planners))
    if not re.fullmatch(r"[A-Za-z0-9._+-]+", name) or name in (".", ".."):
        raise PlannerlabError(f"--name: letters, digits and . _ + - only, got {name!r}")
    folder = Path(args.out) / name
    store = pl.TrialStore(px.store_path(args.out, name))
    command = _command(args)
    trials = spec.trials

    # -- run, with a progress bar
    started = datetime.now(UTC)
    t0 = time.perf_counter()
    counts = {"ran": 0, "skipped": 0, "errors": 0}
    progress = Progress(
        SpinnerColumn(),
        TextColumn("{task.description}", style="bold", markup=False),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[detail]}", markup=False),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=console,
    )

    def detail() -> str:
        s = f"{counts['ran']} run, {counts['skipped']} skipped"
        return s + (f", {counts['errors']} errors" if counts["errors"] else "")

    task = progress.add_task(f"compare {name}", total=len(trials), detail="")

    def on_done(rec: Any, skipped: bool) -> None:
        counts["skipped" if skipped else "ran"] += 1
        if not rec.ran:
            counts["errors"] += 1
        last = "" if skipped else f" · last: {rec.planner} s{rec.seed} {rec.status}"
        progress.update(task, advance=1, detail=detail() + last)

    try:
        with progress:
            run = px.run_spec(spec, store, on_done)
    except KeyboardInterrupt:
        done = counts["ran"] + counts["skipped"]
        console.print(
            Text.assemble(
                ("interrupted", "yellow"),
                f": {done} of {len(trials)} trials are finished and safe in {store.path} (the "
                f"running ones were stopped). Rerun the same command to resume:\n  {command}",
            ),
            highlight=False,
        )
        return 130
    wall_s = time.perf_counter() - t0

    # -- report
    records = sorted(run.records, key=spec.sort_key)
    rows = pl.summarise(records)
    meta = {
        "command": command,
        **spec.to_dict(),
        "seeds_spec": args.seeds,
        "ran": run.ran,
        "skipped": run.skipped,
        "errors": sum(1 for r in records if not r.ran),
        "started_at": started.isoformat(timespec="seconds"),
        "wall_s": wall_s,
        "store": str(store.path),
        "versions": versions(),
        "machine": px.machine_info(),
    }
    files = pl.write_reports(folder, name, records, rows, meta)

    if args.json:
        print(
            json.dumps(
                _json_safe(
                    {
                        "name": name,
                        "store": str(store.path),
                        "files": [str(f) for f in files],
                        "trials": len(trials),
                        "ran": run.ran,
                        "skipped": run.skipped,
                        "errors": meta["errors"],
                        "wall_s": wall_s,
                        "summary": [r.to_dict() for r in rows],
                    }
                )
            )
        )
        return 0
    _print_tables(console, rows, columns)
    if args.minima:
        planners = _split(args.planners)
        baseline = "gradient" if "gradient" in planners else planners[0]
        stalls, own = pl.local_minima(records, baseline)
        console.print(Text("Local minima (from the trial records)", style="bold"))
        for line in px.describe_minima(stalls, own, baseline):
            console.print(line, highlight=False)
    _print_failed_trials(console, records)
    console.print(
        f"{len(trials)} trials: {run.ran} run now, {run.skipped} already in the "
        f"store; {wall_s:.1f} s",
        highlight=False,
    )
    console.print(f"trial store: {store.path}", highlight=False, soft_wrap=True)
    for f in files:
        console.print(f"wrote {f}", highlight=False, soft_wrap=True)
    return 0


def _print_failed_trials(console: Console, records: list[Any]) -> None:
    """One line each for the trials that raised and the trials whose process died."""
    errors = [r for r in records if r.status == ERROR_STATUS]
    if errors:
        console.print(
            Text.assemble(
                (f"{len(errors)} trial(s) raised", "red"),
                f" (rerun them with --retry-errors), e.g. {errors[0].key}: {errors[0].error}",
            ),
            highlight=False,
        )
    died = [r for r in records if r.status == DIED_STATUS]
    if died:
        console.print(
            Text.assemble(
                (f"{len(died)} trial process(es) died", "red"),
                f" (the next run of this command tries them again), e.g. {died[0].key}: "
                f"{died[0].error}",
            ),
            highlight=False,
        )


def _print_tables(console: Console, rows: list[Any], columns: list[str]) -> None:
    for problem in dict.fromkeys(r.problem for r in rows):
        print_summary_tables(console, problem, [r for r in rows if r.problem == problem], columns)
    console.print(
        f"{column_notes(columns)}. Medians over the trials that ran; times and "
        "checks summed over legs. All columns: --wide, report.md, summary.csv.",
        style="dim",
        highlight=False,
    )

    console.print(px.BUDGET_NOTE, style="dim", highlight=False)

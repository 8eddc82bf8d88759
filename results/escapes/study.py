"""The escape study at full size (issue 33, item 3): every planner family at its best
settings on the traps and the paper's task, 20 seeds, every solved plan executed in
PyBullet; budgets in collision checks, a time limit only as a guard; resumable; one
command, ``--jobs 2``.

    python results/escapes/study.py run              # the whole study (resumes)
    python results/escapes/study.py report           # tables and figures from the store
    python results/escapes/study.py run --seeds 0-1 --out /tmp/slice    # a slice
    python results/escapes/study.py estimate /tmp/slice --seeds 20       # its full size

**Which planners.** "Every family at its best settings" is measured, not chosen
(``--members best``, the default; :mod:`plannerlab.comparison.screen`): a **screen** runs
every member of every family (:data:`FAMILIES`) once, on the first seed, on every
problem; then each family's best member there (the most problems planned and executed
cleanly, ties by the fewest checks) runs on every seed. The screen's trials are the
study's first seed. Why: the 22 members on 20 seeds cost about 6 CPU-hours (3 h on 2
cores; measured with ``estimate`` on a slice of seed 0 at ``25183da``, 77 % of it the
executions' physics), the screen and the seven best about 2 CPU-hours. ``--members all``
runs every member on every seed.

``run`` makes the trials (problem × planner × seed; a deterministic planner, whose seeds
are one run, on the first seed only) and runs them in one queue, ``--jobs`` at a
time, each in its own process (:func:`plannerlab.comparison.runner.run_comparison`),
appending each record to ``OUT/trials.jsonl`` as it finishes: an interrupted study
resumes where it stopped. The longest problems go first so the queue ends on short
trials. ``OUT/study.json`` records the commit, the budgets, the planners, the problems,
the seeds and the machine's load when the study started and ended; a study is one
commit: ``run`` refuses to add to a store made at another commit (or from a tree with
changes) unless told ``--mixed``.

**Budgets** (per leg, the same for every planner and problem): ``--checks`` collision
checks (default 1 000 000; a planner stops when they are used up, so a trial's work does
not depend on the machine), ``--guard`` seconds of planning (default 60: a guard against
a planner that checks slowly, not the budget), iterations lifted. A planner that is
deterministic here (the registry's ``uses_rng = False``) runs on the first seed only.

**Best settings**: every planner's defaults (their attempt caps, ``max_escapes`` and
``max_replans``, are sized for check budgets), and the settings of ``BEST`` below.

``report`` writes ``results/escape_study.md`` (the glance table: each family's best
member per problem; the table of every planner; the command, the commit and the load),
``OUT/escapes_by_family.png`` and ``OUT/escapes_by_planner.png``
(:func:`plannerlab.plot.escapes.escape_matrix`) and ``OUT/progress_traps.png``,
``OUT/progress_tasks.png`` (:func:`plannerlab.plot.study.progress_panels`).

``estimate`` projects a slice's trial times to the full study: per (problem, planner) the
mean wall time of its trials times the seeds the full study runs, over ``--jobs``.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from statistics import median
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

TRAPS = (
    "armz_deep_a",
    "armz_deep_b",
    "armz_deep_e",
    "armz_pocket",
    "armz_window",
    "armz_cavity",
    "armz_thin_wall",
)
TASKS = ("armz_inspection", "armz_inspection_direct")
#: the planner families, each with its members (trajectory optimisation: every registered
#: ``trajopt*`` planner, when there is one)
FAMILIES: dict[str, tuple[str, ...]] = {
    "the paper's gradient": ("gradient",),
    "clearance descent": (
        "gradient.clearance",
        "gradient.clearance+detour",
        "gradient.clearance+random_detour",
        "gradient.clearance+rrtconnect",
    ),
    "follow-the-leader": (
        "gradient.follow_leader",
        "gradient.follow_leader+detour",
        "gradient.follow_leader+random",
    ),
    "hybrids": ("gradient+rrtconnect", "gradient.multistart"),
    "OMPL": ("ompl.rrtconnect", "ompl.kpiece1", "ompl.prm", "ompl.rrtstar"),
    "native": ("native.rrtconnect", "native.rrtstar", "native.rrtconnect+leader"),
    "trajectory optimisation": (),
}
#: settings other than the defaults (none: the defaults are the best measured)
BEST: dict[str, dict[str, Any]] = {}
CHECKS = 1_000_000
GUARD_S = 60.0
ITERATIONS = 100_000_000
OUT = ROOT / "results" / "escapes" / "study"
REPORT = ROOT / "results" / "escape_study.md"


def families() -> dict[str, tuple[str, ...]]:
    """:data:`FAMILIES`, trajectory optimisation filled from the registry."""
    from plannerlab import planner_names

    out = dict(FAMILIES)
    out["trajectory optimisation"] = tuple(n for n in planner_names() if n.startswith("trajopt"))
    return out


def planners() -> list[str]:
    return [p for members in families().values() for p in members]


def deterministic(planner: str) -> bool:
    from plannerlab.planners import get_entry

    return not get_entry(planner).uses_rng


def commit() -> tuple[str, bool]:
    """The checkout's commit and whether its tracked files have changes."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        return head, bool(dirty)
    except (OSError, subprocess.CalledProcessError):
        return "unknown", True


def problems_of(args: argparse.Namespace) -> list[str]:
    return args.problems.split(",") if args.problems else list(TASKS + TRAPS)


def trials(args: argparse.Namespace, names: list[str], seeds: list[int]) -> list[Any]:
    """The trials of ``names`` on ``seeds`` (a deterministic planner on the first only),
    longest problems first."""
    from plannerlab.comparison.spec import ComparisonSpec

    problems = problems_of(args)
    budget = {
        "max_collision_checks": args.checks,
        "time_limit_s": args.guard,
        "max_iterations": ITERATIONS,
    }
    out = []
    for problem in problems:
        for planner in names:
            spec = ComparisonSpec.build(
                [problem],
                [planner],
                seeds[:1] if deterministic(planner) else seeds,
                budget=budget,
                settings={planner: BEST[planner]} if planner in BEST else None,
                execute=True,
            )
            out += [(t, spec.trial_timeout(t)) for t in spec.trials]
    # interleave the planners of a problem, problem by problem (longest first)
    return sorted(out, key=lambda tt: (problems.index(tt[0].problem), tt[0].seed))


def cmd_run(args: argparse.Namespace) -> int:
    from plannerlab.comparison.store import TrialStore

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    meta_path = out / "study.json"
    head, dirty = commit()
    meta = json.loads(meta_path.read_text()) if meta_path.exists() else {}
    if meta and (meta.get("commit") != head or dirty or meta.get("dirty")) and not args.mixed:
        print(
            f"{meta_path}: the store was made at {meta.get('commit')}"
            f"{' (with changes)' if meta.get('dirty') else ''}, this checkout is {head}"
            f"{' (with changes)' if dirty else ''}: a study is one commit (--mixed to add)",
            file=sys.stderr,
        )
        return 2
    from plannerlab.comparison.trial import parse_seeds

    seeds = parse_seeds(args.seeds)
    names = args.planners.split(",") if args.planners else planners()
    store = TrialStore(out / "trials.jsonl")
    # --members best: the screen (every member on the first seed), then each family's
    # best member on every seed (plannerlab.comparison.screen); all: every member
    grid = trials(args, names, seeds if args.members == "all" else seeds[:1])
    meta.update(
        members=args.members,
        screen_seed=seeds[0] if args.members == "best" else None,
        planners=names,
    )
    t0 = time.monotonic()
    count = {"done": 0, "of": len(grid)}

    def on_done(rec: Any, skipped: bool) -> None:
        count["done"] += 1
        if not skipped:
            print(
                f"[{count['done']}/{count['of']}] {rec.problem} {rec.planner} s{rec.seed}: "
                f"{rec.status} in {rec.wall_s or 0.0:.1f} s "
                f"({time.monotonic() - t0:.0f} s, load {os.getloadavg()[0]:.1f})",
                file=sys.stderr,
                flush=True,
            )

    def stop(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt  # the runner stops its trials; the store keeps the rest

    signal.signal(signal.SIGTERM, stop)
    ran = skipped = 0
    try:
        ran, skipped = _stages(
            args, store, meta, (meta_path, head, dirty), (names, seeds, grid), (on_done, count)
        )
    finally:  # an interrupted run keeps its wall time (the store keeps its trials)
        meta.update(
            load_at_end=list(os.getloadavg()),
            wall_s=round((meta.get("wall_s") or 0.0) + time.monotonic() - t0, 1),
            trials=len(store.load()),
        )
        meta_path.write_text(json.dumps(meta, indent=1) + "\n")
    meta["finished"] = datetime.now(UTC).isoformat(timespec="seconds")
    meta_path.write_text(json.dumps(meta, indent=1) + "\n")
    print(f"{ran} trials run now, {skipped} already in {out / 'trials.jsonl'}")
    return 0


def _stages(args, store, meta, where, what, report):
    """The screen and the best members' seeds (``--members best``), or every member on
    every seed (``all``): (trials run, trials already in the store)."""
    from plannerlab.comparison.runner import run_comparison

    meta_path, head, dirty = where
    names, seeds, grid = what
    on_done, count = report
    ran = skipped = 0
    for stage in range(2 if args.members == "best" else 1):
        if stage == 1:
            from plannerlab.comparison.screen import best_members

            fams = {f: [m for m in ms if m in names] for f, ms in families().items()}
            best = best_members(store.load().values(), fams, seeds[0], problems_of(args))
            meta["best"] = best
            print(
                "the screen's best: " + ", ".join(f"{f}: {m}" for f, m in best.items()),
                file=sys.stderr,
                flush=True,
            )
            grid = trials(args, sorted(set(best.values()), key=names.index), seeds)
        count.update(done=0, of=len(grid))
        _write_meta(meta_path, meta, head, dirty, grid, args)
        limits = {t.key: limit for t, limit in grid}
        run = run_comparison(
            [t for t, _ in grid],
            store,
            jobs=args.jobs,
            on_done=on_done,
            trial_timeout_s=lambda t, limits=limits: limits[t.key],
        )
        ran += run.ran
        skipped += run.skipped
    return ran, skipped


def _write_meta(
    meta_path: Path, meta: dict[str, Any], head: str, dirty: bool, grid: list[Any], args: Any
) -> None:
    """The store's ``study.json``: commit, command, budgets, problems, seeds, the load."""
    meta.update(
        commit=head,
        dirty=dirty,
        command=" ".join(["python", "results/escapes/study.py", *sys.argv[1:]]),
        budget={"max_collision_checks": args.checks, "time_limit_s": args.guard},
        problems=sorted({t.problem for t, _ in grid}),
        seeds=args.seeds,
        jobs=args.jobs,
        started=meta.get("started") or datetime.now(UTC).isoformat(timespec="seconds"),
        load_at_start=meta.get("load_at_start") or list(os.getloadavg()),
    )
    meta_path.write_text(json.dumps(meta, indent=1) + "\n")


def load(out: Path) -> list[Any]:
    """The study's trial records (typed, ``TrialRecord``); the last record of a key wins."""
    from plannerlab import TrialStore

    return list(TrialStore(out / "trials.jsonl").load().values())


def clean(r: Any) -> bool:
    """Planned (every leg) and executed cleanly (every leg, the executor's verdict)."""
    return bool(r.success) and bool(r.exec_success)


def cells(recs: list[Any]) -> dict[tuple[str, str], dict[str, Any]]:
    """Per (problem, planner): seeds, clean, median checks and planning time of the
    solved, the failures by status."""
    by: dict[tuple[str, str], list[Any]] = {}
    for r in recs:
        by.setdefault((r.problem, r.planner), []).append(r)
    out = {}
    for key, rs in by.items():
        solved = [r for r in rs if r.success]
        fails: dict[str, int] = {}
        for r in rs:
            if not r.success:
                fails[str(r.status)] = fails.get(str(r.status), 0) + 1
        out[key] = {
            "seeds": len(rs),
            "clean": sum(clean(r) for r in rs),
            "solved": len(solved),
            "checks": median([r.collision_checks for r in solved]) if solved else None,
            "time_s": median([r.time_s for r in solved]) if solved else None,
            "wall_s": sum(float(r.wall_s or 0.0) for r in rs),
            "cpu_s": sum(float(r.cpu_s or r.wall_s or 0.0) for r in rs),
            "fails": fails,
            "one_run": deterministic(key[1]),
        }
    return out


def _short(planner: str) -> str:
    return planner.replace("gradient.", "").replace("native.", "").replace("ompl.", "")


def glance(
    table: dict[tuple[str, str], dict[str, Any]],
    problems: list[str],
    best: dict[str, str] | None = None,
) -> list[list[Any]]:
    """Per family and problem: its best member and that member's cell. With ``best``
    (the screen's choice: the member the study ran on every seed) that member; without
    (``--members all``) the member with the most executed cleanly, then fewest median
    checks, per problem."""
    rows = []
    for family, members in families().items():
        if best is not None:
            members = (best[family],) if family in best else ()
        row = []
        for p in problems:
            have = [(m, table[(p, m)]) for m in members if (p, m) in table]
            if not have:
                row.append(None)
                continue
            row.append(
                max(
                    have,
                    key=lambda mc: (mc[1]["clean"] / mc[1]["seeds"], -(mc[1]["checks"] or 1e18)),
                )
            )
        rows.append([family, row])
    return rows


def cmd_report(args: argparse.Namespace) -> int:
    from plannerlab.plot.escapes import Cell, escape_matrix
    from plannerlab.plot.plans import save

    out = Path(args.out)
    recs = load(out)
    meta = json.loads((out / "study.json").read_text())
    table = cells(recs)
    problems = [p for p in TASKS + TRAPS if any(k[0] == p for k in table)]
    names = [p for p in planners() if any(k[1] == p for k in table)]
    rows = glance(table, problems, meta.get("best"))
    fam_cells = [
        [
            Cell(0, 0)
            if mc is None
            else Cell(
                mc[1]["clean"],
                mc[1]["seeds"],
                _short(mc[0]) + (" (1 run)" if mc[1]["one_run"] else ""),
            )
            for mc in row
        ]
        for _, row in rows
    ]
    title = f"escape study at {meta['commit'][:7]}: executed cleanly / seeds"
    save(
        escape_matrix([r[0] for r in rows], problems, fam_cells, title),
        out / "escapes_by_family.png",
    )
    groups, k = [], -1
    for members in families().values():
        k += sum(1 for m in members if m in names)
        groups.append(k)
    pl_cells = [
        [
            Cell(
                table[(p, m)]["clean"],
                table[(p, m)]["seeds"],
                "1 run" if table[(p, m)]["one_run"] else "",
            )
            if (p, m) in table
            else Cell(0, 0)
            for p in problems
        ]
        for m in names
    ]
    save(
        escape_matrix(names, problems, pl_cells, title, groups[:-1]), out / "escapes_by_planner.png"
    )
    _progress(recs, out)
    report = REPORT if out.resolve() == OUT.resolve() else out / "escape_study.md"
    report.write_text(_markdown(meta, rows, table, problems, names))
    print(f"wrote {report}, {out}/escapes_by_family.png, escapes_by_planner.png, progress_*.png")
    return 0


def _progress(recs: list[Any], out: Path) -> None:
    """The progress figures: per trap the median best goal distance against planning
    time, per task the legs still to go."""
    from plannerlab import load_problem
    from plannerlab.plot.plans import save
    from plannerlab.plot.study import progress_panels

    for name, problems, task in (("traps", TRAPS, False), ("tasks", TASKS, True)):
        by: dict[str, dict[str, list[Any]]] = {}
        for r in recs:
            if r.problem not in problems:
                continue
            total = load_problem(r.problem).legs if task else None
            curve, t = ([(0.0, float(total))] if task else []), 0.0
            for i, leg in enumerate(r.legs_run):
                if not task:
                    curve += [(t + x[0], x[2]) for x in leg.progress or [] if x[2] is not None]
                t += float(leg.time_s or 0.0)
                if task:
                    curve.append((t, float(total - (i + 1 if leg.status == "solved" else i))))
            if not task and r.success:
                curve.append((t, 0.0))
            if curve:
                by.setdefault(r.problem, {}).setdefault(r.planner, []).append(curve)
        if by:
            fig = progress_panels(
                by,
                "escape study: median over seeds against planning time",
                t_max_s=GUARD_S * (7 if task else 1),
                ylabel="legs still to go (median)"
                if task
                else "best goal distance (median) [x tolerance]",
            )
            save(fig, out / f"progress_{name}.png")


def _fmt(x: float | None) -> str:
    if x is None:
        return "–"
    return f"{x:,.0f}" if x >= 100 else f"{x:.2g}"


def _markdown(meta, rows, table, problems, names) -> str:
    n_trials = sum(c["seeds"] for c in table.values())
    cpu_h = sum(c["cpu_s"] for c in table.values()) / 3600
    jobs = int(meta.get("jobs") or 1)
    short = [p.removeprefix("armz_") for p in problems]
    budget = meta["budget"]
    load0 = meta.get("load_at_start", [0.0])[0]
    load1 = meta.get("load_at_end", [0.0])[0]
    lines = [
        "# The escape study at full size (issue 33, item 3)",
        "",
        "```bash",
        meta.get("command", "python results/escapes/study.py run"),
        "python results/escapes/study.py report",
        "```",
        "",
        f"At `{meta['commit']}`{' (with changes)' if meta.get('dirty') else ''}; per leg "
        f"{budget['max_collision_checks']:,} collision checks, {budget['time_limit_s']:g} s "
        f"of planning as a guard, iterations lifted; seeds {meta['seeds']} (a deterministic "
        f"planner: one run); every solved plan executed in PyBullet; {n_trials} trials, "
        f"{jobs} at a time, {meta.get('wall_s', 0) / 3600:.2f} h of wall time as recorded; "
        f"the trials' own CPU time {cpu_h:.2f} h, {cpu_h / jobs:.2f} h on {jobs} cores; load "
        f"average at the start {load0:.1f}, at the end {load1:.1f}.",
        "",
        (
            "**At a glance**: each family's best member on the screen (every member once, "
            f"on seed {meta.get('screen_seed')}: the most problems executed cleanly, then "
            "the fewest checks), run on every seed; executed cleanly / seeds "
            "(`escapes/study/escapes_by_family.png`). The screen chose "
            + ", ".join(f"`{m}` ({f})" for f, m in meta["best"].items())
            + "."
            if meta.get("best")
            else "**At a glance**: each family's best member per problem, executed cleanly / "
            "seeds (`escapes/study/escapes_by_family.png`)."
        ),
        "",
        "| family | " + " | ".join(short) + " |",
        "|---|" + "---|" * len(problems),
    ]
    for family, row in rows:
        cells_ = []
        for mc in row:
            if mc is None:
                cells_.append("–")
            else:
                one = " (1 run)" if mc[1]["one_run"] else ""
                cells_.append(f"{mc[1]['clean']}/{mc[1]['seeds']}{one} `{_short(mc[0])}`")
        lines.append(f"| {family} | " + " | ".join(cells_) + " |")
    lines += [
        "",
        "**Every planner**: executed cleanly / seeds; median collision checks of the solved "
        "trials (summed over the legs) (`escapes/study/escapes_by_planner.png`)"
        + ("; a member the screen did not choose ran once (x/1)." if meta.get("best") else "."),
        "",
        "| planner | " + " | ".join(short) + " |",
        "|---|" + "---|" * len(problems),
    ]
    for m in names:
        cs = []
        for p in problems:
            c = table.get((p, m))
            cs.append("–" if c is None else f"{c['clean']}/{c['seeds']}, {_fmt(c['checks'])}")
        lines.append(f"| `{m}` | " + " | ".join(cs) + " |")
    lines += [
        "",
        "![by family](escapes/study/escapes_by_family.png)",
        "",
        "![by planner](escapes/study/escapes_by_planner.png)",
        "",
        "![traps](escapes/study/progress_traps.png)",
        "",
        "![tasks](escapes/study/progress_tasks.png)",
        "",
    ]
    return "\n".join(lines)


def cmd_estimate(args: argparse.Namespace) -> int:
    """The full study's time from a slice's trials: per (problem, planner) the mean time
    of a trial times the seeds the full study runs, summed, over ``--jobs``; in wall time
    as the slice ran (with its machine's load) and in CPU time (each trial's own: its wall
    time when it has a core to itself)."""
    recs = load(Path(args.slice))
    table = cells(recs)
    wall = cpu = 0.0
    lines = []
    for (p, m), c in sorted(table.items()):
        full = 1 if c["one_run"] else args.seeds
        wall += c["wall_s"] / c["seeds"] * full
        cpu += c["cpu_s"] / c["seeds"] * full
        lines.append((c["cpu_s"] / c["seeds"] * full, p, m, c["cpu_s"] / c["seeds"]))
    for cost, p, m, per in sorted(lines, reverse=True)[:15]:
        print(f"{p:24s} {m:34s} {per:7.1f} CPU s a trial, {cost / 60:6.1f} min in all")
    meta_path = Path(args.slice) / "study.json"
    meta = json.loads(meta_path.read_text()) if meta_path.exists() else {}
    print(
        f"the slice: {len(recs)} trials in {meta.get('wall_s', 0) / 60:.1f} min at --jobs "
        f"{meta.get('jobs')}, load average {meta.get('load_at_start', ['?'])[0]} at the start, "
        f"{meta.get('load_at_end', ['?'])[0]} at the end; its trials "
        f"{sum(c['wall_s'] for c in table.values()) / 60:.1f} wall-minutes, "
        f"{sum(c['cpu_s'] for c in table.values()) / 60:.1f} CPU-minutes"
    )
    print(
        f"full study ({args.seeds} seeds) at --jobs {args.jobs}: {cpu / 3600 / args.jobs:.2f} h "
        f"of CPU per core ({cpu / 3600:.2f} CPU-hours), {wall / 3600 / args.jobs:.2f} h at the "
        "slice's load"
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run the study (resumes)")
    r.add_argument("--seeds", default="0-19")
    r.add_argument("--jobs", type=int, default=2)
    r.add_argument("--checks", type=int, default=CHECKS, help="collision checks per leg")
    r.add_argument(
        "--guard", type=float, default=GUARD_S, help="planning seconds per leg (a guard)"
    )
    r.add_argument("--out", default=str(OUT))
    r.add_argument("--planners", default="", help="a subset, comma-separated")
    r.add_argument("--problems", default="", help="a subset, comma-separated")
    r.add_argument("--mixed", action="store_true", help="add to a store of another commit")
    r.add_argument(
        "--members",
        choices=("best", "all"),
        default="best",
        help="best: every member on the first seed (the screen), then each family's best "
        "on every seed; all: every member on every seed",
    )
    r.set_defaults(func=cmd_run)
    p = sub.add_parser("report", help="tables and figures from the store")
    p.add_argument("--out", default=str(OUT))
    p.set_defaults(func=cmd_report)
    e = sub.add_parser("estimate", help="the full study's time from a slice")
    e.add_argument("slice")
    e.add_argument("--seeds", type=int, default=20)
    e.add_argument("--jobs", type=int, default=2)
    e.set_defaults(func=cmd_estimate)
    args = ap.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())

"""The escape study's tables and figures from its trial stores (issue 18, point 5).

    python results/escapes/report.py [STORE_DIR] [--write]     (default: results/escapes)

Reads ``STORE_DIR/<problem>/trials.jsonl`` (written by ``results/escapes/run.sh``), prints
the Markdown tables that ``results/escapes.md`` holds between its ``<!-- headline -->`` and
``<!-- /table -->`` marks, and draws ``STORE_DIR/progress_traps.png`` and
``STORE_DIR/progress_tasks.png``. Only with ``--write`` does it rewrite those marks in
``results/escapes.md`` and the headline table in docs/results.md (between
``<!-- escapes -->`` marks): a report of old stores must not overwrite the current
documents by being run. Only trials that ran (not killed, no error) count
as runs; a trial killed past its wall-clock limit counts as run and failed.

Columns, per problem and planner:

- **seeds**: trials in the store; **solved**: every leg planned; **clean**: solved and
  every leg executed cleanly in PyBullet (no unexpected contact, deviation from the plan
  within ``max_deviation_m``, tip in the goal region);
- **time to solution** and **checks to solution**: median and p95 over the solved trials
  (planning time summed over legs, collision checks summed over legs; the planning time
  includes simplification and the final re-check, and for RRT*, which is made to hold its
  first path and improve it while time is left, the whole 30 s);
- **goal first reached**: median over the solved trials of the planning time until each
  leg's goal region was first reached (the progress record's first goal distance of 0),
  summed over the legs: RRT*'s time to its first path;
- **minima met / escaped**: summed over the trials (a stall the planner met, and one it
  left);
- **escape start**: over every escape attempt that left its stall, the median joint-space
  distance [rad] of the attempt's start from the stall, and from the leg's start.
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path
from statistics import median
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from plannerlab import load_problem  # noqa: E402
from plannerlab.plot.plans import save  # noqa: E402
from plannerlab.plot.study import progress_panels  # noqa: E402

TRAPS = (
    "armz_deep_a",
    "armz_deep_b",
    "armz_deep_e",
    "armz_pocket",
    "armz_window",
    "armz_cavity",
    "armz_thin_wall",
)
TASKS = ("armz_inspection_direct", "armz_inspection")
TIME_LIMIT_S = 30.0
#: the order of the rows (run.sh's)
PLANNERS = (
    "gradient",
    "gradient.clearance",
    "gradient.clearance+detour",
    "gradient.clearance+random_detour",
    "gradient.clearance+rrtconnect",
    "gradient.follow_leader",
    "gradient.follow_leader+detour",
    "gradient.follow_leader+random",
    "gradient+rrtconnect",
    "gradient.multistart",
    "ompl.rrtconnect",
    "ompl.kpiece1",
    "ompl.prm",
    "ompl.rrtstar",
    "native.rrtconnect",
    "native.rrtconnect+leader",
)


def deterministic(planner: str) -> bool:
    """A planner that ignores its seed (the registry's ``uses_rng``): its seeds are one
    run, so the study runs it on one seed and its cells read "k/1 (one run)"."""
    from plannerlab.planners import REGISTRY

    entry = REGISTRY.get(planner)
    return entry is not None and not entry.uses_rng


def planner_order(name: str) -> int:
    return PLANNERS.index(name) if name in PLANNERS else len(PLANNERS)


def load(store_dir: Path) -> dict[str, list[dict[str, Any]]]:
    out: dict[str, list[dict[str, Any]]] = {}
    for problem in TRAPS + TASKS:
        f = store_dir / problem / "trials.jsonl"
        if f.exists():
            recs = [json.loads(line) for line in f.read_text().splitlines() if line.strip()]
            # the last record of a key wins (a retried trial)
            out[problem] = list({r["key"]: r for r in recs}.values())
    return out


def pct(xs: list[float], q: float) -> float:
    return float(np.percentile(xs, q)) if xs else math.nan


def fmt(x: float, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    return f"{x:.{digits}g}" if abs(x) < 1 else f"{x:.{digits + 1}g}"


def clean(r: dict[str, Any]) -> bool:
    e = r.get("execution") or {}
    return bool(r.get("success")) and bool(e.get("success"))


def escape_starts(r: dict[str, Any]) -> list[tuple[float, float]]:
    out = []
    for leg in r.get("legs_run") or []:
        for e in (leg.get("extra") or {}).get("escapes") or []:
            if isinstance(e, dict) and e.get("left_stall"):
                out.append((float(e["start_from_stall_rad"]), float(e["start_from_leg_start_rad"])))
    return out


def first_reach_s(r: dict[str, Any]) -> float:
    """Planning time until each leg's goal region was first reached (its progress's first
    row at goal distance 0; the leg's time if none), summed over the legs: for an optimizing
    planner that keeps improving its path until the limit, the time to its first path."""
    total = 0.0
    for leg in r.get("legs_run") or []:
        at = [float(x[0]) for x in leg.get("progress") or [] if x[2] is not None and x[2] <= 0.0]
        total += at[0] if at else float(leg.get("time_s") or 0.0)
    return total


def row(problem: str, planner: str, recs: list[dict[str, Any]]) -> dict[str, Any]:
    solved = [r for r in recs if r.get("success")]
    t = [float(r["totals"]["time_s"]) for r in solved]
    c = [float(r["totals"]["collision_checks"]) for r in solved]
    ran = [r for r in recs if r.get("totals")]
    starts = [s for r in recs for s in escape_starts(r)]
    statuses: dict[str, int] = {}
    for r in recs:
        if not r.get("success"):
            statuses[str(r.get("status"))] = statuses.get(str(r.get("status")), 0) + 1
    return {
        "problem": problem,
        "planner": planner,
        "n": len(recs),
        "solved": len(solved),
        "clean": sum(clean(r) for r in recs),
        "t50": pct(t, 50),
        "t95": pct(t, 95),
        "first50": pct([first_reach_s(r) for r in solved], 50),
        "c50": pct(c, 50),
        "c95": pct(c, 95),
        "minima": sum(int(r["totals"].get("local_minima") or 0) for r in ran),
        "escaped": sum(int(r["totals"].get("escapes") or 0) for r in ran),
        "from_stall": median([s[0] for s in starts]) if starts else math.nan,
        "from_start": median([s[1] for s in starts]) if starts else math.nan,
        "failures": statuses,
        "legs": [len(r.get("legs_run") or []) for r in recs],
    }


def rows(data: dict[str, list[dict[str, Any]]]) -> list[dict[str, Any]]:
    out = []
    for problem, recs in data.items():
        planners: dict[str, list[dict[str, Any]]] = {}
        for r in sorted(recs, key=lambda r: int(r["seed"])):
            planners.setdefault(r["planner"], []).append(r)
        out += [row(problem, pl, planners[pl]) for pl in sorted(planners, key=planner_order)]
    return out


def table(rs: list[dict[str, Any]]) -> str:
    head = (
        "| problem | planner | seeds | solved | executed cleanly | time to solution "
        "median / p95 [s] | goal first reached, median [s] | checks to solution median / p95 | "
        "minima met / escaped | "
        "escape start from stall / from leg start, median [rad] | failed as |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rs:
        fails = ", ".join(f"{k} {v}" for k, v in sorted(r["failures"].items())) or "–"
        lines.append(
            f"| {r['problem']} | `{r['planner']}` | "
            f"{r['n']}{' (one run)' if deterministic(r['planner']) else ''} | "
            f"{r['solved']} | {r['clean']} | "
            f"{fmt(r['t50'])} / {fmt(r['t95'])} | {fmt(r['first50'])} | "
            f"{fmt(r['c50'])} / {fmt(r['c95'])} | "
            f"{r['minima']} / {r['escaped']} | {fmt(r['from_stall'])} / {fmt(r['from_start'])} | "
            f"{fails} |"
        )
    return head + "\n".join(lines) + "\n"


def headline(rs: list[dict[str, Any]], problems: tuple[str, ...]) -> str:
    """Planners × problems: executed cleanly / seeds."""
    present = [p for p in problems if any(r["problem"] == p for r in rs)]
    planners = sorted(dict.fromkeys(r["planner"] for r in rs), key=planner_order)
    cell = {(r["problem"], r["planner"]): r for r in rs}
    short = [p.removeprefix("armz_") for p in present]
    out = "| planner | " + " | ".join(short) + " |\n|---|" + "---|" * len(present) + "\n"
    for pl in planners:
        cells = []
        for p in present:
            r = cell.get((p, pl))
            one = " (one run)" if r and deterministic(pl) else ""
            cells.append(f"{r['clean']}/{r['n']}{one}" if r else "–")
        out += f"| `{pl}` | " + " | ".join(cells) + " |\n"
    return out


def curves(recs: list[dict[str, Any]], total_legs: int | None) -> list[list[tuple[float, float]]]:
    """Per seed: (planning time since the first leg [s], best goal distance) for a single
    leg (``total_legs`` None); for a task, (time, legs still to go)."""
    out = []
    for r in recs:
        t0 = 0.0
        pts: list[tuple[float, float]] = [] if total_legs is None else [(0.0, float(total_legs))]
        for i, leg in enumerate(r.get("legs_run") or []):
            if total_legs is None:
                pts += [
                    (t0 + float(x[0]), float(x[2]))
                    for x in leg.get("progress") or []
                    if x[2] is not None
                ]
            t0 += float(leg.get("time_s") or 0.0)
            if total_legs is not None:
                done = i + 1 if leg.get("status") == "solved" else i
                pts.append((t0, float(total_legs - done)))
        if total_legs is None and r.get("success"):
            pts.append((t0, 0.0))
        if pts:
            out.append(pts)
    return out


def figures(data: dict[str, list[dict[str, Any]]], store_dir: Path) -> None:
    for name, problems, task in (("traps", TRAPS, False), ("tasks", TASKS, True)):
        by_problem = {}
        for p in problems:
            if p not in data:
                continue
            planners: dict[str, list[dict[str, Any]]] = {}
            for r in data[p]:
                planners.setdefault(r["planner"], []).append(r)
            total = load_problem(p).legs if task else None
            by_problem[p] = {pl: curves(rs, total) for pl, rs in planners.items()}
        if not by_problem:
            continue
        fig = progress_panels(
            by_problem,
            "escape study: median over seeds"
            + (" of the legs still to go" if task else " of the best goal distance")
            + f" against planning time ({TIME_LIMIT_S:.0f} s per leg)",
            t_max_s=TIME_LIMIT_S * (7 if task else 1),
            ylabel="legs still to go (median)"
            if task
            else "best goal distance (median) [x tolerance; 0: in the goal]",
        )
        save(fig, store_dir / f"progress_{name}.png")


def main() -> None:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("store_dir", nargs="?", type=Path, default=ROOT / "results" / "escapes")
    ap.add_argument(
        "--write",
        action="store_true",
        help="rewrite the tables in results/escapes.md and docs/results.md (default: print)",
    )
    args = ap.parse_args()
    store_dir = args.store_dir
    data = load(store_dir)
    rs = rows(data)
    text = (
        "<!-- headline -->\nExecuted cleanly / seeds run, 30 s per leg:\n\n"
        + headline(rs, TRAPS + TASKS)
        + "<!-- /headline -->\n\n<!-- table -->\n"
        + table(rs)
        + "<!-- /table -->\n"
    )
    print(text)
    if args.write:
        write(rs, text)
    figures(data, store_dir)


def write(rs: list[dict[str, Any]], text: str) -> None:
    """The tables into results/escapes.md and the headline into docs/results.md."""
    md = ROOT / "results" / "escapes.md"
    if md.exists():
        old = md.read_text()
        new = re.sub(r"<!-- headline -->.*<!-- /table -->\n", lambda _: text, old, flags=re.S)
        md.write_text(new)
    readme = ROOT / "docs" / "results.md"  # the headline table there too, between its marks
    old = readme.read_text()
    head = "<!-- escapes -->\n" + headline(rs, TRAPS + TASKS) + "<!-- /escapes -->"
    readme.write_text(
        re.sub(r"<!-- escapes -->.*?<!-- /escapes -->", lambda _: head, old, flags=re.S)
    )


if __name__ == "__main__":
    main()

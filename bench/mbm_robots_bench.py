"""MotionBenchMaker's UR5 and Fetch sets (and the Panda's): every problem solved by
plannerlab's planners, each path re-checked; resumable.

Import the sets first (vamp-planner 0.6.4 sdist through pip into a cache outside the
repository; 7 scenarios × 100 problems each)::

    PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --robot ur5 --out /tmp/mbm/ur5
    PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --robot fetch \
        --out /tmp/mbm/fetch

then, per robot (one JSON line per problem is appended to ``--log``; a run started again
with the same log skips the problems already there, so it can be stopped and resumed)::

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/mbm_robots_bench.py /tmp/mbm/ur5 \\
        --log /tmp/mbm/ur5.jsonl [--planner ompl.rrtconnect] [--time-limit 10] [--interleave]
    PYTHONPATH=. .venv/bin/python bench/mbm_robots_bench.py --report /tmp/mbm/ur5.jsonl

Each problem: one ``solve`` of its leg with the planner's defaults (seed = the problem's
index in name order), then the path re-checked by plannerlab's checker (compiled core, no
margin) with edges cut so that no joint moves more than ``--recheck-step`` (default 0.0025
rad, an eighth of the imported ``joint_step``), its ends compared with the start and the
goal. A problem counts solved only if its path passes. For every problem not solved the log
says why, and whether its start and goal states are valid in the spherized model.

The report prints solved counts per scenario, the median and 95th percentile of the
planning time (the leg's ``time_s``) and the whole call, the statuses, and the failures;
times carry the machine's load average as logged, as the machine is shared.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

SCENARIOS = (
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "box",
    "cage",
    "table_pick",
    "table_under_pick",
)


def state_why(problem: Any, q: Any) -> str:
    """Why state ``q`` is invalid for plannerlab's checker (no margin); "" if valid."""
    import numpy as np

    from plannerlab.collision.fcl_checker import CollisionChecker

    checker = CollisionChecker(problem.robot, problem.scene, backend="core", margin_m=0.0)
    q = np.asarray(q, dtype=float)
    lo, hi = np.asarray(problem.robot.lower), np.asarray(problem.robot.upper)
    if np.any(q < lo - 1e-9) or np.any(q > hi + 1e-9):
        return "outside the joint limits"
    check = checker.check_path(np.stack([q, q]), 1.0)
    if check.valid:
        return ""
    return "in collision: " + ", ".join(" x ".join(p) for p in check.pairs[:3])


def run(args: argparse.Namespace) -> None:
    import numpy as np
    from mbm_bench import recheck

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget, parse_problem

    per = [sorted(args.folder.glob(f"{s}_[0-9]*.toml"))[: args.per_scenario] for s in SCENARIOS]
    if args.interleave:  # problem 1 of every scenario, then problem 2, ...: a run cut
        # short covers every scenario
        files = [f for k in range(max(map(len, per))) for group in per for f in group[k : k + 1]]
    else:
        files = [f for group in per for f in group]
    if not files:
        sys.exit(f"no imported MotionBenchMaker problem files in {args.folder}")
    if args.reverse:
        files = files[::-1]
    done: set[str] = set()
    for log_path in [args.log, *args.skip_logged]:
        if log_path.is_file():
            for line in log_path.read_text().splitlines():
                if line.startswith("{"):
                    done.add(json.loads(line)["name"])
    todo = [(i, f) for i, f in enumerate(files) if f.stem not in done]
    print(f"{len(files)} problems, {len(done)} done, {len(todo)} to go", flush=True)
    overrides = {k: json.loads(v) for k, v in (kv.split("=", 1) for kv in args.set)}
    planner = make_planner(args.planner, overrides)
    clock = time.process_time if args.cpu_clock else None
    budget = Budget(time_limit_s=args.time_limit, clock=clock)
    warm = parse_problem(files[0])
    planner.solve(warm, 0, budget, np.random.default_rng(10**6))  # untimed warm-up
    index = {f: i for i, f in enumerate(sorted(files))}

    def logged_elsewhere() -> set[str]:
        names: set[str] = set()
        for log_path in args.skip_logged:
            if log_path.is_file():
                names |= {
                    json.loads(s)["name"]
                    for s in log_path.read_text().splitlines()
                    if s.startswith("{")
                }
        return names

    with args.log.open("a") as log:
        for _, f in todo:
            if f.stem in logged_elsewhere():  # the other process got there first
                continue
            i = index[f]
            p = parse_problem(f)
            t0, c0 = time.perf_counter(), time.process_time()
            r = planner.solve(p, 0, budget, np.random.default_rng(i))
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            solved = r.status.name == "SOLVED"
            why = recheck(p, r.path, args.recheck_step) if solved else ""
            rec: dict[str, Any] = {
                "name": p.name,
                "seed": i,
                "planner": args.planner,
                "status": r.status.name,
                "solved": solved and not why,
                "recheck": why,
                "plan_s": r.time_s,
                "wall_s": wall,
                "cpu_s": cpu,
                "checks": r.collision_checks,
                "reason": r.reason,
                "load": os.getloadavg()[0],
                "overrides": overrides,
                "clock": "cpu" if args.cpu_clock else "wall",
                "iterations": r.iterations,
                **{k: r.extra[k] for k in ("nodes", "goal_pool", "range_rad") if k in r.extra},
            }
            if not rec["solved"]:
                rec["start_why"] = state_why(p, p.q_start)
                rec["goal_why"] = state_why(p, p.goal(0).q_rad)
            log.write(json.dumps(rec) + "\n")
            log.flush()
            print(f"{p.name}: {r.status.name} {wall:.3f} s {why}", flush=True)


def report(logs: list[Path]) -> None:
    import numpy as np

    for path in logs:
        recs = [json.loads(s) for s in path.read_text().splitlines() if s.startswith("{")]
        if not recs:
            print(f"{path}: empty")
            continue
        print(f"## {path.name}: {recs[0]['planner']}, {len(recs)} problems logged")
        print(
            "| scenario | solved (re-checked) | failed re-check | median planning ms "
            "| p95 planning ms | median whole call ms |"
        )
        print("|---|---|---|---|---|---|")
        groups: dict[str, list[dict[str, Any]]] = {}
        for r in recs:
            groups.setdefault(r["name"].rsplit("_", 1)[0], []).append(r)
        groups["all"] = recs
        for name, rs in groups.items():
            ok = [r for r in rs if r["solved"]]
            bad = sum(1 for r in rs if r["status"] == "SOLVED" and not r["solved"])
            pt = np.array([r["plan_s"] for r in ok] or [np.nan]) * 1e3
            wt = np.array([r["wall_s"] for r in ok] or [np.nan]) * 1e3
            print(
                f"| {name} | {len(ok)}/{len(rs)} | {bad} | {np.median(pt):.1f} | "
                f"{np.percentile(pt, 95):.1f} | {np.median(wt):.1f} |"
            )
        loads = [r["load"] for r in recs]
        statuses = {k: sum(r["status"] == k for r in recs) for k in {r["status"] for r in recs}}
        print(
            f"statuses {statuses}; load average {min(loads):.1f}-{max(loads):.1f} "
            f"(median {np.median(loads):.1f}) on {os.cpu_count()} cores"
        )
        for r in recs:
            if not r["solved"]:
                print(
                    f"  not solved: {r['name']}: {r['status']} {r['recheck']} "
                    f"{r['reason'][:160]}; start: {r.get('start_why') or 'valid'}; "
                    f"goal: {r.get('goal_why') or 'valid'}"
                )
        print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported problem files")
    ap.add_argument("--log", type=Path, help="JSON lines, appended (resumable)")
    ap.add_argument("--planner", default="ompl.rrtconnect")
    ap.add_argument("--per-scenario", type=int, default=100)
    ap.add_argument("--interleave", action="store_true", help="round-robin over scenarios")
    ap.add_argument("--reverse", action="store_true", help="last problem first")
    ap.add_argument(
        "--skip-logged",
        type=Path,
        nargs="*",
        default=[],
        help="also skip the problems of these logs (a second process from the other end)",
    )
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument(
        "--cpu-clock",
        action="store_true",
        help="read the time limit on the process's CPU time (time.process_time): on a "
        "shared machine, about what the limit gives on an idle core",
    )
    ap.add_argument(
        "--set", action="append", default=[], metavar="KEY=JSON",
        help="a planner setting overridden (repeatable), e.g. --set range_rad=1.0",
    )  # fmt: skip
    ap.add_argument("--recheck-step", type=float, default=0.0025, help="[rad]")
    ap.add_argument("--report", type=Path, nargs="*", help="summarise these logs")
    args = ap.parse_args()
    if args.report:
        report(args.report)
        return
    if args.folder is None or args.log is None:
        ap.error("a folder of imported problem files and --log are needed")
    run(args)


if __name__ == "__main__":
    main()

"""``native.rrtconnect`` of this checkout against a baseline checkout, in one run: planning
time, the whole call and the checks per second, with ratios new / baseline and the
machine's load.

Each side runs in its own process (``PYTHONPATH`` = its checkout), on the same problems
and seeds, in alternating rounds (baseline, new, baseline, new, …) so that both see the
same load; a problem's time is its mean over the rounds. Problems: the first
``--per-scenario`` MotionBenchMaker Panda problems of each ``--scenarios`` (import them
first, ``python -m plannerlab import mbm --fetch --out /tmp/mbm``; ``--time-limit`` each)
and the Arm-Z traps (``--trap-time-limit`` each, seeds 0 and 1; their figure is
checks / ``time_s``, as ``bench/native_bench.py`` reports it).

"Planning time" is the leg's ``time_s`` (the budget clock: after the checker is built,
to the end of the planner's re-check); "whole call" is ``solve`` from the caller's side
(the checker and the compiled model built, the context, the result). Every path is
re-checked by the side's own checker (``check_path(path, joint_step / 4, mode="grid")``)
and by the FCL reference on the same grid; a solution counts only if it passes both.

Same search: each side also solves every problem on a collision-check budget with no
time limit (the search then does not depend on the machine); the bench reports how many
problems gave the same path, checks and iterations on both sides.

Run (a baseline checkout, e.g. ``git worktree add /tmp/base main``)::

    PYTHONPATH=. .venv/bin/python bench/native_overhead_bench.py /tmp/mbm --baseline /tmp/base
        [--per-scenario 10] [--rounds 2] [--scenarios box,cage] [--skip-traps]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
TRAPS = ("armz_pocket", "armz_window", "armz_cavity", "armz_thin_wall")
SAME_SEARCH_CHECKS = 2_000_000


def worker(spec_path: str) -> None:
    """Runs in one side's process: every job of the spec, one JSON line each."""
    import numpy as np

    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners import make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget, parse_problem

    spec = json.loads(Path(spec_path).read_text())
    planner = make_planner("native.rrtconnect")
    problems: dict[str, Any] = {}

    def problem(job: dict[str, Any]) -> Any:
        key = job["name"]
        if key not in problems:
            problems[key] = parse_problem(Path(job["path"])) if job["path"] else load_problem(key)
            planner.solve(problems[key], 0, Budget(max_iterations=1), np.random.default_rng(99))
        return problems[key]

    for job in spec["jobs"]:
        p = problem(job)
        budget = (
            Budget(max_collision_checks=SAME_SEARCH_CHECKS)
            if job["same_search"]
            else Budget(time_limit_s=job["time_limit_s"])
        )
        t0 = time.perf_counter()
        r = planner.solve(p, 0, budget, np.random.default_rng(job["seed"]))
        whole = time.perf_counter() - t0
        ok = False
        if r.status.value == "solved":
            step = p.joint_step / 4.0
            ok = bool(problem_checker(p).check_path(r.path, step, mode="grid").valid) and bool(
                problem_checker(p, backend="fcl").check_path(r.path, step, mode="grid").valid
            )
        row = {
            "name": job["name"],
            "seed": job["seed"],
            "same_search": job["same_search"],
            "status": r.status.value,
            "ok": ok,
            "time_s": r.time_s,
            "whole_s": whole,
            "checks": r.collision_checks,
            "iterations": r.iterations,
            "path": hashlib.sha1(np.ascontiguousarray(r.path).tobytes()).hexdigest(),
        }
        print(json.dumps(row), flush=True)


def run_side(root: Path, jobs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump({"jobs": jobs}, f)
    env = dict(os.environ, PYTHONPATH=str(root))
    code = (
        "import importlib.util, sys; "
        f"s = importlib.util.spec_from_file_location('b', {str(Path(__file__).resolve())!r}); "
        "m = importlib.util.module_from_spec(s); s.loader.exec_module(m); m.worker(sys.argv[1])"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, f.name],
        env=env,
        cwd=root,
        capture_output=True,
        text=True,
        check=False,
    )
    Path(f.name).unlink()
    rows = [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]
    if out.returncode != 0 or len(rows) != len(jobs):
        raise SystemExit(f"worker in {root} failed:\n{out.stderr[-3000:]}")
    return rows


def pct(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(q * (len(xs) - 1))))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, help="imported MotionBenchMaker problems")
    ap.add_argument("--baseline", type=Path, required=True, help="the baseline checkout")
    ap.add_argument("--scenarios", default="bookshelf_small,box,cage")
    ap.add_argument("--per-scenario", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--time-limit", type=float, default=10.0)
    ap.add_argument("--trap-time-limit", type=float, default=3.0)
    ap.add_argument("--skip-traps", action="store_true")
    args = ap.parse_args()
    sides = {"baseline": args.baseline.resolve(), "new": ROOT}
    mbm = []
    for sc in args.scenarios.split(","):
        files = sorted(args.folder.glob(f"{sc}_[0-9]*.toml"))[: args.per_scenario]
        mbm += [{"name": f.stem, "path": str(f), "seed": 0} for f in files]
    traps = (
        []
        if args.skip_traps
        else [{"name": n, "path": "", "seed": s} for n in TRAPS for s in (0, 1)]
    )
    timed = [dict(j, same_search=False, time_limit_s=args.time_limit) for j in mbm] + [
        dict(j, same_search=False, time_limit_s=args.trap_time_limit) for j in traps
    ]
    same = [dict(j, same_search=True, time_limit_s=None) for j in mbm + traps]
    load0 = os.getloadavg()
    rows: dict[str, list[dict[str, Any]]] = {k: [] for k in sides}
    for r in range(args.rounds):
        for side, root in sides.items():
            rows[side] += run_side(root, timed + (same if r == 0 else []))
            print(f"  round {r + 1}, {side} done", flush=True)
    load1 = os.getloadavg()

    def per_problem(side: str, names: set[str]) -> dict[tuple[str, int], dict[str, float]]:
        acc: dict[tuple[str, int], list[dict[str, Any]]] = {}
        for row in rows[side]:
            if not row["same_search"] and row["name"] in names:
                acc.setdefault((row["name"], row["seed"]), []).append(row)
        return {
            k: {
                "time_s": statistics.mean(x["time_s"] for x in v),
                "whole_s": statistics.mean(x["whole_s"] for x in v),
                "checks": statistics.mean(x["checks"] for x in v),
                "ok": all(x["ok"] for x in v),
            }
            for k, v in acc.items()
        }

    print(
        f"\n## native.rrtconnect: new ({ROOT}) against baseline ({sides['baseline']})\n\n"
        f"load average {load0[0]:.1f} at the start, {load1[0]:.1f} at the end; "
        f"{os.cpu_count()} cores; {args.rounds} rounds, alternating\n"
    )
    names = {j["name"] for j in mbm}
    if mbm:
        st = {s: per_problem(s, names) for s in sides}
        print(
            f"### MotionBenchMaker Panda ({len(mbm)} problems: {args.per_scenario} each of "
            f"{args.scenarios}; {args.time_limit:g} s, seed 0)\n"
        )
        print("| side | solved and re-checked | median planning time | p95 | median whole call |")
        print("|---|---|---|---|---|")
        med = {}
        for s in sides:
            v = st[s].values()
            t = [x["time_s"] for x in v]
            w = [x["whole_s"] for x in v]
            med[s] = (statistics.median(t), pct(t, 0.95), statistics.median(w))
            print(
                f"| {s} | {sum(x['ok'] for x in v)}/{len(mbm)} | {med[s][0] * 1e3:.2f} ms | "
                f"{med[s][1] * 1e3:.2f} ms | {med[s][2] * 1e3:.2f} ms |"
            )
        ratios = [st["new"][k]["time_s"] / st["baseline"][k]["time_s"] for k in st["new"]]
        print(
            f"\nnew / baseline: median planning time {med['new'][0] / med['baseline'][0]:.3f}, "
            f"p95 {med['new'][1] / med['baseline'][1]:.3f}, whole call "
            f"{med['new'][2] / med['baseline'][2]:.3f}; median of per-problem ratios "
            f"{statistics.median(ratios):.3f}\n"
        )
    if traps:
        tn = set(TRAPS)
        st = {s: per_problem(s, tn) for s in sides}
        print(f"### Arm-Z traps: checks / planning time ({args.trap_time_limit:g} s, seeds 0, 1)\n")
        print("| problem | baseline | new | new / baseline |")
        print("|---|---|---|---|")
        for n in TRAPS:
            rate = {}
            for s in sides:
                v = [x for (name, _), x in st[s].items() if name == n]
                rate[s] = sum(x["checks"] for x in v) / sum(x["time_s"] for x in v)
            ratio = rate["new"] / rate["baseline"]
            print(f"| {n} | {rate['baseline']:,.0f} | {rate['new']:,.0f} | {ratio:.2f} |")
    key = ("path", "checks", "iterations", "status")
    by = {
        s: {(r["name"], r["seed"]): tuple(r[k] for k in key) for r in rows[s] if r["same_search"]}
        for s in sides
    }
    n_same = sum(by["new"][k] == by["baseline"][k] for k in by["new"])
    print(
        f"\nsame search (a budget of {SAME_SEARCH_CHECKS:,} checks, no time limit): "
        f"{n_same}/{len(by['new'])} problems gave the same path, checks, iterations and status"
    )


if __name__ == "__main__":
    main()

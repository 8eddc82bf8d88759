"""The compiled sampling planners (``native.rrtconnect``) beside ``ompl.rrtconnect`` and
VAMP, ratios from one run, with the machine's load.

(a) MotionBenchMaker's Panda problems (import them first; the set comes through pip into
    ``~/.cache/plannerlab/mbm``)::

        PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --out /tmp/mbm

    ``native.rrtconnect`` and ``ompl.rrtconnect`` on the same problems, one after the other
    on each problem (so both see the same load), ``--time-limit`` each (default 10 s),
    after one untimed warm-up solve each. "Planning time" is the leg's ``time_s`` (its
    budget clock: from after the checker is built to the end of the planner's own
    re-check). Every solution is re-checked here by plannerlab's checker
    (``check_path(path, joint_step / 4, mode="grid")``, the problem's margin) and counted
    only if it passes. Default: the first 20 of ``bookshelf_small``, ``box``, ``cage``;
    ``--all``: the 700.
(b) VAMP (vamp-planner 0.6.4, built into ``--vamp-python``'s venv, see
    ``../shared/peers/vamp/README.md``) on the same problems in a subprocess: its
    RRT-Connect with its defaults (Halton sampler), planning time (its own ``nanoseconds``)
    and the whole call; its simplified paths are re-checked by plannerlab's checker too.
(c) The Arm-Z traps: collision checks per second of each planner (``collision_checks /
    time_s`` of a solve with ``--trap-time-limit``), seeds 0 and 1.

Run::

    PYTHONPATH=. .venv/bin/python bench/native_bench.py /tmp/mbm [--all] [--time-limit 10]
        [--vamp-python ~/.cache/vamp-peer/venv/bin/python] [--skip-traps]
"""

from __future__ import annotations

import argparse
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
SCENARIOS = (
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "box",
    "cage",
    "table_pick",
    "table_under_pick",
)
DEFAULT_SCENARIOS = ("bookshelf_small", "box", "cage")
TRAPS = ("armz_pocket", "armz_window", "armz_cavity", "armz_thin_wall")
VAMP_SDIST = Path.home() / ".cache" / "vamp-peer" / "vamp_planner-0.6.4"


# ---------------------------------------------------------------------- VAMP (own venv)
def vamp_worker(spec_path: str) -> None:
    """Runs in VAMP's venv: RRT-Connect (defaults, Halton) and its simplification on each
    (scenario, index); one JSON line per problem."""
    import pickle

    import vamp

    spec = json.loads(Path(spec_path).read_text())
    with open(Path(spec["sdist"]) / "resources" / "panda" / "problems.pkl", "rb") as f:
        problems = pickle.load(f)["problems"]
    module, planner, plan_settings, simp_settings = vamp.configure_robot_and_planner_with_kwargs(
        "panda", "rrtc"
    )
    sampler = module.halton()
    warm = problems[spec["jobs"][0][1]][spec["jobs"][0][2]]
    planner(warm["start"], warm["goals"], vamp.problem_dict_to_vamp(warm), plan_settings, sampler)
    for name, scenario, index in spec["jobs"]:
        data = problems[scenario][index]
        env = vamp.problem_dict_to_vamp(data)
        sampler.reset()
        t0 = time.perf_counter()
        res = planner(data["start"], data["goals"], env, plan_settings, sampler)
        plan_wall = time.perf_counter() - t0
        row: dict[str, Any] = {"name": name, "valid": bool(data["valid"]), "solved": False}
        if res.solved:
            t1 = time.perf_counter()
            simple = module.simplify(res.path, env, simp_settings, sampler)
            row.update(
                solved=True,
                plan_s=res.nanoseconds * 1e-9,
                call_s=plan_wall + time.perf_counter() - t1,
                iterations=int(res.iterations),
                path=simple.path.numpy().tolist(),
            )
        print(json.dumps(row), flush=True)


# ---------------------------------------------------------------------- plannerlab side
def recheck(problem: Any, path: Any) -> str:
    """Why a path fails plannerlab's grid re-check at joint_step / 4 with the problem's
    margin (or does not start at the start / end in the goal region); "" if it passes."""
    import numpy as np

    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.robots.base import joint_difference

    robot, goal = problem.robot, problem.goal(0)
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if np.max(np.abs(joint_difference(P[0], problem.q_start, robot.continuous))) > 1e-6:
        return "does not start at the start"
    if not bool(goal.contains(robot, P[-1])):
        return "ends outside the goal region"
    check = problem_checker(problem).check_path(P, problem.joint_step / 4.0, mode="grid")
    return "" if check.valid else f"edge {check.first_invalid_edge}: {check.pairs[:2]}"


def solve_once(planner: Any, problem: Any, budget: Any, seed: int) -> dict[str, Any]:
    import numpy as np

    from plannerlab.robots.paths import path_length

    t0 = time.perf_counter()
    r = planner.solve(problem, 0, budget, np.random.default_rng(seed))
    wall = time.perf_counter() - t0
    row = {
        "length_rad": path_length(r.path, problem.robot.continuous),
        "status": r.status.value,
        "plan_s": r.time_s,
        "wall_s": wall,
        "checks": r.collision_checks,
        "iterations": r.iterations,
        "path": r.path,
        "reason": r.reason,
    }
    row["ok"] = r.status.value == "solved" and not (why := recheck(problem, r.path))
    if r.status.value == "solved" and why:
        row["recheck"] = why
    return row


def stats(times: list[float]) -> tuple[float, float]:
    import numpy as np

    if not times:
        return float("nan"), float("nan")
    return float(np.median(times)), float(np.percentile(times, 95))


def ms(x: float) -> str:
    return f"{x * 1e3:.2f} ms" if x >= 1e-3 else f"{x * 1e6:.0f} µs"


def mbm(args: argparse.Namespace) -> list[str]:
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget, parse_problem

    scenarios = SCENARIOS if args.all else DEFAULT_SCENARIOS
    per = 100 if args.all else args.per_scenario
    files = []
    for s in scenarios:
        files += sorted(args.folder.glob(f"{s}_[0-9]*.toml"))[:per]
    if not files:
        sys.exit(f"no imported MotionBenchMaker problem files in {args.folder}")
    problems = [parse_problem(f) for f in files]
    budget = Budget(time_limit_s=args.time_limit)
    names = ("native.rrtconnect", "ompl.rrtconnect")
    planners = {n: make_planner(n) for n in names}
    for n in names:  # warm-up, untimed (compiled kernels, OMPL)
        planners[n].solve(problems[0], 0, budget, __import__("numpy").random.default_rng(10**6))
    load0 = os.getloadavg()[0]
    runs: dict[str, list[dict[str, Any]]] = {n: [] for n in names}
    for i, p in enumerate(problems):
        for n in names:
            runs[n].append(solve_once(planners[n], p, budget, i))
        if (i + 1) % 20 == 0:
            print(f"  {i + 1}/{len(problems)} problems", flush=True)
    invalid = {
        p.name
        for p, r in zip(problems, runs["ompl.rrtconnect"], strict=True)
        if r["status"] in ("invalid_start", "invalid_goal")
    }
    out = [
        f"### (a) MotionBenchMaker Panda: {len(problems)} problems "
        f"({', '.join(scenarios)}; first {per} each), {args.time_limit:g} s each",
        "",
        f"load average {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end, "
        f"{os.cpu_count()} cores; {len(invalid)} problems invalid (start or goal in "
        "collision: " + (", ".join(sorted(invalid)) or "none") + ")",
        "",
        "| planner | solved and re-checked | median planning time | p95 | median checks |"
        " median whole call | median path length |",
        "|---|---|---|---|---|---|---|",
    ]
    med = {}
    for n in names:
        ok = [r for r in runs[n] if r["ok"]]
        t = [r["plan_s"] for r in ok]
        m, p95 = stats(t)
        med[n] = (m, p95)
        bad = sum(1 for r in runs[n] if "recheck" in r)
        out.append(
            f"| `{n}` | {len(ok)}/{len(problems) - len(invalid)}"
            + (f" ({bad} refused by the re-check)" if bad else "")
            + f" | {ms(m)} | {ms(p95)} | {statistics.median([r['checks'] for r in ok] or [0]):.0f}"
            f" | {ms(stats([r['wall_s'] for r in ok])[0])}"
            f" | {stats([r['length_rad'] for r in ok])[0]:.2f} rad |"
        )
    # the ratio on the problems both solved
    both = [
        (a["plan_s"], b["plan_s"])
        for a, b in zip(runs["native.rrtconnect"], runs["ompl.rrtconnect"], strict=True)
        if a["ok"] and b["ok"]
    ]
    out += [
        "",
        f"ratio native / ompl, median planning time: "
        f"{med['native.rrtconnect'][0] / med['ompl.rrtconnect'][0]:.3f} "
        f"(target ≤ 1/40 = 0.025); p95: "
        f"{med['native.rrtconnect'][1] / med['ompl.rrtconnect'][1]:.3f} (target ≤ 0.05); "
        f"median of the per-problem ratios on the {len(both)} both solved: "
        f"{statistics.median([a / b for a, b in both]) if both else float('nan'):.3f}",
    ]
    unsolved = [
        f"{p.name}: {r['status']} ({r['reason'][:100]})"
        for p, r in zip(problems, runs["native.rrtconnect"], strict=True)
        if not r["ok"] and p.name not in invalid
    ]
    if unsolved:
        out += ["", "native.rrtconnect did not solve: " + "; ".join(unsolved)]
    out += vamp_rows(args, problems, runs["native.rrtconnect"], invalid)
    return out


def vamp_rows(
    args: argparse.Namespace, problems: list[Any], native: list[dict[str, Any]], invalid: set[str]
) -> list[str]:
    py = Path(args.vamp_python).expanduser()
    if not py.exists():
        return ["", f"VAMP skipped: {py} not found (../shared/peers/vamp/README.md)"]
    jobs = []
    for p in problems:
        scenario, index = p.name.rsplit("_", 1)
        jobs.append((p.name, scenario, int(index) - 1))
    with tempfile.TemporaryDirectory(prefix="native_bench_") as tmp:
        spec = Path(tmp) / "spec.json"
        spec.write_text(json.dumps({"sdist": str(args.vamp_sdist), "jobs": jobs}))
        proc = subprocess.run(
            [str(py), __file__, "--vamp-worker", str(spec)],
            capture_output=True,
            text=True,
            timeout=3600,
        )
    if proc.returncode != 0:
        return ["", f"VAMP failed: {proc.stderr[-2000:]}"]
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    by_name = {p.name: p for p in problems}
    ok, refused = [], 0
    for r in rows:
        if r["solved"]:
            if recheck(by_name[r["name"]], r["path"]):
                refused += 1
            else:
                ok.append(r)
    vm, vp = stats([r["plan_s"] for r in ok])
    vc = stats([r["call_s"] for r in ok])[0]
    nm = stats([r["plan_s"] for r in native if r["ok"]])[0]
    return [
        "",
        "### (b) VAMP beside it (same problems, same run, its own venv)",
        "",
        "| planner | solved (re-checked by plannerlab) | median planning time | p95 |"
        " median whole call |",
        "|---|---|---|---|---|",
        f"| VAMP 0.6.4 RRT-Connect | {len(ok)}/{len(problems) - len(invalid)}"
        + (f" ({refused} of its simplified paths refused by the re-check)" if refused else "")
        + f" | {ms(vm)} | {ms(vp)} | {ms(vc)} |",
        "",
        f"ratio of medians native / VAMP (planning time): {nm / vm:.1f} (goal ≤ 10)",
    ]


def traps(args: argparse.Namespace) -> list[str]:
    import numpy as np

    from plannerlab.planners import make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget

    budget = Budget(time_limit_s=args.trap_time_limit)
    names = ("native.rrtconnect", "ompl.rrtconnect")
    planners = {n: make_planner(n) for n in names}
    out = [
        "",
        f"### (c) Arm-Z traps: collision checks per second ({args.trap_time_limit:g} s per "
        f"solve, seeds 0 and 1; load average {os.getloadavg()[0]:.1f})",
        "",
        "| problem | native.rrtconnect checks/s (statuses) | ompl.rrtconnect checks/s (statuses) |"
        " ratio |",
        "|---|---|---|---|",
    ]
    ratios = []
    for name in TRAPS:
        p = load_problem(name)
        rate, status = {}, {}
        for n in names:
            planners[n].solve(p, 0, Budget(max_iterations=1), np.random.default_rng(99))  # warm
            rows = [solve_once(planners[n], p, budget, s) for s in (0, 1)]
            rate[n] = sum(r["checks"] for r in rows) / sum(r["plan_s"] for r in rows)
            status[n] = ", ".join(
                r["status"] + ("" if r["ok"] or r["status"] != "solved" else " (refused)")
                for r in rows
            )
        ratio = rate["native.rrtconnect"] / rate["ompl.rrtconnect"]
        ratios.append(ratio)
        out.append(
            f"| {name} | {rate['native.rrtconnect']:,.0f} ({status['native.rrtconnect']}) | "
            f"{rate['ompl.rrtconnect']:,.0f} ({status['ompl.rrtconnect']}) | {ratio:.1f} |"
        )
        print(f"  {name} done", flush=True)
    out += ["", f"smallest ratio {min(ratios):.1f} (target ≥ 30)"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported MotionBenchMaker problems")
    ap.add_argument("--all", action="store_true", help="all 700 problems")
    ap.add_argument("--per-scenario", type=int, default=20)
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument("--trap-time-limit", type=float, default=3.0, help="per trap solve [s]")
    ap.add_argument("--vamp-python", default="~/.cache/vamp-peer/venv/bin/python")
    ap.add_argument("--vamp-sdist", type=Path, default=VAMP_SDIST)
    ap.add_argument("--skip-mbm", action="store_true")
    ap.add_argument("--skip-traps", action="store_true")
    ap.add_argument("--vamp-worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.vamp_worker:
        vamp_worker(args.vamp_worker)
        return
    lines = [f"commit {_commit()}; load average {os.getloadavg()[0]:.1f}", ""]
    if not args.skip_mbm:
        if args.folder is None:
            ap.error("the folder of imported problem files is needed (or --skip-mbm)")
        lines += mbm(args)
    if not args.skip_traps:
        lines += traps(args)
    print("\n".join(lines))


def _commit() -> str:
    try:
        return subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT
        ).stdout.strip()
    except OSError:
        return "?"


if __name__ == "__main__":
    main()

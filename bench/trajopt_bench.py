"""The trajectory optimisers (``trajopt.*``, issue 34) beside ``native.rrtconnect`` (its
simplified path) and VAMP on MotionBenchMaker's Panda, ratios from one run, with the
machine's load; and the solvers measured against each other.

Import the problems first (the set comes through pip into ``~/.cache/plannerlab/mbm``)::

    PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --out /tmp/mbm

(a) The first ``--per-scenario`` (20) problems of ``bookshelf_small``, ``box`` and
    ``cage`` (the first 60, as ``bench/native_bench.py``), ``--time-limit`` (10 s) each,
    every planner on a problem one after the other (the same load), after one untimed
    warm-up solve each. "Time" is the leg's ``time_s`` (its budget clock: from after the
    checker is built to the end of the planner's own re-check; the optimisers' set-up,
    their sphere field, is inside it). Every path is re-checked here
    (``check_path(path, joint_step / 4, mode="grid")``, the problem's margin) and counted
    only if it passes and ends in the goal; with ``--execute`` every counted path is
    executed in PyBullet on the problem's URDF (the spherized Panda), and "executed
    cleanly" is the execution's verdict (no contact, deviation within its limit, goal
    reached). Roughness: :func:`plannerlab.robots.paths.roughness` (the sum of squared
    turning angles of the path resampled at 200 states of equal joint-space arc length).
(b) VAMP (vamp-planner 0.6.4 in ``--vamp-python``'s venv, ``../shared/peers/vamp/``): its
    RRT-Connect and its simplification, through ``bench/native_bench.py``'s worker, its
    paths re-checked and their roughness and length measured the same way.
(c) ``--solvers``: ``trajopt.line`` with each solver (``gauss_newton``, ``lbfgs``,
    ``auglag``) on the first ``--solver-problems`` problems of each scenario: solved,
    merit evaluations, time.

The bench runs with ``OPENBLAS_NUM_THREADS=1`` unless it is set: L-BFGS-B's C core calls
BLAS on vectors of a few hundred numbers, and on the shared 2-core machine (load 15)
OpenBLAS's threads made each of its iterations take 21 ms instead of 2 (measured with
cProfile on ``box_0001``: 2.43 s against 0.25 s for the same 56 evaluations).

Run::

    PYTHONPATH=. .venv/bin/python bench/trajopt_bench.py /tmp/mbm [--execute] [--solvers]
        [--planners trajopt.line+rrtconnect,trajopt.rrtconnect] [--per-scenario 20]
        [--offset 0]   # another sample: skip that many problems of each scenario
        [--time-limit 10] [--vamp-python ~/.cache/vamp-peer/venv/bin/python]
        [--rows rows.jsonl]   # each solve as it ends; a rerun resumes from them
"""

from __future__ import annotations

import argparse
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy (see the docstring)
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ("bookshelf_small", "box", "cage")
BASELINE = "native.rrtconnect"
VAMP_SDIST = Path.home() / ".cache" / "vamp-peer" / "vamp_planner-0.6.4"


def recheck(problem: Any, path: Any) -> str:
    """Why a path fails the grid re-check at joint_step / 4 with the problem's margin (or
    does not start at the start / end in the goal region); "" if it passes."""
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


def measured(problem: Any, path: Any) -> dict[str, float]:
    import numpy as np

    from plannerlab.robots.paths import path_length, roughness

    P = np.atleast_2d(np.asarray(path, dtype=float))
    cont = problem.robot.continuous
    return {"roughness": roughness(P, cont), "length_rad": path_length(P, cont)}


def solve_once(planner: Any, problem: Any, budget: Any, seed: int, execute: bool) -> dict:
    import numpy as np

    r = planner.solve(problem, 0, budget, np.random.default_rng(seed))
    row: dict[str, Any] = {
        "status": r.status.value,
        "time_s": r.time_s,
        "checks": r.collision_checks,
        "iterations": r.iterations,
        "reason": r.reason,
        "optimised": r.extra.get("optimised"),
    }
    why = recheck(problem, r.path) if r.status.value == "solved" else "not solved"
    row["ok"] = not why
    if r.status.value == "solved" and why:
        row["refused"] = why
    if row["ok"]:
        row.update(measured(problem, r.path))
        if execute:
            from plannerlab.run.pipeline import execute_results

            ex = execute_results(problem, [r])[0]
            row["executed"] = bool(ex.success)
            row["exec_reason"] = ex.reason
    return row


def med(xs: list[float]) -> float:
    return float(statistics.median(xs)) if xs else float("nan")


def p95(xs: list[float]) -> float:
    import numpy as np

    return float(np.percentile(xs, 95)) if xs else float("nan")


def ms(x: float) -> str:
    return f"{x * 1e3:.1f} ms"


def load_problems(args: argparse.Namespace, per: int) -> list[Any]:
    from plannerlab.problem.load import parse_problem

    files: list[Path] = []
    for s in SCENARIOS:
        files += sorted(args.folder.glob(f"{s}_[0-9]*.toml"))[args.offset : args.offset + per]
    if not files:
        sys.exit(f"no imported MotionBenchMaker problem files in {args.folder}")
    return [parse_problem(f) for f in files]


def mbm(args: argparse.Namespace) -> list[str]:
    import numpy as np

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    problems = load_problems(args, args.per_scenario)
    budget = Budget(time_limit_s=args.time_limit)
    names = [BASELINE, *[n for n in args.planners.split(",") if n and n != BASELINE]]
    runs: dict[str, list[dict[str, Any]]] = {n: [] for n in names}
    done = _rows_done(args.rows)
    planners = {n: make_planner(n) for n in names}
    for n in names:  # warm-up, untimed (compiled kernels)
        planners[n].solve(problems[0], 0, budget, np.random.default_rng(10**6))
    load0 = os.getloadavg()
    for i, p in enumerate(problems):
        for n in names:
            row = done.get((p.name, n))
            if row is None:
                row = solve_once(planners[n], p, budget, i, args.execute)
                _append_row(args.rows, {"problem": p.name, "planner": n, **row})
            runs[n].append(row)
        if (i + 1) % 10 == 0:
            print(f"  {i + 1}/{len(problems)} problems (load {os.getloadavg()[0]:.1f})", flush=True)
    load1 = os.getloadavg()
    invalid = {
        p.name
        for p, r in zip(problems, runs[BASELINE], strict=True)
        if r["status"] in ("invalid_start", "invalid_goal")
    }
    n_valid = len(problems) - len(invalid)
    out = [
        f"### (a) MotionBenchMaker Panda: {len(problems)} problems ({', '.join(SCENARIOS)}, "
        f"{args.per_scenario} each from number {args.offset + 1}), {args.time_limit:g} s each",
        "",
        f"load average {load0[0]:.1f} / {load0[1]:.1f} (1 / 5 min) at the start, "
        f"{load1[0]:.1f} / {load1[1]:.1f} at the end, {os.cpu_count()} cores; "
        f"{len(invalid)} problems invalid (start or goal in collision)",
        "",
        "| planner | solved and re-checked | executed cleanly | median time | p95 | "
        "time / native (ratio of medians; median of ratios) | median roughness [rad²] | "
        "roughness / native (ratio of medians; median of ratios) | median length [rad] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    base = runs[BASELINE]
    base_t = med([r["time_s"] for r in base if r["ok"]])
    base_r = med([r["roughness"] for r in base if r["ok"]])
    for n in names:
        rows = runs[n]
        ok = [r for r in rows if r["ok"]]
        t = [r["time_s"] for r in ok]
        rough = [r["roughness"] for r in ok]
        both = [(a, b) for a, b in zip(rows, base, strict=True) if a["ok"] and b["ok"]]
        t_ratio = med([a["time_s"] / b["time_s"] for a, b in both])
        r_ratio = med([a["roughness"] / b["roughness"] for a, b in both if b["roughness"] > 0])
        refused = sum(1 for r in rows if "refused" in r)
        executed = f"{sum(1 for r in ok if r.get('executed'))}/{len(ok)}" if args.execute else "–"
        not_opt = sum(1 for r in ok if r.get("optimised") is False)
        out.append(
            f"| `{n}` | {len(ok)}/{n_valid}"
            + (f" ({refused} refused by the re-check)" if refused else "")
            + (f" ({not_opt} the seed's path, not optimised)" if not_opt else "")
            + f" | {executed} | {ms(med(t))} | {ms(p95(t))} | "
            f"{med(t) / base_t:.2f}; {t_ratio:.2f} | {med(rough):.3f} | "
            f"{med(rough) / base_r:.3f}; {r_ratio:.3f} | "
            f"{med([r['length_rad'] for r in ok]):.2f} |"
        )
    for n in names:
        bad = [
            f"{p.name}: {r['status']} ({r.get('refused') or r['reason'][:90]})"
            for p, r in zip(problems, runs[n], strict=True)
            if not r["ok"] and p.name not in invalid
        ]
        unclean = [
            f"{p.name}: {r.get('exec_reason', '')[:120]}"
            for p, r in zip(problems, runs[n], strict=True)
            if r["ok"] and args.execute and not r.get("executed")
        ]
        if bad:
            out += ["", f"`{n}` did not solve: " + "; ".join(bad)]
        if unclean:
            out += ["", f"`{n}` not executed cleanly: " + "; ".join(unclean)]
    out += vamp_rows(args, problems, invalid)
    return out


def _rows_done(path: Path | None) -> dict[tuple[str, str], dict[str, Any]]:
    """The rows of an earlier, interrupted run (``--rows``), by (problem, planner)."""
    if path is None or not path.exists():
        return {}
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {(r["problem"], r["planner"]): r for r in rows}


def _append_row(path: Path | None, row: dict[str, Any]) -> None:
    """One problem's row, appended (a run that is stopped resumes from its rows)."""
    if path is not None:
        with path.open("a") as f:
            f.write(json.dumps(row) + "\n")


def vamp_rows(args: argparse.Namespace, problems: list[Any], invalid: set[str]) -> list[str]:
    py = Path(args.vamp_python).expanduser()
    if not py.exists():
        return ["", f"VAMP skipped: {py} not found (../shared/peers/vamp/README.md)"]
    jobs = []
    for p in problems:
        scenario, index = p.name.rsplit("_", 1)
        jobs.append((p.name, scenario, int(index) - 1))
    with tempfile.TemporaryDirectory(prefix="trajopt_bench_") as tmp:
        spec = Path(tmp) / "spec.json"
        spec.write_text(json.dumps({"sdist": str(args.vamp_sdist), "jobs": jobs}))
        proc = subprocess.run(
            [str(py), str(ROOT / "bench" / "native_bench.py"), "--vamp-worker", str(spec)],
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
                ok.append({**r, **measured(by_name[r["name"]], r["path"])})
    return [
        "",
        "### (b) VAMP beside them (same problems, same run, its own venv)",
        "",
        "| planner | solved (re-checked here) | median planning time | median whole call |"
        " median roughness [rad²] | median length [rad] |",
        "|---|---|---|---|---|---|",
        f"| VAMP 0.6.4 RRT-Connect + simplify | {len(ok)}/{len(problems) - len(invalid)}"
        + (f" ({refused} refused by the re-check)" if refused else "")
        + f" | {ms(med([r['plan_s'] for r in ok]))} | {ms(med([r['call_s'] for r in ok]))} | "
        f"{med([r['roughness'] for r in ok]):.3f} | {med([r['length_rad'] for r in ok]):.2f} |",
    ]


def solvers(args: argparse.Namespace) -> list[str]:
    import numpy as np

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    problems = load_problems(args, args.solver_problems)
    budget = Budget(time_limit_s=args.time_limit)
    names = ("gauss_newton", "lbfgs", "auglag")
    planners = {n: make_planner("trajopt.line", {"solver": n}) for n in names}
    for n in names:
        planners[n].solve(problems[0], 0, budget, np.random.default_rng(10**6))
    load0 = os.getloadavg()[0]
    rows: dict[str, list[dict[str, Any]]] = {n: [] for n in names}
    for i, p in enumerate(problems):
        for n in names:
            t0 = time.perf_counter()
            r = planners[n].solve(p, 0, budget, np.random.default_rng(i))
            ok = r.status.value == "solved" and not recheck(p, r.path)
            rows[n].append(
                {
                    "ok": ok,
                    "time_s": r.time_s,
                    "wall_s": time.perf_counter() - t0,
                    "iterations": r.iterations,
                    "status": r.status.value,
                }
            )
    out = [
        "",
        f"### (c) The solvers: `trajopt.line` on the first {args.solver_problems} problems of "
        f"each scenario ({len(problems)}), {args.time_limit:g} s each "
        f"(load average {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end)",
        "",
        "| solver | solved and re-checked | median merit evaluations (solved) |"
        " median time (solved) | median time / gauss_newton's (problems both solved) |",
        "|---|---|---|---|---|",
    ]
    gn = rows["gauss_newton"]
    for n in names:
        ok = [r for r in rows[n] if r["ok"]]
        both = [
            a["time_s"] / b["time_s"]
            for a, b in zip(rows[n], gn, strict=True)
            if a["ok"] and b["ok"]
        ]
        out.append(
            f"| `{n}` | {len(ok)}/{len(problems)} | {med([r['iterations'] for r in ok]):.0f} | "
            f"{ms(med([r['time_s'] for r in ok]))} | {med(both):.1f} |"
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported MotionBenchMaker problems")
    ap.add_argument("--planners", default="trajopt.line+rrtconnect,trajopt.rrtconnect")
    ap.add_argument("--per-scenario", type=int, default=20)
    ap.add_argument(
        "--offset", type=int, default=0, help="skip this many problems of each scenario first"
    )
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument("--execute", action="store_true", help="execute every path in PyBullet")
    ap.add_argument("--solvers", action="store_true", help="(c): the solvers side by side")
    ap.add_argument("--solver-problems", type=int, default=5)
    ap.add_argument("--skip-mbm", action="store_true")
    ap.add_argument(
        "--rows", type=Path, help="JSON lines of each solve: written as it goes, read on a rerun"
    )
    ap.add_argument("--vamp-python", default="~/.cache/vamp-peer/venv/bin/python")
    ap.add_argument("--vamp-sdist", type=Path, default=VAMP_SDIST)
    args = ap.parse_args()
    if args.folder is None:
        print("trajopt_bench: skipped (give the folder of imported MotionBenchMaker problems)")
        return
    lines = [
        f"commit {_commit()}; load average {os.getloadavg()[0]:.1f}; "
        f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}",
        "",
    ]
    if not args.skip_mbm:
        lines += mbm(args)
    if args.solvers:
        lines += solvers(args)
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

"""MotionBenchMaker's Panda problems: plannerlab's planners and MPlib's RRT-Connect side by
side, on the same problems, on the same machine, in one run.

Import the problems first (the Panda set is fetched through pip into a cache outside the
repository; 7 scenarios × 100 problems)::

    PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --out /tmp/mbm

then::

    PYTHONPATH=. .venv/bin/python bench/mbm_bench.py /tmp/mbm [--per-scenario 10]
        [--planners ompl.rrtconnect,gradient+rrtconnect] [--time-limit 10]
        [--mplib-python PATH]

What is timed: for plannerlab the whole ``solve`` call of one leg (goal state handed over,
RRT-Connect, simplification, interpolation, plannerlab's own re-check at
``joint_step / 4`` and, when it refuses the path, the repair), after one untimed warm-up
solve that loads the compiled core; for
MPlib its OMPL ``planner.plan`` call (RRT-Connect and simplification in C++; the TOPP-RA
retiming of ``plan_qpos`` is left out, as plannerlab's solve does not retime), on a
planner built before the clock starts. Both get the same RRT-Connect range (OMPL's
default for the Panda's limits, 20 % of the state space's extent, unless ``--range``).
"Planning time" is plannerlab's leg ``time_s`` (its budget clock: from after the problem's
checker is built to the end of its re-check; the planned-clearance measurement made after
it, a per-state distance query over the path that is not planning, is left out) and
MPlib's ``planner.plan`` wall time. The whole ``solve`` call is also shown, in wall and CPU
time (``time.process_time``); on a shared machine the CPU time is the steadier.

Every solution, plannerlab's and MPlib's alike, is re-checked here by plannerlab's checker
(the compiled core, no margin, as MotionBenchMaker's states have none) with edges cut
so that no joint moves more than ``--recheck-step`` (default 0.0025 rad, an eighth of the
imported problems' ``joint_step``); a solution that fails it is not counted as solved
(the table shows how many failed).

MPlib pins numpy < 2, so it runs in its own virtual environment
(``python3 -m venv .venv-mplib && .venv-mplib/bin/pip install mplib``); without it the
MPlib row is skipped with a message. MPlib gets the same spherized Panda URDF and SRDF
the problem files name, every obstacle as an FCL box, cylinder or sphere at the same
pose, and the scene's allowed-collision pairs.

VAMP's figure (RRT-Connect median 35 µs, 699/700 solved, one core of a Ryzen 9 7950X) is
the one its authors published; VAMP does not build here, so it is printed as published,
on other hardware, not measured.
"""

from __future__ import annotations

import argparse
import json
import os
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
VAMP_PUBLISHED = "VAMP RRT-Connect (published: Ryzen 9 7950X, one core; not measured here)"


# ---------------------------------------------------------------------- MPlib side (own venv)
def mplib_worker(spec_path: str) -> None:
    """Runs inside the MPlib venv: one RRT-Connect plan per problem, one JSON line."""
    import mplib
    import numpy as np
    from mplib.collision_detection import fcl as mfcl

    spec = json.loads(Path(spec_path).read_text())
    planner = mplib.Planner(urdf=spec["urdf"], srdf=spec["srdf"], move_group=spec["move_group"])
    world = planner.planning_world
    acm = world.get_allowed_collision_matrix()
    out = []
    names: list[str] = []
    set_pairs: list[tuple[str, str]] = []
    for prob in spec["problems"]:
        for n in names:
            world.remove_object(n)
        for a, b in set_pairs:
            acm.remove_entry(a, b)
        names, set_pairs = [], []
        for k, o in enumerate(prob["obstacles"]):
            if o["type"] == "box":
                geom = mfcl.Box(o["size"])
            elif o["type"] == "cylinder":
                geom = mfcl.Cylinder(o["size"][0], o["size"][1])
            else:
                geom = mfcl.Sphere(o["size"][0])
            name = f"obstacle{k}"
            pose = mplib.Pose(o["p"], o["q_wxyz"])
            world.add_object(
                mfcl.FCLObject(name, pose, [mfcl.CollisionObject(geom)], [mplib.Pose()])
            )
            names.append(name)
        for a, b in prob["allowed"]:
            acm.set_entry(a, b, True)
            set_pairs.append((a, b))
        q_start = np.array(prob["q_start"])
        planner.robot.set_qpos(planner.pad_move_group_qpos(q_start), True)
        t0, c0 = time.perf_counter(), time.process_time()
        status, path = planner.planner.plan(
            q_start,
            [np.array(prob["q_goal"])],
            time=spec["time_limit_s"],
            range=spec["range"],
            simplify=True,
        )
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        solved = status == "Exact solution"
        out.append(
            {
                "name": prob["name"],
                "solved": solved,
                "status": str(status),
                "wall_s": wall,
                "cpu_s": cpu,
                "path": np.asarray(path).tolist() if solved else [],
            }
        )
    print(json.dumps({"version": getattr(mplib, "__version__", "?"), "runs": out}))


def mplib_spec(problem: Any) -> dict[str, Any]:
    """A problem's obstacles, allowed pairs, start and goal for the MPlib worker."""
    import numpy as np

    from plannerlab.problem.scene import Box, Cylinder

    def wxyz(R: Any) -> list[float]:
        from scipy.spatial.transform import Rotation

        x, y, z, w = Rotation.from_matrix(R).as_quat()
        return [float(w), float(x), float(y), float(z)]

    obstacles = []
    for o in problem.scene.obstacles:
        T = np.asarray(o.T_world_obstacle)
        if isinstance(o, Box):
            kind, size = "box", [float(v) for v in o.size_m]
        elif isinstance(o, Cylinder):
            kind, size = "cylinder", [float(o.radius_m), float(o.length_m)]
        else:
            kind, size = "sphere", [float(o.radius_m)]
        obstacles.append(
            {"type": kind, "size": size, "p": T[:3, 3].tolist(), "q_wxyz": wxyz(T[:3, :3])}
        )
    goal = problem.goal(0)
    return {
        "name": problem.name,
        "obstacles": obstacles,
        "allowed": [list(p) for p in problem.robot.allowed_collisions],
        "q_start": np.asarray(problem.q_start).tolist(),
        "q_goal": np.asarray(goal.q_rad).tolist(),
    }


# ---------------------------------------------------------------------- plannerlab side
def recheck(problem: Any, path: Any, step_rad: float) -> str:
    """Why the path fails plannerlab's checker (no margin) at ``step_rad``, its ends
    included and the ends compared with the problem's start and goal; "" if it passes."""
    import numpy as np

    from plannerlab.collision.fcl_checker import CollisionChecker

    checker = CollisionChecker(problem.robot, problem.scene, backend="core", margin_m=0.0)
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if len(P) < 2:
        return "fewer than two states"
    if np.max(np.abs(P[0] - problem.q_start)) > 1e-6:
        return "does not start at the start state"
    goal = problem.goal(0)
    if np.max(np.abs(P[-1] - goal.q_rad)) > goal.tol_rad + 1e-9:
        return "does not end in the goal's tolerance"
    check = checker.check_path(P, step_rad)
    if check.valid:
        return ""
    n_edges = len(P) - 1
    return f"edge {check.first_invalid_edge}/{n_edges}: " + ", ".join(
        " x ".join(pair) for pair in check.pairs[:2]
    )


def plannerlab_runs(problems: list[Any], planner_name: str, time_limit_s: float, rng_range: float):
    import numpy as np

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    overrides = {"range": rng_range} if "ompl." in planner_name else {}
    planner = make_planner(planner_name, overrides)
    budget = Budget(time_limit_s=time_limit_s)
    planner.solve(problems[0], 0, budget, np.random.default_rng(10**6))  # warm-up, untimed
    runs = []
    for i, p in enumerate(problems):
        t0, c0 = time.perf_counter(), time.process_time()
        r = planner.solve(p, 0, budget, np.random.default_rng(i))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        runs.append(
            {
                "name": p.name,
                "solved": r.status.name == "SOLVED",
                "status": r.status.name,
                "wall_s": wall,
                "cpu_s": cpu,
                "checks": r.collision_checks,
                "plan_s": r.time_s,
                "path": np.asarray(r.path),
                "reason": r.reason,
                "repair": r.extra.get("repair", ""),
            }
        )
    return runs


def default_range(robot: Any) -> float:
    """OMPL's default RRT-Connect range for a bounded real vector space: 20 % of its
    extent (the diagonal of the joint-limit box) [rad]."""
    import numpy as np

    return 0.2 * float(np.linalg.norm(np.asarray(robot.upper) - np.asarray(robot.lower)))


def summary(label: str, runs: list[dict[str, Any]], problems: dict[str, Any], step: float):
    import numpy as np

    rechecked_fail = 0
    failures: list[str] = []
    ok_times, ok_cpu, ok_plan = [], [], []
    for r in runs:
        if r["solved"]:
            why = recheck(problems[r["name"]], r["path"], step)
            if not why:
                ok_times.append(r["wall_s"])
                ok_cpu.append(r["cpu_s"])
                ok_plan.append(r.get("plan_s", r["wall_s"]))
            else:
                rechecked_fail += 1
                failures.append(f"{r['name']}: {why}")
    n = len(runs)
    t = np.array(ok_times) if ok_times else np.array([np.nan])
    c = np.array(ok_cpu) if ok_cpu else np.array([np.nan])
    pt = np.array(ok_plan) if ok_plan else np.array([np.nan])
    return {
        "label": label,
        "solved": len(ok_times),
        "n": n,
        "recheck_failed": rechecked_fail,
        "median_wall_ms": float(np.median(t) * 1e3),
        "p95_wall_ms": float(np.percentile(t, 95) * 1e3),
        "median_cpu_ms": float(np.median(c) * 1e3),
        "median_plan_ms": float(np.median(pt) * 1e3),
        "p95_plan_ms": float(np.percentile(pt, 95) * 1e3),
        "p95_cpu_ms": float(np.percentile(c, 95) * 1e3),
        "median_checks": float(np.median([r["checks"] for r in runs]))
        if "checks" in runs[0]
        else None,
        "statuses": {k: sum(r["status"] == k for r in runs) for k in {r["status"] for r in runs}},
        "recheck_failures": failures,
        "not_solved": [
            f"{r['name']}: {r['status']}: {r.get('reason', '')}" for r in runs if not r["solved"]
        ],
        "repairs": {
            k: sum(r.get("repair") == k for r in runs)
            for k in {r.get("repair", "") for r in runs} - {""}
        },
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported problem files")
    ap.add_argument("--per-scenario", type=int, default=10, help="first N problems of each")
    ap.add_argument("--planners", default="ompl.rrtconnect,gradient+rrtconnect")
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument("--range", type=float, default=0.0, help="RRT-Connect range (0: OMPL's)")
    ap.add_argument("--recheck-step", type=float, default=0.0025, help="[rad]")
    ap.add_argument(
        "--mplib-python", default=str(ROOT / ".venv-mplib" / "bin" / "python"), help="MPlib venv"
    )
    ap.add_argument("--json", type=Path, default=None, help="write the summaries here")
    ap.add_argument("--mplib-worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.mplib_worker:
        mplib_worker(args.mplib_worker)
        return
    if args.folder is None:
        ap.error("the folder of imported problem files is needed")

    import numpy as np

    from plannerlab.problem.load import parse_problem

    files = []
    for s in SCENARIOS:
        found = sorted(args.folder.glob(f"{s}_[0-9]*.toml"))[: args.per_scenario]
        files += found
    if not files:
        sys.exit(f"no imported MotionBenchMaker problem files in {args.folder}")
    problems = [parse_problem(f) for f in files]
    by_name = {p.name: p for p in problems}
    rrt_range = args.range or default_range(problems[0].robot)
    print(
        f"{len(problems)} problems ({args.per_scenario} per scenario) from {args.folder}; "
        f"RRT-Connect range {rrt_range:.3f} rad; time limit {args.time_limit} s; "
        f"re-check at {args.recheck_step} rad, no margin; load average "
        f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores",
        flush=True,
    )
    rows = []
    for name in [s.strip() for s in args.planners.split(",") if s.strip()]:
        runs = plannerlab_runs(problems, name, args.time_limit, rrt_range)
        rows.append(summary(f"plannerlab {name}", runs, by_name, args.recheck_step))
        print(f"done: {name}", flush=True)
    py = Path(args.mplib_python)
    if not py.exists():
        print(
            f"MPlib row skipped: {py} not found (python3 -m venv .venv-mplib && pip install mplib)"
        )
    else:
        robot = problems[0].robot
        with tempfile.TemporaryDirectory(prefix="plannerlab_mbm_") as tmp:
            spec = {
                "urdf": str(robot.urdf_path),
                "srdf": str(robot.srdf_path),
                "move_group": robot.tip_link,
                "time_limit_s": args.time_limit,
                "range": rrt_range,
                "problems": [mplib_spec(p) for p in problems],
            }
            spec_path = Path(tmp) / "spec.json"
            spec_path.write_text(json.dumps(spec))
            env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
            done = subprocess.run(
                [str(py), __file__, "--mplib-worker", str(spec_path)],
                capture_output=True,
                text=True,
                env=env,
                check=False,
            )
        if done.returncode != 0:
            print(f"MPlib row failed:\n{done.stderr[-3000:]}")
        else:
            line = [s for s in done.stdout.splitlines() if s.startswith("{")][-1]
            got = json.loads(line)
            rows.append(
                summary(
                    f"MPlib {got['version']} RRT-Connect", got["runs"], by_name, args.recheck_step
                )
            )
    mplib_row = next((r for r in rows if r["label"].startswith("MPlib")), None)
    print(
        "| planner | solved (re-checked) | failed re-check | median planning ms | p95 planning ms "
        "| median / MPlib | median ms, whole call (wall) | median ms, whole call (CPU) "
        "| CPU / MPlib |"
    )
    print("|" + "---|" * 9)
    for r in rows:
        ok = mplib_row is not None and np.isfinite(mplib_row["median_cpu_ms"])
        plan_ratio = f"{r['median_plan_ms'] / mplib_row['median_plan_ms']:.2f}" if ok else "-"
        cpu_ratio = f"{r['median_cpu_ms'] / mplib_row['median_cpu_ms']:.2f}" if ok else "-"
        print(
            f"| {r['label']} | {r['solved']}/{r['n']} | {r['recheck_failed']} | "
            f"{r['median_plan_ms']:.2f} | {r['p95_plan_ms']:.2f} | {plan_ratio} | "
            f"{r['median_wall_ms']:.2f} | {r['median_cpu_ms']:.2f} | {cpu_ratio} |"
        )
    print(f"| {VAMP_PUBLISHED} | 699/700 | - | 0.035 | - | - | - | - | - |")
    for r in rows:
        checks = (
            ""
            if r["median_checks"] is None
            else f", median collision checks {r['median_checks']:.0f}"
        )
        print(f"{r['label']}: statuses {r['statuses']}{checks}")
        for how, count in sorted(r["repairs"].items()):
            print(f"  repaired after the re-check refused the first path ({count}): {how}")
        for f in r["recheck_failures"]:
            print(f"  re-check failed: {f}")
        for f in r["not_solved"]:
            print(f"  not solved: {f[:300]}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()

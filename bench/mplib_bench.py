"""plannerlab's ``ompl.rrtconnect`` against MPlib's ``plan_qpos`` on the same problem.

The 12-module Arm-Z (11 joints), the same URDF, start, joint goal, RRT-Connect range and
box obstacle; each planner runs ``--seeds`` times and we time what a user waits for:
the whole ``solve`` call for plannerlab (IK pool skipped: the joint goal is handed over
as its one goal state; simplification, interpolation and the final re-check at
``joint_step / 4`` included), the whole ``plan_qpos`` call for MPlib (its RRT-Connect,
simplification and TOPP-RA time parameterisation).

MPlib pins numpy < 2, so it runs in its own virtual environment, made once from the
repository root with::

    python3 -m venv .venv-mplib && .venv-mplib/bin/pip install mplib

then::

    PYTHONPATH=. .venv/bin/python bench/mplib_bench.py [--seeds 10] [--range 0.1]

Without ``.venv-mplib`` (or ``--mplib-python``) the MPlib row is skipped with a message.

Fairness notes (``/work/shared/docs/peers.md``): MPlib's URDF parser drops ``<capsule>``,
so its URDF has each capsule rebuilt as a cylinder plus two spheres (the same solid); its
SRDF disables exactly the link pairs plannerlab excludes; its joints are revolute over
[-π, π] (MPlib refuses continuous joints), while plannerlab's turn freely. Both planners
get the same range number; the metrics differ (MPlib: Euclidean in R^11; plannerlab:
OMPL's compound SO(2) metric, the L1 sum of joint angle changes, so the same number
means shorter steps for plannerlab). Edges: plannerlab keeps the problem's default
clearance margin (``[planning] safety_margin_m``, 1 cm: capsules inflated by it) and
checks its edges, while planning and in the re-check alike, in metres: by conservative
advancement on the compiled core (every checked state keeps the margin, every state
between two checked ones at least half of it; no joint moves more than ``joint_step``,
0.05 rad, between checked states; see :mod:`plannerlab.collision.core`); MPlib checks no
margin, at its OMPL default resolution in joint space. ``--margin 0`` gives plannerlab's
former setting (no margin, radian steps).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
N_MODULES = 12
BOX_CENTER_M = (1.6, -0.1, 3.2)
BOX_SIZE_M = (0.6, 3.0, 1.0)


# ---------------------------------------------------------------------- MPlib side (own venv)
def mplib_worker(spec_path: str) -> None:
    """Runs inside .venv-mplib: plan ``seeds`` times, print one JSON line."""
    import mplib
    import numpy as np

    spec = json.loads(Path(spec_path).read_text())
    planner = mplib.Planner(
        urdf=spec["urdf"],
        srdf=spec["srdf"],
        move_group=spec["move_group"],
    )
    from mplib.collision_detection import fcl as mfcl

    box = mfcl.CollisionObject(mfcl.Box(spec["box_size"]))
    pose = mplib.Pose(spec["box_center"], [1.0, 0.0, 0.0, 0.0])
    planner.planning_world.add_object(mfcl.FCLObject("box", pose, [box], [mplib.Pose()]))
    q_start = np.array(spec["q_start"])
    q_goal = np.array(spec["q_goal"])
    times, cpu, ok, waypoints = [], [], 0, []
    for _ in range(spec["seeds"]):  # MPlib's OMPL seeds itself: runs differ, not by seed
        t0, c0 = time.perf_counter(), time.process_time()
        res = planner.plan_qpos(
            [q_goal],
            q_start,
            rrt_range=spec["range"],
            planning_time=spec["time_limit_s"],
        )
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        if res["status"] == "Success":
            ok += 1
            waypoints.append(len(res["position"]))
    print(
        json.dumps(
            {
                "times_s": times,
                "cpu_s": cpu,
                "solved": ok,
                "waypoints": waypoints,
                "version": getattr(mplib, "__version__", "?"),
            }
        )
    )


# ---------------------------------------------------------------------- plannerlab side
def capsules_as_cylinders(urdf: str) -> str:
    """Each ``<collision>`` capsule → a cylinder and two spheres (same origin, same solid)."""
    pat = re.compile(
        r'<collision>\s*<origin xyz="([^"]+)" rpy="([^"]+)"/>\s*'
        r'<geometry><capsule radius="([^"]+)" length="([^"]+)"/></geometry>\s*</collision>'
    )

    def repl(m: re.Match[str]) -> str:
        import numpy as np

        from plannerlab.robots.base import rpy_to_matrix

        xyz = np.array([float(v) for v in m.group(1).split()])
        rpy = np.array([float(v) for v in m.group(2).split()])
        r, length = float(m.group(3)), float(m.group(4))
        axis = rpy_to_matrix(rpy)[:, 2]
        ends = [xyz + s * length / 2.0 * axis for s in (-1.0, 1.0)]
        parts = [
            f'<collision><origin xyz="{m.group(1)}" rpy="{m.group(2)}"/>'
            f'<geometry><cylinder radius="{r!r}" length="{length!r}"/></geometry></collision>'
        ]
        for e in ends:
            parts.append(
                f'<collision><origin xyz="{" ".join(repr(float(v)) for v in e)}" rpy="0 0 0"/>'
                f'<geometry><sphere radius="{r!r}"/></geometry></collision>'
            )
        return "\n    ".join(parts)

    out, n = pat.subn(repl, urdf)
    if n == 0:
        raise RuntimeError("no capsule found in the URDF")
    out = re.sub(r"\s*<visual>.*?</visual>", "", out, flags=re.S)  # capsules there too
    # MPlib refuses continuous joints ("constrained planning"): revolute over [-pi, pi]
    out = out.replace('type="continuous"', 'type="revolute"')
    return out.replace("<limit effort=", f'<limit lower="{-math.pi!r}" upper="{math.pi!r}" effort=')


def srdf(robot) -> str:
    names = robot.link_names
    lines = ['<?xml version="1.0"?>', '<robot name="armz">']
    for i, j in sorted(robot.excluded_pairs):
        lines.append(
            f'  <disable_collisions link1="{names[i]}" link2="{names[j]}" reason="Adjacent"/>'
        )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def scenario(seed: int = 0):
    """The robot, scene, start and joint goal (the straight edge between them collides)."""
    import numpy as np

    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Box, Scene
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import pose_matrix
    from plannerlab.robots.paths import interpolate_edge

    robot = ArmZ(n_modules=N_MODULES)
    scene = Scene((Box("box", pose_matrix(BOX_CENTER_M, [0, 0, 0]), BOX_SIZE_M),))
    checker = CollisionChecker(robot, scene)
    rng = np.random.default_rng(seed)
    while True:
        qs = rng.uniform(-np.pi, np.pi, robot.dof)
        qg = rng.uniform(-np.pi, np.pi, robot.dof)
        if not (checker.is_valid(qs) and checker.is_valid(qg)):
            continue
        edge = interpolate_edge(qs, qg, 0.05, robot.continuous)
        if checker.first_invalid(edge) is not None:
            return robot, scene, qs, qg


def plannerlab_runs(
    robot, scene, qs, qg, seeds: int, rrt_range: float, time_limit_s: float, margin_m: float
):
    import numpy as np

    import plannerlab.planners.ompl.goal as pl_ompl  # where the goal pool calls IK
    from plannerlab.planners import make_planner
    from plannerlab.problem.goals import GoalRegion
    from plannerlab.problem.load import Budget, Problem

    p_goal, n_goal = robot.tip(qg)
    goal = GoalRegion("qg", p_goal, n_goal, pos_tol_m=1e-3, angle_tol_deg=0.1)
    problem = Problem(
        "mplib_bench", robot, scene, qs, (goal,), joint_step=0.05, safety_margin_m=margin_m
    )
    planner = make_planner("ompl.rrtconnect", {"range": rrt_range, "goal_samples": 1})
    budget = Budget(time_limit_s=time_limit_s)

    def joint_goal(robot_, goal_, checker, rng, seeds=(), attempts=0, **kw):
        return qg.copy() if checker.is_valid(qg) else None  # one counted check

    original = pl_ompl.sample_goal_state
    pl_ompl.sample_goal_state = joint_goal
    times, cpu, ok, checks, waypoints, statuses = [], [], 0, [], [], []
    try:
        # warm-up, untimed: loads the compiled core from numba's cache (MPlib's planner is
        # likewise built before its clock starts)
        planner.solve(problem, 0, budget, np.random.default_rng(10**6))
        for seed in range(seeds):
            t0, c0 = time.perf_counter(), time.process_time()
            r = planner.solve(problem, 0, budget, np.random.default_rng(seed))
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            statuses.append(r.status.name)
            if r.status.name == "SOLVED":
                ok += 1
                waypoints.append(len(r.path))
            checks.append(r.collision_checks)
    finally:
        pl_ompl.sample_goal_state = original
    return {
        "times_s": times,
        "cpu_s": cpu,
        "solved": ok,
        "checks": checks,
        "waypoints": waypoints,
        "statuses": statuses,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument(
        "--margin",
        type=float,
        default=0.01,
        help="plannerlab's clearance margin [m] (also its edge resolution; 0: none)",
    )
    ap.add_argument("--range", type=float, default=0.1, help="RRT-Connect range (MPlib: 0.1)")
    ap.add_argument("--time-limit", type=float, default=20.0)
    ap.add_argument("--mplib-python", default=str(ROOT / ".venv-mplib" / "bin" / "python"))
    ap.add_argument("--mplib-worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.mplib_worker:
        mplib_worker(args.mplib_worker)
        return

    import numpy as np

    robot, scene, qs, qg = scenario()
    print(f"Arm-Z {N_MODULES} modules ({robot.dof} joints), box {BOX_SIZE_M} m at {BOX_CENTER_M}")
    print(f"start  {np.array2string(qs, precision=3)}")
    print(f"goal   {np.array2string(qg, precision=3)}")
    print(
        f"range {args.range}, {args.seeds} seeds, time limit {args.time_limit} s each, "
        f"plannerlab margin {args.margin} m"
    )
    pl = plannerlab_runs(robot, scene, qs, qg, args.seeds, args.range, args.time_limit, args.margin)
    rows = [("plannerlab ompl.rrtconnect", pl)]
    py = Path(args.mplib_python)
    if not py.exists():
        print(
            f"MPlib row skipped: {py} not found. Make it once with\n"
            "    python3 -m venv .venv-mplib && .venv-mplib/bin/pip install mplib"
        )
    else:
        with tempfile.TemporaryDirectory(prefix="plannerlab_mplib_") as tmp:
            urdf_path = Path(tmp) / "armz.urdf"
            srdf_path = Path(tmp) / "armz.srdf"
            urdf_path.write_text(capsules_as_cylinders(robot.urdf()))
            srdf_path.write_text(srdf(robot))
            spec = {
                "urdf": str(urdf_path),
                "srdf": str(srdf_path),
                "move_group": robot.link_frame_names[-1],
                "box_size": list(BOX_SIZE_M),
                "box_center": list(BOX_CENTER_M),
                "q_start": qs.tolist(),
                "q_goal": qg.tolist(),
                "seeds": args.seeds,
                "range": args.range,
                "time_limit_s": args.time_limit,
            }
            spec_path = Path(tmp) / "spec.json"
            spec_path.write_text(json.dumps(spec))
            env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
            res = subprocess.run(
                [str(py), __file__, "--mplib-worker", str(spec_path)],
                capture_output=True,
                text=True,
                env=env,
            )
            if res.returncode != 0:
                print(f"MPlib row failed:\n{res.stderr[-2000:]}")
            else:
                line = [s for s in res.stdout.splitlines() if s.startswith("{")][-1]
                rows.append((f"MPlib {json.loads(line)['version']} plan_qpos", json.loads(line)))
    print(
        f"{'planner':32s} {'solved':>7s} {'median wall s':>14s} {'median CPU s':>13s} "
        f"{'mean wall s':>12s} {'waypoints':>10s}"
    )
    for name, r in rows:
        t = np.array(r["times_s"])
        c = np.array(r["cpu_s"])
        w = np.median(r["waypoints"]) if r["waypoints"] else float("nan")
        print(
            f"{name:32s} {r['solved']:>3d}/{len(t):<3d} {np.median(t):14.3f} "
            f"{np.median(c):13.3f} {t.mean():12.3f} {w:10.0f}"
        )
    if len(rows) == 2:
        for key, label in (("times_s", "wall"), ("cpu_s", "CPU")):
            a = np.median(rows[0][1][key])
            b = np.median(rows[1][1][key])
            verdict = "met" if b / a >= 2.0 else "NOT met"
            print(f"MPlib / plannerlab median {label} time: {b / a:.2f}x (target >= 2x: {verdict})")
    print(f"plannerlab collision checks per solve: median {np.median(pl['checks']):.0f}")
    print(f"plannerlab statuses: {', '.join(pl['statuses'])}")


if __name__ == "__main__":
    main()

"""Six arms as they ship on a table and a shelf problem each, planned, executed and
refereed on their real meshes (issue 35's targets).

The arms: UR10, Kinova (Jaco 2, ``kinova.urdf``), SO-101, Panda and Z1 from
``example-robot-data`` 6.0.0 and the xArm6 and the KUKA iiwa (``kuka_iiwa/model.urdf``)
from ``pybullet_data``, each with plannerlab's
defaults (:func:`plannerlab.robots.urdf.tip.default_tip_link`: the tool centre frame, else
the hand; the covers' defaults).

The problems are made by one method for every arm, sized to its reach ``R`` (the
farthest tip of 20 000 seeded random states from the base): no number is tuned to an arm.

* **table**: a table top in front (``x`` 0.3R–0.9R, top at 0.05R, 1.2R wide), a ring
  (``problems/urdf/meshes/ring.stl`` scaled by R / 0.85 m, the Panda's reach) standing on
  it across the middle; leg 1 a tip goal on the far side (``y < 0``) from a start on the
  near side, leg 2 back to the start (joint goal);
* **shelf**: an open box (``x`` 0.45R–0.85R, ``z`` 0.15R–0.65R, 0.8R wide, plates 0.04R)
  with a cup (``problems/urdf/meshes/cup.obj`` scaled likewise) on its floor; leg 1 a tip
  goal inside from a start outside, leg 2 back.

Starts and goals: the first of the seeded random states (in order) that is valid with the
problem's margin (``safety_margin_m`` = 1.2 % of R) and whose tip lies in the region; the
tip goal is that state's tip and normal (``pos_tol_m`` = 1 % of R, 5°). Problems are
written to ``--out`` as TOML with the URDF's absolute path.

Each problem is solved by each ``--planners`` (seed 0, ``--time-limit`` per leg), its
plan executed in PyBullet (``plannerlab execute``'s road) and refereed by
``bench/mesh_referee.py`` (PyBullet ``getClosestPoints`` on the URDF as it ships, 0.005
rad): per leg status, planning time, execution wall time against the motion's duration,
clean execution, referee's smallest distance.

    pip download --no-deps example-robot-data==6.0.0 -d /tmp/erd
    unzip -q /tmp/erd/example_robot_data-6.0.0-0-py3-none-any.whl -d /tmp/erd/whl
    PYTHONPATH=. python bench/mesh_arms_bench.py \\
        --erd /tmp/erd/whl/cmeel.prefix/share/example-robot-data/robots --out /tmp/mesh_arms
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
MESHES = HERE.parent / "problems" / "urdf" / "meshes"
#: the Panda's reach, the size the ring and the cup were made for [m]
PANDA_REACH_M = 0.85

ARMS = {
    "ur10": ("erd", "ur_description/urdf/ur10_robot.urdf"),
    "xarm6": ("pybullet", "xarm/xarm6_robot.urdf"),
    "kinova": ("erd", "kinova_description/robots/kinova.urdf"),
    "so101": ("erd", "so_arm_description/urdf/so101.urdf"),
    "panda": ("erd", "panda_description/urdf/panda.urdf"),
    "z1": ("erd", "z1_description/urdf/z1.urdf"),
    "iiwa": ("pybullet", "kuka_iiwa/model.urdf"),
}


def _toml(doc: dict[str, Any]) -> str:
    """A problem dict as TOML text (tables, arrays of tables, numbers, strings, lists)."""

    def val(v: Any) -> str:
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple, np.ndarray)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return repr(float(v)) if isinstance(v, (float, np.floating)) else str(v)

    out = []
    for key, body in doc.items():
        rows = body if isinstance(body, list) else [body]
        for row in rows:
            out.append(f"[[{key}]]" if isinstance(body, list) else f"[{key}]")
            out += [f"{k} = {val(v)}" for k, v in row.items()]
            out.append("")
    return "\n".join(out)


def _box(name: str, lo: list[float], hi: list[float]) -> dict[str, Any]:
    lo_a, hi_a = np.asarray(lo), np.asarray(hi)
    return {
        "name": name,
        "type": "box",
        "center_m": ((lo_a + hi_a) / 2).round(4).tolist(),
        "size_m": (hi_a - lo_a).round(4).tolist(),
    }


def scenes(R: float) -> dict[str, tuple[list[dict[str, Any]], Any, Any]]:
    """Per problem: its obstacles, the start's tip region and the goal's (lo, hi boxes)."""
    s = R / PANDA_REACH_M
    top, t = 0.05 * R, 0.04 * R
    table = [
        _box("table_top", [0.3 * R, -0.6 * R, top - t], [0.9 * R, 0.6 * R, top]),
        {
            "name": "ring",
            "type": "mesh",
            "file": str(MESHES / "ring.stl"),
            "center_m": [round(0.55 * R, 4), 0.0, round(top + 0.1 * s + 0.001 * R, 4)],
            "rpy_deg": [90.0, 0.0, 0.0],
            "scale": [s, s, s],
        },
    ]
    table_start = ([0.35 * R, 0.15 * R, top + 0.05 * R], [0.8 * R, 0.55 * R, top + 0.4 * R])
    table_goal = ([0.35 * R, -0.55 * R, top + 0.05 * R], [0.8 * R, -0.15 * R, top + 0.4 * R])
    x0, x1, zb, zt, w = 0.45 * R, 0.85 * R, 0.15 * R, 0.65 * R, 0.4 * R
    shelf = [
        _box("shelf_bottom", [x0, -w, zb - t], [x1, w, zb]),
        _box("shelf_top", [x0, -w, zt], [x1, w, zt + t]),
        _box("shelf_left", [x0, w, zb - t], [x1, w + t, zt + t]),
        _box("shelf_right", [x0, -w - t, zb - t], [x1, -w, zt + t]),
        _box("shelf_back", [x1, -w - t, zb - t], [x1 + t, w + t, zt + t]),
        {
            "name": "cup",
            "type": "mesh",
            "file": str(MESHES / "cup.obj"),
            "center_m": [round(0.7 * R, 4), round(-0.2 * R, 4), round(zb + 0.061 * s, 4)],
            "scale": [s, s, s],
        },
    ]
    shelf_start = ([0.0, -0.5 * R, zb], [x0 - 0.1 * R, 0.5 * R, zt + 0.2 * R])
    shelf_goal = (
        [x0 + 0.05 * R, -w + 0.05 * R, zb + 0.05 * R],
        [x1 - 0.05 * R, w - 0.05 * R, zt - 0.05 * R],
    )
    return {"table": (table, table_start, table_goal), "shelf": (shelf, shelf_start, shelf_goal)}


def make_problems(arm: str, urdf: Path, out: Path, seed: int = 0) -> list[Path]:
    """The arm's table and shelf problems written to ``out`` (module docstring)."""
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.problem.load import problem_from_dict
    from plannerlab.robots.urdf.model import UrdfChain
    from plannerlab.run.robot_info import default_tip_link

    tip = default_tip_link(urdf)
    robot = UrdfChain(urdf, tip)
    rng = np.random.default_rng(seed)
    Q = rng.uniform(robot.lower, robot.upper, size=(20000, robot.dof))
    P, N = robot.tip(Q)
    R = float(np.max(np.linalg.norm(P, axis=1)))
    files = []
    for name, (obstacles, start_box, goal_box) in scenes(R).items():
        base = {
            "problem": {"name": f"{arm}_{name}", "description": f"{arm} as it ships: {name}"},
            "robot": {"type": "urdf", "urdf": str(urdf.resolve()), "tip_link": tip},
            "planning": {"safety_margin_m": round(0.012 * R, 4)},
            "obstacles": obstacles,
        }
        probe = problem_from_dict(
            {**base, "start": {"q": Q[0].tolist()}, "goals": [{"name": "g", "q": Q[1].tolist()}]},
            str(out / f"{arm}_{name}.toml"),
        )
        checker = problem_checker(probe)

        def first(box: Any, checker: Any = checker) -> int | None:
            lo, hi = np.asarray(box[0]), np.asarray(box[1])
            for i in np.flatnonzero(np.all((P >= lo) & (P <= hi), axis=1)):
                if checker.is_valid(Q[i]):
                    return int(i)
            return None

        i_s, i_g = first(start_box), first(goal_box)
        if i_s is None or i_g is None:
            which = "start" if i_s is None else "goal"
            print(f"{arm} {name}: no valid state with its tip in the {which} region; skipped")
            continue
        doc = {
            **base,
            "start": {"q": Q[i_s].round(6).tolist()},
            "goals": [
                {
                    "name": "reach",
                    "p_m": P[i_g].round(5).tolist(),
                    "n": N[i_g].round(6).tolist(),
                    "pos_tol_m": round(0.01 * R, 4),
                    "angle_tol_deg": 5.0,
                },
                {"name": "back", "q": Q[i_s].round(6).tolist(), "joint_tol_rad": 0.001},
            ],
        }
        f = out / f"{arm}_{name}.toml"
        f.write_text(f"# made by bench/mesh_arms_bench.py (reach R = {R:.3f} m)\n" + _toml(doc))
        files.append(f)
    return files


def run(problem_file: Path, planner: str, time_limit_s: float, out: Path) -> list[dict[str, Any]]:
    """Solve, save, execute, referee one problem with one planner; one row per leg."""
    from mesh_referee import referee

    import plannerlab as pl

    problem = pl.load_problem(problem_file)
    t0 = time.perf_counter()
    plan = pl.solve(problem, planner, 0, budget=pl.Budget(time_limit_s=time_limit_s))
    solve_s = time.perf_counter() - t0
    plan_file = out / f"{problem_file.stem}__{planner}.json"
    plan.save(plan_file)
    execs = []
    if all(leg.solved for leg in plan.legs):
        t1 = time.perf_counter()
        execs = pl.execute(plan, problem)
        exec_s = time.perf_counter() - t1
    else:
        exec_s = float("nan")
    ref = {leg: (n, d, v) for leg, n, d, v in referee(plan_file, 0.005)}
    rows = []
    for k, leg in enumerate(plan.legs):
        e = execs[k] if k < len(execs) else None
        n, d, verdict = ref.get(leg.leg, (0, float("nan"), "no path"))
        rows.append(
            {
                "problem": problem_file.stem,
                "planner": planner,
                "leg": leg.goal,
                "status": leg.status.value,
                "time_s": round(float(leg.time_s), 2),
                "checks": int(leg.collision_checks),
                "executed_cleanly": None if e is None else bool(e.success),
                "why_not": None if e is None else e.reason,
                "motion_s": None if e is None else round(float(e.sim_time_s), 2),
                "exec_wall_s": None if e is None else round(float(e.wall_time_s), 2),
                "referee_states": n,
                "referee_min_mm": round(d * 1e3, 1),
                "referee": verdict,
            }
        )
    rows[0]["solve_all_s"] = round(solve_s, 1)
    rows[0]["execute_all_s"] = round(exec_s, 1)
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--erd", type=Path, required=True, help="example-robot-data's robots/")
    ap.add_argument("--out", type=Path, default=Path("/tmp/mesh_arms"))
    ap.add_argument("--arms", default=",".join(ARMS))
    ap.add_argument("--planners", default="ompl.rrtconnect,native.rrtconnect")
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--problems-only", action="store_true", help="only write the problems")
    args = ap.parse_args()
    import pybullet_data

    args.out.mkdir(parents=True, exist_ok=True)
    print(f"load average at start: {os.getloadavg()}", flush=True)
    rows_file = args.out / "rows.jsonl"
    done = set()
    if rows_file.exists():  # an interrupted run resumes
        for line in rows_file.read_text().splitlines():
            r = json.loads(line)
            done.add((r["problem"], r["planner"]))
    for arm in args.arms.split(","):
        source, rel = ARMS[arm]
        root = args.erd if source == "erd" else Path(pybullet_data.getDataPath())
        files = sorted(args.out.glob(f"{arm}_*.toml")) or make_problems(arm, root / rel, args.out)
        if args.problems_only:
            print(arm, [f.name for f in files], flush=True)
            continue
        for f in files:
            for planner in args.planners.split(","):
                if (f.stem, planner) in done:
                    continue
                for r in run(f, planner, args.time_limit, args.out):
                    print(json.dumps(r), flush=True)
                    with rows_file.open("a") as fh:
                        fh.write(json.dumps(r) + "\n")
    print(f"load average at end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""MotionBenchMaker's Panda problems: plannerlab's planners, VAMP and plainmp side by side,
on the same problems, with the same time accounting, in one run (issue 32, item 6).

Import the problems first (the set comes through pip into ``~/.cache/plannerlab/mbm``)::

    PYTHONPATH=. .venv/bin/python -m plannerlab import mbm --fetch --out /tmp/mbm

then (one command; the peers that are not installed are skipped with a message)::

    PYTHONPATH=. .venv/bin/python bench/peers_bench.py /tmp/mbm \\
        [--scenarios bookshelf_small,box,cage] [--per-scenario 20] [--offset 0] [--all] \\
        [--time-limit 10] [--vamp-python /work/peers/vamp/venv/bin/python] \\
        [--plainmp-python /work/peers/plainmp/bin/python] [--log rows.jsonl]

**The planners**, each with its own defaults:

- ``native.rrtconnect`` and ``ompl.rrtconnect`` (plannerlab, in this process), after one
  untimed warm-up solve each (compiled kernels, OMPL);
- VAMP 0.6.4 RRT-Connect (``vamp.configure_robot_and_planner_with_kwargs("panda", "rrtc")``:
  range 1.0, dynamic domain, Halton sampler, resolution 1/32 built in) and its
  simplification, on its own copy of the problem (``problem_dict_to_vamp`` from its
  ``problems.pkl``: the same MotionBenchMaker scenes, its cylinders as capsules);
- plainmp 0.3.6 (OMPL's RRT-Connect in C++, range 2.0 as it ships, OMPL's shortcut) on
  *plannerlab's* robot: the spherized Panda URDF's spheres, link by link, and exactly the
  link pairs plannerlab checks (none on the root body against the scene), the problem's
  boxes and cylinders as plainmp's SDFs; motions checked on plainmp's box validator at
  ``--plainmp-box-rad`` per joint (default: the problem's ``joint_step / 4``, plannerlab's
  own final grid), and optionally at VAMP's resolution too (``--plainmp-euclidean``).

**Time accounting, the same for all**: *planning time* is the planner's own measurement of
its search and its path simplification (plannerlab: the leg's ``time_s``, from after the
checker is built to the end of its own re-check; VAMP: ``nanoseconds`` of ``rrtc`` plus
those of ``simplify``; plainmp: its ``ns_internal``, OMPL's ``solve`` and shortcut);
the *whole call* is the wall time from a problem in memory to a returned path (plannerlab:
``planner.solve``, which builds the checker; VAMP: its environment, ``rrtc`` and
``simplify``; plainmp: its SDFs, problem and ``solve``). Each problem is handed to every
planner in turn (the peers are persistent worker processes in their own virtual
environments, fed one problem at a time), so all see the same load.

**Counted solved** only when the path passes plannerlab's re-check at the final resolution
(``check_path(path, joint_step / 4, mode="grid")`` with the problem's margin, as
``bench/native_bench.py``), starts at the start and ends in the goal region.

**Installing the peers** (never in the repository; each in its own venv):

- VAMP: ``WORK=/work/peers/vamp bash ../shared/peers/vamp/build.sh`` (offline build, see its
  README; ``--vamp-python $WORK/venv/bin/python``, ``--vamp-sdist
  $WORK/vamp_planner-0.6.4``, whose ``resources/panda/problems.pkl`` the build writes);
- plainmp: Debian's ``libompl-dev`` (1.5.2), ``libboost-system-dev``,
  ``libboost-filesystem-dev``, ``libboost-serialization-dev`` and ``libeigen3-dev``, then
  ``python3 -m venv /work/peers/plainmp && /work/peers/plainmp/bin/pip install
  plainmp==0.3.6`` (a source build, about 6 minutes on 2 free cores).

The load average is printed at the start and the end; timings are ratios within this run.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
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
DEFAULT_SCENARIOS = ("bookshelf_small", "box", "cage")
PLANNERLAB = ("native.rrtconnect", "ompl.rrtconnect")


# ---------------------------------------------------------------------- workers (own venvs)
def _serve(handle: Any) -> None:
    """Answer one JSON line per problem line on stdin (a worker's loop)."""
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        if line.strip():
            print(json.dumps(handle(json.loads(line))), flush=True)


def vamp_worker(sdist: str, robot: str) -> None:
    """In VAMP's venv: RRT-Connect with its defaults for ``robot`` and its simplification
    on VAMP's own copy of each problem (scenario, index)."""
    import pickle

    import vamp

    with open(Path(sdist) / "resources" / robot / "problems.pkl", "rb") as f:
        problems = pickle.load(f)["problems"]
    module, planner, plan_settings, simp_settings = vamp.configure_robot_and_planner_with_kwargs(
        robot, "rrtc"
    )
    sampler = module.halton()

    def handle(job: dict[str, Any]) -> dict[str, Any]:
        data = problems[job["scenario"]][job["index"]]
        sampler.reset()
        t0 = time.perf_counter()
        env = vamp.problem_dict_to_vamp(data)
        res = planner(data["start"], data["goals"], env, plan_settings, sampler)
        row: dict[str, Any] = {"valid": bool(data["valid"]), "solved": bool(res.solved)}
        if res.solved:  # Path.validate on an unsolved path crashes the interpreter
            simple = module.simplify(res.path, env, simp_settings, sampler)
            row.update(
                call_s=time.perf_counter() - t0,
                plan_s=(res.nanoseconds + simple.nanoseconds) * 1e-9,
                iterations=int(res.iterations),
                path=simple.path.numpy().tolist(),
            )
        return row

    handle({"scenario": next(iter(problems)), "index": 0})  # warm-up
    _serve(handle)


def plainmp_worker(robot_json: str) -> None:
    """In plainmp's venv: OMPL's RRT-Connect through plainmp on plannerlab's spheres and
    link pairs (``robot_json``), each problem's obstacles as plainmp's SDFs."""
    import numpy as np
    from plainmp.constraint import SphereAttachmentSpec, SphereCollisionCst
    from plainmp.kinematics import BaseType, KinematicModel
    from plainmp.ompl_solver import OMPLSolver, OMPLSolverConfig, RefineType, set_random_seed
    from plainmp.problem import Problem
    from plainmp.psdf import BoxSDF, CylinderSDF, Pose, SphereSDF, UnionSDF

    robot = json.loads(Path(robot_json).read_text())
    kin = KinematicModel(Path(robot["urdf"]).read_text())
    specs = [
        SphereAttachmentSpec(
            link,
            np.array([s[:3] for s in spheres], dtype=float).T.copy(),
            np.array([s[3] for s in spheres], dtype=float),
            link in robot["only_self"],
        )
        for link, spheres in robot["spheres"].items()
    ]
    pairs = [tuple(p) for p in robot["pairs"]]
    cst = SphereCollisionCst(kin, robot["joints"], BaseType.FIXED, specs, pairs, None, True)
    lb, ub = np.array(robot["lower"]), np.array(robot["upper"])

    def sdf(o: dict[str, Any]) -> Any:
        pose = Pose(np.array(o["p"]), np.array(o["R"]))
        if o["type"] == "box":
            return BoxSDF(np.array(o["size"]), pose)
        if o["type"] == "cylinder":
            return CylinderSDF(o["size"][0], o["size"][1], pose)
        return SphereSDF(o["size"][0], pose)

    def handle(job: dict[str, Any]) -> dict[str, Any]:
        set_random_seed(job["seed"])
        t0 = time.perf_counter()
        cst.set_sdf(UnionSDF([sdf(o) for o in job["obstacles"]]))
        if job["validator"] == "box":
            res_q: Any = np.full(len(lb), job["resolution"])
        else:
            res_q = float(job["resolution"])
        problem = Problem(
            np.array(job["q_start"]), lb, ub, np.array(job["q_goal"]), cst, None, res_q,
            job["validator"],
        )  # fmt: skip
        config = OMPLSolverConfig(timeout=job["time_limit_s"], refine_seq=[RefineType.SHORTCUT])
        ret = OMPLSolver(config).solve(problem)
        call_s = time.perf_counter() - t0
        if ret.traj is None:
            return {"solved": False, "status": ret.terminate_state.name}
        return {
            "solved": True,
            "call_s": call_s,
            "plan_s": ret.ns_internal * 1e-9,
            "checks": int(ret.n_call),
            "path": ret.traj.numpy().tolist(),
        }

    _serve(handle)


class Worker:
    """A peer's persistent worker process, fed one problem line at a time."""

    def __init__(self, name: str, cmd: list[str]) -> None:
        self.name = name
        self.proc = subprocess.Popen(
            cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        first = self._line()
        if not first.get("ready"):
            raise RuntimeError(f"{name}: {first}")

    def _line(self) -> dict[str, Any]:
        assert self.proc.stdout is not None
        while True:
            line = self.proc.stdout.readline()
            if not line:
                err = self.proc.stderr.read() if self.proc.stderr else ""
                raise RuntimeError(f"{self.name} worker ended: {err[-2000:]}")
            if line.startswith("{"):
                return dict(json.loads(line))

    def ask(self, job: dict[str, Any]) -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.write(json.dumps(job) + "\n")
        self.proc.stdin.flush()
        return self._line()

    def close(self) -> None:
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()


# ---------------------------------------------------------------------- plannerlab's side
def robot_for_plainmp(problem: Any) -> dict[str, Any]:
    """plannerlab's spherized robot as plainmp takes it: the URDF, per link its spheres in
    the link's frame (read from the URDF's ``<collision><sphere>``), the URDF link pairs
    plannerlab checks (some capsule pair of the two not excluded), the links on the root
    body (checked against nothing but the robot) and the joint limits."""
    robot = problem.robot
    tree = ET.parse(robot.urdf_path)
    spheres: dict[str, list[list[float]]] = {}
    for link in tree.getroot().iter("link"):
        for col in link.iter("collision"):
            sph = col.find("geometry/sphere")
            if sph is None:
                raise SystemExit(f"{robot.urdf_path}: link {link.get('name')}: not a sphere")
            origin = col.find("origin")
            xyz = (
                [0.0, 0.0, 0.0]
                if origin is None
                else [float(v) for v in origin.get("xyz", "0 0 0").split()]
            )
            spheres.setdefault(link.get("name", ""), []).append(
                [*xyz, float(sph.get("radius", "0"))]
            )
    links = robot.link_urdf_names
    checked: set[tuple[str, str]] = set()
    excluded = robot.excluded_pairs
    for i in range(len(links)):
        for j in range(i + 1, len(links)):
            a, b = links[i], links[j]
            if a != b and (i, j) not in excluded and (j, i) not in excluded:
                checked.add((min(a, b), max(a, b)))
    only_self = sorted({links[i] for i in robot.fixed_links})
    return {
        "urdf": str(robot.urdf_path),
        "joints": list(robot.joint_names),
        "spheres": spheres,
        "pairs": sorted(checked),
        "only_self": only_self,
        "lower": [float(v) for v in robot.lower],
        "upper": [float(v) for v in robot.upper],
    }


def obstacles_of(problem: Any) -> list[dict[str, Any]]:
    """The problem's obstacles as plain data (type, size, position, rotation matrix)."""
    import numpy as np

    from plannerlab.problem.scene import Box, Cylinder

    out = []
    for o in problem.scene.obstacles:
        T = np.asarray(o.T_world_obstacle)
        if isinstance(o, Box):
            kind, size = "box", [float(v) for v in o.size_m]
        elif isinstance(o, Cylinder):
            kind, size = "cylinder", [float(o.radius_m), float(o.length_m)]
        else:
            kind, size = "sphere", [float(o.radius_m)]
        out.append({"type": kind, "size": size, "p": T[:3, 3].tolist(), "R": T[:3, :3].tolist()})
    return out


def ms(x: float) -> str:
    if x != x:
        return "–"
    return f"{x * 1e3:.2f} ms" if x >= 1e-3 else f"{x * 1e6:.0f} µs"


def stats(xs: list[float]) -> tuple[float, float]:
    import numpy as np

    if not xs:
        return float("nan"), float("nan")
    return float(np.median(xs)), float(np.percentile(xs, 95))


def select(args: argparse.Namespace) -> list[Path]:
    scenarios = SCENARIOS if args.all else tuple(args.scenarios.split(","))
    files: list[Path] = []
    for s in scenarios:
        found = sorted(args.folder.glob(f"{s}_[0-9]*.toml"))
        if not found:
            sys.exit(f"no imported problems {s}_NNNN.toml in {args.folder}")
        files += found if args.all else found[args.offset : args.offset + args.per_scenario]
    return files


def start_workers(
    args: argparse.Namespace, robot_json: Path
) -> tuple[dict[str, Worker], list[str]]:
    workers: dict[str, Worker] = {}
    notes: list[str] = []
    vamp_py = Path(args.vamp_python).expanduser()
    if "vamp" not in args.planners:
        pass
    elif vamp_py.exists():
        workers["VAMP 0.6.4 rrtc"] = Worker(
            "VAMP",
            [str(vamp_py), __file__, "--vamp-worker", str(Path(args.vamp_sdist).expanduser()),
             "--robot", args.robot],
        )  # fmt: skip
    else:
        notes.append(f"VAMP skipped: {vamp_py} not found (see the module's docstring)")
    pm_py = Path(args.plainmp_python).expanduser()
    if "plainmp" not in args.planners:
        pass
    elif pm_py.exists():
        workers["plainmp 0.3.6 RRTConnect"] = Worker(
            "plainmp", [str(pm_py), __file__, "--plainmp-worker", str(robot_json)]
        )
    else:
        notes.append(f"plainmp skipped: {pm_py} not found (see the module's docstring)")
    return workers, notes


def run(args: argparse.Namespace) -> list[str]:
    import tempfile

    import numpy as np
    from native_bench import recheck

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget, parse_problem

    files = select(args)
    problems = [parse_problem(f) for f in files]
    budget = Budget(time_limit_s=args.time_limit)
    ours = [n for n in PLANNERLAB if n in args.planners]
    planners = {n: make_planner(n) for n in ours}
    for n in ours:  # warm-up, untimed
        planners[n].solve(problems[0], 0, budget, np.random.default_rng(10**6))
    tmp = Path(tempfile.mkdtemp(prefix="peers_bench_"))
    robot_json = tmp / "robot.json"
    robot_json.write_text(json.dumps(robot_for_plainmp(problems[0])))
    workers, notes = start_workers(args, robot_json)
    plainmp_modes = [("box", args.plainmp_box_rad)]
    if args.plainmp_euclidean:
        plainmp_modes.append(("euclidean", args.plainmp_euclidean))
    labels = list(ours)
    for w in workers:
        if w.startswith("plainmp"):
            labels += [f"{w} ({v} {r if r else 'joint_step/4'})" for v, r in plainmp_modes]
        else:
            labels.append(w)
    rows: dict[str, list[dict[str, Any]]] = {k: [] for k in labels}
    load0 = os.getloadavg()
    log = args.log.open("a") if args.log else None
    try:
        for i, p in enumerate(problems):
            scenario, index = p.name.rsplit("_", 1)
            for n in ours:
                t0 = time.perf_counter()
                r = planners[n].solve(p, 0, budget, np.random.default_rng(i))
                row = {"solved": r.status.value == "solved", "plan_s": r.time_s,
                       "call_s": time.perf_counter() - t0, "path": r.path,
                       "checks": r.collision_checks, "status": r.status.value}  # fmt: skip
                rows[n].append(row)
            for w, worker in workers.items():
                if w.startswith("VAMP"):
                    rows[w].append(worker.ask({"scenario": scenario, "index": int(index) - 1}))
                    continue
                for (v, res), label in zip(
                    plainmp_modes, [x for x in labels if x.startswith(w)], strict=True
                ):
                    job = {
                        "seed": i,
                        "obstacles": obstacles_of(p),
                        "q_start": np.asarray(p.q_start).tolist(),
                        "q_goal": np.asarray(p.goal(0).q_rad).tolist(),
                        "validator": v,
                        "resolution": res or p.joint_step / 4.0,
                        "time_limit_s": args.time_limit,
                    }
                    rows[label].append(worker.ask(job))
            for k in labels:
                r = rows[k][-1]
                why = recheck(p, r["path"]) if r["solved"] else "not solved"
                r.update(name=p.name, ok=not why, why=why, load=os.getloadavg()[0])
                if log:
                    log.write(
                        json.dumps({"planner": k, **{a: b for a, b in r.items() if a != "path"}})
                        + "\n"
                    )
            if (i + 1) % 10 == 0:
                print(
                    f"  {i + 1}/{len(problems)} problems (load {os.getloadavg()[0]:.1f})",
                    flush=True,
                )
    finally:
        for worker in workers.values():
            worker.close()
        if log:
            log.close()
    return report(args, problems, rows, notes, load0)


def report(
    args: argparse.Namespace,
    problems: list[Any],
    rows: dict[str, list[dict[str, Any]]],
    notes: list[str],
    load0: tuple[float, float, float],
) -> list[str]:
    invalid = {
        r["name"]
        for k in PLANNERLAB
        for r in rows.get(k, [])
        if r["status"] in ("invalid_start", "invalid_goal")
    }
    vamp_rows = next((v for k, v in rows.items() if k.startswith("VAMP")), [])
    vamp_invalid = {r["name"] for r in vamp_rows if not r["valid"]}
    if not any(k in rows for k in PLANNERLAB):
        invalid = vamp_invalid
    valid = len(problems) - len(invalid)
    out = [
        f"### MotionBenchMaker Panda: {len(problems)} problems, {args.time_limit:g} s each",
        "",
        f"load average {load0[0]:.1f} / {load0[1]:.1f} (1 / 5 min) at the start, "
        f"{os.getloadavg()[0]:.1f} / {os.getloadavg()[1]:.1f} at the end, "
        f"{os.cpu_count()} cores; problems: {problems[0].name} … {problems[-1].name}; "
        f"{len(invalid)} invalid in the spherized model ({', '.join(sorted(invalid)) or 'none'})"
        + (
            f"; VAMP's own flags: {len(vamp_invalid)} invalid, the same problems: "
            f"{vamp_invalid == invalid}"
            if vamp_rows
            else ""
        ),
        "",
        "| planner | solved, re-checked | refused by the re-check | median planning | p95 "
        "| median whole call | p95 | planning / VAMP (median) | whole call / VAMP |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    vamp = next((k for k in rows if k.startswith("VAMP")), None)
    ok = {k: [r for r in v if r["ok"]] for k, v in rows.items()}
    ref = stats([r["plan_s"] for r in ok[vamp]])[0] if vamp else float("nan")
    ref_call = stats([r["call_s"] for r in ok[vamp]])[0] if vamp else float("nan")
    for k, v in rows.items():
        pm, pp = stats([r["plan_s"] for r in ok[k]])
        cm, cp = stats([r["call_s"] for r in ok[k]])
        refused = sum(1 for r in v if r["solved"] and not r["ok"])
        out.append(
            f"| {k} | {len(ok[k])}/{valid} | {refused} | {ms(pm)} | {ms(pp)} | {ms(cm)} | "
            f"{ms(cp)} | {pm / ref:.1f} | {cm / ref_call:.1f} |"
        )
    out += ["", "Not solved or refused (planner: problem: why):"]
    for k, v in rows.items():
        bad = [
            f"{r['name']} ({r['why'][:80]})" for r in v if not r["ok"] and r["name"] not in invalid
        ]
        if bad:
            out.append(f"- {k}: " + "; ".join(bad))
    both = [
        (a["plan_s"], b["plan_s"])
        for a, b in zip(
            rows.get("native.rrtconnect", []), rows.get("ompl.rrtconnect", []), strict=False
        )
        if a["ok"] and b["ok"]
    ]
    if both:
        out.append(
            f"\nnative / ompl, the median of per-problem planning-time ratios on the {len(both)} "
            f"both solved: {statistics.median(a / b for a, b in both):.3f}"
        )
    return out + [""] + notes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported MotionBenchMaker problems")
    ap.add_argument("--scenarios", default=",".join(DEFAULT_SCENARIOS))
    ap.add_argument("--per-scenario", type=int, default=20)
    ap.add_argument("--offset", type=int, default=0, help="skip the first N of each scenario")
    ap.add_argument("--all", action="store_true", help="all 700 problems")
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument("--vamp-python", default="/work/peers/vamp/venv/bin/python")
    ap.add_argument("--vamp-sdist", default="/work/peers/vamp/vamp_planner-0.6.4")
    ap.add_argument("--plainmp-python", default="/work/peers/plainmp/bin/python")
    ap.add_argument(
        "--plainmp-box-rad", type=float, default=0.0,
        help="plainmp's box validator width per joint [rad]; 0: joint_step / 4",
    )  # fmt: skip
    ap.add_argument(
        "--plainmp-euclidean", type=float, default=1 / 32,
        help="also plainmp on its euclidean validator at this resolution (VAMP's 1/32); 0: not",
    )  # fmt: skip
    ap.add_argument("--log", type=Path, help="one JSON line per planner and problem (appended)")
    ap.add_argument(
        "--robot", default="panda", choices=("panda", "ur5", "fetch"),
        help="whose problems the folder holds (VAMP's module and problems.pkl)",
    )  # fmt: skip
    ap.add_argument(
        "--planners", default="native.rrtconnect,ompl.rrtconnect,vamp,plainmp",
        help="which of the four to run (comma-separated)",
    )  # fmt: skip
    ap.add_argument("--vamp-worker", help=argparse.SUPPRESS)
    ap.add_argument("--plainmp-worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.vamp_worker:
        vamp_worker(args.vamp_worker, args.robot)
        return
    if args.plainmp_worker:
        plainmp_worker(args.plainmp_worker)
        return
    if args.folder is None:
        ap.error("the folder of imported problem files is needed")
    args.planners = args.planners.split(",")
    print("\n".join(run(args)))


if __name__ == "__main__":
    main()

"""OMPL's KinematicChain benchmark (the horn, N links): C++ OMPL 1.5.2 beside plannerlab's
native planners, both in one window, ratios from that window and the machine's load.

The problems are plannerlab's own (``plannerlab import kinematic-chain``,
:mod:`plannerlab.problem.kinematic_chain`): the demo's chain, horn, start and goal; links
as capsules of radius 1 mm, walls as boxes 2 mm thick, no margin; edges checked every
0.05 rad and paths re-checked every 0.0125 rad. The C++ side
(``bench/kinematic_chain/chain_ompl.cpp``, our own program on OMPL's public API) reads the
same chain and walls from a geometry file this script writes from the loaded problem
(capsule radii, boxes' centres, yaws and half sizes) and checks them in the plane (the
exact capsule-box and capsule-capsule distances; its state test agrees with plannerlab's
on random states: ``chain_ompl GEOMETRY state-cost 0 0`` prints the valid fraction). Its
state space is the demo's (every joint a full turn, the demo's distance and random
projection), its motions are checked by OMPL's discrete motion validator at a resolution
20× finer than the demo's (``setStateValidityCheckingResolution(0.0005)``; ``--motion
grid``: plannerlab's grid instead, at most 0.0125 rad per joint).

Each (N, seed) runs every planner of both sides one after the other (so both see the same
load), ``--time-limit`` each (default 10 s). Times:

* C++: ``solve()`` plus ``simplifySolution()`` (the path a user gets), wall clock inside
  the program; its path is then re-checked by plannerlab's checker at 0.0125 rad (not
  timed) and the run counts as solved only if it passes;
* plannerlab: the leg's ``time_s`` (its budget clock: from after the checker is built to
  the end of the planner's shortcuts and re-check at 0.0125 rad); its kernels are loaded
  before that clock (one warm-up solve per process).

``--cpu-clock`` reads both sides on the process's CPU time instead (C++: ``std::clock``
over the same solve and simplification; plannerlab: its budget's clock is
``time.process_time``, so its time limit is CPU seconds too): on a loaded machine a
single-threaded planner's CPU time is what it would take alone, where wall time counts
the other jobs' share. The C++ time limit stays wall clock (``solve(t)``), so under load
C++ gets less CPU before its limit than plannerlab: the failures are not comparable then,
only the solved runs' times. Every row keeps both times.

A run that does not solve counts at the time limit: the medians are over all runs (OMPL's
benchmark convention). Each run is one JSON line appended to ``--out`` (default
``results/runs/kinematic_chain/runs.jsonl``); a rerun resumes and skips the runs already
there. The table (solved runs, median time per N, the best of each side, their ratio, the
load during the runs) is printed at the end.

Set-up: ``apt-get install -y libompl-dev libboost-system-dev libboost-filesystem-dev
libboost-serialization-dev`` (Debian's OMPL 1.5.2 and the Boost libraries it links);
the script builds ``bench/kinematic_chain/chain_ompl`` with ``make -C
bench/kinematic_chain`` when it is missing or older than its source.

Run::

    PYTHONPATH=. .venv/bin/python bench/kinematic_chain_bench.py
        [--links 10 20 30] [--seeds 10] [--time-limit 10]
        [--cpp KPIECE1,STRIDE,RRTConnect] [--native native.kpiece,native.rrtconnect]
        [--motion ompl|grid] [--out FILE] [--fresh] [--cpu-clock]

Any registered planner runs on the plannerlab side (``--native``; ``--cpp ""`` runs no C++
and needs no OMPL), e.g. a trajectory optimiser at 10 and 20 links::

    PYTHONPATH=. .venv/bin/python bench/kinematic_chain_bench.py --links 10 20 \
        --cpp "" --native native.kpiece,PLANNER --out /tmp/kc.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CPP_DIR = ROOT / "bench" / "kinematic_chain"
CPP = CPP_DIR / "chain_ompl"
#: OMPL's state validity checking resolution on the C++ side: 20× finer than the demo's
#: default (1 % of the space's extent)
RESOLUTION = 0.01 / 20


def build_cpp() -> Path:
    """``chain_ompl``, built by make when missing or older than its source."""
    src = CPP_DIR / "chain_ompl.cpp"
    if CPP.exists() and CPP.stat().st_mtime >= src.stat().st_mtime:
        return CPP
    if (
        shutil.which("pkg-config") is None
        or subprocess.run(["pkg-config", "--exists", "ompl"], check=False).returncode
    ):
        sys.exit(
            "kinematic_chain_bench: OMPL's development files are missing: "
            "apt-get install -y libompl-dev libboost-system-dev libboost-filesystem-dev "
            "libboost-serialization-dev (Debian's OMPL 1.5.2), then run again"
        )
    subprocess.run(["make", "-C", str(CPP_DIR)], check=True)
    return CPP


def geometry_text(problem: Any) -> str:
    """The chain and walls of a loaded KinematicChain problem, for ``chain_ompl``: link
    length, capsule radii against the walls (with the margin) and between links (with
    half of it each), the walls' centres, yaws and half sizes in the plane, OMPL's
    resolution, plannerlab's grid (joint step and edge weights), start and goal."""
    from plannerlab.collision.fcl_checker import problem_checker

    robot = problem.robot
    n = int(robot.dof)
    radii = [float(r) for r in robot.link_radii_m]
    if len(radii) != n or not np.allclose(radii, radii[0]):
        raise SystemExit(f"{problem.source}: not a KinematicChain problem (one capsule a link)")
    margin = float(problem.safety_margin_m)
    checker = problem_checker(problem)
    lines = [
        f"links {n}",
        f"link_length {1.0 / n!r}",
        f"radius_scene {radii[0] + margin!r}",
        f"radius_self {radii[0] + margin / 2.0!r}",
        f"resolution {RESOLUTION!r}",
        f"grid_step {problem.joint_step / 4.0!r}",
        "edge_weights " + " ".join(repr(float(w)) for w in checker.model.edge_weights),
    ]
    walls = []
    for ob in problem.scene.obstacles:
        T = np.asarray(ob.T_world_obstacle, dtype=float).tolist()
        hx, hy = (float(v) / 2.0 for v in ob.size_m[:2])
        yaw = math.atan2(T[1][0], T[0][0])
        walls.append(f"{T[0][3]!r} {T[1][3]!r} {yaw!r} {hx!r} {hy!r}")
    lines.append(f"walls {len(walls)}")
    lines += walls
    goal = problem.goals[0]
    lines.append("start " + " ".join(repr(float(x)) for x in problem.q_start))
    lines.append("goal " + " ".join(repr(float(x)) for x in goal.q_rad))
    return "\n".join(lines) + "\n"


def run_cpp(geometry: Path, planner: str, seed: int, time_limit: float, motion: str) -> dict:
    try:
        out = subprocess.run(
            [str(CPP), str(geometry), planner, str(seed + 1), repr(time_limit), motion],
            capture_output=True,
            text=True,
            timeout=time_limit * 3 + 60,
            check=False,
        )
    except subprocess.TimeoutExpired:  # a planner that does not stop: a failed run
        return {
            "side": "ompl",
            "planner": planner,
            "status": "did not stop",
            "solved": False,
            "time_s": time_limit,
            "cpu_s": time_limit,  # (not measured: a failure counts at the limit)
            "checks": 0,
            "path": None,
        }
    if out.returncode != 0:
        raise SystemExit(f"chain_ompl {planner} seed {seed}: {out.stderr.strip()}")
    r: dict = json.loads(out.stdout)
    return r


def run_native(
    problem: Any, planner: str, seed: int, time_limit: float, cpu_clock: bool = False
) -> dict:
    import time

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    rng = np.random.default_rng(np.random.SeedSequence([seed, 0]))
    clock = time.process_time if cpu_clock else None
    c0 = time.process_time()
    r = make_planner(planner).solve(problem, 0, Budget(time_limit_s=time_limit, clock=clock), rng)
    cpu_s = time.process_time() - c0
    solved = r.status.value == "solved"
    return {
        "side": "plannerlab",
        "planner": planner,
        "status": r.status.value,
        "solved": solved,
        "time_s": float(r.time_s),
        "clock": "cpu" if cpu_clock else "wall",
        "cpu_s": cpu_s,
        "checks": int(r.collision_checks),
        "iterations": int(r.iterations),
        "waypoints": int(len(r.path)) if solved else 0,
        "extra": {k: r.extra.get(k) for k in ("nodes", "cells", "planning_checks")},
    }


def recheck(checker: Any, path: Any, step: float) -> bool:
    P = np.asarray(path, dtype=float)
    check = checker.check_path(P, step, mode="grid")
    return bool(check.complete and check.valid)


def _append(out: Path, row: dict) -> None:
    with out.open("a", encoding="utf-8") as f:
        f.write(json.dumps(row) + "\n")
        f.flush()
        os.fsync(f.fileno())


def _done(out: Path) -> set[tuple[str, str, int, int]]:
    keys = set()
    if out.exists():
        for line in out.read_text(encoding="utf-8").splitlines():
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line cut short by an interruption: run again
            keys.add((r["side"], r["planner"], r["links"], r["seed"]))
    return keys


def run(args: argparse.Namespace) -> Path:
    import plannerlab as pl
    import plannerlab.extras as px
    from plannerlab.collision.fcl_checker import problem_checker

    cpp = [p for p in args.cpp.split(",") if p]
    native = [p for p in args.native.split(",") if p]
    if cpp:
        build_cpp()
    out: Path = args.out
    out.parent.mkdir(parents=True, exist_ok=True)
    if args.fresh and out.exists():
        out.unlink()
    done = _done(out)
    work = Path(tempfile.mkdtemp(prefix="kinematic_chain_"))
    total = len(args.links) * args.seeds * (len(cpp) + len(native))
    count = 0
    for n in args.links:
        problem = pl.load_problem(px.kinematic_chain.write_problem(n, work))
        checker = problem_checker(problem)
        step = problem.joint_step / 4.0
        geometry = work / f"kinematic_chain_{n}.geometry"
        geometry.write_text(geometry_text(problem), encoding="utf-8")
        for planner in native:  # kernels loaded before any clock, as in every trial
            run_native(problem, planner, 0, 0.05)
        for seed in range(args.seeds):
            for side, planner in [("ompl", p) for p in cpp] + [("plannerlab", p) for p in native]:
                count += 1
                if (side, planner, n, seed) in done:
                    continue
                load0 = os.getloadavg()[0]
                if side == "ompl":
                    r = run_cpp(geometry, planner, seed, args.time_limit, args.motion)
                    path = r.pop("path")
                    r["recheck_ok"] = bool(path) and recheck(checker, path, step)
                    r["solved"] = bool(r["solved"] and r["recheck_ok"])
                else:
                    r = run_native(problem, planner, seed, args.time_limit, args.cpu_clock)
                r.update(links=n, seed=seed, time_limit_s=args.time_limit, motion=args.motion)
                if args.cpu_clock and side == "ompl":  # the table reads "time_s"
                    r["wall_s"], r["time_s"] = r["time_s"], r["cpu_s"]
                    r["clock"] = "cpu"  # (plannerlab's time_s is its budget's CPU clock)
                r["load"] = [load0, os.getloadavg()[0]]
                _append(out, r)
                mark = "solved" if r["solved"] else "-"
                print(
                    f"[{count}/{total}] N={n} seed {seed} {side} {planner}: {mark} "
                    f"{r['time_s']:.3f} s, {r['checks']} checks, load {load0:.1f}",
                    flush=True,
                )
    shutil.rmtree(work, ignore_errors=True)
    return out


def table(out: Path, time_limit: float) -> str:
    rows = [json.loads(line) for line in out.read_text(encoding="utf-8").splitlines() if line]
    by: dict[tuple[int, str, str], list[dict]] = {}
    for r in rows:
        by.setdefault((r["links"], r["side"], r["planner"]), []).append(r)

    def stats(runs: list[dict]) -> tuple[int, float, float]:
        times = [r["time_s"] if r["solved"] else r["time_limit_s"] for r in runs]
        solved = [r["time_s"] for r in runs if r["solved"]]
        return (
            len(solved),
            statistics.median(times),
            (statistics.median(solved) if solved else math.nan),
        )

    lines = [
        "| N | side | planner | solved | median time, all runs [s] | median time, solved [s] "
        "| median checks |",
        "|---|---|---|---|---|---|---|",
    ]
    summary = []
    loads = [x for r in rows for x in r["load"]]
    for n in sorted({k[0] for k in by}):
        best: dict[str, tuple[int, float, str]] = {}
        for (links, side, planner), runs in sorted(by.items()):
            if links != n:
                continue
            k, med_all, med_solved = stats(runs)
            checks = statistics.median(r["checks"] for r in runs)
            lines.append(
                f"| {n} | {'C++ OMPL 1.5.2' if side == 'ompl' else 'plannerlab'} | {planner} | "
                f"{k}/{len(runs)} | {med_all:.3f} | {med_solved:.3f} | {checks:.0f} |"
            )
            if side not in best or (k, -med_all) > (best[side][0], -best[side][1]):
                best[side] = (k, med_all, planner)
        if len(best) == 2:
            (ko, to, po), (kp, tp, pp) = best["ompl"], best["plannerlab"]
            target = 1.0 if n <= 10 else 2.0
            ok = kp >= ko and tp <= target * to
            summary.append(
                f"N = {n}: best C++ {po} {ko} solved, median {to:.3f} s; best plannerlab {pp} "
                f"{kp} solved, median {tp:.3f} s: ratio {tp / to:.2f} (target: solved >= C++ and "
                f"ratio <= {target:g}): {'met' if ok else 'NOT met'}"
            )
    lines.append("")
    lines += summary
    if loads:
        lines.append(
            f"load average (1 min) during the runs: {min(loads):.1f} … {max(loads):.1f} on "
            f"{os.cpu_count()} cores; time limit {time_limit:g} s; times: C++ solve + "
            "simplify, plannerlab time_s (search, shortcuts, re-check)"
            + ("; CPU time (--cpu-clock)" if any(r.get("clock") == "cpu" for r in rows) else "")
        )
        if len({r.get("clock", "wall") for r in rows}) > 1:
            lines.append("WARNING: the runs mix wall-clock and CPU-clock times (--out reused)")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--links", type=int, nargs="+", default=[10, 20, 30])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--time-limit", type=float, default=10.0)
    ap.add_argument("--cpp", default="KPIECE1,STRIDE,RRTConnect", help="C++ OMPL planners")
    ap.add_argument("--native", default="native.kpiece,native.rrtconnect")
    ap.add_argument("--motion", choices=("ompl", "grid"), default="ompl")
    ap.add_argument(
        "--out", type=Path, default=ROOT / "results" / "runs" / "kinematic_chain" / "runs.jsonl"
    )
    ap.add_argument(
        "--cpu-clock",
        action="store_true",
        help="time both sides on process CPU time (a loaded machine); see the docstring",
    )
    ap.add_argument("--fresh", action="store_true", help="start again (delete --out first)")
    ap.add_argument("--table-only", action="store_true", help="print the table of --out")
    args = ap.parse_args()
    if not args.table_only:
        run(args)
    print(table(args.out, args.time_limit))


if __name__ == "__main__":
    main()

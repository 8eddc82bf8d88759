"""The compiled core against the FCL checker and PyBullet, measured in one run.

Same states, same URDF and obstacles for all three. Prints µs per state and ratios, the
issue-9 targets beside them, and the machine and versions. Nothing is asserted (tests
never time anything); rerun it to compare.

    PYTHONPATH=. .venv/bin/python bench/core_bench.py [--states 2000] [--problem armz_inspection]

PyBullet is used the fair way (``/work/shared/docs/peers.md``): one
``resetJointStatesMultiDof`` call per state, ``URDF_USE_SELF_COLLISION`` with the same
excluded pairs (``plannerlab.sim.SimWorld`` sets the filters), ``performCollisionDetection``,
and a contact counts only at distance ≤ 0.

Timings are best-of-5 CPU time of this process (``process_time``): every contender is
single-threaded and in-process, so CPU time compares them fairly even when other jobs load
the machine (wall-clock on a 2-core machine shared by several users is not
reproducible). The numba compile cost is measured in fresh processes
with an empty and then a warm ``NUMBA_CACHE_DIR``.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from importlib.metadata import version

import numpy as np
from rich.console import Console
from rich.table import Table

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.catalog import load_problem
from plannerlab.robots.armz.model import ArmZ


def per_call(fn: Callable[[], object], calls: int, repeats: int = 5) -> float:
    """Best of ``repeats`` runs of ``calls`` calls, CPU seconds of this process per call."""
    fn()
    best = np.inf
    for _ in range(repeats):
        t0 = time.process_time()
        for _ in range(calls):
            fn()
        best = min(best, (time.process_time() - t0) / calls)
    return best


def machine() -> str:
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    libs = ", ".join(
        f"{m} {version(m)}" for m in ("numpy", "numba", "python-fcl", "pybullet", "ompl")
    )
    return (
        f"{cpu}, {os.cpu_count()} cpus, load {load:.1f}; Python {platform.python_version()}; {libs}"
    )


class PyBulletChecker:
    """Validity by PyBullet, used the fast way (see the module docstring)."""

    def __init__(self, robot, scene) -> None:
        from plannerlab.sim import SimWorld

        self.world = SimWorld(robot, scene)
        self.c = self.world.client
        self.body = self.world.body
        self.joints = list(self.world._joints)

    def is_valid(self, q: np.ndarray) -> bool:
        q_urdf = self.world._to_urdf(q)
        self.c.resetJointStatesMultiDof(self.body, self.joints, [[float(v)] for v in q_urdf])
        self.c.performCollisionDetection()
        return not any(pt[8] <= 0.0 for pt in self.c.getContactPoints(bodyA=self.body))

    def valid_batch(self, Q: np.ndarray) -> np.ndarray:
        return np.array([self.is_valid(q) for q in Q])

    def close(self) -> None:
        self.world.close()


_COMPILE_SNIPPET = """
import time
t0, c0 = time.perf_counter(), time.process_time()
import numpy as np
from plannerlab.collision.core import Core
from plannerlab.problem.catalog import load_problem
t1, c1 = time.perf_counter(), time.process_time()
p = load_problem({problem!r})
core = Core(p.robot, p.scene)
Q = np.random.default_rng(0).uniform(p.robot.lower, p.robot.upper, (10, p.robot.dof))
core.valid(Q); core.first_invalid(Q); core.pair_distances(Q[0], 0.1); core.fk(Q[0])
core.is_valid(Q[0]); core.edge_first_invalid(Q[0], Q[1], 0.05)
t2, c2 = time.perf_counter(), time.process_time()
print(t1 - t0, t2 - t1, c1 - c0, c2 - c1)
"""


def compile_cost(problem: str) -> list[tuple[float, float, float, float]]:
    """(import, first calls) wall and CPU seconds in fresh processes: empty cache, then warm."""
    code = _COMPILE_SNIPPET.format(problem=problem)
    out = []
    with tempfile.TemporaryDirectory(prefix="plannerlab_numba_") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp)
        for _ in range(2):
            res = subprocess.run(
                [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
            )
            a, b, c, d = (float(v) for v in res.stdout.split())
            out.append((a, b, c, d))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--states", type=int, default=2000)
    ap.add_argument("--problem", default="armz_inspection")
    ap.add_argument("--no-pybullet", action="store_true")
    args = ap.parse_args()
    con = Console()
    problem = load_problem(args.problem)
    robot = problem.robot
    rng = np.random.default_rng(0)
    Q = rng.uniform(robot.lower, robot.upper, (args.states, robot.dof))
    core = CollisionChecker(robot, problem.scene, backend="core")
    fcl = CollisionChecker(robot, problem.scene, backend="fcl")
    pb = None if args.no_pybullet else PyBulletChecker(robot, problem.scene)
    agree_fcl = float(np.mean(core.valid_batch(Q) == fcl.valid_batch(Q)))
    agree_pb = float(np.mean(core.valid_batch(Q) == pb.valid_batch(Q))) if pb else float("nan")
    it = iter(range(10**9))

    def q() -> np.ndarray:
        return Q[next(it) % len(Q)]

    n1 = min(500, len(Q))
    # rows: (operation, target µs or None, core s, fcl s, pybullet s)
    rows: list[tuple[str, float | None, float, float, float]] = []
    c_core = core._core
    rows.append(
        (
            "fk, one state",
            10.0,
            per_call(lambda: c_core.fk(q()), 2000),
            per_call(lambda: robot.fk(q()), 2000),
            float("nan"),
        )
    )
    rows.append(
        (
            "fk, batch (per state)",
            None,
            per_call(lambda: c_core.fk(Q), 3) / len(Q),
            per_call(lambda: robot.fk(Q), 3) / len(Q),
            float("nan"),
        )
    )
    rows.append(
        (
            "validity, one state per call",
            30.0,
            per_call(lambda: core.is_valid(q()), 2000),
            per_call(lambda: fcl.is_valid(q()), 300),
            per_call(lambda: pb.is_valid(q()), 300) if pb else float("nan"),
        )
    )
    rows.append(
        (
            "validity, batch (per state)",
            10.0,
            per_call(lambda: core.valid_batch(Q), 3) / len(Q),
            per_call(lambda: fcl.valid_batch(Q[:n1]), 1) / n1,
            float("nan"),
        )
    )
    # edges: 20 states between two valid states, whole edge in one call
    V = Q[core.valid_batch(Q)]
    edges = [np.linspace(V[i], V[i + 1], 20) for i in range(0, min(len(V) - 1, 200), 2)]
    ie = iter(range(10**9))

    def edge() -> np.ndarray:
        return edges[next(ie) % len(edges)]

    rows.append(
        (
            "edge of 20 states, one call (per state)",
            None,
            per_call(lambda: core.first_invalid(edge()), 300) / 20,
            per_call(lambda: fcl.first_invalid(edge()), 50) / 20,
            float("nan"),
        )
    )
    # scaling 24 -> 96 modules, same scene
    scale = {}
    for n in (24, 96):
        r = ArmZ(n_modules=n, T_world_base=robot.T_world_base) if robot.kind == "armz" else None
        if r is None:
            break
        Qn = np.random.default_rng(1).uniform(r.lower, r.upper, (args.states, r.dof))
        cn = CollisionChecker(r, problem.scene, backend="core")
        fn = CollisionChecker(r, problem.scene, backend="fcl")
        jn = iter(range(10**9))
        Vn = Qn[cn.valid_batch(Qn)]
        scale[n] = (
            per_call(lambda cn=cn, Qn=Qn: cn.valid_batch(Qn), 3) / len(Qn),
            per_call(lambda cn=cn, Vn=Vn: cn.valid_batch(Vn), 3) / len(Vn),
            per_call(lambda cn=cn, Qn=Qn, jn=jn: cn.is_valid(Qn[next(jn) % len(Qn)]), 1000),
            per_call(lambda fn=fn, Qn=Qn: fn.valid_batch(Qn[:n1]), 1) / n1,
            float(np.mean(cn.valid_batch(Qn))),
        )
    if pb:
        pb.close()
    cold, warm = compile_cost(args.problem)

    table = Table(
        title=f"core vs FCL checker vs PyBullet on {problem.name} ({robot.dof} joints, "
        f"{len(problem.scene.obstacles)} obstacles, {len(Q)} uniform states; "
        f"verdicts agree with FCL {agree_fcl:.1%}, with PyBullet {agree_pb:.1%})"
    )
    for col in ("operation", "core", "target", "FCL checker", "FCL/core", "PyBullet", "PB/core"):
        table.add_column(col)
    for name, target, tc, tf, tp in rows:
        table.add_row(
            name,
            f"{tc * 1e6:,.2f} µs",
            ""
            if target is None
            else f"≤ {target:g} µs: {'met' if tc * 1e6 <= target else 'NOT met'}",
            f"{tf * 1e6:,.1f} µs",
            f"{tf / tc:,.1f}x",
            "" if np.isnan(tp) else f"{tp * 1e6:,.1f} µs",
            "" if np.isnan(tp) else f"{tp / tc:,.1f}x",
        )
    con.print(table)
    if len(scale) == 2:
        t = Table(title="scaling 24 -> 96 modules, same scene (per state; target ≤ 4.5x)")
        for col in ("", "24 modules", "96 modules", "96/24"):
            t.add_column(col)
        labels = (
            "core batch, uniform states",
            "core batch, valid states only (full check)",
            "core one state per call, uniform",
            "FCL checker batch, uniform",
            "valid fraction of the uniform states",
        )
        for k, label in enumerate(labels):
            a, b = scale[24][k], scale[96][k]
            unit = 1e6 if k < 4 else 1.0
            t.add_row(
                label,
                f"{a * unit:,.2f}" + (" µs" if k < 4 else ""),
                f"{b * unit:,.2f}" + (" µs" if k < 4 else ""),
                f"{b / a:.2f}x",
            )
        con.print(t)
    for label, (ti, tf, ci, cf) in (("empty cache", cold), ("warm cache", warm)):
        con.print(
            f"numba, fresh process, {label}: import {ti:.2f} s wall / {ci:.2f} s CPU, "
            f"first calls (compile or load) {tf:.2f} s wall / {cf:.2f} s CPU"
        )
    con.print(f"machine: {machine()}")


if __name__ == "__main__":
    main()

"""A URDF robot (MotionBenchMaker's spherized Panda) on the compiled core: verdicts against
FCL on random states in imported MotionBenchMaker scenes, and the cost per state, the
core's generic kernels (``core.py``: ``chain_segments`` + ``valid_batch``,
``chain_first_invalid``) beside the fused ``ChainValidity`` of ``collision/chain.py``, in
the same run.

Import the problems first (``plannerlab import mbm --fetch --limit 1 --out DIR``), then

    PYTHONPATH=. .venv/bin/python bench/urdf_core_bench.py DIR [--states 7200]

**Agreement.** For every ``*_0001.toml`` in DIR and for margins 0 and 0.01 m it checks
``--states`` uniform random states (seed 11) with FCL, the core and ``ChainValidity`` and
counts the verdicts that differ from FCL's (7 scenes x 2 margins x 7 200 = 100 800 states).

**Cost** (first problem, 2 000 uniform random states, seed 0; each figure the least of
``--repeats`` repetitions, old and new interleaved, so that other load on the machine
counts least and alike): kinematics, batched validity, and one state at a time on four
roads: the kernel's Python method alone; ``CollisionChecker.is_valid`` (what the planners
call); the OMPL adapter's validity callback (``guard.is_valid(space.to_q(state))`` of
``planners/ompl.py``) called by OMPL's own ``SpaceInformation.isValid`` on OMPL states, one
Python call per state; and that callback's parts. "new, wired" is the checker with its
core's ``valid`` / ``is_valid`` answered by ``ChainValidity`` (as ``Core`` would once wired
to it; ``core.py`` is not changed here).
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.collision.chain_valid import ChainValidity
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.load import Budget, parse_problem


def _agreement(files: list[Path], n_states: int) -> None:
    total = old_differ = new_differ = 0
    for f in files:
        p = parse_problem(f)
        for margin in (0.0, 0.01):
            core = CollisionChecker(p.robot, p.scene, backend="core", margin_m=margin)
            fcl = CollisionChecker(p.robot, p.scene, backend="fcl", margin_m=margin)
            assert core._core is not None
            fused = ChainValidity.of(core._core)
            Q = np.random.default_rng(11).uniform(p.robot.lower, p.robot.upper, (n_states, 7))
            a, b, c = core.valid_batch(Q), fcl.valid_batch(Q), fused.valid(Q)
            total += len(Q)
            old_differ += int(np.sum(a != b))
            new_differ += int(np.sum(c != b))
            print(
                f"{f.stem:24s} margin {margin:4.2f} m  valid {b.mean():.3f}  differ from FCL: "
                f"core {np.sum(a != b)}, ChainValidity {np.sum(c != b)}"
            )
    print(f"{total} states: core {old_differ}, ChainValidity {new_differ} verdicts differ from FCL")


def _wired(checker: CollisionChecker, fused: ChainValidity) -> CollisionChecker:
    """The checker with its core's validity answered by ``fused`` (bench only: what wiring
    ChainValidity into Core would give, without changing core.py)."""
    core: Any = checker._core
    core.valid = fused.valid
    core.is_valid = fused.is_valid
    core.first_invalid = fused.first_invalid
    return checker


def _ompl_road(checker: CollisionChecker, problem: Any, Q: np.ndarray) -> dict[str, Any]:
    """The OMPL adapter's validity callback on OMPL states: (isValid, to_q, guard, states)."""
    from plannerlab.planners import ompl as adapter  # the only user of ompl
    from plannerlab.planners.base import BudgetTracker

    space = adapter._Space(problem.robot)
    tracker = BudgetTracker(Budget(time_limit_s=1e9), checker)
    guard = adapter._Guard(checker, tracker)
    si = adapter.ob.SpaceInformation(space.space)

    def state_valid(state: Any) -> bool:  # as in OmplPlanner's solve
        return guard.is_valid(space.to_q(state))

    si.setStateValidityChecker(state_valid)
    si.setup()
    states = []
    for q in Q:
        s = space.space.allocState()
        space.set_state(s, q)
        states.append(s)
    return {"si": si, "space": space, "guard": guard, "states": states}


def _best(fn: Callable[[], object], n: int, repeats: int, out: list[float]) -> None:
    t = time.perf_counter()
    fn()
    out.append((time.perf_counter() - t) / n * 1e6)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("folder", type=Path)
    ap.add_argument("--states", type=int, default=7200)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--skip-agreement", action="store_true")
    args = ap.parse_args()
    files = sorted(args.folder.glob("*_0001.toml"))
    print(f"load average at the start: {os.getloadavg()[0]:.2f} (2 cores)")
    if not args.skip_agreement:
        _agreement(files, args.states)
    p = parse_problem(files[0])
    old = CollisionChecker(p.robot, p.scene, backend="core")
    new = CollisionChecker(p.robot, p.scene, backend="core")
    assert old._core is not None and new._core is not None
    fused = ChainValidity.of(new._core)
    _wired(new, fused)
    Q = np.random.default_rng(0).uniform(p.robot.lower, p.robot.upper, (2000, 7))
    assert np.array_equal(old.valid_batch(Q), new.valid_batch(Q))
    one = Q[:500]
    roads = {name: _ompl_road(c, p, one) for name, c in (("old", old), ("new", new))}
    rows: dict[str, list[float]] = {}

    def timed(name: str, fn: Callable[[], object], n: int) -> None:
        _best(fn, n, args.repeats, rows.setdefault(name, []))

    for _ in range(args.repeats):
        timed("kinematics (core.segments)", lambda: old._core.segments(Q), len(Q))  # type: ignore[union-attr]
        timed("batched validity, old (Core.valid)", lambda: old.valid_batch(Q), len(Q))
        timed("batched validity, new (ChainValidity.valid)", lambda: fused.valid(Q), len(Q))
        timed(
            "one state, new kernel method (ChainValidity.is_valid)",
            lambda: [fused.is_valid(q) for q in one],
            len(one),
        )
        timed(
            "one state, old (CollisionChecker.is_valid)",
            lambda: [old.is_valid(q) for q in one],
            len(one),
        )
        timed(
            "one state, new, wired (CollisionChecker.is_valid)",
            lambda: [new.is_valid(q) for q in one],
            len(one),
        )
        for name, road in roads.items():
            timed(
                f"one state, {name}: OMPL isValid -> callback",
                lambda road=road: [road["si"].isValid(s) for s in road["states"]],
                len(one),
            )
        road = roads["new"]
        timed(
            "  of which space.to_q(state)",
            lambda road=road: [road["space"].to_q(s) for s in road["states"]],
            len(one),
        )
        timed(
            "  of which guard.is_valid(q), new",
            lambda road=road: [road["guard"].is_valid(q) for q in one],
            len(one),
        )
    for name, vals in rows.items():
        print(f"{name:58s} {min(vals):7.2f} µs/state (median {np.median(vals):.2f})")
    b_old = min(rows["batched validity, old (Core.valid)"])
    b_new = min(rows["batched validity, new (ChainValidity.valid)"])
    o_old = min(rows["one state, old (CollisionChecker.is_valid)"])
    o_new = min(rows["one state, new, wired (CollisionChecker.is_valid)"])
    w_old = min(rows["one state, old: OMPL isValid -> callback"])
    w_new = min(rows["one state, new: OMPL isValid -> callback"])
    print(
        f"ratios old/new: batched {b_old / b_new:.2f}, one state (checker) {o_old / o_new:.2f}, "
        f"one state through OMPL {w_old / w_new:.2f}"
    )
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()

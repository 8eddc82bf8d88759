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

**Cost** (first problem, 2 000 uniform random states, seed 0). Every figure is µs per
state, the least of ``--repeats`` repetitions (the median beside it), old and new
interleaved in each repetition, so that other load on the machine counts least and alike:
kinematics; batched validity on all, valid and invalid states (the new one also with the
bodies met in chain order, the pair-ordering question); the cost of a call with no work
(0 states: dispatch and allocation); edges between valid states cut to 0.3 rad at the
problem's ``joint_step`` (OMPL's batched motion check); one state at a time on four roads:
``ChainValidity.is_valid``, ``CollisionChecker.is_valid`` (what the planners call), the
OMPL adapter's validity callback (``guard.is_valid(space.to_q(state))`` of
``planners/ompl.py``) called by OMPL's own ``SpaceInformation.isValid`` on OMPL states,
one Python call per state, and that callback's parts. "new, wired" is the checker with its
core's ``valid`` / ``is_valid`` / ``first_invalid`` answered by ``ChainValidity`` (as
``Core`` will once wired to it; ``core.py`` is not changed here).
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.collision.chain_check import ChainValidity
from plannerlab.collision.chain_valid import chain_first_bad
from plannerlab.collision.core import chain_first_invalid, edge_states
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.load import Budget, parse_problem
from plannerlab.robots.paths import MAX_EDGE_STATES


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
    import ompl.base as ob  # through the adapter's own modules below, as the planner does

    from plannerlab.planners.base import BudgetTracker
    from plannerlab.planners.ompl.guard import Guard
    from plannerlab.planners.ompl.space import Space

    space = Space(problem.robot)
    tracker = BudgetTracker(Budget(time_limit_s=1e9), checker)
    guard = Guard(checker, tracker)
    si = ob.SpaceInformation(space.space)

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


def _edges(core: Any, fused: ChainValidity, Q: np.ndarray, step: float) -> tuple[Any, Any, int]:
    """Edges between consecutive valid states of Q, each shortened to 0.3 rad at most:
    the core's ``edge_first_invalid`` and the same states through ``fused`` (edge_states,
    then one ``first_invalid`` call), and how many states they hold."""
    V = Q[core.valid(Q)]
    pairs = []
    for qa, qb in zip(V[:-1], V[1:], strict=True):
        d = qb - qa
        pairs.append((qa, qa + d * min(1.0, 0.3 / np.abs(d).max())))
    cont = np.ascontiguousarray(core.robot.continuous, dtype=np.bool_)
    weights = np.zeros(core.robot.dof)
    n_states = sum(core.edge_first_invalid(a, b, step)[0] for a, b in pairs)

    def old() -> None:
        for a, b in pairs:
            core.edge_first_invalid(a, b, step)

    def new() -> None:
        for a, b in pairs:
            _, E = edge_states(a, b, step, cont, 2**62, MAX_EDGE_STATES, weights)
            fused.first_invalid(E)

    return old, new, n_states


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("folder", type=Path)
    ap.add_argument("--states", type=int, default=7200)
    ap.add_argument("--repeats", type=int, default=21)
    ap.add_argument("--skip-agreement", action="store_true")
    args = ap.parse_args()
    files = sorted(args.folder.glob("*_0001.toml"))
    print(f"load average at the start: {os.getloadavg()[0]:.2f} (2 cores)")
    if not args.skip_agreement:
        _agreement(files, args.states)
    p = parse_problem(files[0])
    old = CollisionChecker(p.robot, p.scene, backend="core")
    new = CollisionChecker(p.robot, p.scene, backend="core")
    core: Any = old._core
    core._fused = None  # "old": the core's own kernels, as before ChainValidity was wired in
    assert core is not None and new._core is not None
    fused = ChainValidity.of(new._core)
    base_first = ChainValidity.of(new._core, body_order=np.arange(p.robot.dof + 1))
    _wired(new, fused)
    Q = np.random.default_rng(0).uniform(p.robot.lower, p.robot.upper, (2000, 7))
    v = old.valid_batch(Q)
    assert np.array_equal(v, new.valid_batch(Q))
    good, bad, none = Q[v], Q[~v], Q[:0]
    one = Q[:200]
    roads = {name: _ompl_road(c, p, one) for name, c in (("old", old), ("new", new))}
    edge_old, edge_new, n_edge = _edges(core, fused, Q[:400], p.joint_step)
    rows: dict[str, list[float]] = {}

    def timed(name: str, fn: Callable[[], object], n: int) -> None:
        t = time.perf_counter()
        fn()
        rows.setdefault(name, []).append((time.perf_counter() - t) / n * 1e6)

    print(
        f"{p.name}: {len(Q)} states ({len(good)} valid), {n_edge} edge states at "
        f"{p.joint_step} rad; µs per state, least of {args.repeats} (median)"
    )
    for _ in range(args.repeats):
        timed("kinematics (core.segments)", lambda: core.segments(Q), len(Q))
        timed("batched, all states: old (Core.valid)", lambda: old.valid_batch(Q), len(Q))
        timed("batched, all states: new (ChainValidity.valid)", lambda: fused.valid(Q), len(Q))
        timed("batched, valid states: old", lambda: core.valid(good), len(good))
        timed("batched, valid states: new", lambda: fused.valid(good), len(good))
        timed("batched, invalid states: old", lambda: core.valid(bad), len(bad))
        timed("batched, invalid states: new (last body first)", lambda: fused.valid(bad), len(bad))
        timed(
            "batched, invalid states: new, first body first",
            lambda: base_first.valid(bad),
            len(bad),
        )
        timed(
            "call overhead: old chain_first_invalid, 0 states",
            lambda: [chain_first_invalid(none, *core._chain, *core._geo) for _ in range(200)],
            200,
        )
        timed(
            "call overhead: new chain_first_bad, 0 states",
            lambda: [chain_first_bad(none, *fused.args) for _ in range(200)],
            200,
        )
        timed("edges (0.3 rad): old (Core.edge_first_invalid)", edge_old, n_edge)
        timed("edges (0.3 rad): new (edge_states + ChainValidity)", edge_new, n_edge)
        timed(
            "one state: new, ChainValidity.is_valid", lambda: [fused.is_valid(q) for q in one], 200
        )
        timed(
            "one state: old, CollisionChecker.is_valid", lambda: [old.is_valid(q) for q in one], 200
        )
        timed(
            "one state: new, wired, CollisionChecker.is_valid",
            lambda: [new.is_valid(q) for q in one],
            200,
        )
        for name, road in roads.items():
            timed(
                f"one state through OMPL's isValid: {name}",
                lambda road=road: [road["si"].isValid(s) for s in road["states"]],
                200,
            )
        road = roads["new"]
        timed(
            "  of which the adapter's space.to_q(state)",
            lambda road=road: [road["space"].to_q(s) for s in road["states"]],
            200,
        )
        timed(
            "  of which the adapter's guard.is_valid(q), new",
            lambda road=road: [road["guard"].is_valid(q) for q in one],
            200,
        )
    for name, vals in rows.items():
        print(f"{name:56s} {min(vals):7.2f} ({np.median(vals):.2f})")

    def ratio(a: str, b: str) -> str:
        return f"{min(rows[a]) / min(rows[b]):.2f}"

    print(
        "ratios old/new: batched "
        + ratio(
            "batched, all states: old (Core.valid)",
            "batched, all states: new (ChainValidity.valid)",
        )
        + ", one state (checker) "
        + ratio(
            "one state: old, CollisionChecker.is_valid",
            "one state: new, wired, CollisionChecker.is_valid",
        )
        + ", one state through OMPL "
        + ratio("one state through OMPL's isValid: old", "one state through OMPL's isValid: new")
        + ", edges "
        + ratio(
            "edges (0.3 rad): old (Core.edge_first_invalid)",
            "edges (0.3 rad): new (edge_states + ChainValidity)",
        )
    )
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()

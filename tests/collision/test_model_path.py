"""The grid re-check in the compiled model (``check_path(..., mode="grid")`` through
:func:`plannerlab.collision.model_path.grid_check`) gives what densifying the path in
numpy and checking its states in order gives (the checker's road until its model is
built, and the only one without a model): the
verdict, the states checked and counted, the first invalid edge and state, and the same
stops between chunks; on the Panda in a MotionBenchMaker-like scene and on Arm-Z."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.fcl_checker import CollisionChecker, PathCheck
from plannerlab.errors import PlannerlabError
from plannerlab.problem.catalog import load_problem

NAMES = ("panda", "armz_pocket")


def checkers(name: str) -> tuple[Any, CollisionChecker, CollisionChecker]:
    p = load_problem(
        PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml" if name == "panda" else name
    )
    compiled = CollisionChecker(p.robot, p.scene, margin_m=p.safety_margin_m)
    compiled.model  # noqa: B018 - built: an unfused core's grid checks run in it
    numpy_road = CollisionChecker(p.robot, p.scene, margin_m=p.safety_margin_m)
    assert numpy_road._grid_model() is None  # no model built: the dense path in numpy
    if compiled._core.fused:  # a fused chain keeps the numpy road: the kernel is put in here
        assert compiled._grid_model() is None
        compiled._path_model = compiled.model
    assert compiled._grid_model() is not None
    return p, compiled, numpy_road


def same(a: PathCheck, b: PathCheck) -> bool:
    states = (a.first_invalid_state is None and b.first_invalid_state is None) or (
        a.first_invalid_state is not None
        and b.first_invalid_state is not None
        and np.array_equal(a.first_invalid_state, b.first_invalid_state)
    )
    return states and (a.valid, a.states_checked, a.first_invalid_edge, a.pairs, a.complete) == (
        b.valid,
        b.states_checked,
        b.first_invalid_edge,
        b.pairs,
        b.complete,
    )


@pytest.mark.parametrize("name", NAMES)
def test_grid_check_in_the_model_is_the_dense_path_checked_in_order(name: str):
    p, new, old = checkers(name)
    r = p.robot
    lo = np.where(r.continuous, -np.pi, r.lower)
    hi = np.where(r.continuous, np.pi, r.upper)
    step = p.joint_step / 4.0
    rng = np.random.default_rng(5)
    verdicts = set()
    for _ in range(60):
        k = int(rng.integers(1, 5))
        P = lo + (hi - lo) * rng.random((k, r.dof))
        P[1:] = P[0] + rng.uniform(0.02, 0.3) * (P[1:] - P[0])  # short edges: some free
        for stop, chunk in ((None, 4096), (lambda: False, 7)):
            c_new, c_old = new.checks, old.checks
            a = new.check_path(P, step, stop=stop, chunk=chunk, mode="grid")
            b = old.check_path(P, step, stop=stop, chunk=chunk, mode="grid")
            assert same(a, b), (a, b)
            assert new.checks - c_new == old.checks - c_old >= a.states_checked
            verdicts.add(a.valid)
    assert verdicts == {True, False}  # both kinds of path were compared


@pytest.mark.parametrize("name", NAMES)
def test_grid_check_stops_between_chunks_as_before(name: str):
    """``stop`` is asked before each chunk of states: after two chunks of 5 it ends the
    check incomplete, with 10 states checked and counted, on both roads."""
    p, new, old = checkers(name)
    r = p.robot
    P = np.vstack(
        [p.q_start, p.q_start + 0.5 * np.sign(np.where(r.upper > p.q_start + 0.5, 1, -1))]
    )
    results = []
    for c in (new, old):
        asked = [0]

        def stop(asked: list[int] = asked) -> bool:
            asked[0] += 1
            return asked[0] > 2

        c0 = c.checks
        res = c.check_path(P, p.joint_step / 4.0, stop=stop, chunk=5, mode="grid")
        results.append((res.complete, res.valid, res.states_checked, c.checks - c0))
    assert results[0] == results[1] == (False, False, 10, 10)


def test_grid_check_refuses_a_too_long_edge_as_densify_does():
    p, new, _ = checkers("panda")
    P = np.vstack([p.q_start, p.q_start + 1.0])
    with pytest.raises(PlannerlabError, match="more than the limit"):
        new.check_path(P, 1e-6, mode="grid")

"""The public checker (``pl.checker``): what a user who checks states gets."""

from __future__ import annotations

import numpy as np
import pytest

import plannerlab as pl
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError


@pytest.fixture(scope="module")
def window():
    problem = pl.load_problem("armz_window")
    return problem, pl.checker(problem)


def test_one_state_and_a_batch_give_the_same_verdicts_as_fcl(window):
    problem, check = window
    rng = np.random.default_rng(3)
    Q = rng.uniform(check.lower, check.upper, (400, check.dof))
    ok = check.valid(Q)
    assert ok.dtype == bool and ok.shape == (400,)
    assert 0.05 < ok.mean() < 0.95
    assert [check.valid(q) for q in Q[:100]] == ok[:100].tolist()
    fcl = CollisionChecker(problem.robot, problem.scene, "fcl", problem.safety_margin_m)
    assert np.array_equal(ok, fcl.valid_batch(Q))
    assert check.checks >= 500


def test_the_bounds_wrap_continuous_joints_and_bad_states_are_refused(window):
    problem, check = window
    assert check.dof == problem.robot.dof
    assert np.all(check.lower == -np.pi) and np.all(check.upper == np.pi)  # Arm-Z turns
    with pytest.raises(PlannerlabError, match=rf"shape \({check.dof},\)"):
        check.valid(np.zeros(check.dof + 1))
    with pytest.raises(PlannerlabError, match="finite"):
        check.valid(np.full(check.dof, np.nan))
    with pytest.raises(PlannerlabError, match="one state"):
        check.clearance(np.zeros((2, check.dof)))


def test_clearance_is_the_robots_own_distance_to_the_scene(window):
    problem, check = window
    q = np.full(check.dof, np.pi)  # the straight column, clear of the walls
    d = check.clearance(q)
    fcl = CollisionChecker(problem.robot, problem.scene, "fcl", 0.0)
    assert d == pytest.approx(fcl.clearance(q), abs=1e-6)
    assert d > check.margin_m


def test_edge_valid_is_the_grids_verdict(window):
    problem, check = window
    rng = np.random.default_rng(5)
    Q = rng.uniform(check.lower, check.upper, (300, check.dof))
    V = Q[check.valid(Q)]
    grid = CollisionChecker(problem.robot, problem.scene, margin_m=problem.safety_margin_m,
                            edge_check="grid")  # fmt: skip
    seen = set()
    for a, b in zip(V[:20], V[1:21], strict=True):
        b = a + 0.2 * (b - a)
        want = grid.check_edge(a, b, check.joint_step_rad)[1] is None
        assert check.edge_valid(a, b) == want
        seen.add(want)
    assert seen == {True, False}


def test_read_only_states_reuse_the_compiled_queries(window):
    """A read-only array (a frozen record's path) is another type to numba: without a
    writeable copy at the boundary, every compiled query would be compiled again for it,
    inside the clock of whatever leg met it first."""
    from plannerlab.collision import one_state, queries

    problem, check = window
    rng = np.random.default_rng(7)
    Q = rng.uniform(check.lower, check.upper, (20, check.dof))
    expected = check.valid(Q)
    one = [check.valid(q) for q in Q]
    core = problem_core(problem)
    core_one = [core.is_valid(q) for q in Q]
    seen = (len(queries.states.signatures), len(one_state.valid_state.signatures))
    R = Q.copy()
    R.setflags(write=False)
    assert np.array_equal(check.valid(R), expected)
    assert [check.valid(q) for q in R] == one
    assert [core.is_valid(q) for q in R] == core_one
    assert core.first_invalid(R) == core.first_invalid(Q)
    assert (len(queries.states.signatures), len(one_state.valid_state.signatures)) == seen


def problem_core(problem):
    """The compiled core checker of ``problem`` (what the planners call)."""
    return CollisionChecker(problem.robot, problem.scene, margin_m=problem.safety_margin_m)

"""The clearance margin (``[planning] safety_margin_m``) and the metric edge resolution.

* Every registered planner's solved path keeps the margin: no state of it is closer than
  the margin to the scene (or a link pair closer than the margin to each other), by the
  FCL reference's distance on the robot's true capsules; ``min_clearance_m`` says so.
* Edges are checked in metres: on the grid (``edge_check="grid"``) no point of the robot
  moves further than the margin between two checked states (Arm-Z, IRb-6 and the
  continuum chain); certified (``"certified"``, the default on the core) the grid's
  verdict from a few stretches each proved free as a whole, with far fewer state tests.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_planner_contract import PARAMS, _result, problem_for

from plannerlab.collision.agreement import sample_states
from plannerlab.collision.core import Core
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem

#: the core's and FCL's distances agree to ~1e-6 m (FCL's capsule distances are iterative)
TOL_M = 1e-5


@pytest.mark.parametrize("name", PARAMS)
def test_solved_path_keeps_the_margin(name: str) -> None:
    r = _result(name)
    if not r.solved:
        pytest.fail(f"not solved: {r.reason}")
    if getattr(make_planner(name), "allows_contact", False):
        pytest.skip("chord_arc wraps around obstacles by design (declared contacts)")
    problem = problem_for(name)
    margin = problem.safety_margin_m
    assert margin > 0
    reference = CollisionChecker(problem.robot, problem.scene, backend="fcl")  # no margin
    clearances = np.array([reference.clearance(q) for q in r.path])
    assert clearances.min() >= margin - TOL_M, (clearances.min(), margin)
    assert r.min_clearance_m == pytest.approx(clearances.min(), abs=TOL_M)


def _axis_motion_m(checker: CollisionChecker, states: np.ndarray) -> np.ndarray:
    """Per step between consecutive states: an upper bound of how far any point of the
    capsules moved (axis points on a fine grid, plus radius x the turn of the axis)."""
    robot = checker.robot
    S = np.asarray(robot.link_segments(states), dtype=float)  # (k, L, 2, 3)
    t = np.linspace(0.0, 1.0, 21)[None, None, :, None]
    pts = S[:, :, :1] + t * (S[:, :, 1:] - S[:, :, :1])  # (k, L, 21, 3)
    moved = np.linalg.norm(np.diff(pts, axis=0), axis=-1).max(axis=-1)  # (k-1, L)
    axis = S[:, :, 1] - S[:, :, 0]
    axis /= np.maximum(np.linalg.norm(axis, axis=-1, keepdims=True), 1e-12)
    turn = np.arccos(np.clip(np.sum(axis[1:] * axis[:-1], axis=-1), -1.0, 1.0))
    return (moved + turn * np.asarray(robot.link_radii_m)[None, :]).max(axis=1)


@pytest.mark.parametrize("problem_name", ["armz_inspection", "irb6_case1", "continuum_case1"])
def test_no_point_moves_more_than_the_margin_between_checked_states(problem_name: str) -> None:
    problem = load_problem(problem_name)
    # the continuum files turn the margin off (a sleeve they touch): check 1 cm there too
    margin = problem.safety_margin_m or 0.01
    checker = CollisionChecker(problem.robot, problem.scene, margin_m=margin, edge_check="grid")
    robot = problem.robot
    rng = np.random.default_rng(3)
    q0 = np.asarray(problem.q_start, dtype=float)
    span = np.minimum(robot.upper - robot.lower, 2 * np.pi)
    q1 = np.clip(q0 + rng.uniform(-0.05, 0.05, robot.dof) * span, robot.lower, robot.upper)
    q2 = np.clip(q1 + rng.uniform(-0.05, 0.05, robot.dof) * span, robot.lower, robot.upper)
    path = np.array([q0, q1, q2])
    states, _ = checker.densify(path, problem.joint_step / 4.0)
    motion = _axis_motion_m(checker, states)
    assert motion.max() <= margin * (1 + 1e-6), (motion.max(), margin)
    plain = CollisionChecker(robot, problem.scene)  # no margin: radian steps only
    coarse, _ = plain.densify(path, problem.joint_step / 4.0)
    assert len(states) >= len(coarse)  # the radian step still holds too
    if problem_name == "armz_inspection":
        # on the 16-m arm the metric bound is what decides: radian steps alone let the
        # geometry move further than the margin between checked states
        assert _axis_motion_m(plain, coarse).max() > margin
    # the core's edge check checks exactly these states (the edge's count agrees)
    n, bad = checker.check_edge(q0, q1, problem.joint_step / 4.0, max_states=0)
    assert n == len(checker.densify(path[:2], problem.joint_step / 4.0)[0]) - 1
    assert bad is None


def _near_contact_edges(problem_name: str, n: int, seed: int):
    """Edges that start at valid states within ~1 mm of the margin's contact."""
    problem = load_problem(problem_name)
    robot = problem.robot
    margin = problem.safety_margin_m
    certified = CollisionChecker(robot, problem.scene, margin_m=margin)
    rng = np.random.default_rng(seed)
    starts = sample_states(certified._core, "contact", 3 * n, rng)
    starts = starts[certified._core.valid(starts)][:n]
    ends = starts + rng.normal(0.0, 0.02, starts.shape)
    return problem, certified, starts, ends


@pytest.mark.parametrize("problem_name", ["armz_pocket", "irb6_case1"])
def test_certified_edges_are_the_grids_verdict_and_keep_half_the_margin(
    problem_name: str,
) -> None:
    """Certified edges (the default with the core) give the grid's verdict on edges that
    graze the margin, a valid one keeps half the margin between its checked states, and
    on Arm-Z they need far fewer state tests than the grid."""
    problem, certified, starts, ends = _near_contact_edges(problem_name, 24, seed=7)
    margin = problem.safety_margin_m
    assert certified.edge_check == "certified"
    grid = CollisionChecker(problem.robot, problem.scene, margin_m=margin, edge_check="grid")
    true = Core(problem.robot, problem.scene, 0.0)  # no margin: the real capsules
    step = problem.joint_step / 4.0
    t = np.linspace(0.0, 1.0, 401)[:, None]
    n_valid = used = grid_used = 0
    for a, b in zip(starts, ends, strict=True):
        check = certified.check_path(np.array([a, b]), step)
        g = grid.check_path(np.array([a, b]), step)
        assert check.valid == g.valid
        used += check.states_checked
        grid_used += g.states_checked
        if check.valid:
            n_valid += 1
            between = min(true.clearance(q) for q in a + t * (b - a))
            assert between >= margin / 2 - 1e-9, (between, margin)
    assert 0 < n_valid < len(starts)  # both verdicts met
    if problem_name == "armz_pocket":
        assert used * 3 < grid_used  # the point of it: far fewer states than the grid


def test_certified_edges_find_every_collision_the_margin_free_grid_finds() -> None:
    problem, certified, starts, _ = _near_contact_edges("armz_pocket", 30, seed=8)
    plain = CollisionChecker(problem.robot, problem.scene)  # no margin, radian steps
    rng = np.random.default_rng(9)
    ends = starts + rng.normal(0.0, 0.05, starts.shape)
    step = problem.joint_step / 4.0
    hits = 0
    for a, b in zip(starts, ends, strict=True):
        if not plain.check_path(np.array([a, b]), step).valid:
            hits += 1
            assert not certified.check_path(np.array([a, b]), step).valid
            n, bad = certified.check_edge(a, b, step)
            assert bad is not None and bad == n - 1
    assert hits > 0


def test_certified_edge_check_stops_at_its_limit() -> None:
    problem = load_problem("armz_pocket")
    certified = CollisionChecker(problem.robot, problem.scene, margin_m=problem.safety_margin_m)
    a = np.asarray(problem.q_start, dtype=float)
    b = a + 0.05
    step = problem.joint_step / 4.0
    n_all, bad_all = certified.check_edge(a, b, step)
    assert bad_all is None and n_all > 2  # valid, and more than two states
    c0 = certified.checks
    n, bad = certified.check_edge(a, b, step, max_states=2)
    assert certified.checks - c0 == 2
    assert n > 2 and bad is None  # unfinished: more than the limit is needed
    with pytest.raises(ValueError, match="edge_check"):
        CollisionChecker(problem.robot, problem.scene, edge_check="fast")
    with pytest.raises(ValueError, match="edge_check"):  # conservative advancement is gone
        CollisionChecker(problem.robot, problem.scene, edge_check="advance")

"""The clearance descent (``gradient.clearance`` and its escapes) towards a goal state
(:class:`~plannerlab.problem.goals.JointGoal`): it descends on the joint residual plus
clearance, not on the tip pose the goal state implies. Fixed seeds, check budgets; every
path re-checked with FCL at a quarter of the problem's joint step."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.goals import JointGoal
from plannerlab.problem.load import Budget, parse_problem
from plannerlab.problem.mbm import problem_toml
from plannerlab.robots.paths import path_length

PANDA = ROOT / "problems" / "urdf" / "panda"
MBM = Path(__file__).resolve().parents[1] / "data" / "mbm"


def _recheck(problem, path: np.ndarray) -> None:
    fcl = CollisionChecker(problem.robot, problem.scene, backend="fcl")
    assert fcl.check_path(path, problem.joint_step / 4).valid


@pytest.fixture(scope="module")
def shelf(tmp_path_factory):
    """The MotionBenchMaker-like Panda shelf problem of tests/data/mbm, imported."""
    out = tmp_path_factory.mktemp("mbm") / "shelf.toml"
    out.write_text(
        problem_toml(
            MBM / "scene_shelf.yaml",
            MBM / "request_shelf.yaml",
            out_path=out,
            urdf=PANDA / "panda_spherized.urdf",
            srdf=PANDA / "panda.srdf",
            tip_link="panda_hand",
        ),
        encoding="utf-8",
    )
    return parse_problem(out)


@pytest.mark.parametrize("planner", ["gradient.clearance", "gradient.clearance+detour"])
def test_the_clearance_descent_reaches_an_imported_goal_state(shelf, planner):
    """The Panda into the shelf: the descent goes to the goal state itself, nearly
    straight in joint space (no tip approach point, no stall: the detour is not needed),
    and ends within the goal's joint tolerance."""
    goal = shelf.goals[0]
    assert isinstance(goal, JointGoal)
    r = make_planner(planner).solve(
        shelf, 0, Budget(max_collision_checks=400), np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    assert (r.local_minima, r.collision_checks) == (0, 122)
    assert float(goal.joint_error(r.path[-1])) <= goal.tol_rad
    straight = float(np.linalg.norm(goal.q_rad - shelf.q_start))
    assert path_length(r.path, shelf.robot.continuous) <= 1.01 * straight
    _recheck(shelf, r.path)


@pytest.fixture(scope="module")
def variant():
    """``armz_inspection_v00`` with its witness states as goal states (0.01 rad): leg 4
    goes from witness state 3 to witness state 4."""
    problem = parse_problem(ROOT / "problems" / "variants" / "armz_inspection_v00.toml")
    W = np.array(problem.extras["witness"]["goal_states_rad"], dtype=float)
    goals = tuple(
        JointGoal.at(problem.robot, g.name, w, 0.01) for g, w in zip(problem.goals, W, strict=True)
    )
    return dataclasses.replace(problem, goals=goals), W


def test_the_detour_escapes_a_stall_on_the_way_to_a_goal_state(variant):
    """Arm-Z, leg 4 of a room variant towards a goal state: the plain descent stalls at a
    wall; the detour retracts the tip along the body and the descent then reaches the
    goal state, within a check budget."""
    problem, W = variant
    goal = problem.goal(4)
    budget = Budget(max_collision_checks=1000)
    plain = make_planner("gradient.clearance").solve(
        problem, 4, budget, np.random.default_rng(0), q_start=W[3]
    )
    assert plain.status is Status.LOCAL_MINIMUM
    assert float(goal.joint_error(plain.path[-1])) > 1.0  # stuck far from the goal state
    r = make_planner("gradient.clearance+detour").solve(
        problem, 4, budget, np.random.default_rng(0), q_start=W[3]
    )
    assert r.status is Status.SOLVED, r.reason
    assert (r.local_minima, r.escapes) == (1, 1)
    assert r.extra["escapes"][0]["how"] == "retract 2 modules"
    assert r.collision_checks == 503
    assert float(goal.joint_error(r.path[-1])) <= goal.tol_rad
    np.testing.assert_allclose(r.path[0], W[3])
    _recheck(problem, r.path)

"""Where the descent near a stall finds no goal, ``gradient.clearance+rrtconnect`` draws
its escape's goal states from the IK pool (OMPL's ``goal_selection = "near_or_ik"``)
instead of giving up with ``invalid_goal``.

The problem: a 10-module Arm-Z (9 joints) from the straight column, its goal 1 m behind
a 2.5 m plate (the goal pose is the tip of a collision-free state, found by drawing bent
states and keeping one whose descent stalls at the plate while IK reaches the goal). The
clearance descent stalls against the plate; from the stall the unchecked descent that
picks the near goal stalls too (the plate's clearance term stops it), so there is no
goal near the stall; IK seeded from the stall finds goal states the other side.
"""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget

BEHIND_PLATE_TOML = """\
[problem]
name = "armz_behind_plate"
description = "a short Arm-Z; its goal behind a plate the clearance descent stalls at"

[robot]
type = "armz"
n_modules = 10

[start]
fill_deg = 180.0

[[obstacles]]
name = "ground"
type = "box"
center_m = [0.0, 0.0, -0.95]
size_m = [40.0, 40.0, 1.0]

[[obstacles]]
name = "plate"
type = "box"
center_m = [1.598, 0.0, 4.909]
size_m = [0.2, 2.5, 2.5]

[[goals]]
name = "behind"
p_m = [2.598, 0.866, 4.909]
n = [-0.0974, 0.306, 0.947]
pos_tol_m = 0.2
angle_tol_deg = 15.0

[budget]
max_collision_checks = 60000

[checking]
joint_step = 0.05
"""


@pytest.fixture(scope="module")
def behind_plate(tmp_path_factory):
    path = tmp_path_factory.mktemp("escape_goals") / "armz_behind_plate.toml"
    path.write_text(BEHIND_PLATE_TOML, encoding="utf-8")
    return load_problem(path)


@pytest.fixture(scope="module")
def stall(behind_plate):
    r = make_planner("gradient.clearance").solve(
        behind_plate, 0, Budget(max_iterations=1500), np.random.default_rng(0)
    )
    assert r.status is Status.LOCAL_MINIMUM, r.reason
    return r.path[-1]


def test_no_goal_near_the_stall_but_the_ik_pool_has_some(behind_plate, stall):
    budget = Budget(max_collision_checks=50_000)
    near = make_planner("ompl.rrtconnect", {"goal_selection": "near", "goal_samples": 1}).solve(
        behind_plate, 0, budget, np.random.default_rng(0), q_start=stall
    )
    assert near.status is Status.INVALID_GOAL, near.reason
    assert near.extra["goal_pool"] == 0
    both = make_planner("ompl.rrtconnect", {"goal_selection": "near_or_ik"}).solve(
        behind_plate, 0, budget, np.random.default_rng(0), q_start=stall
    )
    assert both.extra["goal_near_found"] is False
    assert 1 <= both.extra["goal_pool"] <= 4
    assert both.status is Status.SOLVED, both.reason


def test_clearance_rrtconnect_escapes_to_ik_goals_instead_of_giving_up(behind_plate, stall):
    problem = behind_plate
    r = make_planner("gradient.clearance+rrtconnect").solve(
        problem, 0, problem.budget, np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    assert (r.local_minima, r.escapes) == (1, 1)
    (escape,) = r.extra["escapes"]
    assert escape["how"] == "rrtconnect" and escape["start_from_stall_rad"] == 0.0
    assert r.collision_checks <= problem.budget.max_collision_checks
    # the descent's part ends at the stall; the whole path is collision-free, in the goal
    assert any(np.allclose(q, stall) for q in r.path)
    checker = problem_checker(problem)
    assert checker.check_path(r.path, problem.joint_step).valid
    assert bool(problem.goal(0).contains(problem.robot, r.path[-1]))

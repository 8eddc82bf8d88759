"""The compiled IK descent of a URDF chain (collision/chain_ik.py): the numpy descent's
steps to rounding, and goal states that are in the region, collision-free and the same
for the same seed."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.chain_ik import descent_for_robot
from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.ik import sample_goal_state, solve_ik
from plannerlab.problem.load import parse_problem
from plannerlab.robots.armz.model import ArmZ

PANDA = PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml"


@pytest.fixture(scope="module")
def panda():
    problem = parse_problem(PANDA)
    p, n = problem.robot.tip(problem.goal(0).q_rad)
    return problem, GoalRegion("tip", p, n, 0.01, 10.0)


def test_the_compiled_descent_takes_the_numpy_descents_steps(panda):
    problem, goal = panda
    robot = problem.robot
    descent = descent_for_robot(robot)
    assert descent is not None
    rng = np.random.default_rng(3)
    reached = 0
    for _ in range(12):
        q0 = rng.uniform(robot.lower, robot.upper)
        a = solve_ik(robot, goal, q0, descent=descent)
        b = solve_ik(robot, goal, q0)
        assert a.iterations == b.iterations and a.success == b.success
        assert np.abs(a.q - b.q).max() < 1e-9
        reached += a.success
    assert 0 < reached < 12  # some descents reach the region, some do not


def test_compiled_goal_states_are_in_the_region_valid_and_seeded(panda):
    problem, goal = panda
    robot = problem.robot
    checker = problem_checker(problem)
    found = []
    for seed in range(6):
        descent = descent_for_robot(robot)
        q = sample_goal_state(
            robot,
            goal,
            checker,
            np.random.default_rng(seed),
            seeds=[problem.q_start],
            descent=descent,
        )
        again = sample_goal_state(
            robot,
            goal,
            checker,
            np.random.default_rng(seed),
            seeds=[problem.q_start],
            descent=descent,
        )
        assert q is not None and np.array_equal(q, again)
        assert goal.contains(robot, q) and checker.is_valid(q)
        assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
        found.append(q)
    assert len({tuple(np.round(q, 6)) for q in found}) > 1  # seeds give different states


def test_only_families_that_register_it_get_the_compiled_descent():
    assert descent_for_robot(ArmZ(n_modules=6)) is None

"""Shared fixtures: small problems built in code, and paths to the bundled ones."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Budget, Problem
from plannerlab.problem.scene import Box, Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


@pytest.fixture
def armz() -> ArmZ:
    return ArmZ()


def small_armz_problem(n_modules: int = 6, with_wall: bool = True) -> Problem:
    """A short Arm-Z beside a wall, with a reachable goal: quick to solve."""
    robot = ArmZ(n_modules=n_modules)
    q_start = np.full(robot.dof, np.pi)
    q_goal = q_start.copy()
    q_goal[1] -= 1.0
    q_goal[3] += 0.8
    p, n = robot.tip(q_goal)
    obstacles = (
        (Box("wall", pose_matrix([2.0, 0.0, 2.0], [0, 0, 0]), [0.4, 4.0, 4.0]),)
        if with_wall
        else ()
    )
    return Problem(
        name=f"small_armz_{n_modules}",
        robot=robot,
        scene=Scene(obstacles),
        q_start=q_start,
        goals=(GoalRegion("goal", p, n, 0.1, 10.0),),
        budget=Budget(max_iterations=500),
        joint_step=0.02,
    )


def colliding_state(problem: Problem, seed: int = 0) -> np.ndarray:
    """The first of a fixed random sequence of states that collides in ``problem``."""
    from plannerlab.collision.fcl_checker import CollisionChecker

    checker = CollisionChecker(problem.robot, problem.scene)
    Q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (200, problem.robot.dof))
    return Q[int(np.flatnonzero(~checker.valid_batch(Q))[0])]


@pytest.fixture
def small_problem() -> Problem:
    return small_armz_problem()

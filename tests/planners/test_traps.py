"""Trap problems for the paper's gradient method (docs/traps.md).

Each trap is an Arm-Z scene where the faithful gradient method stalls far from the goal
although a collision-free path exists: the problem file's ``[witness]`` path, re-checked
here with FCL. The obstacle-free run reaching the goal shows that the stall is the trap's
doing, not the goal's.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import assert_golden_path, assert_witness_solves, path_fingerprint

from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.scene import Scene

TRAPS = ("armz_pocket", "armz_window", "armz_cavity", "armz_thin_wall")


@pytest.fixture(scope="module", params=TRAPS)
def trap(request):
    return load_problem(request.param)


def solve(problem, planner: str, seed: int = 0):
    return make_planner(planner).solve(problem, 0, problem.budget, np.random.default_rng(seed))


def test_trap_is_the_papers_arm_at_the_straight_column(trap):
    robot = trap.robot
    assert robot.kind == "armz" and robot.n_modules == 24
    assert robot.collision_radius_m == 0.75 and robot.self_exclude_within == 5
    np.testing.assert_allclose(trap.q_start, np.pi)
    assert trap.simulation.gravity_mps2 == (0.0, 0.0, 0.0)
    assert trap.budget.max_iterations == 2000 and trap.joint_step == 0.02
    assert "ground" in trap.scene.names and len(trap.scene.names) >= 2


def test_witness_is_collision_free_from_the_start_into_the_goal(trap):
    assert_witness_solves(trap)


def test_faithful_gradient_stalls_far_from_the_goal(trap):
    r = solve(trap, "gradient")
    assert r.status is Status.LOCAL_MINIMUM, r.reason
    assert r.iterations == r.extra["stall_iteration"] < trap.budget.max_iterations
    assert r.pos_err_m > 2 * trap.goal(0).pos_tol_m
    assert r.trace[-1] >= r.settings["epsilon"]
    window = r.settings["stall_window"]
    assert r.trace[-window:].min() > r.trace.min() - r.settings["stall_min_decrease"]
    # the analytic variant takes the same route to the same stall
    an = solve(trap, "gradient.analytic")
    assert an.status is Status.LOCAL_MINIMUM and an.iterations == r.iterations
    np.testing.assert_allclose(an.path[-1], r.path[-1], atol=1e-4)


#: golden values of the analytic variant (seed 0; it ignores its generator): the stall
#: iteration; the path in tests/data/golden_paths.json (``traps/<problem>``)
STALLS = {"armz_pocket": 61, "armz_window": 62, "armz_cavity": 62, "armz_thin_wall": 62}


def test_stall_is_pinned(trap):
    r = solve(trap, "gradient.analytic")
    assert r.status is Status.LOCAL_MINIMUM
    assert r.extra["stall_iteration"] == STALLS[trap.name]
    assert_golden_path(f"traps/{trap.name}", path_fingerprint(r.path))


def test_without_the_trap_the_gradient_reaches_the_goal(trap):
    ground = tuple(o for o in trap.scene.obstacles if o.name == "ground")
    free = dataclasses.replace(trap, scene=Scene(ground))
    r = solve(free, "gradient.analytic")
    assert r.status is Status.SOLVED, r.reason

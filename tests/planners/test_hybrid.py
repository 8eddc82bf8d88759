"""The planners that extend the gradient method: they meet the trap's local minimum,
leave it, and their paths hold up in PyBullet."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.robots.base import joint_difference
from plannerlab.robots.paths import path_length
from plannerlab.sim.execute import execute


def _pocket_without_margin():
    """armz_pocket with ``[planning] safety_margin_m = 0``: the escape's mechanics (one
    stall 0.076 rad from the start, one RRT-Connect escape from it) on the trap as it was
    shaped. With the default 1-cm margin the descent meets more minima on its way (see
    :func:`test_gradient_rrtconnect_escapes_every_minimum_with_the_default_margin`);
    ``tests/planners/test_margin.py`` holds every planner to the margin."""
    return dataclasses.replace(load_problem("armz_pocket"), safety_margin_m=0.0)


def test_gradient_rrtconnect_escapes_every_minimum_with_the_default_margin():
    problem = load_problem("armz_pocket")
    assert problem.safety_margin_m == pytest.approx(0.01)
    r = make_planner("gradient+rrtconnect").solve(
        problem, 0, problem.budget.replace(max_collision_checks=200_000), np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    assert r.local_minima >= 1 and r.escapes == r.local_minima
    assert r.extra["escapes"][0]["start_from_stall_rad"] == 0.0
    assert r.min_clearance_m >= problem.safety_margin_m


def test_gradient_rrtconnect_escapes_from_the_stall_itself():
    problem = _pocket_without_margin()
    r = make_planner("gradient+rrtconnect").solve(
        problem, 0, problem.budget.replace(max_collision_checks=50_000), np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    assert r.local_minima == 1 and r.escapes == 1
    (record,) = r.extra["escapes"]
    assert record["start_from_stall_rad"] == 0.0
    assert record["start_from_leg_start_rad"] == pytest.approx(record["descent_before_stall_rad"])
    assert record["left_stall"]
    # the escape shows in the progress rows as a drop of the best goal distance: a plateau
    # at the stall (> 0, the descent's best), then 0 once RRT-Connect reached the region
    stall = make_planner("gradient").solve(
        problem, 0, problem.budget.replace(max_collision_checks=50_000), np.random.default_rng(0)
    )
    assert stall.status is Status.LOCAL_MINIMUM
    t, checks, dist, cost = r.progress.T
    drop = int(np.flatnonzero(dist == 0.0)[0])
    assert drop > 0 and dist[drop - 1] > 1.0  # outside the region by its tolerances
    assert dist[drop - 1] == pytest.approx(stall.progress[-1, 2], rel=0.05)
    assert checks[drop] > checks[drop - 1] and t[drop] > t[drop - 1]
    assert cost[-1] == pytest.approx(path_length(r.path, problem.robot.continuous))
    assert (
        CollisionChecker(problem.robot, problem.scene)
        .check_path(r.path, problem.joint_step / 4)
        .valid
    )


def test_with_a_retreat_the_escape_starts_back_at_the_start_and_executes_without_contact():
    """armz_pocket's descent stalls 0.076 rad from the start: a 0.3 rad retreat goes back
    to the start (the record says so), and that path does not touch the boulder in
    PyBullet (from the stall itself the tracking arm touches it, 8.7 mm)."""
    problem = _pocket_without_margin()
    r = make_planner("gradient+rrtconnect", {"retreat_rad": 0.3}).solve(
        problem, 0, problem.budget.replace(max_collision_checks=50_000), np.random.default_rng(0)
    )
    assert r.status is Status.SOLVED, r.reason
    (record,) = r.extra["escapes"]
    assert record["start_from_leg_start_rad"] == 0.0
    assert record["start_from_stall_rad"] > 0.0
    e = execute(problem, r.path, leg=0)
    assert e.success, e.reason
    assert not e.contacts


def test_retreat_cuts_the_descent_back_from_the_stall():
    problem = load_problem("armz_pocket")
    stall = make_planner("gradient.analytic").solve(
        problem, 0, problem.budget, np.random.default_rng(0)
    )
    assert stall.status is Status.LOCAL_MINIMUM
    planner = make_planner("gradient+rrtconnect", {"retreat_rad": 0.3})
    path = [p for p in stall.path]
    q = planner._retreat(path, len(stall.path) - 1, problem.robot.continuous)
    far = np.max(np.abs(joint_difference(q, stall.path[-1], problem.robot.continuous)))
    # the pocket's stall is within 0.3 rad of the start: the whole descent is undone
    assert far >= planner.settings.retreat_rad or len(path) == 1
    assert np.array_equal(path[-1], q)


def test_multistart_counts_minima_and_escapes_consistently():
    problem = load_problem("armz_cavity")
    r = make_planner("gradient.multistart").solve(
        problem, 0, problem.budget.replace(max_collision_checks=20_000), np.random.default_rng(1)
    )
    assert r.local_minima >= 1
    assert 0 <= r.escapes <= r.local_minima
    assert (
        CollisionChecker(problem.robot, problem.scene)
        .check_path(r.path, problem.joint_step / 4)
        .valid
    )

"""One planning context per problem and leg (planners/context.py): the checker built once
and shared by every sub-solve, the start state checked once, the sub-solves' work counted
by the leg's tracker, and an escape that selects its goal with its caller's settings."""

from __future__ import annotations

import dataclasses

import numpy as np
from conftest import toy_problem

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.planners import make_planner
from plannerlab.planners.base import Status
from plannerlab.planners.context import PlanningContext
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget
from plannerlab.robots.base import wrap_to_pi
from plannerlab.run.pipeline import leg_rng


def test_a_context_checks_its_start_once_and_a_sub_solves_context_not_again():
    problem = toy_problem()
    checker = problem_checker(problem)
    c0 = checker.checks
    ctx = PlanningContext.build(problem, 0, problem.budget, checker=checker)
    assert ctx.checker is checker and ctx.goal is problem.goal(0)
    assert (ctx.start_checked, ctx.start_problem) == (True, None)
    assert checker.checks - c0 == ctx.tracker.checks_used == 1  # the one start check
    q = ctx.q_start + 0.05
    sub = ctx.sub(Budget(max_collision_checks=10), q)
    assert sub.checker is checker and sub.tracker.parent is ctx.tracker
    assert (sub.start_checked, sub.start_problem) == (False, None)
    np.testing.assert_array_equal(sub.q_start, q)
    assert checker.checks - c0 == 1  # no second check of a sub-solve's start


def test_a_colliding_start_is_said_by_the_context_and_the_planner_reports_it():
    problem = toy_problem(radius_m=0.9)  # the column's capsules reach into the ball
    planner = make_planner("gradient")
    ctx = PlanningContext.for_planner(planner, problem, 0, problem.budget)
    assert ctx.start_problem is not None and "ball" in ctx.start_problem
    r = planner.plan(ctx, leg_rng(0, 0))
    assert r.status is Status.INVALID_START and r.reason == ctx.start_problem
    assert r.collision_checks == ctx.tracker.checks_used  # the start check, once


def test_a_hybrids_descents_and_escape_count_on_the_legs_one_checker():
    """gradient+rrtconnect on armz_pocket without the margin: one stall, one RRT-Connect
    escape (test_hybrid). Every check the result counts was made on the leg's checker: no
    descent or escape built a checker of its own (its checks would be charged on top)."""
    problem = dataclasses.replace(load_problem("armz_pocket"), safety_margin_m=0.0)
    budget = Budget(max_collision_checks=50_000)
    planner = make_planner("gradient+rrtconnect")
    checker = problem_checker(problem)
    c0 = checker.checks
    ctx = PlanningContext.for_planner(planner, problem, 0, budget, checker=checker)
    r = planner.plan(ctx, np.random.default_rng(0))
    assert r.status is Status.SOLVED, r.reason
    assert (r.local_minima, r.escapes) == (1, 1)
    assert r.collision_checks == checker.checks - c0 == ctx.tracker.checks_used
    # the contract's call builds the same context: the same path and counts
    again = planner.solve(problem, 0, budget, np.random.default_rng(0))
    np.testing.assert_array_equal(again.path, r.path)
    assert (again.collision_checks, again.iterations) == (r.collision_checks, r.iterations)


def test_an_escape_selects_its_goal_with_its_callers_settings():
    """The clearance descent's RRT-Connect escape takes the goal state the caller's own
    descent finds near its start (the caller's settings: here a deeper goal_depth), not
    the one a default gradient.clearance would find."""
    problem = toy_problem()
    caller = make_planner("gradient.clearance+rrtconnect", {"goal_depth": 0.05})
    ctx = PlanningContext.for_planner(caller, problem, 0, problem.budget)
    q0 = wrap_to_pi(ctx.q_start, problem.robot.continuous)  # where OMPL starts from
    q_caller = caller.near_goal_state(ctx, q0)
    q_default = make_planner("gradient.clearance").near_goal_state(ctx, q0)
    assert q_caller is not None and q_default is not None
    assert float(np.max(np.abs(q_caller - q_default))) > 0.1  # the settings matter here
    escape = make_planner(
        "ompl.rrtconnect", {"goal_selection": "near", "goal_samples": 1, "simplify": False}
    )
    budget = ctx.tracker.remaining(checks_cap=5_000)
    sub = ctx.sub(budget, ctx.q_start, near_goal=caller.near_goal_state)
    r = escape.plan(sub, leg_rng(0, 0))
    assert r.status is Status.SOLVED, r.reason
    np.testing.assert_allclose(r.path[-1], wrap_to_pi(q_caller, problem.robot.continuous))
    assert r.collision_checks == sub.tracker.checks_used <= 5_000

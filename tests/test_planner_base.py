"""The planners' shared pieces (planners/base.py): the one budget tracker."""

from __future__ import annotations

import numpy as np
from conftest import toy_problem

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners.base import BudgetTracker, PlanResult, Status
from plannerlab.problem.load import Budget


def _sub_result(iterations: int, checks: int, fk_calls: int = 0) -> PlanResult:
    return PlanResult(
        "sub",
        "toy",
        0,
        "near",
        Status.FAILED,
        "a sub-solve",
        np.zeros((1, 5)),
        iterations=iterations,
        collision_checks=checks,
        fk_calls=fk_calls,
    )


def test_checks_used_are_the_checkers_since_the_start_plus_those_charged():
    problem = toy_problem()
    checker = CollisionChecker(problem.robot, problem.scene)
    checker.valid_batch(np.tile(problem.q_start, (7, 1)))  # before the tracker: not counted
    tracker = BudgetTracker(Budget(max_collision_checks=100), checker)
    checker.valid_batch(np.tile(problem.q_start, (5, 1)))
    tracker.charge(_sub_result(iterations=3, checks=20, fk_calls=4))
    tracker.charge_checks(2)
    assert tracker.checks_used == 5 + 20 + 2
    assert tracker.checks_left() == 100 - 27
    assert (tracker.iterations, tracker.fk_calls) == (3, 4)


def test_remaining_is_what_the_sub_solves_left_capped_for_an_escape():
    tracker = BudgetTracker(Budget(max_iterations=10, max_collision_checks=100))
    tracker.charge(_sub_result(iterations=4, checks=30))
    sub = tracker.remaining()
    assert sub is not None
    assert (sub.max_iterations, sub.max_collision_checks, sub.time_limit_s) == (6, 70, None)
    capped = tracker.remaining(checks_cap=20, limit_iterations=False)
    assert capped is not None
    assert (capped.max_iterations, capped.max_collision_checks) == (None, 20)


def test_a_used_up_limit_leaves_no_sub_budget_and_is_named():
    tracker = BudgetTracker(Budget(max_iterations=10, max_collision_checks=100))
    assert tracker.exhausted() is None
    tracker.charge(_sub_result(iterations=2, checks=100))
    assert tracker.remaining() is None
    assert tracker.exhausted() == "collision-check budget of 100 used up"
    # the planner's own iteration count, when given, is judged first
    assert tracker.exhausted(iterations=10) == "iteration budget of 10 used up"
    assert tracker.checks_left() == 0


def test_a_time_limit_counts_from_the_trackers_start():
    tracker = BudgetTracker(Budget(time_limit_s=1e-9))
    while tracker.elapsed_s < 1e-9:
        pass
    assert tracker.exhausted() == "time limit of 1e-09 s reached"
    assert tracker.remaining() is None
    assert BudgetTracker(Budget(time_limit_s=3600.0)).remaining() is not None

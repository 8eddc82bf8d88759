"""The planners' shared pieces (planners/base.py): the one budget tracker and the one way
to build a result."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import toy_problem

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    BudgetTracker,
    LegRun,
    PlanResult,
    Status,
    StepClock,
    with_overrides,
)
from plannerlab.planners.gradient import GradientSettings
from plannerlab.problem.load import Budget
from plannerlab.robots.paths import path_length


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


def test_a_tracker_reads_the_budgets_clock_and_hands_it_to_sub_budgets_and_children():
    clock = StepClock(0.1)
    budget = Budget(time_limit_s=1.0, clock=clock)
    tracker = BudgetTracker(budget)  # its start: the clock's first read, 0
    assert tracker.clock is clock
    assert tracker.elapsed_s == pytest.approx(0.1)
    sub = tracker.remaining()  # read at 0.2: 0.8 s left, on the same clock
    assert sub is not None and sub.clock is clock
    assert sub.time_limit_s == pytest.approx(0.8)
    child = tracker.child(sub)
    assert child.clock is clock and child.elapsed_s == pytest.approx(0.1)
    while tracker.exhausted() is None:
        pass
    assert clock.reads == 11  # 0, 0.1, ... 1.0: the limit is reached at the 11th read
    assert tracker.time_up() and tracker.remaining() is None
    # the clock is no part of the budget's record or equality
    assert "clock" not in budget.to_dict()
    assert budget.replace(max_iterations=3).clock is clock


def test_a_step_clock_counts_work_and_an_explicit_clock_wins():
    done = [0]
    clock = StepClock(1e-3, 1e-5, lambda: done[0])
    tracker = BudgetTracker(Budget(time_limit_s=0.5), clock=clock)
    done[0] = 10_000
    assert tracker.elapsed_s == pytest.approx(1e-3 + 0.1)
    assert not tracker.time_up()
    done[0] = 60_000
    assert tracker.time_up()
    with pytest.raises(PlannerlabError, match="read_s"):
        StepClock(0.0)


def test_a_leg_runs_result_has_the_paths_errors_cost_and_the_trackers_counts():
    problem = toy_problem()
    robot, goal = problem.robot, problem.goal(0)
    checker = CollisionChecker(robot, problem.scene)
    tracker = BudgetTracker(problem.budget, checker)
    settings = GradientSettings(gamma=0.04)
    run = LegRun("gradient", settings, problem, 0, tracker)
    path = np.array([problem.q_start, problem.q_start + 0.1, problem.q_start + 0.3])
    checker.valid_batch(path)  # three checks
    tracker.charge_checks(4)
    run.progress.note(1.5)
    r = run.result(Status.SOLVED, "done", path, iterations=9, fk_calls=2, trace=[3.0, 2.0])
    pos_err, ang_err = goal.errors(robot, path[-1])
    assert (r.planner, r.problem, r.leg, r.goal) == ("gradient", "toy", 0, "near")
    assert (r.iterations, r.fk_calls, r.collision_checks) == (9, 2, 3 + 4)
    assert (r.pos_err_m, r.angle_err_deg) == (float(pos_err), float(ang_err))
    assert r.settings["gamma"] == 0.04 and r.trace.tolist() == [3.0, 2.0]
    assert 0.0 < r.time_s <= tracker.elapsed_s
    # the progress: the noted row, then one at the end with the path's length as its cost
    assert r.progress[0, 2] == 1.5 and r.progress[-1, 1] == 7
    assert (
        r.progress[-1, 3]
        == path_length(path, robot.continuous)
        == pytest.approx(0.3 * np.sqrt(robot.dof))
    )
    unsolved = LegRun("gradient", settings, problem, 0, tracker).result(Status.FAILED, "no", path)
    assert np.isnan(unsolved.progress[-1, 3])
    assert unsolved.progress[-1, 2] == float(goal.distance(robot, path[-1]))


def test_a_leg_that_is_not_planned_has_no_time_checks_progress_or_settings():
    problem = toy_problem()
    r = LegRun("ompl.rrt", None, problem, 0).result(
        Status.UNREACHABLE, "too far", [problem.q_start]
    )
    assert (r.time_s, r.collision_checks, r.iterations) == (0.0, 0, 0)
    assert r.progress.shape == (0, 4) and dict(r.settings) == {}
    assert r.path.tolist() == [problem.q_start.tolist()]


def test_progress_rows_a_planner_made_itself_are_kept():
    problem = toy_problem()
    run = LegRun("gradient", None, problem, 0, BudgetTracker(problem.budget))
    rows = np.array([[0.5, 10.0, 0.2, np.nan]])
    r = run.result(Status.BUDGET_EXHAUSTED, "used up", [problem.q_start], progress_rows=rows)
    assert np.array_equal(r.progress, rows, equal_nan=True)


def test_a_childs_checks_are_its_parents_through_the_shared_checker_and_its_charges_too():
    problem = toy_problem()
    checker = CollisionChecker(problem.robot, problem.scene)
    parent = BudgetTracker(Budget(max_iterations=50, max_collision_checks=100), checker)
    checker.valid_batch(np.tile(problem.q_start, (3, 1)))
    sub = parent.remaining(checks_cap=40)
    assert sub is not None and sub.max_collision_checks == 40
    child = parent.child(sub)
    assert (child.checker, child.budget, child.checks_used) == (checker, sub, 0)
    checker.valid_batch(np.tile(problem.q_start, (5, 1)))  # the sub-solve's checks
    child.charge_checks(2)  # checked elsewhere: the parent cannot see them, so charged
    assert (child.checks_used, child.checks_left()) == (5 + 2, 40 - 7)
    assert parent.checks_used == 3 + 5 + 2
    # the sub-solve's result: its iterations and FK calls are charged, its checks are not
    # (the parent counts them already)
    parent.charge(_sub_result(iterations=6, checks=child.checks_used, fk_calls=9), checks=False)
    assert (parent.checks_used, parent.iterations, parent.fk_calls) == (10, 6, 9)


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("route_escape", "maybe", "expected bool"),  # a string not a flag (CLI coercion)
        ("route_escape", 3, "expected true or false"),  # a TOML number where a flag is
        ("max_escapes", 2.5, "expected a whole number"),
        ("max_escapes", True, "expected a whole number"),
        ("max_step_rad", [0.1], "expected a number"),
        ("escape", 1, "expected a string"),
    ],
)
def test_a_setting_of_the_wrong_type_is_refused_by_name(key, value, expected):
    """Overrides from a TOML file keep their types: a value of the wrong type is refused
    with the setting's name and what it takes, never passed on (`route_escape = 3` used to
    reach the planner as a truthy number)."""
    from plannerlab.planners.clearance.settings import ClearanceSettings

    with pytest.raises(PlannerlabError, match=f"setting {key} of gradient.clearance: {expected}"):
        with_overrides(ClearanceSettings(), {key: value}, "gradient.clearance")


def test_settings_of_the_right_type_pass_and_whole_floats_count():
    from plannerlab.planners.clearance.settings import ClearanceSettings

    s = with_overrides(
        ClearanceSettings(),
        {"route_escape": False, "max_escapes": 3.0, "max_step_rad": 1, "escape": "detour"},
        "gradient.clearance",
    )
    assert s.route_escape is False and s.max_escapes == 3 and isinstance(s.max_escapes, int)
    assert s.max_step_rad == 1.0 and isinstance(s.max_step_rad, float) and s.escape == "detour"
    cli = with_overrides(ClearanceSettings(), {"route_escape": "no"}, "gradient.clearance")
    assert cli.route_escape is False  # the CLI's strings are still read as flags

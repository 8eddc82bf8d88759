"""One checker per trial (run/pipeline.py ``SharedChecker``): the solve and the
execution's re-check use the same checker, and what they give is what they gave with a
checker each."""

from __future__ import annotations

from conftest import toy_problem

from plannerlab.run.pipeline import SharedChecker, execute_results, solve_legs


def test_solve_and_execution_share_one_checker_and_give_the_same_records():
    problem = toy_problem()
    shared = SharedChecker(problem)
    plan = solve_legs(problem, "ompl.rrtconnect", 5, shared=shared)
    checker = shared.get()
    assert shared.get() is checker
    after_solve = checker.checks
    assert after_solve > 0  # the solve checked its states on it
    (execution,) = execute_results(problem, plan.legs, shared=shared)
    assert checker.checks > after_solve  # the re-check counted on the same checker
    # a checker each (the road before): the same plan and the same execution
    alone = solve_legs(problem, "ompl.rrtconnect", 5)
    assert [r.path.tolist() for r in alone.legs] == [r.path.tolist() for r in plan.legs]
    assert [r.collision_checks for r in alone.legs] == [r.collision_checks for r in plan.legs]
    (again,) = execute_results(problem, alone.legs)
    a, b = execution.to_dict(include_log=False), again.to_dict(include_log=False)
    for d in (a, b):
        d.pop("wall_time_s")  # a clock
    assert a == b

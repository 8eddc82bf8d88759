"""``hold_clearance`` of the clearance descent: the step held off the clearance floor is
projected in the Gauss-Newton metric, so it still lowers the objective.

Room variant v14, leg A (``problems/variants/armz_inspection_v14.toml``): the descent
reaches the clearance floor (``module_26`` 3.05 cm from ``wall_near_right``, the floor
3 cm); the plain step is refused for crossing it. The Euclidean projection of that step
(before) raised F at every trust radius, the radius collapsed below ``min_step_rad`` and
the leg stalled at iteration 8 ("no step of 0.0001 rad lowers F", the detour found no
retract). Projected in the metric of the Gauss-Newton model the held step lowers F and
the leg is solved.
"""

from __future__ import annotations

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners.base import Status
from plannerlab.problem.catalog import load_problem
from plannerlab.run.pipeline import solve_legs


def test_v14_leg_a_is_solved_along_the_clearance_floor() -> None:
    problem = load_problem("problems/variants/armz_inspection_v14.toml")
    budget = problem.budget.replace(max_collision_checks=100_000, time_limit_s=None)
    plan = solve_legs(
        problem,
        "gradient.clearance+detour",
        0,
        legs=[0, 1],
        budget=budget,
        stop_on_failure=True,
    )
    enter, leg_a = plan.legs
    assert enter.status is Status.SOLVED
    assert leg_a.status is Status.SOLVED, leg_a.reason
    assert leg_a.collision_checks <= 100_000
    assert leg_a.escapes == 0  # the descent itself got there, no detour
    checker = CollisionChecker(problem.robot, problem.scene)
    assert checker.check_path(leg_a.path, problem.joint_step / 4).valid
    assert np.isfinite(leg_a.min_clearance_m) and leg_a.min_clearance_m > 0.02

"""The paper's descent and the random restarts check their edges in metres, as every
planner's edges are checked (issue 17): a step whose two grid states are clear, but whose
tip sweeps through a thin plate between them, is blocked before the plate.

Found by the escape study (results/escapes.md): a `gradient.multistart` plan on
`armz_cavity` passed the planner's 0.02 rad grid and failed the executor's re-check, on a
descent step of 0.17 rad whose states 0.02 rad apart were clear.
"""

from __future__ import annotations

import numpy as np
from conftest import small_armz_problem

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.planners import make_planner
from plannerlab.problem.scene import Box, Scene
from plannerlab.robots.base import joint_difference, pose_matrix
from plannerlab.robots.paths import interpolate_edge


def _plate_problem():
    """The 24-module Arm-Z turning about its first joint by one coarse grid step (1.5 rad:
    the tip moves about 1.9 m), and a 2-cm plate across the tip's arc half way."""
    base = small_armz_problem(n_modules=24, with_wall=False)
    robot = base.robot
    q_a = base.q_start.copy()
    q_b, q_mid = q_a.copy(), q_a.copy()
    q_b[0] += 1.5
    q_mid[0] += 0.75
    p_a, p_b, p_mid = robot.tip(q_a)[0], robot.tip(q_b)[0], robot.tip(q_mid)[0]
    along = (p_b - p_a) / np.linalg.norm(p_b - p_a)  # the plate faces the sweep
    rpy = [0.0, -np.arcsin(along[2]), np.arctan2(along[1], along[0])]
    plate = Box("plate", pose_matrix(p_mid, rpy), [0.02, 0.3, 0.3])
    fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
    problem = base.__class__(
        **fields | {"scene": Scene((plate,)), "joint_step": 1.5, "safety_margin_m": 0.01}
    )
    return problem, q_a, q_b


def test_a_step_through_a_plate_between_its_grid_states_is_blocked():
    problem, q_a, q_b = _plate_problem()
    checker = problem_checker(problem)
    assert checker.edge_check == "certified"
    grid = interpolate_edge(q_a, q_b, problem.joint_step, problem.robot.continuous)
    assert len(grid) == 2 and checker.first_invalid(grid) is None  # the grid sees nothing
    assert checker.check_edge(q_a, q_b, problem.joint_step)[1] is not None  # metres do
    descent = make_planner("gradient")
    q_end, blocked = descent._advance_kinematic(problem, checker, q_a, q_b, None)
    assert blocked
    assert np.allclose(q_end, q_a)  # the one grid state past the plate is not reached


def test_a_restart_edge_through_a_plate_is_refused():
    """gradient.multistart's restarts draw q_b near the stall and keep it only if the edge
    is clear: here the draw is made to land across the plate."""
    problem, q_a, q_b = _plate_problem()
    planner = make_planner("gradient.multistart", {"restart_tries": 1})

    class Draw:  # a generator whose one normal draw lands on q_b
        def normal(self, loc: float, scale: float, size: int) -> np.ndarray:
            return q_b - q_a

    from plannerlab.planners.context import PlanningContext

    ctx = PlanningContext.build(problem, 0, problem.budget, q_start=q_a)
    assert planner._restart(ctx, Draw(), q_a, 0.3) is None
    no_plate = problem.__class__(
        **{f: getattr(problem, f) for f in problem.__dataclass_fields__} | {"scene": Scene(())}
    )
    free = PlanningContext.build(no_plate, 0, no_plate.budget, q_start=q_a)
    edge = planner._restart(free, Draw(), q_a, 0.3)
    assert edge is not None
    assert np.allclose(joint_difference(edge[-1], q_b, no_plate.robot.continuous), 0.0)

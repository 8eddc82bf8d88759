"""The compiled clearance field on robots other than Arm-Z: its geometry is the compiled
robot–scene model's (``collision/spheres.py``), so it runs on any chain with a tip. Its
cost and distances equal the numpy field's, its gradient the numpy field's (finite
differences off Arm-Z) to their accuracy. (The planners keep the numpy engine off Arm-Z:
``test_descent_core.test_robots_other_than_armz_descend_in_numpy_and_say_so``.)"""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.planners.clearance import ClearanceField
from plannerlab.planners.clearance.compiled import CompiledField, step_rule
from plannerlab.problem.catalog import load_problem


@pytest.mark.parametrize(
    "name", ["armz_pocket", "irb6_case1", "irb6_track_obstacle", "continuum_case1"]
)
def test_the_compiled_field_equals_the_numpy_field(name):
    problem = load_problem(name)
    robot = problem.robot
    margin = 0.3
    field = ClearanceField(robot, problem.scene, margin)
    compiled = CompiledField(field, far_m=10.0)  # every distance below 10 m reported
    rule = step_rule(1.0, 1.0, 0.2, True, 0.1, 0.3)
    rng = np.random.default_rng(4)
    lo, hi = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
    closes = 0
    for _ in range(20):
        q = lo + rng.uniform(0.1, 0.9, robot.dof) * (hi - lo)
        ref = field(q)
        e = compiled.evaluate(q, problem.goal(0), rule, True)
        near = ref.distances_m < 10.0
        np.testing.assert_allclose(e.distances_m[near], ref.distances_m[near], atol=1e-12)
        assert e.cost == pytest.approx(ref.cost, rel=1e-10, abs=1e-12)
        scale = max(1.0, float(np.abs(ref.gradient).max()))
        np.testing.assert_allclose(e.gradient, ref.gradient, atol=1e-4 * scale)
        closes += int(ref.close_pairs > 0)
    assert closes > 0  # some states had pairs within the margin: the gradient was tested

"""The clearance descent's field and step at one state, on one of two engines (its
``backend`` setting): :class:`NumpyModel` (the reference, :mod:`plannerlab.planners.
clearance.field` and :class:`~plannerlab.planners.clearance.step.DescentStep`) or
:class:`CompiledStep` (numba, :mod:`plannerlab.planners.clearance.compiled`; the planners
run it on Arm-Z): the same iterates to rounding."""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np

from plannerlab.planners.clearance.field import ClearanceField
from plannerlab.planners.clearance.step import DescentStep, joint_residual_sq
from plannerlab.problem.goals import JointGoal
from plannerlab.robots.base import Array


class NumpyPoint:
    """The numpy descent's view of one state; each piece is computed when first asked
    (the direction only at accepted states), as the numpy descent always did."""

    def __init__(
        self,
        descent: DescentStep,
        field: ClearanceField,
        goal,
        q: Array,
        d_ref: Array | None = None,
    ):
        self._descent, self._field, self._goal, self._q = descent, field, goal, q
        self._d_ref = d_ref

    @cached_property
    def spacious(self) -> bool:
        """No pair below ``clearance_floor_m`` that came closer than in ``d_ref``."""
        if self._d_ref is None:
            return True
        d_new, floor = self.distances_m, self._descent.settings.clearance_floor_m
        return bool(np.all((d_new >= floor) | (d_new >= self._d_ref - 1e-9)))

    @cached_property
    def _clearance(self):
        return self._field(self._q)

    @cached_property
    def f(self) -> float:
        return self._descent._f(self._field.robot, self._goal, self._q)

    @property
    def F(self) -> float:  # noqa: N802 - the module docstring's F
        w = self._descent.settings.clearance_weight
        if isinstance(self._goal, JointGoal):
            return joint_residual_sq(self._goal, self._q) + w * self._clearance.cost
        return self.f + w * self._clearance.cost

    @property
    def cost(self) -> float:
        return self._clearance.cost

    @property
    def gradient(self) -> Array:
        return self._clearance.gradient

    @property
    def distances_m(self) -> Array:
        return self._clearance.distances_m

    @cached_property
    def _errors(self) -> tuple[float, float]:
        pos_err, ang_err = self._goal.errors(self._field.robot, self._q)
        return float(pos_err), float(ang_err)

    @property
    def pos_err_m(self) -> float:
        return self._errors[0]

    @property
    def ang_err_deg(self) -> float:
        return self._errors[1]

    @cached_property
    def joint_err(self) -> float:
        """Largest joint difference from a goal state (:class:`JointGoal` only)."""
        return float(self._goal.joint_error(self._q))

    @cached_property
    def direction(self) -> Array:
        return self._descent._direction(self._field.robot, self._goal, self._field, self._q)[0]


class NumpyModel:
    """The field and the step in numpy (``backend = "numpy"``: the reference)."""

    backend = "numpy"

    def __init__(self, descent: DescentStep, field: ClearanceField) -> None:
        self._descent, self._field = descent, field

    def point(self, goal, q: Array, d_ref: Array | None = None) -> NumpyPoint:
        return NumpyPoint(self._descent, self._field, goal, q, d_ref)

    def hold(self, goal, q: Array, direction: Array) -> Array:
        metric = self._descent._metric(self._field.robot, goal, self._field, q)
        return self._descent._hold_clearance(self._field, q, direction, metric)

    def warm_up(self, goal, q: Array) -> None:
        """Nothing to load."""


class CompiledStep:
    """The field and the step compiled (:mod:`plannerlab.planners.clearance.compiled`): one
    call per state gives F, f, the tip errors, the distances and the step direction."""

    backend = "compiled"

    def __init__(
        self, descent: DescentStep, field: ClearanceField, compiled_model: Any = None
    ) -> None:
        """``compiled_model``: the checker's compiled robot–scene model, whose chain the
        field's spheres ride on (None: the robot's chain packed alone; the same arrays)."""
        from plannerlab.planners.clearance.compiled import CompiledField, step_rule

        s = descent.settings
        self._settings = s
        # distances beyond both the margin and the hold's floor matter to no test of the
        # descent (the spacious test looks only below clearance_floor_m)
        far_m = max(s.influence_m, s.clearance_floor_m + s.hold_band_m)
        self._core = CompiledField(field, far_m=far_m, model=compiled_model)
        self._rule = step_rule(
            s.r1, s.r2, s.clearance_weight, s.direction == "gauss_newton", s.damping, s.goal_depth
        )

    def point(self, goal, q: Array, d_ref: Array | None = None):
        return self._core.evaluate(
            q, goal, self._rule, True, d_ref, self._settings.clearance_floor_m
        )

    def hold(self, goal, q: Array, direction: Array) -> Array:
        """The held step, projected in the metric of the step's quadratic model at q
        (:meth:`ClearanceDescent._metric`, which the compiled evaluation returns)."""
        metric = self.point(goal, q).metric
        floor = self._settings.clearance_floor_m + self._settings.hold_band_m
        return self._core.hold_clearance(q, direction, floor, metric)

    def warm_up(self, goal, q: Array) -> None:
        """Load (or compile) both kernels: one call each."""
        self.hold(goal, q, self.point(goal, q).direction)


Model = NumpyModel | CompiledStep


__all__ = ["CompiledStep", "Model", "NumpyModel", "NumpyPoint"]

"""plannerlab.extras: what the command line needs beyond the public API.

The ``plannerlab`` command is a client of the public API (``import plannerlab as pl``)
and of this module only: whatever a command does, a script can do with the same names.
These are the names a user rarely needs, kept out of the top-level ``plannerlab`` so that
``dir(plannerlab)`` stays the user's toolbox (``docs/api.md`` lists both):

* comparisons as the command line runs them: :class:`ComparisonSpec` (a comparison
  checked before any trial starts) and :func:`run_spec`; where a store lives
  (:func:`store_path`, :func:`default_store_name`), ``--seeds`` text (:func:`parse_seeds`),
  the statuses of trials that raised or overran (:data:`ERROR_STATUS`,
  :data:`TIMEOUT_STATUS`), the reports' notes (:data:`BUDGET_NOTE`, :func:`machine_info`);
* plan files as ``execute``, ``plot`` and ``animate`` read them
  (:func:`read_checked_plan`, :func:`check_plan`, :func:`execute_results`,
  :func:`legs_from_spec`);
* where problems come from (:func:`resolve_problem_path`, :func:`problem_origin`,
  :func:`problems_dir`);
* the continuum paper's cases (:func:`run_continuum_case`, :func:`continuum_case_name`,
  their figures :func:`continuum_case_figure`, :func:`continuum_thickness_figure`,
  :func:`save_figure`); room variants of the paper's task (:func:`generate_variants`,
  :func:`write_variants`, :class:`VariantError`); the IRb-6's analytic IK
  (:func:`irb6_ik`); MotionBenchMaker's importer (``mbm``, a module); OMPL's
  KinematicChain benchmark as problem files (``kinematic_chain``, a module);
* what plannerlab makes of a URDF (:func:`robot_report`, ``plannerlab robot``) and its
  view in the browser (:func:`serve_robot`).

Each name is imported on first use, as in ``plannerlab``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from plannerlab.comparison.continuum import case_name as continuum_case_name
    from plannerlab.comparison.continuum import run_case as run_continuum_case
    from plannerlab.comparison.minima import describe as describe_minima
    from plannerlab.comparison.report import BUDGET_NOTE, machine_info
    from plannerlab.comparison.runner import run_spec
    from plannerlab.comparison.spec import ComparisonSpec
    from plannerlab.comparison.store import default_name as default_store_name
    from plannerlab.comparison.store import store_path
    from plannerlab.comparison.trial import ERROR_STATUS, TIMEOUT_STATUS, Trial, parse_seeds
    from plannerlab.plot.continuum import draw_case as continuum_case_figure
    from plannerlab.plot.continuum import save as save_figure
    from plannerlab.plot.continuum import thickness_figure as continuum_thickness_figure
    from plannerlab.plot.view import serve_robot
    from plannerlab.problem import kinematic_chain, mbm
    from plannerlab.problem.catalog import problem_origin, problems_dir, resolve_problem_path
    from plannerlab.problem.variants import VariantError, write_variants
    from plannerlab.problem.variants import generate as generate_variants
    from plannerlab.robots.irb6.report import irb6_ik
    from plannerlab.run.pipeline import execute_results, legs_from_spec
    from plannerlab.run.plan_check import check_plan, read_checked_plan
    from plannerlab.run.robot_info import robot_report

#: name -> "module:attribute" ("module" alone: the module itself), imported on first access
_EXPORTS: dict[str, str] = {
    # comparisons
    "ComparisonSpec": "plannerlab.comparison.spec:ComparisonSpec",
    "Trial": "plannerlab.comparison.trial:Trial",
    "run_spec": "plannerlab.comparison.runner:run_spec",
    "store_path": "plannerlab.comparison.store:store_path",
    "default_store_name": "plannerlab.comparison.store:default_name",
    "parse_seeds": "plannerlab.comparison.trial:parse_seeds",
    "ERROR_STATUS": "plannerlab.comparison.trial:ERROR_STATUS",
    "TIMEOUT_STATUS": "plannerlab.comparison.trial:TIMEOUT_STATUS",
    "BUDGET_NOTE": "plannerlab.comparison.report:BUDGET_NOTE",
    "machine_info": "plannerlab.comparison.report:machine_info",
    "describe_minima": "plannerlab.comparison.minima:describe",
    # plan files
    "read_checked_plan": "plannerlab.run.plan_check:read_checked_plan",
    "check_plan": "plannerlab.run.plan_check:check_plan",
    "execute_results": "plannerlab.run.pipeline:execute_results",
    "legs_from_spec": "plannerlab.run.pipeline:legs_from_spec",
    # where problems come from
    "resolve_problem_path": "plannerlab.problem.catalog:resolve_problem_path",
    "problem_origin": "plannerlab.problem.catalog:problem_origin",
    "problems_dir": "plannerlab.problem.catalog:problems_dir",
    # the continuum paper's cases
    "run_continuum_case": "plannerlab.comparison.continuum:run_case",
    "continuum_case_name": "plannerlab.comparison.continuum:case_name",
    "continuum_case_figure": "plannerlab.plot.continuum:draw_case",
    "continuum_thickness_figure": "plannerlab.plot.continuum:thickness_figure",
    "save_figure": "plannerlab.plot.continuum:save",
    # room variants, the IRb-6's analytic IK, MotionBenchMaker
    "generate_variants": "plannerlab.problem.variants:generate",
    "write_variants": "plannerlab.problem.variants:write_variants",
    "VariantError": "plannerlab.problem.variants:VariantError",
    "irb6_ik": "plannerlab.robots.irb6.report:irb6_ik",
    "kinematic_chain": "plannerlab.problem.kinematic_chain",
    "robot_report": "plannerlab.run.robot_info:robot_report",
    "serve_robot": "plannerlab.plot.view:serve_robot",
    "mbm": "plannerlab.problem.mbm",
}

__all__ = [
    "BUDGET_NOTE",
    "ComparisonSpec",
    "ERROR_STATUS",
    "TIMEOUT_STATUS",
    "Trial",
    "VariantError",
    "check_plan",
    "continuum_case_figure",
    "continuum_case_name",
    "continuum_thickness_figure",
    "default_store_name",
    "describe_minima",
    "execute_results",
    "generate_variants",
    "irb6_ik",
    "kinematic_chain",
    "legs_from_spec",
    "machine_info",
    "mbm",
    "parse_seeds",
    "problem_origin",
    "problems_dir",
    "read_checked_plan",
    "resolve_problem_path",
    "robot_report",
    "run_continuum_case",
    "run_spec",
    "save_figure",
    "serve_robot",
    "store_path",
    "write_variants",
]


def __getattr__(name: str) -> Any:
    target = _EXPORTS.get(name)
    if target is None:
        raise AttributeError(f"module 'plannerlab.extras' has no attribute {name!r}")
    module_name, _, attr = target.partition(":")
    module = importlib.import_module(module_name)
    value = getattr(module, attr) if attr else module
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])

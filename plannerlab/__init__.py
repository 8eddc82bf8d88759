"""plannerlab: motion planners compared on one problem definition, executed in PyBullet.

What a notebook or a script needs, imported on first use (so ``import plannerlab`` loads
none of the engines)::

    import plannerlab as pl

    problem = pl.load_problem("armz_pocket")
    plan = pl.solve(problem, "gradient+rrtconnect", seed=0)  # a Plan: one PlanResult per leg
    executions = pl.execute(plan, problem)                     # one Execution per leg
    run = pl.compare(["armz_pocket"], ["gradient", "ompl.rrtconnect"], range(3), "t.jsonl")
    rows = pl.summarise(run.records)

The data flow is one way: problem file → :func:`load_problem` → planner
(:func:`make_planner`, :func:`solve`) → record (:class:`Plan`, :class:`PlanResult`) →
:func:`execute` (:class:`Execution`) → table (:func:`compare`, :func:`summarise`,
:func:`markdown_report`); figures with :func:`snapshot_figure` and :func:`trace_figure`,
animations with :func:`animate_plan`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from plannerlab.comparison.report import markdown as markdown_report
    from plannerlab.comparison.runner import ComparisonRun, compare
    from plannerlab.comparison.statistics import summarise
    from plannerlab.comparison.trial import Trial
    from plannerlab.errors import PlannerlabError
    from plannerlab.planners import make_planner, planner_names
    from plannerlab.plot.animate import animate_plan
    from plannerlab.plot.plans import snapshot_figure, trace_figure
    from plannerlab.problem.catalog import list_problems, load_problem
    from plannerlab.problem.load import Budget, Problem
    from plannerlab.record.execution import Execution
    from plannerlab.record.leg import PlanResult, Status
    from plannerlab.record.plan import ExecutionFile, Plan
    from plannerlab.run.pipeline import execute_plan as execute
    from plannerlab.run.pipeline import solve_legs as solve

#: public name -> "module:attribute", imported on first access
_EXPORTS: dict[str, str] = {
    "load_problem": "plannerlab.problem.catalog:load_problem",
    "list_problems": "plannerlab.problem.catalog:list_problems",
    "problems_dir": "plannerlab.problem.catalog:problems_dir",
    "Problem": "plannerlab.problem.load:Problem",
    "Budget": "plannerlab.problem.load:Budget",
    "planner_names": "plannerlab.planners:planner_names",
    "make_planner": "plannerlab.planners:make_planner",
    "solve": "plannerlab.run.pipeline:solve_legs",
    "execute": "plannerlab.run.pipeline:execute_plan",
    "compare": "plannerlab.comparison.runner:compare",
    "summarise": "plannerlab.comparison.statistics:summarise",
    "Trial": "plannerlab.comparison.trial:Trial",
    "ComparisonRun": "plannerlab.comparison.runner:ComparisonRun",
    "Status": "plannerlab.record.leg:Status",
    "PlanResult": "plannerlab.record.leg:PlanResult",
    "Plan": "plannerlab.record.plan:Plan",
    "Execution": "plannerlab.record.execution:Execution",
    "ExecutionFile": "plannerlab.record.plan:ExecutionFile",
    "PlannerlabError": "plannerlab.errors:PlannerlabError",
    "markdown_report": "plannerlab.comparison.report:markdown",
    "snapshot_figure": "plannerlab.plot.plans:snapshot_figure",
    "trace_figure": "plannerlab.plot.plans:trace_figure",
    "animate_plan": "plannerlab.plot.animate:animate_plan",
}

__all__ = [
    "Budget",
    "ComparisonRun",
    "Execution",
    "ExecutionFile",
    "Plan",
    "PlanResult",
    "PlannerlabError",
    "Problem",
    "Status",
    "Trial",
    "animate_plan",
    "compare",
    "execute",
    "list_problems",
    "load_problem",
    "make_planner",
    "markdown_report",
    "planner_names",
    "problems_dir",
    "snapshot_figure",
    "solve",
    "summarise",
    "trace_figure",
]


def __getattr__(name: str) -> Any:
    target = _EXPORTS.get(name)
    if target is None:
        raise AttributeError(f"module 'plannerlab' has no attribute {name!r}")
    module_name, attr = target.split(":")
    value = getattr(importlib.import_module(module_name), attr)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])

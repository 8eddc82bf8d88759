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
animations with :func:`animate_plan`; an interactive 3-D view in the browser (or inline in a
notebook) with :func:`view`.
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
    from plannerlab.plot.view import Viewer
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
    "Viewer": "plannerlab.plot.view:Viewer",
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
    "Viewer",
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
    "view",
]


def view(
    plan: Any,
    execution: Any = None,
    *,
    problem: Any = None,
    host: str = "127.0.0.1",
    port: int = 0,
    mesh_dirs: Any = (),
    max_frames: int = 300,
    fps: float = 20.0,
) -> Viewer:
    """Serve an interactive 3-D view of a plan (and its execution) and return the running
    :class:`Viewer` (its ``url``; ``close()`` stops it; in a notebook it shows inline).

    Args:
        plan: a :class:`Plan`, or a plan file (``PLAN.json``): its problem file is loaded
            and the plan checked against it, and ``PLAN.exec.json`` beside it (written by
            ``plannerlab execute``) is shown when ``execution`` is None.
        execution: an :class:`ExecutionFile` (or its path), or :class:`Execution` records;
            None: the one beside a plan file, else none (the planned motion only).
        problem: the plan's problem (default: the problem file the plan names).
        host, port: where to serve (port 0: any free port; a port in use is an error).
        mesh_dirs: more folders to find a URDF robot's visual meshes in.
        max_frames: timeline frames per leg; fps: frames per second when playing.

    Raises:
        PlannerlabError: an unreadable plan or execution file, a problem file that is
            gone or changed, a plan that does not fit its problem, a port in use.
    """
    from pathlib import Path

    from plannerlab.errors import PlanFileError
    from plannerlab.plot.view import serve
    from plannerlab.record.plan import ExecutionFile, execution_path
    from plannerlab.run.clearance import link_clearance
    from plannerlab.run.plan_check import check_plan, read_plan

    executions: Any = ()
    if isinstance(plan, str | Path):
        plan_file = Path(plan)
        plan = read_plan(plan_file)
        if problem is None:
            if not Path(plan.problem_file).is_file():
                raise PlanFileError(
                    f"{plan_file}: [problem_file] names {plan.problem_file}, which no longer "
                    "exists: restore it (the plan is drawn in its problem's scene), or give "
                    "the problem (plannerlab.view(plan, problem=...))"
                )
            problem = plan.load_problem()
        check_plan(plan, problem, plan_file)
        beside = execution_path(plan_file)
        if execution is None and beside.is_file():
            execution = beside
    elif problem is None:
        problem = plan.load_problem()
    if isinstance(execution, str | Path):
        execution = ExecutionFile.load(execution)
    if isinstance(execution, ExecutionFile):
        executions = execution.executions
    elif execution is not None:
        executions = (execution,) if hasattr(execution, "q_actual_rad") else tuple(execution)
    return serve(
        problem,
        plan,
        executions,
        host=host,
        port=port,
        clearance=link_clearance(problem),
        mesh_dirs=mesh_dirs,
        max_frames=max_frames,
        fps=fps,
    )


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

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

The command line is this API's first client (``plannerlab/cli/`` imports nothing else of
the package but its records), so whatever a command does is here too: plan files
(:func:`read_checked_plan`, :func:`execute_results`, :func:`plot_plan`), the catalogues
(:func:`problem_catalog`, :func:`planner_catalog`, :func:`planner_info`), comparisons
(:class:`ComparisonSpec`, :func:`run_spec`, :class:`TrialStore`, :func:`write_reports`),
the continuum paper's cases (:func:`run_continuum_case`), room variants
(:func:`generate_variants`), the IRb-6's analytic IK (:func:`irb6_ik`),
MotionBenchMaker's importer (``pl.mbm``) and OMPL's KinematicChain benchmark
(``pl.kinematic_chain``).
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


if TYPE_CHECKING:
    from plannerlab.comparison.continuum import case_name as continuum_case_name
    from plannerlab.comparison.continuum import run_case as run_continuum_case
    from plannerlab.comparison.report import BUDGET_NOTE, machine_info, write_reports
    from plannerlab.comparison.runner import run_spec
    from plannerlab.comparison.spec import ComparisonSpec
    from plannerlab.comparison.store import TrialStore, store_path
    from plannerlab.comparison.store import default_name as default_store_name
    from plannerlab.comparison.trial import ERROR_STATUS, TIMEOUT_STATUS, parse_seeds
    from plannerlab.plot.continuum import draw_case as continuum_case_figure
    from plannerlab.plot.continuum import save as save_figure
    from plannerlab.plot.continuum import thickness_figure as continuum_thickness_figure
    from plannerlab.plot.plans import plot_plan
    from plannerlab.problem import kinematic_chain, mbm
    from plannerlab.problem.catalog import problem_catalog, problem_origin, resolve_problem_path
    from plannerlab.problem.load import parse_problem
    from plannerlab.problem.variants import VariantError, write_variants
    from plannerlab.problem.variants import generate as generate_variants
    from plannerlab.robots.irb6.report import irb6_ik
    from plannerlab.run.pipeline import execute_results, legs_from_spec
    from plannerlab.run.plan_check import check_plan, read_checked_plan, read_plan
    from plannerlab.run.planner_info import planner_catalog, planner_info

#: what the command line needs beyond the road above (``cli/`` is this API's first
#: client: it imports nothing else of plannerlab but ``record``); a name without an
#: attribute is a module (``pl.mbm``)
_EXPORTS |= {
    # problems
    "parse_problem": "plannerlab.problem.load:parse_problem",
    "resolve_problem_path": "plannerlab.problem.catalog:resolve_problem_path",
    "problem_origin": "plannerlab.problem.catalog:problem_origin",
    "problem_catalog": "plannerlab.problem.catalog:problem_catalog",
    "mbm": "plannerlab.problem.mbm",
    "kinematic_chain": "plannerlab.problem.kinematic_chain",
    # planners
    "planner_catalog": "plannerlab.run.planner_info:planner_catalog",
    "planner_info": "plannerlab.run.planner_info:planner_info",
    # plan files and execution
    "legs_from_spec": "plannerlab.run.pipeline:legs_from_spec",
    "execute_results": "plannerlab.run.pipeline:execute_results",
    "read_plan": "plannerlab.run.plan_check:read_plan",
    "check_plan": "plannerlab.run.plan_check:check_plan",
    "read_checked_plan": "plannerlab.run.plan_check:read_checked_plan",
    # figures
    "plot_plan": "plannerlab.plot.plans:plot_plan",
    "continuum_case_figure": "plannerlab.plot.continuum:draw_case",
    "continuum_thickness_figure": "plannerlab.plot.continuum:thickness_figure",
    "save_figure": "plannerlab.plot.continuum:save",
    # comparisons
    "ComparisonSpec": "plannerlab.comparison.spec:ComparisonSpec",
    "run_spec": "plannerlab.comparison.runner:run_spec",
    "TrialStore": "plannerlab.comparison.store:TrialStore",
    "store_path": "plannerlab.comparison.store:store_path",
    "default_store_name": "plannerlab.comparison.store:default_name",
    "parse_seeds": "plannerlab.comparison.trial:parse_seeds",
    "ERROR_STATUS": "plannerlab.comparison.trial:ERROR_STATUS",
    "TIMEOUT_STATUS": "plannerlab.comparison.trial:TIMEOUT_STATUS",
    "machine_info": "plannerlab.comparison.report:machine_info",
    "write_reports": "plannerlab.comparison.report:write_reports",
    "BUDGET_NOTE": "plannerlab.comparison.report:BUDGET_NOTE",
    "run_continuum_case": "plannerlab.comparison.continuum:run_case",
    "continuum_case_name": "plannerlab.comparison.continuum:case_name",
    # Arm-Z variants, the IRb-6's analytic IK
    "generate_variants": "plannerlab.problem.variants:generate",
    "write_variants": "plannerlab.problem.variants:write_variants",
    "VariantError": "plannerlab.problem.variants:VariantError",
    "irb6_ik": "plannerlab.robots.irb6.report:irb6_ik",
}
__all__ += [
    "BUDGET_NOTE",
    "ComparisonSpec",
    "ERROR_STATUS",
    "TIMEOUT_STATUS",
    "TrialStore",
    "VariantError",
    "check_plan",
    "continuum_case_figure",
    "continuum_case_name",
    "continuum_thickness_figure",
    "default_store_name",
    "execute_results",
    "generate_variants",
    "irb6_ik",
    "kinematic_chain",
    "legs_from_spec",
    "machine_info",
    "mbm",
    "parse_problem",
    "parse_seeds",
    "planner_catalog",
    "planner_info",
    "plot_plan",
    "problem_catalog",
    "problem_origin",
    "read_checked_plan",
    "read_plan",
    "resolve_problem_path",
    "run_continuum_case",
    "run_spec",
    "save_figure",
    "store_path",
    "write_reports",
    "write_variants",
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

    from plannerlab.plot.view import serve
    from plannerlab.record.plan import ExecutionFile, execution_path
    from plannerlab.run.clearance import link_clearance
    from plannerlab.run.plan_check import check_plan, read_checked_plan, read_plan

    executions: Any = ()
    if isinstance(plan, str | Path):
        plan_file = Path(plan)
        if problem is None:  # found from the plan's folder, its recorded path or by name
            plan, problem = read_checked_plan(plan_file)
        else:
            plan = read_plan(plan_file)
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
    module_name, _, attr = target.partition(":")
    module = importlib.import_module(module_name)
    value = getattr(module, attr) if attr else module
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])

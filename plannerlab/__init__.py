"""plannerlab: motion planners compared on one problem definition, executed in PyBullet.

What a notebook or a script needs, imported on first use (so ``import plannerlab`` loads
none of the engines)::

    import plannerlab as pl

    problem = pl.load_problem("armz_pocket")
    plan = pl.solve(problem, "gradient+rrtconnect", seed=0)  # a Plan: one PlanResult per leg
    executions = pl.execute(plan, problem)                     # one Execution per leg
    run = pl.compare(["armz_pocket"], ["gradient", "ompl.rrtconnect"], range(3), "t.jsonl")
    rows = pl.summarise(run.records)

The data flow is one way: problem file → ``load_problem`` → planner (``make_planner``,
``solve``) → record (``Plan``, ``PlanResult``) → ``execute`` (``Execution``) → table
(``compare``, ``summarise``, ``markdown_report``); figures with ``snapshot_figure``,
``trace_figure`` and ``plot_plan``, animations with ``animate_plan``; an interactive 3-D
view in the browser (or inline in a notebook) with ``view``. ``docs/api.md`` lists every
name with what it does.

What only the command line needs (store paths, report notes, the continuum paper's
cases, room variants, the IRb-6's analytic IK, MotionBenchMaker's importer, OMPL's
KinematicChain benchmark) is in :mod:`plannerlab.extras`, not here.
"""

from __future__ import annotations

import importlib
import os
import sys
from typing import TYPE_CHECKING, Any


def _numba_cache_dir() -> None:
    """Point numba's cache at a folder named by a digest of the package's compiled code.

    numba keeps a kernel's cached machine code until the kernel's *own* file changes;
    a kernel that calls a function of another file (every planner's kernel calls the
    collision core's) would go on running the old callee after an update. Named by a
    digest of every source file that holds compiled code (naming numba, ``njit`` or
    ``@kernel``), the cache starts afresh whenever any of them changes
    (``~/.cache/plannerlab/numba/<digest>``; old folders are removed by
    :func:`_prune_numba_caches`). A ``NUMBA_CACHE_DIR`` set by the user wins. numba imported
    before plannerlab (``from numba import njit`` first, as a notebook or a bench may) has
    read its configuration already: its ``config.CACHE_DIR`` is set then too (numba reads
    it when a kernel is decorated, which is after this). Before, the package's digest was
    skipped then, numba fell back to ``__pycache__`` beside the sources, and after an
    update a cached caller ran against a changed callee's layout: a segmentation fault of
    ``bench/state_test_bench.py`` in a checkout updated by a merge."""
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parent
    digest = hashlib.sha1(usedforsecurity=False)
    for path in sorted(root.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text or b"@kernel" in text or b"njit" in text:
            digest.update(path.relative_to(root).as_posix().encode() + b"\0" + text)
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "plannerlab"
    folder = base / "numba" / digest.hexdigest()[:16]
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "stamp").touch()
        _prune_numba_caches(folder)
    except OSError:
        return  # not writable: numba's default (__pycache__ beside the sources)
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    numba = sys.modules.get("numba")
    if numba is not None:  # imported first: its configuration was read without it
        numba.core.config.CACHE_DIR = str(folder)


#: a cache folder used (its ``stamp`` touched by an import) within this many seconds is
#: never removed: another checkout's process may be writing to it
CACHE_IN_USE_S = 7 * 24 * 3600.0


def _prune_numba_caches(folder: Any) -> None:
    """Remove the cache folders of other code versions beside ``folder``, keeping the three
    most recently used and every one used within :data:`CACHE_IN_USE_S`. Before, only the
    four most recent were kept whatever their age: with five checkouts at work at once
    (worktrees, a CI clone), an import in one removed a folder that another's running
    process was writing, and numba's cache save failed there (``FileNotFoundError``)."""
    import shutil
    import time

    def used(p: Any) -> float:
        stamp = p / "stamp"
        return stamp.stat().st_mtime if stamp.exists() else 0.0

    old = sorted((p for p in folder.parent.iterdir() if p.is_dir() and p != folder), key=used)
    now = time.time()
    for stale in old[:-3]:
        if now - used(stale) > CACHE_IN_USE_S:
            shutil.rmtree(stale, ignore_errors=True)


_numba_cache_dir()

if TYPE_CHECKING:
    from plannerlab.collision.public import Checker, checker
    from plannerlab.comparison.minima import local_minima
    from plannerlab.comparison.report import markdown as markdown_report
    from plannerlab.comparison.report import write_reports
    from plannerlab.comparison.runner import ComparisonRun, compare
    from plannerlab.comparison.statistics import SummaryRow, summarise
    from plannerlab.comparison.store import TrialStore
    from plannerlab.errors import PlannerlabError
    from plannerlab.planners import make_planner, planner_names
    from plannerlab.plot.animate import animate_plan
    from plannerlab.plot.plans import plot_plan, snapshot_figure, trace_figure
    from plannerlab.plot.view import Viewer
    from plannerlab.problem.catalog import load_problem, problem_catalog
    from plannerlab.problem.load import Budget, Problem, parse_problem
    from plannerlab.record.execution import Execution
    from plannerlab.record.leg import PlanResult, Status
    from plannerlab.record.plan import ExecutionFile, Plan
    from plannerlab.record.trial import ExecutionRecord, LegRecord, TrialRecord
    from plannerlab.run.pipeline import execute_plan as execute
    from plannerlab.run.pipeline import solve_legs as solve
    from plannerlab.run.plan_check import read_plan
    from plannerlab.run.planner_info import planner_catalog, planner_info

#: public name -> "module:attribute", imported on first access (the architecture test
#: reads these strings as the imports they are)
_EXPORTS: dict[str, str] = {
    # problems
    "load_problem": "plannerlab.problem.catalog:load_problem",
    "parse_problem": "plannerlab.problem.load:parse_problem",
    "problem_catalog": "plannerlab.problem.catalog:problem_catalog",
    "Problem": "plannerlab.problem.load:Problem",
    "Budget": "plannerlab.problem.load:Budget",
    # planners
    "planner_names": "plannerlab.planners:planner_names",
    "planner_catalog": "plannerlab.run.planner_info:planner_catalog",
    "planner_info": "plannerlab.run.planner_info:planner_info",
    "make_planner": "plannerlab.planners:make_planner",
    # the collision checker of a problem
    "checker": "plannerlab.collision.public:checker",
    "Checker": "plannerlab.collision.public:Checker",
    # plans and their execution
    "solve": "plannerlab.run.pipeline:solve_legs",
    "execute": "plannerlab.run.pipeline:execute_plan",
    "read_plan": "plannerlab.run.plan_check:read_plan",
    # records
    "Status": "plannerlab.record.leg:Status",
    "PlanResult": "plannerlab.record.leg:PlanResult",
    "Plan": "plannerlab.record.plan:Plan",
    "Execution": "plannerlab.record.execution:Execution",
    "ExecutionFile": "plannerlab.record.plan:ExecutionFile",
    "TrialRecord": "plannerlab.record.trial:TrialRecord",
    "LegRecord": "plannerlab.record.trial:LegRecord",
    "ExecutionRecord": "plannerlab.record.trial:ExecutionRecord",
    # comparisons
    "compare": "plannerlab.comparison.runner:compare",
    "ComparisonRun": "plannerlab.comparison.runner:ComparisonRun",
    "TrialStore": "plannerlab.comparison.store:TrialStore",
    "summarise": "plannerlab.comparison.statistics:summarise",
    "SummaryRow": "plannerlab.comparison.statistics:SummaryRow",
    "markdown_report": "plannerlab.comparison.report:markdown",
    "write_reports": "plannerlab.comparison.report:write_reports",
    "local_minima": "plannerlab.comparison.minima:local_minima",
    # figures and the viewer
    "snapshot_figure": "plannerlab.plot.plans:snapshot_figure",
    "trace_figure": "plannerlab.plot.plans:trace_figure",
    "plot_plan": "plannerlab.plot.plans:plot_plan",
    "animate_plan": "plannerlab.plot.animate:animate_plan",
    "Viewer": "plannerlab.plot.view:Viewer",
    # errors
    "PlannerlabError": "plannerlab.errors:PlannerlabError",
}

__all__ = [
    "Budget",
    "Checker",
    "ComparisonRun",
    "Execution",
    "ExecutionFile",
    "ExecutionRecord",
    "LegRecord",
    "Plan",
    "PlanResult",
    "PlannerlabError",
    "Problem",
    "Status",
    "SummaryRow",
    "TrialRecord",
    "TrialStore",
    "Viewer",
    "animate_plan",
    "checker",
    "compare",
    "execute",
    "load_problem",
    "local_minima",
    "make_planner",
    "markdown_report",
    "parse_problem",
    "planner_catalog",
    "planner_info",
    "planner_names",
    "plot_plan",
    "problem_catalog",
    "read_plan",
    "snapshot_figure",
    "solve",
    "summarise",
    "trace_figure",
    "view",
    "write_reports",
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
    value = getattr(importlib.import_module(module_name), attr)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])

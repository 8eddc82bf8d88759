"""The continuum paper's table, one case at a time (``plannerlab continuum``):
:func:`run_case`.

A case is planned by :func:`plannerlab.run.pipeline.solve_legs` (``chord_arc``, seed 0,
leg 0) into a :class:`~plannerlab.record.plan.Plan` whose one leg gives the row; then
``runs`` more solves are timed (the search with its motion check, what the paper times,
and the whole solve), one solve at zero thickness (the paper's model:
``inflate_by_radius = false``) and, when the settings themselves drop the robot's radius,
one at the robot's radius, so that the thickness figure is drawn from two records; with
``execute`` the chosen solution runs in PyBullet through
:func:`plannerlab.run.pipeline.execute_results` (the continuum's executor). Figures are
drawn from these records' contact plans by :mod:`plannerlab.plot.continuum`: no figure
searches again, so a case costs ``runs`` + 2 searches (+ 1 with the radius dropped).
"""

from __future__ import annotations

import dataclasses
import statistics
from collections.abc import Mapping
from typing import Any

from plannerlab.errors import PlannerlabError
from plannerlab.record.execution import Execution
from plannerlab.record.leg import PlanResult
from plannerlab.record.plan import Plan

PLANNER = "chord_arc"


def case_name(case: str) -> str:
    """A problem name or path, or a bare number N for ``continuum_caseN``."""
    return f"continuum_case{case}" if case.isdigit() else case


@dataclasses.dataclass(frozen=True)
class CaseRun:
    """One case of the table: the records behind its row and the timing summary.

    Attributes:
        problem: the case's problem.
        plan: the first (warm-up) run as a plan (:func:`plannerlab.run.pipeline.solve_legs`,
            seed 0): its one leg's :class:`~plannerlab.record.leg.PlanResult` is the row.
        execution: the chosen solution executed in PyBullet, or None (not asked for, or
            no chosen solution).
        timing: ``runs``, ``search_median_s``, ``solve_median_s``, ``same_every_run``,
            ``solutions_zero_thickness`` and the paper's row (``paper``, or None).
        thin: the zero-thickness solve (the paper's model).
        thick: the solve at the robot's radius: the row's own leg unless the settings
            drop the radius.
    """

    problem: Any
    plan: Plan
    execution: Execution | None
    timing: dict[str, Any]
    thin: PlanResult
    thick: PlanResult

    @property
    def result(self) -> PlanResult:
        return self.plan.legs[0]

    def to_dict(self, files: Mapping[str, str] | None = None) -> dict[str, Any]:
        """The case as data: the records through their own ``to_dict`` (the codec's), and
        the files written for it."""
        return {
            "problem": self.plan.problem,
            **self.timing,
            "files": dict(files or {}),
            "plan": self.plan.to_dict(),
            "execution": None if self.execution is None else self.execution.to_dict(),
        }


def run_case(
    case: str, runs: int, overrides: Mapping[str, Any] | None = None, *, execute: bool = False
) -> CaseRun:
    """One row of the table (see the module docstring): the plan record, ``runs`` timed
    solves, the zero-thickness (and, if needed, full-thickness) solve, the execution.

    Raises:
        PlannerlabError: ``runs`` < 1, or a bad problem or setting.
    """
    from plannerlab.planners import make_planner
    from plannerlab.planners.chord_arc.planner import PAPER_TABLE
    from plannerlab.problem.catalog import load_problem
    from plannerlab.run.pipeline import execute_results, leg_rng, solve_legs

    if runs < 1:
        raise PlannerlabError(f"--runs must be >= 1, got {runs}")
    overrides = dict(overrides or {})
    problem = load_problem(case_name(case))
    planner = make_planner(PLANNER, overrides)
    budget = problem.budget
    plan = solve_legs(problem, PLANNER, 0, legs=[0], overrides=overrides)  # warm-up
    first = plan.legs[0]
    solve_s, search_s, counts = [], [], set()
    for i in range(runs):
        r = planner.solve(problem, 0, budget, leg_rng(i, 0))
        solve_s.append(r.time_s)
        cp = r.contact_plan
        search_s.append(float(cp.search.get("time_s", float("nan"))) if cp else float("nan"))
        counts.add((r.status.value, *((len(cp.solutions), len(cp.dropped)) if cp else ())))
    thin = make_planner(PLANNER, {**overrides, "inflate_by_radius": False}).solve(
        problem, 0, budget, leg_rng(0, 0)
    )
    thick = first
    if not first.settings.get("inflate_by_radius", True):
        thick = make_planner(PLANNER, {**overrides, "inflate_by_radius": True}).solve(
            problem, 0, budget, leg_rng(0, 0)
        )
    paper = PAPER_TABLE.get(problem.name)
    timing: dict[str, Any] = {
        "runs": runs,
        "search_median_s": statistics.median(search_s),
        "solve_median_s": statistics.median(solve_s),
        "same_every_run": len(counts) <= 1,
        "solutions_zero_thickness": len(thin.contact_plan.solutions) if thin.contact_plan else 0,
        "paper": None if paper is None else dataclasses.asdict(paper),
    }
    execution = None
    if execute and first.contact_plan is not None and first.contact_plan.chosen is not None:
        (execution,) = execute_results(problem, plan.legs)
    return CaseRun(problem, plan, execution, timing, thin, thick)


__all__ = ["PLANNER", "CaseRun", "case_name", "run_case"]

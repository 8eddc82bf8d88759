"""Running a planner over the legs of a problem, and the plan file it produces.

A *task* is every leg of a problem in order; leg ``i`` starts where leg ``i − 1``'s path
ended (the planned end, or the executed end for closed-loop planners, which execute as
they plan). A plan file (JSON) holds the per-leg :class:`PlanResult` s, the seed, the
settings, the budget and the package versions, so that ``plannerlab execute PLAN.json``
and ``plannerlab plot PLAN.json`` can use it later.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlanFileError
from plannerlab.planners import get_entry, make_planner
from plannerlab.planners.base import PlanResult, Status
from plannerlab.problem.catalog import load_problem, resolve_problem_path
from plannerlab.problem.goals import unreachable_reason
from plannerlab.problem.load import Budget, Problem
from plannerlab.record.files import versions, write_json_atomic

PLAN_FORMAT = "plannerlab.plan/1"


def leg_rng(seed: int, leg: int) -> np.random.Generator:
    """The generator of one leg of one trial: independent streams per (seed, leg)."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(leg)]))


@dataclass(frozen=True, eq=False)
class Plan:
    """A planner's results over some legs of a problem."""

    problem: str
    problem_file: str
    planner: str
    seed: int
    budget: dict[str, Any]
    legs: tuple[PlanResult, ...]
    overrides: dict[str, Any] = field(default_factory=dict)
    versions: dict[str, str] = field(default_factory=dict)
    executions: tuple[dict[str, Any], ...] = ()

    @property
    def solved(self) -> bool:
        return all(r.solved for r in self.legs)

    def full_path(self) -> np.ndarray:
        """All legs' paths joined (m, dof)."""
        parts = [self.legs[0].path] + [r.path[1:] for r in self.legs[1:]]
        return np.concatenate(parts)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": PLAN_FORMAT,
            "problem": self.problem,
            "problem_file": self.problem_file,
            "planner": self.planner,
            "seed": self.seed,
            "overrides": self.overrides,
            "budget": self.budget,
            "versions": self.versions,
            "legs": [r.to_dict() for r in self.legs],
            "executions": list(self.executions),
        }

    def save(self, path: str | Path) -> Path:
        return write_json_atomic(path, self.to_dict())

    @classmethod
    def load(cls, path: str | Path) -> Plan:
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise PlanFileError(f"{path}: no such plan file") from None
        except json.JSONDecodeError as exc:
            raise PlanFileError(f"{path}: not JSON ({exc})") from None
        if not isinstance(data, dict) or data.get("format") != PLAN_FORMAT:
            raise PlanFileError(f"{path}: [format] expected {PLAN_FORMAT!r}")
        try:
            return cls(
                problem=data["problem"],
                problem_file=data["problem_file"],
                planner=data["planner"],
                seed=int(data["seed"]),
                budget=data["budget"],
                legs=tuple(PlanResult.from_dict(r) for r in data["legs"]),
                overrides=data.get("overrides", {}),
                versions=data.get("versions", {}),
                executions=tuple(data.get("executions", [])),
            )
        except KeyError as exc:
            raise PlanFileError(f"{path}: [{exc.args[0]}] is missing") from None

    def load_problem(self) -> Problem:
        return load_problem(self.problem_file)


def _unreachable(
    problem: Problem, planner_name: str, leg: int, why: str, q_start: np.ndarray | None
) -> PlanResult:
    """The result of a leg whose goal is out of reach: not planned, the path stays put."""
    q = problem.q_start if q_start is None else np.asarray(q_start, dtype=float)
    goal = problem.goal(leg)
    pos_err, ang_err = (float(v) for v in goal.errors(problem.robot, q))
    return PlanResult(
        planner=planner_name,
        problem=problem.name,
        leg=leg,
        goal=goal.name,
        status=Status.UNREACHABLE,
        reason=why,
        path=np.asarray(q, dtype=float)[None],
        pos_err_m=pos_err,
        angle_err_deg=ang_err,
    )


def solve_legs(
    problem: Problem,
    planner_name: str,
    seed: int,
    *,
    legs: Sequence[int] | None = None,
    budget: Budget | None = None,
    overrides: dict[str, Any] | None = None,
    stop_on_failure: bool = False,
    gui: bool = False,
    on_leg: Callable[[PlanResult], None] | None = None,
) -> Plan:
    """Solve ``legs`` (default: all) in order; each starts where the previous one ended.

    Closed-loop planners get one PyBullet world for the whole task.
    """
    entry = get_entry(planner_name)
    planner = make_planner(planner_name, overrides)
    budget = budget or problem.budget
    legs = list(range(problem.legs)) if legs is None else list(legs)
    results: list[PlanResult] = []
    with ExitStack() as stack:
        stepper = None
        if entry.needs_stepper:
            from plannerlab.sim import SimWorld

            stepper = stack.enter_context(
                SimWorld(
                    problem.robot,
                    problem.scene,
                    gui=gui,
                    gravity_mps2=problem.simulation.gravity_mps2,
                )
            )
        q = None  # the first leg starts at the problem's start state
        for leg in legs:
            why = unreachable_reason(problem.robot, problem.goal(leg))
            if why is not None:
                r = _unreachable(problem, planner_name, leg, why, q)
            else:
                r = planner.solve(
                    problem, leg, budget, leg_rng(seed, leg), q_start=q, stepper=stepper
                )
            r = r.replace(seed=seed)
            results.append(r)
            if on_leg is not None:
                on_leg(r)
            q = r.path[-1]
            if stop_on_failure and r.status is not Status.SOLVED:
                break
    return Plan(
        problem=problem.name,
        problem_file=str(resolve_problem_path(problem.source)) if problem.source else "",
        planner=planner_name,
        seed=seed,
        budget=budget.to_dict(),
        legs=tuple(results),
        overrides=dict(overrides or {}),
        versions=versions(),
    )

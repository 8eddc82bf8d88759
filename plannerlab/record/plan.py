"""Plan files and execution files: a planner's legs, and what executing them did.

A plan file (``plannerlab.plan/2``) holds the per-leg
:class:`~plannerlab.record.leg.PlanResult` records (each path as its waypoints), the seed,
the overrides, the budget, the package versions, the problem file it was planned on (its
absolute path, and its path relative to the plan file's folder) and that file's SHA-256:
the problem is found from the plan's own folder, or at its recorded path, from any
working directory (:meth:`Plan.problem_path`). ``plannerlab execute PLAN.json`` never
rewrites it: the executions go to an execution file (``plannerlab.execution/1``, default
``PLAN.exec.json`` beside the plan), and executing refuses a plan whose problem file
changed since planning (unless told to go on with a warning).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from plannerlab.errors import PlanFileError, PlannerlabError
from plannerlab.record.codec import dumps, loads, to_data
from plannerlab.record.execution import Execution
from plannerlab.record.files import write_text_atomic
from plannerlab.record.leg import PlanResult
from plannerlab.robots.paths import waypoints

if TYPE_CHECKING:
    from plannerlab.problem.load import Problem

PLAN_FORMAT = "plannerlab.plan/2"
#: plan files written before the problem hash (read, not written)
_OLD_PLAN_FORMATS = ("plannerlab.plan/1",)
EXECUTION_FORMAT = "plannerlab.execution/1"


def file_sha256(path: str | Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _read_json(path: Path, what: str) -> Any:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PlanFileError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise PlanFileError(f"{path}: a directory, expected a {what}") from None
    except UnicodeDecodeError:
        raise PlanFileError(f"{path}: not UTF-8 text, expected a {what}") from None
    try:
        return loads(text)
    except ValueError as exc:
        raise PlanFileError(f"{path}: not JSON ({exc})") from None


@dataclass(frozen=True, eq=False)
class Plan:
    """A planner's results over some legs of a problem.

    Attributes:
        problem: problem name; ``problem_file`` the file it was loaded from and
            ``problem_sha256`` that file's hash at planning time ("" if unknown).
        problem_file_from_plan: the problem file's path relative to the folder of the
            plan file (written by :meth:`save`, "" before).
        plan_dir: the folder the plan was read from (set by :meth:`load`; not saved).
        planner, seed, overrides, budget: what was run.
        legs: one :class:`PlanResult` per leg, in order.
        versions: package versions of the planning run.
    """

    problem: str
    problem_file: str
    planner: str
    seed: int
    budget: dict[str, Any]
    legs: tuple[PlanResult, ...]
    overrides: dict[str, Any] = field(default_factory=dict)
    versions: dict[str, str] = field(default_factory=dict)
    problem_sha256: str = ""
    problem_file_from_plan: str = ""
    plan_dir: str = field(default="", repr=False)

    @property
    def solved(self) -> bool:
        return all(r.solved for r in self.legs)

    def full_path(self) -> np.ndarray:
        """All legs' paths joined (m, dof)."""
        parts = [self.legs[0].path] + [r.path[1:] for r in self.legs[1:]]
        return np.concatenate(parts)

    def to_dict(self, plan_file: str | Path | None = None) -> dict[str, Any]:
        """The plan file's content (with ``plan_file``, where the file goes: the problem
        file is then recorded by its absolute path, a relative one taken from the working
        directory, and by its path from the plan file's folder, ``problem_file_from_plan``,
        so that the plan finds its problem from anywhere). Each leg's path is stored as
        its waypoints (:func:`~plannerlab.robots.paths.waypoints`: states inside a straight
        joint-space segment are left out, as executing densifies every segment again), so
        a plan file stays small (an interpolated OMPL path of 14 000 states is a few dozen
        corners).
        That is the canonical form every execution runs
        (:func:`plannerlab.run.pipeline.execute_results`) and :func:`~plannerlab.run.pipeline.
        solve_legs` returns, and JSON's shortest-repr floats read back bit for bit: the
        file is lossless, it executes as the plan in memory does."""
        problem_file, from_plan = self.problem_file, None
        if plan_file is not None:
            found = self.problem_path() if self.plan_dir else None
            problem = found or (Path(self.problem_file) if self.problem_file else None)
            from_plan = ""
            if problem is not None:
                problem_file = str(problem.resolve())
                try:
                    from_plan = os.path.relpath(problem_file, Path(plan_file).resolve().parent)
                except ValueError:  # another drive
                    from_plan = ""
                from_plan = Path(from_plan).as_posix() if from_plan else ""
        where = {"problem_file": problem_file}
        if from_plan is not None:
            where["problem_file_from_plan"] = from_plan
        return {
            "format": PLAN_FORMAT,
            "problem": self.problem,
            **where,
            "problem_sha256": self.problem_sha256,
            "planner": self.planner,
            "seed": self.seed,
            "overrides": self.overrides,
            "budget": self.budget,
            "versions": self.versions,
            "legs": [{**r.to_dict(), "path": to_data(waypoints(r.path))} for r in self.legs],
        }

    def save(self, path: str | Path) -> Path:
        """Write the plan file (:meth:`to_dict` with ``path``)."""
        return write_text_atomic(path, dumps(self.to_dict(path), indent=1) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> Plan:
        path = Path(path)
        data = _read_json(path, "plan file")
        if not isinstance(data, dict) or data.get("format") not in (
            PLAN_FORMAT,
            *_OLD_PLAN_FORMATS,
        ):
            raise PlanFileError(f"{path}: [format] expected {PLAN_FORMAT!r}")
        try:
            legs = data["legs"]
            if not isinstance(legs, list) or not legs:
                raise PlanFileError(f"{path}: [legs] expected a non-empty list of legs")
            return cls(
                problem=data["problem"],
                problem_file=data["problem_file"],
                planner=data["planner"],
                seed=int(data["seed"]),
                budget=data["budget"],
                legs=tuple(PlanResult.from_dict(r) for r in legs),
                overrides=data.get("overrides", {}),
                versions=data.get("versions", {}),
                problem_sha256=data.get("problem_sha256", ""),
                problem_file_from_plan=str(data.get("problem_file_from_plan", "")),
                plan_dir=str(path.resolve().parent),
            )
        except KeyError as exc:
            raise PlanFileError(f"{path}: [{exc.args[0]}] is missing") from None
        except PlanFileError as exc:
            if str(exc).startswith(str(path)):
                raise
            raise PlanFileError(f"{path}: [legs] {exc}") from None

    def _candidates(self) -> list[Path]:
        """Where the problem file may be, in order: relative to the plan's folder, at the
        recorded path (absolute; a relative one, in plans written before, from the working
        directory, then from the plan's folder, then beside the plan)."""
        out: list[Path] = []
        here = Path(self.plan_dir) if self.plan_dir else None
        if here is not None and self.problem_file_from_plan:
            out.append(here / self.problem_file_from_plan)
        if self.problem_file:
            p = Path(self.problem_file)
            out.append(p)
            if here is not None and not p.is_absolute():
                out += [here / p, here / p.name]
        return list(dict.fromkeys(Path(os.path.normpath(c)) for c in out))

    def _find_problem(self) -> tuple[Path | None, str | None]:
        """(the problem file, why it is not the one planned on or None)."""
        if not self.problem_file:
            return None, "the plan records no problem file (planned on a problem in memory)"
        existing = [c for c in self._candidates() if c.is_file()]
        if not self.problem_sha256:
            if existing:
                return existing[0], None
        else:
            for c in existing:
                if file_sha256(c) == self.problem_sha256:
                    return c, None
            by_name = self._bundled_by_name()
            if by_name is not None:
                return by_name, None
        if existing:
            return existing[0], (
                f"the problem file {existing[0]} changed since planning (SHA-256 differs)"
            )
        looked = ", ".join(str(c) for c in self._candidates())
        return None, f"the problem file {self.problem_file} no longer exists (looked for {looked})"

    def _bundled_by_name(self) -> Path | None:
        """A problem of the same file name among ``./problems`` and the bundled ones whose
        bytes are the very file planned on (same SHA-256), or None."""
        from plannerlab.problem.catalog import resolve_problem_path

        try:
            p = resolve_problem_path(Path(self.problem_file).stem)
        except PlannerlabError:  # a name that resolves to nothing
            return None
        return p if p.is_file() and file_sha256(p) == self.problem_sha256 else None

    def problem_path(self) -> Path | None:
        """The problem file this plan was planned on: found relative to the plan file's
        folder, at the recorded path, or (same SHA-256) by its name among the problems;
        a changed file is returned too (:meth:`problem_changed` says so); None when none
        exists."""
        return self._find_problem()[0]

    def problem_changed(self) -> str | None:
        """Why the problem file is not the one planned on, in words (None: unchanged)."""
        return self._find_problem()[1]

    def load_problem(self) -> Problem:
        """The problem at :meth:`problem_path`.

        Raises:
            PlanFileError: no problem file exists where the plan says.
        """
        from plannerlab.problem.catalog import load_problem

        path, why = self._find_problem()
        if path is None:
            raise PlanFileError(f"{why}")
        return load_problem(path)


@dataclass(frozen=True, eq=False)
class ExecutionFile:
    """The executions of a plan's legs, as ``plannerlab execute`` writes them.

    Attributes:
        plan_file: the plan that was executed; ``problem_sha256`` its problem's hash.
        executions: one :class:`Execution` per executed leg.
        versions: package versions of the execution run.
    """

    plan_file: str
    problem: str
    planner: str
    seed: int
    problem_sha256: str
    executions: tuple[Execution, ...]
    versions: dict[str, str] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return bool(self.executions) and all(e.success for e in self.executions)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": EXECUTION_FORMAT,
            "plan_file": self.plan_file,
            "problem": self.problem,
            "planner": self.planner,
            "seed": self.seed,
            "problem_sha256": self.problem_sha256,
            "versions": self.versions,
            "executions": [e.to_dict() for e in self.executions],
        }

    def save(self, path: str | Path) -> Path:
        return write_text_atomic(path, dumps(self.to_dict(), indent=1) + "\n")

    @classmethod
    def of(
        cls,
        plan: Plan,
        plan_file: str | Path,
        executions: Sequence[Execution],
        versions: dict[str, str],
    ) -> ExecutionFile:
        return cls(
            plan_file=str(plan_file),
            problem=plan.problem,
            planner=plan.planner,
            seed=plan.seed,
            problem_sha256=plan.problem_sha256,
            executions=tuple(executions),
            versions=versions,
        )

    @classmethod
    def load(cls, path: str | Path) -> ExecutionFile:
        path = Path(path)
        data = _read_json(path, "execution file")
        if not isinstance(data, dict) or data.get("format") != EXECUTION_FORMAT:
            raise PlanFileError(f"{path}: [format] expected {EXECUTION_FORMAT!r}")
        try:
            return cls(
                plan_file=data["plan_file"],
                problem=data["problem"],
                planner=data["planner"],
                seed=int(data["seed"]),
                problem_sha256=data.get("problem_sha256", ""),
                executions=tuple(Execution.from_dict(e) for e in data["executions"]),
                versions=data.get("versions", {}),
            )
        except KeyError as exc:
            raise PlanFileError(f"{path}: [{exc.args[0]}] is missing") from None


def execution_path(plan_file: str | Path) -> Path:
    """Where ``plannerlab execute PLAN.json`` writes by default: ``PLAN.exec.json``."""
    p = Path(plan_file)
    return p.with_name(p.name.removesuffix(".json") + ".exec.json")

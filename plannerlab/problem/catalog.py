"""Finding and loading problems: what users call.

:func:`load_problem` parses a problem file (see :mod:`plannerlab.problem.load`) and then makes
the checks that need the collision checker: the start state must be collision-free
(the error names the colliding pairs).
"""

from __future__ import annotations

import os
from pathlib import Path

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import ProblemError, UnknownNameError
from plannerlab.problem.load import Problem, parse_problem


def problems_dir() -> Path:
    """The folder of bundled problems: ``$PLANNERLAB_PROBLEMS`` or the repository's
    ``problems/``."""
    env = os.environ.get("PLANNERLAB_PROBLEMS")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "problems"


def list_problems() -> list[Path]:
    """Every problem file in :func:`problems_dir`, sorted by name."""
    d = problems_dir()
    return sorted(d.glob("*.toml")) if d.is_dir() else []


def resolve_problem_path(name_or_path: str | Path, cwd: Path | None = None) -> Path:
    """A problem file from a path or a problem's name (``armz_pocket``).

    A name is looked up in ``./problems`` (relative to ``cwd``, default the current
    directory) first, then in :func:`problems_dir` (the bundled problems).
    """
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists() or len(p.parts) > 1:
        return p
    local = (cwd or Path.cwd()) / "problems" / f"{name_or_path}.toml"
    if local.is_file():
        return local
    candidate = problems_dir() / f"{name_or_path}.toml"
    if candidate.exists():
        return candidate
    raise UnknownNameError("problem", str(name_or_path), [q.stem for q in list_problems()])


def check_start(problem: Problem, checker: CollisionChecker | None = None) -> None:
    """Raise a ProblemError naming the colliding pairs if the start is in collision."""
    checker = checker or CollisionChecker(problem.robot, problem.scene)
    if not checker.is_valid(problem.q_start):
        pairs = checker.colliding_pairs(problem.q_start)
        listing = ", ".join(f"{a} x {b}" for a, b in pairs)
        raise ProblemError(
            problem.source, "start", f"a collision-free start state; it collides: {listing}"
        )


def load_problem(name_or_path: str | Path) -> Problem:
    """Parse, validate and collision-check a problem (by bundled name or by path)."""
    problem = parse_problem(resolve_problem_path(name_or_path))
    check_start(problem)
    return problem

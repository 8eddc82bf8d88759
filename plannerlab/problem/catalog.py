"""Finding and loading problems: what users call.

:func:`load_problem` parses and validates a problem file (see :mod:`plannerlab.problem.load`);
it imports no engine. Whether the start state is collision-free is checked where planning
starts (:func:`plannerlab.run.pipeline.solve_legs`), once.
"""

from __future__ import annotations

import os
from pathlib import Path

from plannerlab.errors import UnknownNameError
from plannerlab.problem.load import Problem, parse_problem


def problems_dir() -> Path:
    """The folder of bundled problems: ``$PLANNERLAB_PROBLEMS`` or the repository's
    ``problems/``."""
    env = os.environ.get("PLANNERLAB_PROBLEMS")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "problems"


def list_problems(cwd: Path | None = None) -> list[Path]:
    """Every problem a name resolves to (see :func:`resolve_problem_path`): the files of
    ``./problems`` (relative to ``cwd``, default the current directory), then the bundled
    ones (:func:`problems_dir`) that no local file of the same name shadows; each group
    sorted by name."""
    local_dir = (cwd or Path.cwd()) / "problems"
    bundled_dir = problems_dir()
    local = sorted(local_dir.glob("*.toml")) if local_dir.is_dir() else []
    bundled = sorted(bundled_dir.glob("*.toml")) if bundled_dir.is_dir() else []
    if local_dir.is_dir() and bundled_dir.is_dir() and local_dir.samefile(bundled_dir):
        return bundled  # run from the repository: ./problems is the bundled folder
    names = {p.stem for p in local}
    return local + [p for p in bundled if p.stem not in names]


def problem_origin(path: Path) -> str:
    """Where a listed problem file comes from: ``"bundled"`` or ``"./problems"``."""
    d = problems_dir()
    if d.is_dir() and path.resolve().is_relative_to(d.resolve()):
        return "bundled"
    return "./problems"


def _grouped(folder: Path) -> list[tuple[Path, str]]:
    """Every problem file under ``folder``: (file, group), the group being its sub-folder
    (``""`` at the top, ``urdf/panda``, ``variants``); the top first, then each group,
    each sorted by name."""
    if not folder.is_dir():
        return []
    out = [(p, p.parent.relative_to(folder).as_posix()) for p in folder.rglob("*.toml")]
    return sorted(((p, "" if g == "." else g) for p, g in out), key=lambda x: (x[1], x[0].name))


def problem_catalog(cwd: Path | None = None) -> list[tuple[Path, str, str]]:
    """Every problem there is, for ``plannerlab problems``: (file, origin, group) with
    origin ``"./problems"`` or ``"bundled"`` and group the sub-folder (``""``, or e.g.
    ``urdf/panda``, ``variants``). The files of ``./problems`` (relative to ``cwd``) and
    its sub-folders come first, then the bundled ones no local file of the same name
    shadows. Each resolves by its name (:func:`resolve_problem_path`), a file of a
    sub-folder when no other problem has its name."""
    local_dir = (cwd or Path.cwd()) / "problems"
    bundled_dir = problems_dir()
    bundled = [(p, "bundled", g) for p, g in _grouped(bundled_dir)]
    if local_dir.is_dir() and bundled_dir.is_dir() and local_dir.samefile(bundled_dir):
        return bundled  # run from the repository: ./problems is the bundled folder
    local = [(p, "./problems", g) for p, g in _grouped(local_dir)]
    names = {p.stem for p, _, _ in local}
    return local + [row for row in bundled if row[0].stem not in names]


def resolve_problem_path(name_or_path: str | Path, cwd: Path | None = None) -> Path:
    """A problem file from a path or a problem's name (``armz_pocket``).

    A name is looked up in ``./problems`` (relative to ``cwd``, default the current
    directory) first, then in :func:`problems_dir` (the bundled problems), then in their
    sub-folders (``variants/``, ``urdf/panda/``: a name found in exactly one of them).
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
    nested = [p for p, _, _ in problem_catalog(cwd) if p.stem == str(name_or_path)]
    if len(nested) == 1:
        return nested[0]
    raise UnknownNameError("problem", str(name_or_path), [q.stem for q in list_problems(cwd)])


def load_problem(name_or_path: str | Path) -> Problem:
    """Parse and validate a problem (by bundled name or by path). Needs no engine: the
    start state is collision-checked where planning starts
    (:func:`plannerlab.run.pipeline.solve_legs`)."""
    return parse_problem(resolve_problem_path(name_or_path))

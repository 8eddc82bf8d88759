"""Finding and loading problems: what users call.

:func:`load_problem` parses and validates a problem file (see :mod:`plannerlab.problem.load`);
it imports no engine. Whether the start state is collision-free is checked where planning
starts (:func:`plannerlab.run.pipeline.solve_legs`), once.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple

from plannerlab.errors import PlannerlabError, UnknownNameError
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


class ProblemEntry(NamedTuple):
    """One problem of :func:`problem_catalog`.

    Attributes:
        name: the name it loads by (``load_problem(name)`` reads ``path``): its file's stem
            when no other listed problem has that stem, else its sub-folder and stem
            (``urdf/panda_mesh/table``).
        path: the problem file.
        origin: ``"./problems"`` (the current directory's) or ``"bundled"``.
        group: its sub-folder (``""`` at the top, ``urdf/panda``, ``variants``).
    """

    name: str
    path: Path
    origin: str
    group: str


def _files(cwd: Path | None) -> list[tuple[Path, str, str]]:
    """(file, origin, group) of every problem, local ones first (see :func:`problem_catalog`)."""
    local_dir = (cwd or Path.cwd()) / "problems"
    bundled_dir = problems_dir()
    bundled = [(p, "bundled", g) for p, g in _grouped(bundled_dir)]
    if local_dir.is_dir() and bundled_dir.is_dir() and local_dir.samefile(bundled_dir):
        return bundled  # run from the repository: ./problems is the bundled folder
    local = [(p, "./problems", g) for p, g in _grouped(local_dir)]
    # a bundled file is shadowed by the local file at its place (the same folder and stem)
    places = {(g, p.stem) for p, _, g in local}
    return local + [row for row in bundled if (row[2], row[0].stem) not in places]


def problem_catalog(cwd: Path | None = None) -> list[ProblemEntry]:
    """Every problem there is, for ``plannerlab problems``, each with the name it loads by
    (:class:`ProblemEntry`). The files of ``./problems`` (relative to ``cwd``) and its
    sub-folders come first, then the bundled ones no local file shadows (a local file at
    the same place: the same sub-folder and name);
    the top folder first, then each sub-folder, each sorted by name. A file of a
    sub-folder is named by its stem when no other problem has that stem, else by its
    sub-folder and stem (``urdf/iiwa_mesh/table`` beside ``urdf/panda_mesh/table``)."""
    files = _files(cwd)
    top = {p.stem for p, _, g in files if not g}
    stems: dict[str, int] = {}
    for p, _, _ in files:
        stems[p.stem] = stems.get(p.stem, 0) + 1
    out = []
    for p, origin, group in files:
        unique = not group or (stems[p.stem] == 1 and p.stem not in top)
        out.append(ProblemEntry(p.stem if unique else f"{group}/{p.stem}", p, origin, group))
    return out


def resolve_problem_path(name_or_path: str | Path, cwd: Path | None = None) -> Path:
    """A problem file from a path or a problem's name (``armz_pocket``,
    ``urdf/panda_mesh/table``): the names :func:`problem_catalog` lists.

    A path (an existing file, or any name ending in ``.toml``) is itself. A name is looked
    up as ``NAME.toml`` in ``./problems`` (relative to ``cwd``, default the current
    directory) first, then in :func:`problems_dir` (the bundled problems); a name with a
    sub-folder (``urdf/panda_mesh/table``) the same way; a bare stem found in exactly one
    sub-folder is that file.

    Raises:
        PlannerlabError: a stem that several sub-folders hold (the error names them all).
        UnknownNameError: a name no problem has (with "did you mean").
    """
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        return p
    for folder in ((cwd or Path.cwd()) / "problems", problems_dir()):
        candidate = folder / f"{name_or_path}.toml"
        if candidate.is_file():
            return candidate
    catalog = problem_catalog(cwd)
    nested = [e for e in catalog if e.path.stem == str(name_or_path)]
    if len(nested) == 1:
        return nested[0].path
    if len(nested) > 1:
        raise PlannerlabError(
            f"problem {str(name_or_path)!r} is ambiguous: "
            f"{' and '.join(repr(e.name) for e in nested)} have that name; give one of these"
        )
    raise UnknownNameError("problem", str(name_or_path), [e.name for e in catalog])


def load_problem(name_or_path: str | Path) -> Problem:
    """Parse and validate a problem (by bundled name or by path). Needs no engine: the
    start state is collision-checked where planning starts
    (:func:`plannerlab.run.pipeline.solve_legs`)."""
    return parse_problem(resolve_problem_path(name_or_path))

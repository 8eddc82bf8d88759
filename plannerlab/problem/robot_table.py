"""The ``[robot]`` table: its type's declared keys parsed and checked, then the robot built.

Each robot family declares its table (:class:`~plannerlab.robots.schema.RobotTable`, in
``robots/<family>/schema.py``, reached through :mod:`plannerlab.robots.registry`); this is
the one parser of every family's table: unknown keys with "did you mean", kinds, limits and
choices, errors naming the file and ``robot.<key>``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from plannerlab.problem.reader import TableReader
from plannerlab.robots.base import Robot
from plannerlab.robots.registry import FAMILIES, robot_table
from plannerlab.robots.schema import COMMON_KEYS, Key, RobotTable, TableValueError


def _table_value(reader: TableReader, key: Key) -> Any:
    """The value of one declared key (its default when absent), checked as declared."""
    name = key.name
    if key.kind == "integer":
        minimum = None if key.minimum is None else int(key.minimum)
        maximum = None if key.maximum is None else int(key.maximum)
        return reader.integer(
            name, key.default, minimum=minimum, maximum=maximum, why_maximum=key.why_maximum
        )
    if key.kind == "number":
        return reader.number(
            name,
            key.default,
            positive=key.positive,
            minimum=key.minimum,
            maximum=key.maximum,
            why_maximum=key.why_maximum,
        )
    if key.kind == "vector":
        v = reader.vector(name, key.length, default=list(key.default))  # type: ignore[arg-type]
        if key.ordered and v[0] > v[1]:
            unit = f" [{key.unit}]" if key.unit else ""
            raise reader.fail(
                name, f"[lower, upper] with lower <= upper{unit}, got {[float(x) for x in v]}"
            )
        return v
    if key.kind == "pairs":
        raw = reader.raw(name, list(key.default))  # type: ignore[arg-type]
        ok = isinstance(raw, list) and all(
            isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) for x in p) for p in raw
        )
        if not ok:
            raise reader.fail(name, f"a list of [name, name] pairs of strings, got {raw!r:.80}")
        return tuple((a, b) for a, b in raw)
    s = reader.string(name, key.default)
    if key.kind == "path":
        if not s:
            return ""
        folder = Path(reader.source).parent if reader.source != "<memory>" else Path.cwd()
        resolved = (folder / s).resolve()
        if not resolved.is_file():
            raise reader.fail(
                name, f"an existing file, relative to the problem file; {resolved} does not exist"
            )
        return str(resolved)
    if key.choices and s not in key.choices:
        choices = " or ".join(
            f'"{c}"' + (" (the default)" if c == key.default else "") for c in key.choices
        )
        raise reader.fail(name, f"{choices}, got {s!r}")
    return s


def parse_robot_table(reader: TableReader, table: RobotTable) -> dict[str, Any]:
    """Every declared key's checked value (defaults filled in) from a ``[robot]`` table.

    Raises:
        ProblemError: naming the file and ``robot.<key>``: a key the table does not declare
            (with "did you mean"), a value of the wrong kind, out of its limits, or not
            among its choices.
    """
    reader.unknown_keys((COMMON_KEYS[0], *table.names, *COMMON_KEYS[1:]))
    for key in table.keys:
        if key.required and not reader.has(key.name):
            raise reader.fail(key.name, f"is missing ({key.meaning})")
    return {key.name: _table_value(reader, key) for key in table.keys}


def build_robot(reader: TableReader) -> Robot:
    """Build the robot described by a problem file's ``[robot]`` table: its type's declared
    keys are parsed here, then its family's constructor builds it."""
    kind = reader.string("type")
    if kind not in FAMILIES:
        import difflib

        close = difflib.get_close_matches(kind, FAMILIES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise reader.fail("type", f"one of {', '.join(FAMILIES)}, got {kind!r}{hint}")
    table = robot_table(kind)
    values = parse_robot_table(reader, table)
    try:
        robot: Robot = table.build(values)
    except TableValueError as exc:
        raise reader.fail(exc.key, exc.expected) from None
    return robot

"""Robot families. Each module holds one family's kinematics, collision capsules and URDF.

:func:`build_robot` turns a problem file's ``[robot]`` table into a model; each family
provides ``from_table(reader)`` and is imported only when a problem asks for it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from plannerlab.robots.base import Robot

if TYPE_CHECKING:
    from plannerlab.problem.load import TableReader

#: robot type in a problem file -> "module:function" building it from the [robot] table
ROBOT_TYPES: dict[str, str] = {
    "armz": "plannerlab.robots.armz.model:from_table",
    "irb6": "plannerlab.robots.irb6.model:from_table",
    "continuum_chain": "plannerlab.robots.continuum.model:from_table",
}


def build_robot(reader: TableReader) -> Robot:
    """Build the robot described by a problem file's ``[robot]`` table."""
    kind = reader.string("type")
    if kind not in ROBOT_TYPES:
        import difflib

        close = difflib.get_close_matches(kind, ROBOT_TYPES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise reader.fail("type", f"one of {', '.join(ROBOT_TYPES)}, got {kind!r}{hint}")
    module_name, func = ROBOT_TYPES[kind].split(":")
    builder = getattr(importlib.import_module(module_name), func)
    return builder(reader)


__all__ = ["ROBOT_TYPES", "Robot", "build_robot"]

"""The ``[[obstacles]]`` tables: boxes, cylinders and spheres with unique names → a
:class:`~plannerlab.problem.scene.Scene`."""

from __future__ import annotations

import numpy as np

from plannerlab.errors import ProblemError
from plannerlab.problem.reader import TableReader
from plannerlab.problem.scene import OBSTACLE_TYPES, Box, Cylinder, Obstacle, Scene, Sphere


def _obstacle(reader: TableReader) -> Obstacle:
    name = reader.string("name")
    kind = reader.string("type")
    if kind not in OBSTACLE_TYPES:
        raise reader.fail("type", f"one of {', '.join(OBSTACLE_TYPES)}, got {kind!r}")
    T = reader.pose("center_m", "rpy_deg")
    if kind == "box":
        reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "size_m", "note"))
        size = reader.vector("size_m", 3)
        if np.any(size <= 0):
            raise reader.fail("size_m", f"three positive edge lengths, got {size.tolist()}")
        return Box(name, T, size)
    if kind == "cylinder":
        reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "radius_m", "length_m", "note"))
        return Cylinder(
            name,
            T,
            reader.number("radius_m", positive=True),
            reader.number("length_m", positive=True),
        )
    reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "radius_m", "note"))
    return Sphere(name, T, reader.number("radius_m", positive=True))


def read_scene(top: TableReader) -> Scene:
    """The problem's obstacles (``[[obstacles]]``, none when absent), each name unique."""
    source = top.source
    raw_obstacles = top.raw("obstacles", [])
    if not isinstance(raw_obstacles, list):
        raise top.fail("obstacles", "an array of tables [[obstacles]]")
    obstacles = [
        _obstacle(TableReader(source, f"obstacles[{i}]", o)) for i, o in enumerate(raw_obstacles)
    ]
    names = [o.name for o in obstacles]
    for i, n in enumerate(names):
        if names.index(n) != i:
            raise ProblemError(source, f"obstacles[{i}].name", f"a unique name; {n!r} is repeated")
    return Scene(tuple(obstacles))

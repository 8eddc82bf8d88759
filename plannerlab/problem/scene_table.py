"""The ``[[obstacles]]`` tables: boxes, cylinders, spheres and meshes with unique names →
a :class:`~plannerlab.problem.scene.Scene` (a mesh's cover boxes among its obstacles, the
mesh itself among its meshes)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError, did_you_mean
from plannerlab.problem.reader import TableReader
from plannerlab.problem.scene import (
    OBSTACLE_TYPES,
    Box,
    Cylinder,
    Mesh,
    Obstacle,
    Scene,
    Sphere,
    capsule_links,
)

#: the most boxes a mesh obstacle's cover may have (default of ``max_boxes``)
MESH_MAX_BOXES: int = 64


def _touch_links(reader: TableReader, robot: Any) -> tuple[str, ...]:
    """``touch_links``: names of the robot's links with collision geometry allowed to
    touch this obstacle (declared contacts; default none)."""
    raw = reader.raw("touch_links", [])
    if not isinstance(raw, list) or not all(isinstance(n, str) for n in raw):
        raise reader.fail("touch_links", f"an array of robot link names (strings), got {raw!r}")
    if robot is None:
        return tuple(dict.fromkeys(raw))
    known = sorted(set(capsule_links(robot)))
    for n in raw:
        if n not in known:
            shown = ", ".join(known) if len(known) <= 40 else ", ".join(known[:40]) + ", ..."
            raise reader.fail(
                "touch_links",
                f"names of the robot's links with collision geometry; {n!r} is not one;"
                f"{did_you_mean(n, known)} the robot's links: {shown}",
            )
    return tuple(dict.fromkeys(raw))


def _mesh(reader: TableReader, name: str, T: np.ndarray, touch: tuple[str, ...]) -> Mesh:
    """A ``type = "mesh"`` obstacle: its file (relative to the problem file) read, scaled
    and covered by boxes."""
    from plannerlab.robots.urdf.meshes import MeshError, box_cover, load_mesh

    reader.unknown_keys(
        ("name", "type", "center_m", "rpy_deg", "file", "scale", "max_boxes", "touch_links", "note")
    )
    file = reader.string("file")
    folder = Path(reader.source).parent if reader.source != "<memory>" else Path.cwd()
    path = (folder / file).resolve()
    raw_scale = reader.raw("scale", 1.0)
    if isinstance(raw_scale, int | float) and not isinstance(raw_scale, bool):
        scale = np.full(3, float(raw_scale))
    else:
        scale = reader.vector("scale", 3)
    if not (np.all(np.isfinite(scale)) and np.all(scale > 0)):
        raise reader.fail("scale", f"a positive number or three, got {raw_scale!r}")
    max_boxes = reader.integer("max_boxes", MESH_MAX_BOXES, minimum=1, maximum=4096)
    where = f"obstacle {name!r}"
    try:
        if not path.is_file():
            raise MeshError(
                str(path),
                where,
                "the file does not exist",
                "fix file (relative to the problem file)",
            )
        V, F = load_mesh(path, scale, where)
        cover = box_cover(V, F, max_boxes, where, str(path))
    except MeshError as exc:
        raise reader.fail("file", f"a mesh plannerlab can read and cover; {exc}") from None
    return Mesh(
        name, T, str(path), scale, V, F, cover.centres_m, cover.half_m, cover.max_excess_m, touch
    )


def _obstacle(reader: TableReader, robot: Any) -> Obstacle | Mesh:
    name = reader.string("name")
    kind = reader.string("type")
    if kind not in OBSTACLE_TYPES:
        raise reader.fail("type", f"one of {', '.join(OBSTACLE_TYPES)}, got {kind!r}")
    T = reader.pose("center_m", "rpy_deg")
    touch = _touch_links(reader, robot)
    common = ("name", "type", "center_m", "rpy_deg", "touch_links", "note")
    if kind == "mesh":
        return _mesh(reader, name, T, touch)
    if kind == "box":
        reader.unknown_keys((*common, "size_m"))
        size = reader.vector("size_m", 3)
        if np.any(size <= 0):
            raise reader.fail("size_m", f"three positive edge lengths, got {size.tolist()}")
        return Box(name, T, size, touch_links=touch)
    if kind == "cylinder":
        reader.unknown_keys((*common, "radius_m", "length_m"))
        return Cylinder(
            name,
            T,
            reader.number("radius_m", positive=True),
            reader.number("length_m", positive=True),
            touch_links=touch,
        )
    reader.unknown_keys((*common, "radius_m"))
    return Sphere(name, T, reader.number("radius_m", positive=True), touch_links=touch)


def read_scene(top: TableReader, robot: Any = None) -> Scene:
    """The problem's obstacles (``[[obstacles]]``, none when absent), each name unique;
    ``touch_links`` checked against the robot's links when it is given."""
    source = top.source
    raw_obstacles = top.raw("obstacles", [])
    if not isinstance(raw_obstacles, list):
        raise top.fail("obstacles", "an array of tables [[obstacles]]")
    obstacles = [
        _obstacle(TableReader(source, f"obstacles[{i}]", o), robot)
        for i, o in enumerate(raw_obstacles)
    ]
    names = [o.name for o in obstacles]
    for i, n in enumerate(names):
        if names.index(n) != i:
            raise ProblemError(source, f"obstacles[{i}].name", f"a unique name; {n!r} is repeated")
        if "#" in n and any(isinstance(o, Mesh) for o in obstacles):
            raise ProblemError(
                source, f"obstacles[{i}].name", f"a name without '#' beside mesh obstacles; {n!r}"
            )
    prims: list[Obstacle] = []
    for o in obstacles:
        prims.extend(o.cover_boxes() if isinstance(o, Mesh) else (o,))
    return Scene(tuple(prims), tuple(o for o in obstacles if isinstance(o, Mesh)))

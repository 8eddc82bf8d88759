"""Obstacles as plain data. No collision library here: :mod:`plannerlab.collision.fcl_checker` turns
these into FCL objects.

Every obstacle has a name (unique in its scene), a pose ``T_world_obstacle`` (4, 4) whose
origin is the shape's centre, and its dimensions in metres. A cylinder's axis is its
local z.

A **mesh obstacle** (:class:`Mesh`: triangles from a file, at a pose, scaled) enters the
scene twice: :attr:`Scene.meshes` holds the real triangles (FCL's ``BVHModel`` and
PyBullet use them), and :attr:`Scene.obstacles` holds its conservative cover of boxes
(:func:`~plannerlab.robots.urdf.meshes.box_cover`: filled voxels merged into boxes, each
named ``<mesh>#k`` with ``cover_of = <mesh>``), which every planner and the compiled core
check exactly, so they see at least the mesh.

**Declared contacts** (``touch_links``, MoveIt's name): an obstacle may name robot links
allowed to touch it (a grasped object and the hand's links). Every collision road skips
the pairs (a capsule of such a link, that obstacle): :func:`touch_mask` gives them per
capsule; other links still collide with the obstacle, and those links with the other
obstacles. A mesh obstacle's cover boxes carry its ``touch_links``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.robots.base import Array


def _frozen(a: Array) -> Array:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Box:
    """A box of full edge lengths ``size_m`` (3,) centred at the pose's origin."""

    name: str
    T_world_obstacle: Array
    size_m: Array
    #: the mesh obstacle this box is a piece of the cover of ("" for a box of its own)
    cover_of: str = ""
    #: robot links allowed to touch it (declared contacts, see the module)
    touch_links: tuple[str, ...] = ()
    kind: str = field(default="box", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_world_obstacle", _frozen(self.T_world_obstacle))
        object.__setattr__(self, "size_m", _frozen(self.size_m))

    def half_extents_world(self) -> Array:
        """Half sizes of the world-axis-aligned box that bounds this one (3,)."""
        R = np.abs(self.T_world_obstacle[:3, :3])
        return R @ (self.size_m / 2.0)


@dataclass(frozen=True, eq=False)
class Cylinder:
    """A solid cylinder of ``radius_m`` and full ``length_m`` along its local z."""

    name: str
    T_world_obstacle: Array
    radius_m: float
    length_m: float
    #: robot links allowed to touch it (declared contacts, see the module)
    touch_links: tuple[str, ...] = ()
    kind: str = field(default="cylinder", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_world_obstacle", _frozen(self.T_world_obstacle))

    def half_extents_world(self) -> Array:
        axis = self.T_world_obstacle[:3, 2]
        radial = self.radius_m * np.sqrt(np.clip(1.0 - axis**2, 0.0, 1.0))
        return np.abs(axis) * self.length_m / 2.0 + radial


@dataclass(frozen=True, eq=False)
class Sphere:
    """A sphere of ``radius_m``."""

    name: str
    T_world_obstacle: Array
    radius_m: float
    #: robot links allowed to touch it (declared contacts, see the module)
    touch_links: tuple[str, ...] = ()
    kind: str = field(default="sphere", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_world_obstacle", _frozen(self.T_world_obstacle))

    def half_extents_world(self) -> Array:
        return np.full(3, self.radius_m)


@dataclass(frozen=True, eq=False)
class Mesh:
    """Triangles ``vertices_m`` (n, 3) [m, scaled, in the obstacle's frame] and ``faces``
    (m, 3) read from ``file``, and the boxes covering them (centres and half sizes (b, 3)
    in the obstacle's frame, reaching at most ``cover_excess_m`` outside the mesh)."""

    name: str
    T_world_obstacle: Array
    file: str
    scale: Array
    vertices_m: Array
    faces: np.ndarray
    cover_centres_m: Array
    cover_half_m: Array
    cover_excess_m: float
    #: robot links allowed to touch it (declared contacts, see the module)
    touch_links: tuple[str, ...] = ()
    kind: str = field(default="mesh", init=False)

    def __post_init__(self) -> None:
        for name in ("T_world_obstacle", "scale", "vertices_m", "cover_centres_m", "cover_half_m"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        faces = np.array(self.faces, dtype=np.int64)
        faces.setflags(write=False)
        object.__setattr__(self, "faces", faces)

    def half_extents_world(self) -> Array:
        """Half sizes of the world-axis-aligned box around the mesh, about its origin."""
        p = self.vertices_m @ self.T_world_obstacle[:3, :3].T
        return np.maximum(np.abs(p.max(axis=0)), np.abs(p.min(axis=0)))

    def vertices_world(self) -> Array:
        """The vertices (n, 3) in the world [m]."""
        T = self.T_world_obstacle
        return self.vertices_m @ T[:3, :3].T + T[:3, 3]

    def cover_boxes(self) -> tuple[Box, ...]:
        """The cover as world boxes named ``<name>#k`` (``cover_of`` = this mesh)."""
        T = self.T_world_obstacle
        out = []
        for k, (c, h) in enumerate(zip(self.cover_centres_m, self.cover_half_m, strict=True)):
            Tk = T.copy()
            Tk[:3, 3] = T[:3, :3] @ c + T[:3, 3]
            out.append(
                Box(
                    f"{self.name}#{k}",
                    Tk,
                    2.0 * h,
                    cover_of=self.name,
                    touch_links=self.touch_links,
                )
            )
        return tuple(out)


Obstacle = Box | Cylinder | Sphere
OBSTACLE_TYPES: tuple[str, ...] = ("box", "cylinder", "sphere", "mesh")


@dataclass(frozen=True, eq=False)
class Scene:
    """The static world: a tuple of uniquely named obstacles, and the mesh obstacles
    (whose cover boxes are among the obstacles, see the module docstring)."""

    obstacles: tuple[Obstacle, ...] = ()
    meshes: tuple[Mesh, ...] = ()

    def __post_init__(self) -> None:
        names = [o.name for o in self.obstacles] + [m.name for m in self.meshes]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"obstacle names must be unique; repeated: {sorted(dup)}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(o.name for o in self.obstacles)

    @property
    def source_names(self) -> tuple[str, ...]:
        """Per obstacle, the name of what it stands for: its own, or its mesh's."""
        return tuple(getattr(o, "cover_of", "") or o.name for o in self.obstacles)

    def mesh(self, name: str) -> Mesh:
        """The mesh obstacle of that name."""
        for m in self.meshes:
            if m.name == name:
                return m
        raise KeyError(name)

    def aabbs(self) -> tuple[Array, Array]:
        """World-axis-aligned bounds of every obstacle: lower (n, 3), upper (n, 3) [m]."""
        if not self.obstacles:
            return np.zeros((0, 3)), np.zeros((0, 3))
        c = np.array([o.T_world_obstacle[:3, 3] for o in self.obstacles])
        h = np.array([o.half_extents_world() for o in self.obstacles])
        return c - h, c + h


def capsule_links(robot: Any) -> tuple[str, ...]:
    """Per capsule of the robot, the name of the robot link it belongs to: a URDF robot's
    URDF link (``link_urdf_names``: a mesh link has many capsules), else the capsule's own
    name (``link_names``). The names ``touch_links`` may use."""
    return tuple(getattr(robot, "link_urdf_names", None) or robot.link_names)


def touch_mask(robot: Any, scene: Scene) -> np.ndarray:
    """(L, n) bool: capsule ``l`` of the robot may touch obstacle ``o`` of
    ``scene.obstacles`` (its link is among the obstacle's ``touch_links``): the pairs
    every collision road skips. All False when no obstacle declares contacts."""
    links = capsule_links(robot)
    if len(links) != len(robot.link_radii_m):
        raise ValueError(
            f"robot {getattr(robot, 'kind', '?')!r} names {len(links)} links for "
            f"{len(robot.link_radii_m)} capsules: its declared contacts cannot be placed"
        )
    out = np.zeros((len(links), len(scene.obstacles)), dtype=bool)
    for o, ob in enumerate(scene.obstacles):
        if ob.touch_links:
            allowed = set(ob.touch_links)
            out[:, o] = [n in allowed for n in links]
    return out

"""Obstacles as plain data. No collision library here: :mod:`plannerlab.collision.fcl_checker` turns
these into FCL objects.

Every obstacle has a name (unique in its scene), a pose ``T_world_obstacle`` (4, 4) whose
origin is the shape's centre, and its dimensions in metres. A cylinder's axis is its
local z.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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
    kind: str = field(default="sphere", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_world_obstacle", _frozen(self.T_world_obstacle))

    def half_extents_world(self) -> Array:
        return np.full(3, self.radius_m)


Obstacle = Box | Cylinder | Sphere
OBSTACLE_TYPES: tuple[str, ...] = ("box", "cylinder", "sphere")


@dataclass(frozen=True, eq=False)
class Scene:
    """The static world: a tuple of uniquely named obstacles."""

    obstacles: tuple[Obstacle, ...] = ()

    def __post_init__(self) -> None:
        names = [o.name for o in self.obstacles]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"obstacle names must be unique; repeated: {sorted(dup)}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(o.name for o in self.obstacles)

    def aabbs(self) -> tuple[Array, Array]:
        """World-axis-aligned bounds of every obstacle: lower (n, 3), upper (n, 3) [m]."""
        if not self.obstacles:
            return np.zeros((0, 3)), np.zeros((0, 3))
        c = np.array([o.T_world_obstacle[:3, 3] for o in self.obstacles])
        h = np.array([o.half_extents_world() for o in self.obstacles])
        return c - h, c + h

"""Planar geometry of the chord-arc search: obstacles, the query, the arcs of a solution.

**Obstacles** are planar: :class:`Circle` and :class:`ConvexPolygon` (a rectangle with a
yaw is :meth:`ConvexPolygon.rectangle`); :class:`ObstacleField` answers inside / signed
distance / direction-into queries for a batch of points. :mod:`.scene` cuts a loaded
problem's boxes (yaw only), vertical cylinders and spheres by the robot's plane.
Plain data and numpy only (no planner framework, no fcl/ompl/pybullet).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array
from plannerlab.robots.continuum.model import arc_points_local

Point = tuple[float, float]
Shape = tuple[tuple[float, float], ...]  # ((θ_k [rad], L_k [m]), ...)


class ChordArcInputError(PlannerlabError, ValueError):
    """The query is not usable: a collision point off every boundary, a target inside
    an obstacle, a bad obstacle, ..."""


# --------------------------------------------------------------------------- obstacles


def _point(v: Any, what: str) -> Point:
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (2,) or not np.all(np.isfinite(a)):
        raise ChordArcInputError(f"{what} must be two finite numbers (x, y), got {v!r}")
    return (float(a[0]), float(a[1]))


@dataclass(frozen=True)
class Circle:
    """A disc (a vertical cylinder or a sphere cut by the plane)."""

    center_m: Point
    radius_m: float
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "center_m", _point(self.center_m, f"circle {self.name!r} centre"))
        if not (math.isfinite(self.radius_m) and self.radius_m > 0):
            raise ChordArcInputError(
                f"circle {self.name!r}: radius must be > 0, got {self.radius_m}"
            )
        object.__setattr__(self, "radius_m", float(self.radius_m))


@dataclass(frozen=True)
class ConvexPolygon:
    """A convex polygon; vertices are stored counter-clockwise (reordered if given CW)."""

    vertices_m: tuple[Point, ...]
    name: str = ""

    def __post_init__(self) -> None:
        v = np.array([_point(p, f"polygon {self.name!r} vertex") for p in self.vertices_m])
        if len(v) < 3:
            raise ChordArcInputError(f"polygon {self.name!r} needs >= 3 vertices, got {len(v)}")
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        if np.all(cross <= 0):
            v = v[::-1]
            cross = -cross[::-1]
        if not np.all(cross > 0):
            raise ChordArcInputError(
                f"polygon {self.name!r} is not strictly convex (or has repeated vertices)"
            )
        object.__setattr__(self, "vertices_m", tuple((float(x), float(y)) for x, y in v))

    @classmethod
    def rectangle(
        cls,
        center_m: Sequence[float],
        size_m: Sequence[float],
        yaw_rad: float = 0.0,
        name: str = "",
    ) -> ConvexPolygon:
        """Rectangle of full sizes ``size_m`` (sx, sy), turned by ``yaw_rad`` about +z."""
        cx, cy = _point(center_m, f"rectangle {name!r} centre")
        sx, sy = _point(size_m, f"rectangle {name!r} size")
        if sx <= 0 or sy <= 0:
            raise ChordArcInputError(f"rectangle {name!r}: sizes must be > 0, got {size_m}")
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        local = [(-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2)]
        verts = tuple((cx + c * x - s * y, cy + s * x + c * y) for x, y in local)
        return cls(verts, name)


PlanarObstacle = Circle | ConvexPolygon


class ObstacleField:
    """Obstacles packed into arrays for batched inside / signed-distance tests."""

    def __init__(self, obstacles: Sequence[PlanarObstacle]) -> None:
        self.obstacles = tuple(obstacles)
        self.names = tuple(o.name or f"#{i}" for i, o in enumerate(self.obstacles))
        circ = [i for i, o in enumerate(self.obstacles) if isinstance(o, Circle)]
        poly = [i for i, o in enumerate(self.obstacles) if isinstance(o, ConvexPolygon)]
        self.circle_ids = np.array(circ, dtype=int)
        self.poly_ids = np.array(poly, dtype=int)
        circles = [o for o in self.obstacles if isinstance(o, Circle)]
        polygons = [o for o in self.obstacles if isinstance(o, ConvexPolygon)]
        self.cc = np.array([c.center_m for c in circles]).reshape(-1, 2)
        self.cr: Array = np.array([c.radius_m for c in circles], dtype=np.float64)
        e_max = max((len(g.vertices_m) for g in polygons), default=0)
        self.e_max = e_max
        self.verts: list[Array] = []
        self.edges: list[Array] = []  # (E, 2) edge vectors v_{j+1} - v_j
        normals = np.zeros((len(poly), e_max, 2))
        offsets = np.zeros((len(poly), e_max))
        for k, g in enumerate(polygons):
            v = np.array(g.vertices_m)
            d = np.roll(v, -1, axis=0) - v
            n = np.stack([d[:, 1], -d[:, 0]], axis=1) / np.hypot(d[:, 0], d[:, 1])[:, None]
            b = np.einsum("ij,ij->i", n, v)
            pad = e_max - len(v)  # repeat the first edge: changes no max
            normals[k] = np.vstack([n, np.repeat(n[:1], pad, axis=0)])
            offsets[k] = np.concatenate([b, np.repeat(b[:1], pad)])
            self.verts.append(v)
            self.edges.append(d)
        self.normals = normals
        self.offsets = offsets
        # Homogeneous half-planes, edge-major: row e·P + k is [n_x, n_y, -b] of edge e of
        # polygon k, so one matrix product with [x; y; 1] gives every signed edge value
        # and the max over edges is a reduction over the leading axis (broadcasting and
        # reductions over a short trailing axis are slow in numpy).
        self.Wh = (
            np.concatenate(
                [
                    np.concatenate([normals[:, e, :], -offsets[:, e, None]], axis=1)
                    for e in range(e_max)
                ],
                axis=0,
            )
            if poly
            else np.zeros((0, 3))
        )
        # Circles: x² + y² - 2 c·p + |c|² - r² < 0 as one product with [x; y; x² + y²; 1].
        self.Ch = (
            np.stack(
                [
                    -2.0 * self.cc[:, 0],
                    -2.0 * self.cc[:, 1],
                    np.ones(len(circ)),
                    (self.cc**2).sum(1),
                ],
                axis=1,
            )
            if circ
            else np.zeros((0, 4))
        )

    def inside_any(self, pts: Array, tol: float) -> Array:
        """(N,) True where a point (N, 2) is deeper than ``tol`` inside some obstacle."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        n = len(pts)
        out = np.zeros(n, dtype=bool)
        if not self.obstacles or n == 0:
            return out
        ph = np.empty((4, n))
        ph[0] = pts[:, 0]
        ph[1] = pts[:, 1]
        ph[2] = 1.0
        if len(self.poly_ids):
            vals = (self.Wh @ ph[:3]).reshape(self.e_max, len(self.poly_ids), n)
            out |= (vals.max(axis=0) < -tol).any(axis=0)
        if len(self.cr):
            ph[2] = ph[0] * ph[0] + ph[1] * ph[1]
            ph[3] = 1.0
            rin2 = np.clip(self.cr - tol, 0.0, None) ** 2
            C = self.Ch.copy()
            C[:, 3] -= rin2
            out |= ((C @ ph) < 0.0).any(axis=0)
        return out

    def signed_distance(self, pts: Array) -> Array:
        """Exact signed distance (N, O) [m] to every obstacle (negative inside)."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        sd = np.empty((len(pts), len(self.obstacles)))
        for k, i in enumerate(self.circle_ids):
            sd[:, i] = np.hypot(*(pts - self.cc[k]).T) - self.cr[k]
        for k, i in enumerate(self.poly_ids):
            v, d = self.verts[k], self.edges[k]
            rel = pts[:, None, :] - v[None]  # (N, E, 2)
            t = np.clip((rel * d).sum(-1) / (d * d).sum(-1), 0.0, 1.0)
            dist = np.hypot(*(rel - t[..., None] * d).transpose(2, 0, 1)).min(axis=1)
            depth = (pts @ self.normals[k, : len(v)].T - self.offsets[k, : len(v)]).max(axis=1)
            sd[:, i] = np.where(depth < 0.0, depth, dist)
        return sd

    def into_direction(self, obstacle: int, p: Array, tol: float) -> Array:
        """Unit direction (2,) from a boundary point into the obstacle.

        Circle: toward the centre. Polygon: minus the sum of the outward normals of the
        edges through the point (one edge: its inward normal; a vertex: the corner's
        bisector).
        """
        o = self.obstacles[obstacle]
        if isinstance(o, Circle):
            d = np.asarray(o.center_m) - p
        else:
            k = int(np.flatnonzero(self.poly_ids == obstacle)[0])
            v, e = self.verts[k], self.edges[k]
            rel = p - v
            t = np.clip((rel * e).sum(-1) / (e * e).sum(-1), 0.0, 1.0)
            dist = np.hypot(*(rel - t[:, None] * e).T)
            on = dist <= max(tol, 1e-12)
            n = self.normals[k, : len(v)]
            d = -n[on].sum(axis=0) if on.any() else -n[np.argmin(dist)]
        return d / np.linalg.norm(d)


# --------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class ChordArcQuery:
    """Everything the search needs, as plain planar data (world x-y plane, metres).

    Args:
        base_xy_m: (x, y) of the base port.
        base_tangent: direction the robot leaves the port (normalised here).
        total_length_m: the robot's length; a solution's arcs sum to at most this.
        obstacles: circles and convex polygons.
        collision_points_m: points on obstacle boundaries where contact is allowed.
        target_xy_m: the point the tip must reach.
    """

    base_xy_m: Point
    base_tangent: Point
    total_length_m: float
    obstacles: tuple[PlanarObstacle, ...]
    collision_points_m: tuple[Point, ...]
    target_xy_m: Point

    def __post_init__(self) -> None:
        object.__setattr__(self, "base_xy_m", _point(self.base_xy_m, "base_xy_m"))
        t = np.array(_point(self.base_tangent, "base_tangent"))
        if np.linalg.norm(t) < 1e-12:
            raise ChordArcInputError("base_tangent must be a non-zero direction")
        t = t / np.linalg.norm(t)
        object.__setattr__(self, "base_tangent", (float(t[0]), float(t[1])))
        if not (math.isfinite(self.total_length_m) and self.total_length_m > 0):
            raise ChordArcInputError(f"total_length_m must be > 0, got {self.total_length_m}")
        object.__setattr__(self, "total_length_m", float(self.total_length_m))
        for o in self.obstacles:
            if not isinstance(o, Circle | ConvexPolygon):
                raise ChordArcInputError(
                    f"obstacles must be Circle or ConvexPolygon, got {type(o).__name__}"
                )
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        pts = tuple(
            _point(p, f"collision point {i}") for i, p in enumerate(self.collision_points_m)
        )
        object.__setattr__(self, "collision_points_m", pts)
        object.__setattr__(self, "target_xy_m", _point(self.target_xy_m, "target_xy_m"))


#: values of :attr:`ChordArcSettings.choose`


@dataclass(frozen=True)
class Arc:
    """One constant-curvature arc of a solution (world plane)."""

    start_xy_m: Point
    start_tangent: Point
    theta_rad: float
    length_m: float
    end_xy_m: Point
    end_tangent: Point

    @property
    def curvature_per_m(self) -> float:
        """Signed curvature κ = θ/L [1/m] (positive bends clockwise seen from +z)."""
        return self.theta_rad / self.length_m

    def points(self, a: Array) -> Array:
        """Points (..., 2) at arc fractions ``a`` (1 = the end; > 1 extends the circle)."""
        t = np.asarray(self.start_tangent)
        r = np.array([t[1], -t[0]])
        loc = arc_points_local(self.theta_rad, self.length_m, a)
        return np.asarray(self.start_xy_m) + loc[..., :1] * r + loc[..., 1:] * t


@dataclass(frozen=True)
class ChordArcSolution:
    """A final shape: arcs from the port through collision points to the target."""

    contact_indices: tuple[int, ...]
    contact_points_m: tuple[Point, ...]
    arcs: tuple[Arc, ...]
    total_length_m: float
    leftover_m: float

    @property
    def theta_rad(self) -> tuple[float, ...]:
        """Bend angle of each arc [rad]."""
        return tuple(a.theta_rad for a in self.arcs)

    @property
    def shape(self) -> Shape:
        """``((θ_k, L_k), ...)``: feed to ``ContinuumChain.q_from_arcs``."""
        return tuple((a.theta_rad, a.length_m) for a in self.arcs)

"""A loaded continuum problem as the chord-arc search's planar data: the scene cut by the
robot's plane, obstacles grown by the link radius, collision points and guides from the
problem file, and the batched planar capsule distances the contact classification uses."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError
from plannerlab.planners.chord_arc.geometry import (
    ChordArcInputError,
    ChordArcQuery,
    ChordArcSolution,
    Circle,
    ConvexPolygon,
    PlanarObstacle,
)
from plannerlab.planners.chord_arc.search import prepare as prepare_check
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import Array

# --------------------------------------------------------------------------- building


def planar_obstacles(scene: Scene, z_m: float, tol: float = 1e-9) -> tuple[PlanarObstacle, ...]:
    """The scene cut by the plane z = ``z_m``: rectangles and circles (see module doc).

    Raises:
        ChordArcInputError: a box or cylinder that is not upright (its cut is not a
            rectangle or a circle).
    """
    out: list[PlanarObstacle] = []
    for o in scene.obstacles:
        T = o.T_world_obstacle
        c = T[:3, 3]
        dz = abs(float(c[2]) - z_m)
        if isinstance(o, Sphere):
            if dz < o.radius_m:
                out.append(Circle((c[0], c[1]), math.sqrt(o.radius_m**2 - dz**2), o.name))
            continue
        if abs(abs(float(T[2, 2])) - 1.0) > tol:
            raise ChordArcInputError(
                f"obstacle {o.name!r}: only upright boxes and vertical cylinders can be cut "
                f"by the robot's plane (local z = {T[:3, 2].round(6).tolist()})"
            )
        if isinstance(o, Box):
            if dz < o.size_m[2] / 2.0:
                yaw = math.atan2(float(T[1, 0]), float(T[0, 0]))
                out.append(
                    ConvexPolygon.rectangle((c[0], c[1]), (o.size_m[0], o.size_m[1]), yaw, o.name)
                )
        elif isinstance(o, Cylinder):
            if dz < o.length_m / 2.0:
                out.append(Circle((c[0], c[1]), o.radius_m, o.name))
        else:  # pragma: no cover - Scene only holds the three types
            raise ChordArcInputError(f"obstacle {o.name!r}: unknown type {type(o).__name__}")
    return tuple(out)


def _grown_polygon(poly: ConvexPolygon, r: float) -> ConvexPolygon:
    """The polygon grown by ``r``, corners chamfered by the tangent at ``r`` along each
    corner's bisector (it contains the exact, rounded Minkowski sum)."""
    v = np.array(poly.vertices_m)  # counter-clockwise
    d = np.roll(v, -1, axis=0) - v
    n = np.stack([d[:, 1], -d[:, 0]], axis=1) / np.hypot(d[:, 0], d[:, 1])[:, None]
    out = []
    for i in range(len(v)):
        n_in, n_out = n[i - 1], n[i]  # normals of the edges into and out of vertex i
        b = (n_in + n_out) / np.linalg.norm(n_in + n_out)
        for m in (n_in, n_out):
            out.append(v[i] + r * (m + b) / (1.0 + float(m @ b)))
    return ConvexPolygon(tuple(map(tuple, out)), poly.name)


def grow_query(
    query: ChordArcQuery, radius_m: float, boundary_tol_m: float = 1e-6
) -> ChordArcQuery:
    """The query for the axis of a robot of radius ``radius_m`` (configuration space).

    Circles grow by the radius; convex polygons grow by it with chamfered corners
    (:func:`_grown_polygon`); each collision point moves out of its obstacle by the radius,
    against the direction into the obstacle (a corner's bisector, an edge's normal, a
    circle's radius), which puts a corner's point on the middle of its chamfer.
    """
    prep = prepare_check(query, ChordArcSettings(boundary_tol_m=boundary_tol_m))
    obstacles: list[PlanarObstacle] = []
    for o in query.obstacles:
        if isinstance(o, Circle):
            obstacles.append(Circle(o.center_m, o.radius_m + radius_m, o.name))
        else:
            obstacles.append(_grown_polygon(o, radius_m))
    points = tuple(
        tuple((np.asarray(p) - radius_m * prep.into[i]).tolist())
        for i, p in enumerate(query.collision_points_m)
    )
    return ChordArcQuery(
        query.base_xy_m,
        query.base_tangent,
        query.total_length_m,
        tuple(obstacles),
        points,
        query.target_xy_m,
    )


def thickness_cuts(
    query: ChordArcQuery,
    solution: ChordArcSolution,
    radius_m: float,
    near_m: float | None = None,
    step_m: float = 5e-4,
) -> Array:
    """Points (k, 2) of a zero-thickness solution where a robot of radius ``radius_m``
    following it would cut an obstacle: the curve comes closer than the radius to an
    obstacle farther than ``near_m`` (default 2·radius) from the solution's collision
    points (at those points the curve passes through the corner by design).
    """
    near = 2.0 * radius_m if near_m is None else near_m
    geo = prepare_check(query, ChordArcSettings()).geometry
    pts = np.vstack(
        [
            a.points(np.linspace(0.0, 1.0, max(2, math.ceil(a.length_m / step_m))))
            for a in solution.arcs
        ]
    )
    sd = geo.signed_distance(pts).min(axis=1)
    corners = np.asarray(solution.contact_points_m, dtype=float).reshape(-1, 2)
    if len(corners):
        d = np.linalg.norm(pts[:, None, :] - corners[None], axis=-1).min(axis=1)
    else:
        d = np.full(len(pts), math.inf)
    return pts[(sd < radius_m - 1e-9) & (d > near)]


def collision_points(problem: Any) -> tuple[tuple[float, float], ...]:
    """``[continuum] collision_points_m`` of a problem: (x, y) or (x, y, z) each [m].

    Raises:
        ProblemError: the table or key is missing, or a point is not 2 or 3 numbers.
    """
    key = "continuum.collision_points_m"
    table = problem.extras.get("continuum")
    if not isinstance(table, dict) or "collision_points_m" not in table:
        raise ProblemError(
            problem.source,
            key,
            "is missing: the chord_arc planner needs the points where contact "
            "is allowed ([continuum] collision_points_m = [[x, y], ...])",
        )
    raw = table["collision_points_m"]
    pts: list[tuple[float, float]] = []
    if not isinstance(raw, list):
        raise ProblemError(problem.source, key, f"a list of [x, y] points, got {raw!r}")
    for i, p in enumerate(raw):
        ok = (
            isinstance(p, list | tuple)
            and len(p) in (2, 3)
            and all(
                isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                for v in p
            )
        )
        if not ok:
            raise ProblemError(
                problem.source,
                f"{key}[{i}]",
                f"two or three finite numbers (x, y[, z]) [m], got {p!r}",
            )
        pts.append((float(p[0]), float(p[1])))
    return tuple(pts)


def guide_obstacles(problem: Any) -> frozenset[str]:
    """``[continuum] guide_obstacles`` of a problem: obstacles that guide the robot (the
    insertion sleeve), whose contacts are expected. Empty if absent.

    Raises:
        ProblemError: not a list of names of the problem's obstacles.
    """
    key = "continuum.guide_obstacles"
    table = problem.extras.get("continuum")
    raw = table.get("guide_obstacles", []) if isinstance(table, dict) else []
    names = set(problem.scene.names)
    if not isinstance(raw, list) or not all(isinstance(n, str) for n in raw):
        raise ProblemError(problem.source, key, f"a list of obstacle names, got {raw!r}")
    unknown = [n for n in raw if n not in names]
    if unknown:
        raise ProblemError(
            problem.source,
            key,
            f"names of obstacles in this problem ({', '.join(sorted(names))}); "
            f"unknown: {', '.join(unknown)}",
        )
    return frozenset(raw)


def _point_segment_distance(p: Array, a: Array, b: Array) -> Array:
    """Distance (...) from points ``p`` to segments ``a``-``b`` (..., 2), broadcasting."""
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    px, py = p[..., 0] - a[..., 0], p[..., 1] - a[..., 1]
    t = np.clip((px * dx + py * dy) / np.maximum(dx * dx + dy * dy, 1e-300), 0.0, 1.0)
    ex, ey = px - t * dx, py - t * dy
    return np.sqrt(ex * ex + ey * ey)


def _cross(u: Array, v: Array) -> Array:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _segment_polygon_distance(a: Array, b: Array, vertices_m: Array) -> Array:
    """Distance (k,) from segments ``a``-``b`` (k, 2) to a convex polygon (n, 2) CCW."""
    v0 = vertices_m
    v1 = np.roll(v0, -1, axis=0)
    e = v1 - v0
    A, B = a[:, None, :], b[:, None, :]  # (k, 1, 2) against the n edges
    inside_a = np.all(_cross(e, A - v0) > 0.0, axis=-1)
    inside_b = np.all(_cross(e, B - v0) > 0.0, axis=-1)
    o1, o2 = _cross(B - A, v0 - A), _cross(B - A, v1 - A)
    o3, o4 = _cross(e, A - v0), _cross(e, B - v0)
    crosses = np.any((o1 * o2 <= 0.0) & (o3 * o4 <= 0.0), axis=-1)
    d = np.minimum(
        np.minimum(_point_segment_distance(A, v0, v1), _point_segment_distance(B, v0, v1)),
        _point_segment_distance(v0, A, B),
    ).min(axis=-1)
    return np.where(inside_a | inside_b | crosses, 0.0, d)


def capsule_distances(
    seg_m: Array, obstacles: Sequence[PlanarObstacle], reach_m: float = math.inf
) -> Array:
    """Distance from link axes to planar obstacles, for a whole path at once.

    The robot lies in the plane and every obstacle is its cut by that plane (upright boxes
    and vertical cylinders reach across it), so a capsule of radius r touches an obstacle
    exactly when its axis segment comes closer than r to the obstacle's cut.

    Args:
        seg_m: (..., 2, 2) axis segments (start, end) in the plane [m], e.g. (states,
            links, 2, 2).
        obstacles: convex polygons and circles (:func:`planar_obstacles`).
        reach_m: only distances up to this are computed exactly; segments whose bounding
            box stays farther than this from an obstacle's bounding box get ``inf``.

    Returns:
        (..., O) distance from each segment to each obstacle [m]; 0 when the segment
        meets the obstacle.
    """
    flat = np.asarray(seg_m, dtype=float).reshape(-1, 2, 2)
    a, b = flat[:, 0], flat[:, 1]
    out = np.full((len(flat), len(obstacles)), math.inf)
    if not len(obstacles) or not len(flat):
        return out.reshape(np.shape(seg_m)[:-2] + (len(obstacles),))
    o_lo = np.empty((len(obstacles), 2))
    o_hi = np.empty((len(obstacles), 2))
    for o, obs in enumerate(obstacles):
        if isinstance(obs, Circle):
            c = np.asarray(obs.center_m)
            o_lo[o], o_hi[o] = c - obs.radius_m, c + obs.radius_m
        else:
            v = np.asarray(obs.vertices_m)
            o_lo[o], o_hi[o] = v.min(axis=0), v.max(axis=0)
    o_lo -= reach_m
    o_hi += reach_m
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    near_all = (
        (lo[:, None, 0] <= o_hi[None, :, 0])
        & (hi[:, None, 0] >= o_lo[None, :, 0])
        & (lo[:, None, 1] <= o_hi[None, :, 1])
        & (hi[:, None, 1] >= o_lo[None, :, 1])
    )  # (N, O)
    for o in np.flatnonzero(near_all.any(axis=0)).tolist():
        obs = obstacles[o]
        near = np.flatnonzero(near_all[:, o])
        if isinstance(obs, Circle):
            c = np.asarray(obs.center_m)
            d = np.maximum(_point_segment_distance(c, a[near], b[near]) - obs.radius_m, 0.0)
        else:
            d = _segment_polygon_distance(a[near], b[near], np.asarray(obs.vertices_m))
        out[near, o] = d
    return out.reshape(np.shape(seg_m)[:-2] + (len(obstacles),))

"""The paper's chord-arc tree search for a planar continuum robot that wraps obstacles.

Source: ``003_d410ec97f064abf9.txt`` (digest in ``docs/papers.md`` §3). A pure function
over plain data (no planner framework, no fcl/ompl/pybullet): :func:`solve_chord_arc`
takes a :class:`ChordArcQuery` and :class:`ChordArcSettings` and returns a
:class:`ChordArcResult`.

**Model.** The robot is a single constant-curvature section pushed through a base port.
A contact at a user-given collision point splits it into two constant-curvature parts,
so a robot passing through k collision points is a (k + 1)-arc curve whose chords join
base → contacts → target. The robot is a curve of zero thickness (as in the paper).

**Search** (:func:`search_chord_arc`). Breadth-first over "bases" (a point and a tangent;
the first is the port). From every base, chords go to every collision point not yet used
on that branch and to the target; each chord gives the signed bend ``θ = 2·atan2(X, Y)``
and the arc length ``L = |p|·(θ/2)/sin(θ/2)`` (:mod:`plannerlab.robots.continuum.model`); the
arc is sampled every ``arc_step_m`` or finer and dropped if any sample lies deeper than
``inside_tol_m`` inside an obstacle (so an arc may end *on* the boundary at its collision
point, or slide along an edge). Arcs bending more than ``max_bend_rad`` are dropped, and so
are branches whose summed arc length exceeds the robot's length. Survivors ending at a
collision point are the next level's bases; survivors ending at the target are solutions.
The whole level (all bases × all chords) is built and tested as one numpy batch. Every
solution found within the budget (``max_depth`` arcs, ``max_expansions`` bases expanded)
is returned, in breadth-first order (fewest contacts first).

**Total length.** The robot's length is fixed: a solution's arcs must sum to at most
``total_length_m``. The leftover ``total_length_m − Σ L_k`` stays straight behind the
port, not inserted (the chain's insertion joint is ``Σ L_k``); it is never spent on
extending the tip past the target.

**Contact types** (the paper's Fig. 3, our reading). At a contact the obstacle lies on one
side of the robot, ``side = +1`` on the robot's right (the direction positive θ bends
toward), ``-1`` on its left. Changing the commanded curvature of the free part by ``Δκ``
moves a point at arc length s of a base-fixed arc sideways by ``(1 − cos κs)/κ² · Δκ``
toward the right, i.e. always toward the side that Δκ bends to. So the obstacle holds the
part before the contact (which then keeps its shape while only the part after it bends,
the paper's "support") exactly when the curvature change pushes the robot *into* it:

* **forward-constrained**: the obstacle is on the concave (inner) side of the arriving arc
  (``side·κ_in > 0``; a straight arrival counts here). It stops *further bending*: the
  robot wraps around it and the next arc must bend more toward it, ``side·(κ_out − κ_in)
  > 0``. Unbending would lift the robot off: both parts unbend as one section.
* **backward-constrained**: the obstacle is on the convex (outer) side
  (``side·κ_in < 0``). It stops *unbending*: the next arc must bend less (or the other
  way, an S shape), again ``side·(κ_out − κ_in) > 0``. Bending further would lift it off.

The search does not look at types (as in the paper); :func:`check_motion` drops the
solutions whose contacts do not hold, and keeps the reason. The same function also
checks the two motions that do not follow the final shape: the initial push (the arriving
arc extended along its own circle by ``l``, the paper's ``a = 1 + l/L``) and the re-bend
of those ``l`` metres from κ_in to κ_out. "Side" at a polygon vertex uses the direction
into the obstacle that bisects its corner.

**Motion sequence** (:class:`MotionStep`, every step a linear interpolation of the last
arc's (θ, L) from ``start_shape`` to ``end_shape``): follow the first arc (insert and bend
together, ``(aθ_1, aL_1)``, so the robot is always a prefix of the final shape); then per
contact: push by ``l = min(push_length_m, L_next/2)``, re-bend the pushed ``l`` to the next
curvature, follow the next arc (``a·θ`` with the curvature of the final shape) to the next
contact or the target.

**Obstacles** are planar: :class:`Circle` and :class:`ConvexPolygon` (a rectangle with a
yaw is :meth:`ConvexPolygon.rectangle`). :meth:`plannerlab.planners.chord_arc.ChordArcPlanner.query`
projects a loaded problem's boxes (yaw only), vertical cylinders and spheres onto the plane
z = 0.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array
from plannerlab.robots.continuum.model import arc_points_local, sinc, tangent_after

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


class _Geometry:
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
CHOICES: tuple[str, ...] = ("shortest", "fewest_contacts", "first")


@dataclass(frozen=True)
class ChordArcSettings:
    """Settings of the ``chord_arc`` planner: its search, motion check and joint path.

    The search functions of this module read the first group; the planner
    (:mod:`plannerlab.planners.chord_arc`) reads the second.

    Search and motion check:
        max_depth: most arcs in a solution (contacts + 1); 0 = collision points + 1.
        max_expansions: most bases expanded (the port counts as one).
        arc_step_m: largest spacing of the samples along an arc [m].
        inside_tol_m: a sample counts as inside an obstacle only deeper than this [m].
        boundary_tol_m: how far a collision point may lie from a boundary [m].
        max_bend_rad: largest |θ| of one arc [rad].
        push_length_m: initial push l at each contact [m] (capped at half the next arc).
        rebend_steps: intermediate curvatures checked while re-bending the pushed part.
        min_kappa_change_per_m: |κ_out − κ_in| below this carries no load [1/m].
        coarse_factor: a first pass samples arcs this many times more sparsely to drop
            blocked arcs early (1 = off).
        chunk_samples: arc samples per numpy batch (bounds memory).

    Planner:
        inflate_by_radius: plan the robot's axis among obstacles grown by the link
            radius, through collision points moved out of their obstacle by the radius, so
            that the chain's capsules touch the corners instead of cutting them (default);
            False: the paper's zero-thickness curve.
        choose: which surviving solution to execute: "shortest" (least arc length),
            "fewest_contacts" (ties: shorter), "first" (breadth-first order).
        path_step_m: largest change of inserted length and of the last arc's length
            between path waypoints [m].
        path_joint_step_rad: largest change of any bend joint between waypoints [rad].
        check_contacts: check every state of every surviving solution's path for the
            chain's capsules touching obstacles away from its collision points, and drop
            such solutions.
        contact_margin_m: a contact is expected within 2·link radius + this of one of
            the solution's collision points [m].
    """

    max_depth: int = 0
    max_expansions: int = 100_000
    arc_step_m: float = 1e-3
    inside_tol_m: float = 1e-6
    boundary_tol_m: float = 1e-6
    max_bend_rad: float = math.pi
    push_length_m: float = 0.005
    rebend_steps: int = 8
    min_kappa_change_per_m: float = 1e-9
    coarse_factor: int = 8
    chunk_samples: int = 65536
    inflate_by_radius: bool = True
    choose: str = "shortest"
    path_step_m: float = 0.002
    path_joint_step_rad: float = 0.02
    check_contacts: bool = True
    contact_margin_m: float = 0.01

    def __post_init__(self) -> None:
        if self.max_depth < 0:
            raise ChordArcInputError(f"max_depth must be >= 0 (0: no limit), got {self.max_depth}")
        for name in ("max_expansions", "rebend_steps", "coarse_factor", "chunk_samples"):
            if getattr(self, name) < 1:
                raise ChordArcInputError(f"{name} must be >= 1, got {getattr(self, name)}")
        for name in (
            "arc_step_m",
            "max_bend_rad",
            "push_length_m",
            "path_step_m",
            "path_joint_step_rad",
        ):
            if not getattr(self, name) > 0:
                raise ChordArcInputError(f"{name} must be > 0, got {getattr(self, name)}")
        for name in ("inside_tol_m", "boundary_tol_m", "contact_margin_m"):
            if not getattr(self, name) >= 0:
                raise ChordArcInputError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.choose not in CHOICES:
            raise ChordArcInputError(
                f"choose must be one of {', '.join(CHOICES)}, got {self.choose!r}"
            )


@dataclass(frozen=True)
class _Prepared:
    geometry: _Geometry
    points: Array  # (m, 2)
    owner: Array  # (m,) obstacle index of each collision point
    into: Array  # (m, 2) unit direction from each collision point into its obstacle
    target: Array  # (2,)


def prepare(query: ChordArcQuery, settings: ChordArcSettings) -> _Prepared:
    """Validate the query against its obstacles (raises :class:`ChordArcInputError`)."""
    geo = _Geometry(query.obstacles)
    pts = np.array(query.collision_points_m, dtype=float).reshape(-1, 2)
    tol = settings.boundary_tol_m
    owner = np.zeros(len(pts), dtype=int)
    if len(pts):
        if not query.obstacles:
            raise ChordArcInputError(
                f"collision point 0 at {query.collision_points_m[0]} m: there are no obstacles"
            )
        sd = geo.signed_distance(pts)
        owner = np.argmin(np.abs(sd), axis=1)
        off = np.abs(sd[np.arange(len(pts)), owner])
        for i in np.flatnonzero(off > tol):
            raise ChordArcInputError(
                f"collision point {i} at {query.collision_points_m[i]} m is not on an "
                f"obstacle boundary: nearest is {geo.names[owner[i]]!r}, "
                f"{off[i]:.3g} m away (tolerance {tol:g} m)"
            )
        deep = sd < -tol
        for i in np.flatnonzero(deep.any(axis=1)):
            j = int(np.flatnonzero(deep[i])[0])
            raise ChordArcInputError(
                f"collision point {i} at {query.collision_points_m[i]} m lies inside "
                f"obstacle {geo.names[j]!r}"
            )
    target = np.array(query.target_xy_m)
    base = np.array(query.base_xy_m)
    if query.obstacles:
        for what, p in (("target", target), ("base", base)):
            sd = geo.signed_distance(p[None])[0]
            if (sd < -tol).any():
                j = int(np.argmin(sd))
                raise ChordArcInputError(
                    f"{what} {tuple(p.tolist())} m lies inside obstacle {geo.names[j]!r} "
                    f"({-sd[j]:.3g} m deep)"
                )
    into = np.array(
        [geo.into_direction(int(owner[i]), pts[i], tol) for i in range(len(pts))]
    ).reshape(-1, 2)
    return _Prepared(geo, pts, owner, into, target)


# --------------------------------------------------------------------------- results


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


@dataclass(frozen=True)
class ContactCheck:
    """How one contact of a solution behaves.

    Attributes:
        order: 1-based contact number from the port.
        point_index: index into the query's collision points.
        obstacle: name of the obstacle touched.
        side: +1 obstacle on the robot's right (toward positive θ), -1 on its left.
        contact_type: "forward" (obstacle on the concave side, blocks further bending) or
            "backward" (on the convex side, blocks unbending).
        kappa_in_per_m, kappa_out_per_m: curvature of the arcs before and after [1/m].
        ok: the contact holds the robot as its type requires (and push/re-bend are free).
        reason: empty when ok, else why not.
    """

    order: int
    point_index: int
    obstacle: str
    side: int
    contact_type: Literal["forward", "backward"]
    kappa_in_per_m: float
    kappa_out_per_m: float
    ok: bool
    reason: str = ""


@dataclass(frozen=True)
class MotionStep:
    """One motion: the last arc's (θ, L) goes linearly from ``start_shape`` to ``end_shape``.

    ``kind``: "follow" (insert and bend at constant curvature: the tip traces the final
    shape, the paper's ``a·θ``), "push" (extend the last arc along its circle, ``a = 1 +
    l/L``), "rebend" (the pushed part changes curvature at constant length).
    """

    kind: Literal["follow", "push", "rebend"]
    section: int
    description: str
    start_shape: Shape
    end_shape: Shape

    def shape_at(self, a: float) -> Shape:
        """Shape at fraction ``a`` ∈ [0, 1] of the step."""
        (t0, l0), (t1, l1) = self.start_shape[-1], self.end_shape[-1]
        return self.start_shape[:-1] + ((t0 + a * (t1 - t0), l0 + a * (l1 - l0)),)


@dataclass(frozen=True)
class ChordArcPlan:
    """A solution whose contacts all hold, with its motion sequence."""

    solution: ChordArcSolution
    contacts: tuple[ContactCheck, ...]
    motion: tuple[MotionStep, ...]


@dataclass(frozen=True)
class DroppedSolution:
    """A geometric solution the motion check rejected, and why."""

    solution: ChordArcSolution
    contacts: tuple[ContactCheck, ...]
    reason: str


@dataclass(frozen=True)
class SearchResult:
    """Output of :func:`search_chord_arc`: every geometric solution plus counters.

    Attributes:
        solutions: in breadth-first order (fewest contacts first).
        expansions: bases expanded (the port is one).
        arcs_built: chords built (to unused points and the target).
        arcs_checked: arcs sampled against the obstacles.
        arcs_rejected_bend: chords dropped for |θ| > max_bend_rad.
        arcs_rejected_length: chords dropped because the robot is too short.
        arcs_rejected_obstacle: arcs with a sample inside an obstacle.
        depth_reached: most arcs on any branch explored.
        budget_exhausted: True when ``max_expansions`` cut the search short.
    """

    solutions: tuple[ChordArcSolution, ...]
    expansions: int
    arcs_built: int
    arcs_checked: int
    arcs_rejected_bend: int
    arcs_rejected_length: int
    arcs_rejected_obstacle: int
    depth_reached: int
    budget_exhausted: bool


@dataclass(frozen=True)
class ChordArcResult:
    """Search plus motion check: plans that hold, dropped solutions with reasons."""

    search: SearchResult
    plans: tuple[ChordArcPlan, ...]
    dropped: tuple[DroppedSolution, ...] = field(default=())

    @property
    def solutions(self) -> tuple[ChordArcSolution, ...]:
        """The solutions that survived the motion check."""
        return tuple(p.solution for p in self.plans)


# --------------------------------------------------------------------------- search


def _sample_fractions(max_length_m: float, step_m: float) -> Array:
    n = max(2, int(math.ceil(max_length_m / step_m)) + 1)
    return np.linspace(0.0, 1.0, n)


def _arcs_free(
    geo: _Geometry, p0: Array, t0: Array, theta: Array, length: Array, settings: ChordArcSettings
) -> NDArray[np.bool_]:
    """(K,) True where arcs (starting at p0 (K, 2) with tangents t0 (K, 2)) are free.

    Arc k gets ``ceil(L_k / step) + 1`` samples, both ends included; all samples of a
    batch of arcs are one flat array (no padding to the longest arc). A first pass with
    a ``coarse_factor`` times longer step drops most blocked arcs cheaply; the arcs it
    leaves get the full ``arc_step_m`` pass. (A coarse sample inside an obstacle is a
    point of the arc inside it, so the two passes drop exactly what one fine pass would,
    plus arcs whose shallow cut fell between the fine samples.)
    """
    free = np.ones(len(theta), dtype=bool)
    if not geo.obstacles or len(theta) == 0:
        return free
    if settings.coarse_factor > 1:
        free = _sampled_free(
            geo, p0, t0, theta, length, settings.arc_step_m * settings.coarse_factor, settings
        )
    idx = np.flatnonzero(free)
    free[idx] = _sampled_free(
        geo, p0[idx], t0[idx], theta[idx], length[idx], settings.arc_step_m, settings
    )
    return free


def _sampled_free(
    geo: _Geometry,
    p0: Array,
    t0: Array,
    theta: Array,
    length: Array,
    step_m: float,
    settings: ChordArcSettings,
) -> Array:
    k_arcs = len(theta)
    free = np.ones(k_arcs, dtype=bool)
    if k_arcs == 0:
        return free
    counts = np.maximum(2, np.ceil(length / step_m).astype(int) + 1)
    ends = np.cumsum(counts)
    lo = 0
    while lo < k_arcs:  # batches of about ``chunk_samples`` points
        hi = int(np.searchsorted(ends, ends[lo] - counts[lo] + settings.chunk_samples, "right"))
        hi = max(hi, lo + 1)
        c = counts[lo:hi]
        owner = np.repeat(np.arange(hi - lo), c)
        first = np.cumsum(c) - c
        a = (np.arange(int(c.sum())) - first[owner]) / (c[owner] - 1)
        g = owner + lo
        half = a * theta[g] * 0.5
        h = a * length[g] * sinc(half)
        lx, ly = h * np.sin(half), h * np.cos(half)  # in the arc's frame (y = tangent)
        tx, ty = t0[g, 0], t0[g, 1]
        world = np.empty((len(g), 2))
        world[:, 0] = p0[g, 0] + lx * ty + ly * tx  # right = (t_y, -t_x)
        world[:, 1] = p0[g, 1] - lx * tx + ly * ty
        hit = geo.inside_any(world, settings.inside_tol_m)  # (M,)
        free[lo:hi] = np.bincount(owner[hit], minlength=hi - lo) == 0
        lo = hi
    return free


@dataclass(frozen=True)
class _Level:
    parent: Array  # (N,) index into the previous level
    point: Array  # (N,) collision point index of this node (-1 for the port)
    p: Array  # (N, 2)
    t: Array  # (N, 2)
    theta: Array  # (N,) arc that ended here
    length: Array  # (N,)
    used_length: Array  # (N,)
    used: NDArray[np.bool_]  # (N, m)


def _search(query: ChordArcQuery, prep: _Prepared, settings: ChordArcSettings) -> SearchResult:
    m = len(prep.points)
    goals = np.vstack([prep.points, prep.target[None]])  # (m + 1, 2); column m = target
    max_depth = settings.max_depth or m + 1
    total = query.total_length_m
    root = _Level(
        parent=np.array([-1]),
        point=np.array([-1]),
        p=np.array([query.base_xy_m]),
        t=np.array([query.base_tangent]),
        theta=np.zeros(1),
        length=np.zeros(1),
        used_length=np.zeros(1),
        used=np.zeros((1, m), dtype=bool),
    )
    levels = [root]
    found: list[tuple[int, int, float, float]] = []  # (level, node, θ, L) of the last arc
    expansions = built = checked = rej_bend = rej_len = rej_obs = 0
    depth_reached = 0
    exhausted = False
    for depth in range(1, max_depth + 1):
        lev = levels[-1]
        n = len(lev.parent)
        if n == 0:
            break
        take = min(n, settings.max_expansions - expansions)
        if take <= 0:
            exhausted = True
            break
        if take < n:
            exhausted = True
        expansions += take
        depth_reached = depth
        p, t, used_len = lev.p[:take], lev.t[:take], lev.used_length[:take]
        r = np.stack([t[:, 1], -t[:, 0]], axis=1)
        d = goals[None] - p[:, None, :]  # (N, m + 1, 2)
        X = np.einsum("nkj,nj->nk", d, r)
        Y = np.einsum("nkj,nj->nk", d, t)
        theta = 2.0 * np.arctan2(X, Y)
        chord = np.hypot(X, Y)
        usable = np.concatenate([~lev.used[:take], np.ones((take, 1), dtype=bool)], axis=1)
        usable &= chord > 1e-12
        built += int(usable.sum())
        bend_ok = np.abs(theta) <= settings.max_bend_rad
        rej_bend += int((usable & ~bend_ok).sum())
        usable &= bend_ok
        s = sinc(theta / 2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            length = np.where(usable, chord / np.where(usable, s, 1.0), np.inf)
        len_ok = used_len[:, None] + length <= total * (1.0 + 1e-12)
        rej_len += int((usable & ~len_ok).sum())
        usable &= len_ok
        node, goal = np.nonzero(usable)
        th, ln = theta[node, goal], length[node, goal]
        ok = _arcs_free(prep.geometry, p[node], t[node], th, ln, settings)
        checked += len(node)
        rej_obs += int((~ok).sum())
        node, goal, th, ln = node[ok], goal[ok], th[ok], ln[ok]
        at_target = goal == m
        for i, tt, ll in zip(node[at_target], th[at_target], ln[at_target], strict=True):
            found.append((len(levels) - 1, int(i), float(tt), float(ll)))
        if depth == max_depth:
            break
        keep = ~at_target
        node, goal, th, ln = node[keep], goal[keep], th[keep], ln[keep]
        used = lev.used[node].copy()
        used[np.arange(len(node)), goal] = True
        levels.append(
            _Level(
                parent=node,
                point=goal,
                p=goals[goal],
                t=tangent_after(t[node], th),
                theta=th,
                length=ln,
                used_length=used_len[node] + ln,
                used=used,
            )
        )
    solutions = tuple(_rebuild(query, levels, prep, f) for f in found)
    return SearchResult(
        solutions, expansions, built, checked, rej_bend, rej_len, rej_obs, depth_reached, exhausted
    )


def _rebuild(
    query: ChordArcQuery, levels: list[_Level], prep: _Prepared, last: tuple[int, int, float, float]
) -> ChordArcSolution:
    li, node, th_last, l_last = last
    chain: list[tuple[int, int]] = []  # (level, node) from the last base back to the port
    while li > 0:
        chain.append((li, node))
        node = int(levels[li].parent[node])
        li -= 1
    chain.reverse()
    arcs: list[Arc] = []
    p, t = np.array(query.base_xy_m), np.array(query.base_tangent)
    contacts = []
    for li, node in chain:
        lev = levels[li]
        th, ln = float(lev.theta[node]), float(lev.length[node])
        end_p, end_t = lev.p[node], lev.t[node]
        arcs.append(
            Arc(
                tuple(p.tolist()),
                tuple(t.tolist()),
                th,
                ln,
                tuple(end_p.tolist()),
                tuple(end_t.tolist()),
            )
        )
        contacts.append(int(lev.point[node]))
        p, t = end_p, end_t
    end_t = tangent_after(t, th_last)
    arcs.append(
        Arc(
            tuple(p.tolist()),
            tuple(t.tolist()),
            th_last,
            l_last,
            tuple(prep.target.tolist()),
            tuple(np.asarray(end_t).tolist()),
        )
    )
    total = float(sum(a.length_m for a in arcs))
    return ChordArcSolution(
        contact_indices=tuple(contacts),
        contact_points_m=tuple(query.collision_points_m[i] for i in contacts),
        arcs=tuple(arcs),
        total_length_m=total,
        leftover_m=max(0.0, query.total_length_m - total),
    )


def search_chord_arc(
    query: ChordArcQuery, settings: ChordArcSettings = ChordArcSettings()
) -> SearchResult:  # noqa: B008
    """The paper's tree search: every geometric solution within the budget.

    Raises:
        ChordArcInputError: a collision point off every obstacle boundary, a target or
            base inside an obstacle.
    """
    return _search(query, prepare(query, settings), settings)


# --------------------------------------------------------------------------- motion check


def _fmt_pt(p: Point) -> str:
    return f"({p[0]:.4g}, {p[1]:.4g})"


def _check(
    solution: ChordArcSolution, prep: _Prepared, settings: ChordArcSettings
) -> ChordArcPlan | DroppedSolution:
    geo = prep.geometry
    checks: list[ContactCheck] = []
    motion: list[MotionStep] = []
    first = solution.arcs[0]
    motion.append(
        MotionStep(
            "follow",
            0,
            f"insert {first.length_m:.4g} m while bending to θ1 = {first.theta_rad:.4g} rad "
            "(the tip traces arc 1)",
            ((0.0, 0.0),),
            ((first.theta_rad, first.length_m),),
        )
    )
    done: Shape = ((first.theta_rad, first.length_m),)
    failure = ""
    for j, pi in enumerate(solution.contact_indices):
        a_in, a_out = solution.arcs[j], solution.arcs[j + 1]
        k_in, k_out = a_in.curvature_per_m, a_out.curvature_per_m
        obst = int(prep.owner[pi])
        name = geo.names[obst]
        c = np.asarray(a_in.end_xy_m)
        t = np.asarray(a_in.end_tangent)
        r = np.array([t[1], -t[0]])
        side_val = float(prep.into[pi] @ r)
        side = 1 if side_val > 0 else -1
        ctype: Literal["forward", "backward"] = "forward" if side * k_in >= 0 else "backward"
        where = f"contact {j + 1} (point {pi} {_fmt_pt(solution.contact_points_m[j])} on {name!r})"
        reason = ""
        dk = k_out - k_in
        if abs(side_val) < 1e-9:
            reason = f"{where}: the robot meets the obstacle head-on, no side holds it"
        elif side * dk <= settings.min_kappa_change_per_m:
            if abs(dk) <= settings.min_kappa_change_per_m:
                reason = (
                    f"{where}: curvature unchanged ({k_in:.4g} 1/m), the contact carries no load"
                )
            elif ctype == "forward":
                reason = (
                    f"{where} is forward-constrained (obstacle on the concave side: it "
                    f"blocks further bending) but the next arc bends less (κ {k_in:.4g} → "
                    f"{k_out:.4g} 1/m): the section would unbend as one and leave it"
                )
            else:
                reason = (
                    f"{where} is backward-constrained (obstacle on the convex side: it "
                    f"blocks unbending) but the next arc bends further (κ {k_in:.4g} → "
                    f"{k_out:.4g} 1/m): the section would bend as one and leave it"
                )
        push = min(settings.push_length_m, 0.5 * a_out.length_m)
        if not reason:
            a_push = 1.0 + push / a_in.length_m
            ext = a_in.points(
                np.linspace(1.0, a_push, 1 + max(2, math.ceil(push / settings.arc_step_m)))
            )
            if geo.inside_any(ext, settings.inside_tol_m).any():
                reason = (
                    f"{where}: the initial push by {push:.3g} m (a = {a_push:.6g}) "
                    "enters an obstacle"
                )
        if not reason:
            ks = k_in + np.linspace(0.0, 1.0, settings.rebend_steps + 1)[1:] * dk
            th = ks * push
            a = _sample_fractions(push, settings.arc_step_m)
            loc = arc_points_local(th[:, None], push, a[None, :])
            pts = c + loc[..., :1] * r + loc[..., 1:] * t
            if geo.inside_any(pts.reshape(-1, 2), settings.inside_tol_m).any():
                reason = (
                    f"{where}: re-bending the pushed {push:.3g} m from κ {k_in:.4g} to "
                    f"{k_out:.4g} 1/m sweeps into an obstacle"
                )
        checks.append(
            ContactCheck(j + 1, int(pi), name, side, ctype, k_in, k_out, not reason, reason)
        )
        if reason and not failure:
            failure = reason
        if failure:
            continue
        pushed = done[:-1] + (
            (a_in.theta_rad * (1.0 + push / a_in.length_m), a_in.length_m + push),
        )
        motion.append(
            MotionStep(
                "push",
                j,
                f"initial push by {push:.4g} m at contact {j + 1} (a = 1 + l/L = "
                f"{1.0 + push / a_in.length_m:.6g})",
                done,
                pushed,
            )
        )
        start = done + ((k_in * push, push),)
        bent = done + ((k_out * push, push),)
        motion.append(
            MotionStep(
                "rebend",
                j + 1,
                f"{ctype}-constrained contact {j + 1} holds arc {j + 1}; the "
                f"pushed {push:.4g} m re-bends to κ = {k_out:.4g} 1/m",
                start,
                bent,
            )
        )
        done = done + ((a_out.theta_rad, a_out.length_m),)
        motion.append(
            MotionStep(
                "follow",
                j + 1,
                f"insert to {a_out.length_m:.4g} m past contact {j + 1} bending a·θ{j + 2}, "
                f"θ{j + 2} = {a_out.theta_rad:.4g} rad",
                bent,
                done,
            )
        )
    if failure:
        return DroppedSolution(solution, tuple(checks), failure)
    return ChordArcPlan(solution, tuple(checks), tuple(motion))


def check_motion(
    solution: ChordArcSolution,
    query: ChordArcQuery,
    settings: ChordArcSettings = ChordArcSettings(),  # noqa: B008
) -> ChordArcPlan | DroppedSolution:
    """Check a solution's contact types, push and re-bend; build its motion sequence."""
    return _check(solution, prepare(query, settings), settings)


def solve_chord_arc(
    query: ChordArcQuery,
    settings: ChordArcSettings = ChordArcSettings(),  # noqa: B008
) -> ChordArcResult:
    """Search, then check every solution's motion. Deterministic: no randomness.

    Raises:
        ChordArcInputError: see :func:`search_chord_arc`.
    """
    prep = prepare(query, settings)
    search = _search(query, prep, settings)
    plans: list[ChordArcPlan] = []
    dropped: list[DroppedSolution] = []
    for sol in search.solutions:
        out = _check(sol, prep, settings)
        if isinstance(out, ChordArcPlan):
            plans.append(out)
        else:
            dropped.append(out)
    return ChordArcResult(search, tuple(plans), tuple(dropped))


__all__ = [
    "CHOICES",
    "Arc",
    "ChordArcInputError",
    "ChordArcPlan",
    "ChordArcQuery",
    "ChordArcResult",
    "ChordArcSettings",
    "ChordArcSolution",
    "Circle",
    "ContactCheck",
    "ConvexPolygon",
    "DroppedSolution",
    "MotionStep",
    "PlanarObstacle",
    "SearchResult",
    "check_motion",
    "prepare",
    "search_chord_arc",
    "solve_chord_arc",
]

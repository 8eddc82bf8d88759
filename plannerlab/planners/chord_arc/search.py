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

The motion check that follows the search is :mod:`.motion`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from plannerlab.planners.chord_arc.geometry import (
    Arc,
    ChordArcInputError,
    ChordArcQuery,
    ChordArcSolution,
    ObstacleField,
)
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.robots.base import Array
from plannerlab.robots.continuum.model import sinc, tangent_after


@dataclass(frozen=True)
class Prepared:
    geometry: ObstacleField
    points: Array  # (m, 2)
    owner: Array  # (m,) obstacle index of each collision point
    into: Array  # (m, 2) unit direction from each collision point into its obstacle
    target: Array  # (2,)


def prepare(query: ChordArcQuery, settings: ChordArcSettings) -> Prepared:
    """Validate the query against its obstacles (raises :class:`ChordArcInputError`)."""
    geo = ObstacleField(query.obstacles)
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
    return Prepared(geo, pts, owner, into, target)


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


# --------------------------------------------------------------------------- search


def sample_fractions(max_length_m: float, step_m: float) -> Array:
    n = max(2, int(math.ceil(max_length_m / step_m)) + 1)
    return np.linspace(0.0, 1.0, n)


def _arcs_free(
    geo: ObstacleField,
    p0: Array,
    t0: Array,
    theta: Array,
    length: Array,
    settings: ChordArcSettings,
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
    geo: ObstacleField,
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


def search_prepared(
    query: ChordArcQuery, prep: Prepared, settings: ChordArcSettings
) -> SearchResult:
    """:func:`search_chord_arc` on a query already :func:`prepare` d (the motion check
    reuses the same preparation)."""
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
    query: ChordArcQuery, levels: list[_Level], prep: Prepared, last: tuple[int, int, float, float]
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
    query: ChordArcQuery,
    settings: ChordArcSettings = ChordArcSettings(),  # noqa: B008
) -> SearchResult:
    """The paper's tree search: every geometric solution within the budget.

    Raises:
        ChordArcInputError: a collision point off every obstacle boundary, a target or
            base inside an obstacle.
    """
    return search_prepared(query, prepare(query, settings), settings)

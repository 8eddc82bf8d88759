"""A collision mesh covered by capsules (a sphere is a capsule of zero length) within a
budget of primitives, its excess adapted to the budget: the cover always succeeds.

The solid covered is the mesh when it is watertight, else its convex hull (PyBullet, too,
checks a moving link's mesh as its hull); a flat mesh (no hull) is covered as a surface.

1. **Surface points.** The solid's surface is cut into triangles of edges at most ``e``
   (every surface point lies within ``e/√3`` of a corner) and the corners are merged into
   the centres of cubic cells of side ``c`` (every corner within ``c√3/2`` of its cell's
   centre): a point set ``P`` such that every surface point lies within
   ``δ = e/√3 + c√3/2`` of a point of ``P``. ``e = c`` is a third of the wanted excess,
   coarser on a large surface (at most :data:`MAX_POINTS` points).
2. **Depth.** The convex hull's depth is exact (its facets' planes); a watertight mesh's
   is estimated on a voxel grid (``mesh.contains`` at the cells' centres, scipy's
   Euclidean distance transform), only to choose candidates (step 3) and merges (step 4).
3. **Spheres.** Greedy set cover of ``P``: candidate centres are the grid's inner cells
   (depth ``D``) and points of ``P`` (depth 0), each may reach ``D + ε − δ``; the one
   holding most uncovered points is taken, its radius shrunk to its farthest point plus
   ``δ`` (so it holds the surface around its points). Uncovered points become candidates
   themselves, so the cover always completes.
4. **Capsules within the budget.** Two primitives are merged into the capsule along their
   farthest end points with the radius that holds both primitives' points (plus ``δ``);
   the merge with the smallest excess is taken while its excess is within the wanted
   excess or the cover has more primitives than the budget (then the excess grows as far
   as the budget needs, and no further).
5. **The excess, measured.** Per primitive ``r − min depth`` along its axis: the ball of
   radius ``depth(x)`` about an axis point ``x`` is inside the solid, so every point of
   the capsule lies within ``r − depth(x)`` of it. Depths are exact (facet planes for the
   hull, ``trimesh.proximity.signed_distance`` for a mesh) at axis samples ``h`` apart,
   and the depth being 1-Lipschitz, ``min − h/2`` bounds the axis' depth from below: the
   reported ``max_excess_m`` is an upper bound of how far the cover reaches outside the
   solid.
6. **Verified**: every vertex of the mesh and of the solid and a dense seeded sample of
   the surface lie inside the union.

Only the surface is covered for sure: an obstacle wholly inside a link without touching
its surface is not seen (the inner spheres usually fill the inside too).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.robots.base import Array

#: the most surface points a cover is computed on (the cells grow to keep within it)
MAX_POINTS: int = 60_000
#: inner grid cells along the solid's longest side (depth estimate and candidates)
GRID_CELLS: int = 64
#: the most candidate centres of the first greedy round
MAX_CANDIDATES: int = 2_500
#: surface points checked against every cover (besides every vertex)
VERIFY_SAMPLES: int = 20_000
#: the most (candidate, point) pairs a greedy sphere round lists
MAX_COVER_ENTRIES: int = 4_000_000
#: inner and surface candidates of the greedy sphere cover (each)
SPHERE_CANDIDATES: int = 700
#: inner points along the solid's longest side (the pieces are clusters of them)
INNER_CELLS: int = 32
#: the nearest inner points a surface point's owner is chosen from
OWNER_NEIGHBOURS: int = 96
#: meshes with more faces than this are covered as their convex hull (a detailed mesh is
#: never refused)
MAX_DETAIL_FACES: int = 400_000


@dataclass(frozen=True)
class CapsuleCover:
    """Capsules covering a mesh, in the mesh's frame.

    Attributes:
        a_m, b_m: (k, 3) the capsules' axis ends [m] (equal for a sphere).
        radii_m: (k,) [m].
        max_excess_m: an upper bound of how far the cover reaches outside the solid [m].
        target_excess_m: the excess wanted [m] (more when the budget asked for it).
        points_verified: vertices + surface samples checked inside the cover.
        watertight: the solid is the mesh (else its convex hull, or its surface when flat).
        solid: ``"mesh"``, ``"convex hull"`` or ``"surface"`` (what the excess is of).
        cached: read from the disk cache.
    """

    a_m: Array
    b_m: Array
    radii_m: Array
    max_excess_m: float
    target_excess_m: float
    points_verified: int
    watertight: bool
    solid: str
    cached: bool = False

    @property
    def count(self) -> int:
        return len(self.radii_m)

    @property
    def capsules(self) -> int:
        """How many primitives are capsules of non-zero length (the rest are spheres)."""
        return int(np.sum(np.linalg.norm(self.b_m - self.a_m, axis=1) > 0))


# ---------------------------------------------------------------------- the solid
@dataclass(frozen=True)
class _Solid:
    """The solid a cover holds: its surface (V, F), how it was chosen, its hull's facet
    planes (``normals``, ``offsets``: inside where ``offsets − normals·x ≥ 0``) or its
    voxel depth (``grid_lo``, ``pitch``, ``depth``), and the trimesh object."""

    V: Array
    F: np.ndarray
    kind: str
    mesh: Any
    normals: Array | None = None
    offsets: Array | None = None
    grid_lo: Array | None = None
    pitch: float = 0.0
    depth: Array | None = None
    bodies: tuple[Any, ...] = ()

    def depth_estimate(self, x: Array) -> Array:
        """Depth (positive inside) at points (n, 3): exact inside the hull, the voxel
        estimate in a mesh, 0 for a surface."""
        if self.kind == "convex hull":
            assert self.normals is not None and self.offsets is not None
            return np.min(self.offsets[None, :] - x @ self.normals.T, axis=1)
        if self.kind == "surface" or self.depth is None:
            return np.zeros(len(x))
        from scipy.ndimage import map_coordinates

        assert self.grid_lo is not None
        idx = ((x - self.grid_lo) / self.pitch - 0.5).T
        return np.asarray(
            map_coordinates(self.depth, idx, order=1, mode="constant", cval=-self.pitch),
            dtype=float,
        )

    def depth_exact(self, x: Array) -> Array:
        """Signed depth (positive inside) at points (n, 3), exact."""
        if len(x) == 0:
            return np.zeros(0)
        if self.kind == "surface":
            return -_proximity(self.mesh, x, "closest_point")
        if self.kind == "convex hull":
            d = self.depth_estimate(x)  # exact inside a convex solid
            out = d < 0
            if out.any():
                d[out] = _proximity(self.mesh, x[out], "signed_distance")
            return d
        # the union's depth is at least each body's (exact where one body holds x)
        return np.max([_proximity(b, x, "signed_distance") for b in self.bodies], axis=0)


def _proximity(mesh: Any, x: Array, what: str) -> Array:
    """The distance from points x (n, 3) to the mesh's surface (``closest_point``), or
    signed, positive inside (``signed_distance``, trimesh's convention). The distances are
    python-fcl's (a point against the mesh's bounding-volume hierarchy, pruned by the best
    distance found: trimesh's own query gathers every triangle within the nearest
    vertex's distance at once, all of them for a point deep in a finely tessellated body:
    80 000 triangles and a few thousand points took 23 GB and minutes); the sign is
    trimesh's ray test."""
    import fcl

    bvh = fcl.BVHModel()
    bvh.beginModel(len(mesh.vertices), len(mesh.faces))
    bvh.addSubModel(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32))
    bvh.endModel()
    body = fcl.CollisionObject(bvh, fcl.Transform())
    point = fcl.CollisionObject(fcl.Sphere(0.0), fcl.Transform())
    request, out = fcl.DistanceRequest(), np.empty(len(x))
    for i, p in enumerate(np.asarray(x, dtype=float)):
        point.setTranslation(p)
        out[i] = max(fcl.distance(point, body, request, fcl.DistanceResult()), 0.0)
    if what == "signed_distance" and len(x):
        inside = np.asarray(mesh.contains(x), dtype=bool)
        out = np.where(inside, out, -out)
    return out


def _solid(V: Array, F: np.ndarray, as_hull: bool = False) -> _Solid:
    """The mesh if each of its bodies is watertight (the union of the bodies, with its
    voxel depth), else its convex hull, else (flat) its surface; the convex hull (else the
    surface) with ``as_hull``."""
    import trimesh

    mesh = trimesh.Trimesh(V, F, process=True)
    if not as_hull and len(mesh.faces) <= MAX_DETAIL_FACES and mesh.is_watertight:
        bodies = list(mesh.split(only_watertight=False))
        if bodies and all(b.is_watertight and b.is_volume for b in bodies):
            if len(bodies) > 1:  # overlapping shells: their union, by manifold3d
                try:
                    union = trimesh.boolean.union(bodies, engine="manifold")
                    if union.is_watertight and union.is_volume:
                        mesh = union
                        bodies = list(mesh.split(only_watertight=False))
                except Exception:  # keep the bodies: depth bounded by the deepest one
                    pass
            return _voxel_depth(mesh, bodies)
    try:
        hull = mesh.convex_hull
        if hull.volume <= 1e-15:
            raise ValueError("flat")
    except Exception:  # qhull refuses a flat point set
        return _Solid(np.asarray(mesh.vertices), np.asarray(mesh.faces), "surface", mesh)
    eq = np.asarray(hull.face_normals, dtype=float)
    offs = np.einsum("ij,ij->i", eq, np.asarray(hull.triangles_center, dtype=float))
    return _Solid(
        np.asarray(hull.vertices, dtype=float),
        np.asarray(hull.faces, dtype=np.int64),
        "convex hull",
        hull,
        normals=eq,
        offsets=offs,
    )


def _voxel_depth(mesh: Any, bodies: list[Any]) -> _Solid:
    """A mesh of watertight bodies with its depth on a grid of cells: signed distance
    (positive inside their union) from each cell's centre to the nearest cell on the
    other side. (Overlapping shells fool a ray-parity test on the whole mesh: each body
    is tested alone.)"""
    from scipy.ndimage import distance_transform_edt

    lo, hi = mesh.bounds
    pitch = float(np.max(hi - lo)) / GRID_CELLS
    shape = np.maximum(np.ceil((hi - lo) / pitch).astype(int), 1) + 2
    lo = lo - pitch
    axes = [lo[k] + pitch * (np.arange(shape[k]) + 0.5) for k in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    inside = np.zeros(len(centres), dtype=bool)
    for b in bodies:
        inside |= np.asarray(b.contains(centres), dtype=bool)
    inside = inside.reshape(tuple(shape))
    depth = (distance_transform_edt(inside) - distance_transform_edt(~inside)) * pitch
    # a cell centre's true distance to the surface is within a cell of the estimate
    depth = np.where(inside, np.maximum(depth - 0.5 * pitch, 0.0), np.minimum(depth, 0.0))
    return _Solid(
        np.asarray(mesh.vertices, dtype=float),
        np.asarray(mesh.faces, dtype=np.int64),
        "mesh",
        mesh,
        grid_lo=lo,
        pitch=pitch,
        depth=depth,
        bodies=tuple(bodies),
    )


# ---------------------------------------------------------------------- surface points
def _lattice(tri: Array, edge_m: float) -> Array:
    """Points of each triangle (t, 3, 3) on a barycentric lattice fine enough that the
    sub-triangles' edges are at most ``edge_m`` (every point of a triangle is then within
    ``edge_m/√3`` of one)."""
    longest = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)
    steps = np.maximum(np.ceil(longest / edge_m).astype(np.int64), 1)
    out = [tri.reshape(-1, 3)]
    for n in np.unique(steps[steps > 1]):
        T = tri[steps == n]
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        u, v = (i[keep] / n)[None, :, None], (j[keep] / n)[None, :, None]
        pts = (
            T[:, None, 0]
            + u * (T[:, None, 1] - T[:, None, 0])
            + v * (T[:, None, 2] - T[:, None, 0])
        )
        out.append(pts.reshape(-1, 3))
    return np.concatenate(out)


def _surface_points(solid: _Solid, target_m: float) -> tuple[Array, float]:
    """Cell centres of the surface's lattice points and the distance ``δ`` within which
    every surface point has one (step 1)."""
    tri = solid.V[solid.F]
    area = float(
        np.sum(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)) / 2
    )
    cell = max(target_m / 3.0, float(np.sqrt(2.0 * area / MAX_POINTS)), 1e-6)
    for _ in range(30):
        if area / cell**2 < 50 * MAX_POINTS:
            X = _lattice(tri, cell)
            keys = np.floor((X - X.min(axis=0)) / cell).astype(np.int64)
            span = keys.max(axis=0) + 1
            flat = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
            u = np.unique(flat)
            if len(u) <= MAX_POINTS:
                k = np.stack(
                    [u // (span[1] * span[2]), (u // span[2]) % span[1], u % span[2]], axis=1
                )
                delta = cell / np.sqrt(3.0) + cell * np.sqrt(3.0) / 2.0
                return X.min(axis=0) + (k + 0.5) * cell, float(delta)
        cell *= 1.25
    raise AssertionError("unreachable: the cells grow until few")  # pragma: no cover


# ---------------------------------------------------------------------- steps 3, 4
def _seg_dist(p: Array, a: Array, b: Array) -> Array:
    """Distances of points p (..., 3) to segments a–b (..., 3) (broadcast)."""
    ab = b - a
    ll = np.sum(ab * ab, axis=-1)
    t = np.clip(np.sum((p - a) * ab, axis=-1) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def _axis_depth(solid: _Solid, a: Array, b: Array, samples: int = 7) -> Array:
    """A lower estimate of the depth along segments a–b (k, 3)."""
    t = np.linspace(0.0, 1.0, samples)
    x = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
    d = solid.depth_estimate(x.reshape(-1, 3)).reshape(len(a), samples)
    return d.min(axis=1) - np.linalg.norm(b - a, axis=1) / (2 * (samples - 1))


#: how far each axis end is drawn in from the points' extent (fractions of half of it)
_SHRINK = np.array([0.0, 0.25, 0.5, 0.75, 1.0])


@dataclass
class _Piece:
    """A cluster of inner points (``gidx``, indices into G), the surface points they own
    (``idx``, indices into P) and the capsule fitted to them."""

    gidx: np.ndarray
    idx: np.ndarray
    a: Array
    b: Array
    r: float
    excess: float  # estimated
    axis: Array


def _fit(
    solid: _Solid, P: Array, G: Array, gidx: np.ndarray, idx: np.ndarray, delta: float
) -> _Piece:
    """The capsule holding the points ``P[idx]`` (plus ``delta``) with the smallest
    estimated excess: along each principal axis of the inner points ``G[gidx]``, its ends
    drawn in from the points' extent by every pair of :data:`_SHRINK` fractions."""
    X = P[idx]
    Y = G[gidx] if len(gidx) >= 4 else X
    c = Y.mean(axis=0)
    if len(Y) > 1:
        _, vecs = np.linalg.eigh(np.cov((Y - c).T) + 1e-18 * np.eye(3))
    else:
        vecs = np.eye(3)
    best: tuple[float, Array, Array, Array] | None = None
    for u in vecs.T[::-1]:
        t = (X - c) @ u
        rho2 = np.maximum(np.sum((X - c) ** 2, axis=1) - t * t, 0.0)  # to the axis line
        lo, hi = float(t.min()), float(t.max())
        half = (hi - lo) / 2
        s0, s1 = np.meshgrid(_SHRINK * half, _SHRINK * half, indexing="ij")
        ok = (lo + s0) <= (hi - s1) + 1e-15
        ta, tb = (lo + s0)[ok], np.maximum(hi - s1, lo + s0)[ok]
        out = np.maximum(np.maximum(t[None, :] - tb[:, None], ta[:, None] - t[None, :]), 0.0)
        rad = np.sqrt(np.max(rho2[None, :] + out * out, axis=1)) + delta
        A = c + ta[:, None] * u
        B = c + tb[:, None] * u
        exc = rad - _axis_depth(solid, A, B)
        k = int(np.argmin(exc))
        if best is None or exc[k] < best[0]:
            best = (float(exc[k]), A[k], B[k], u)
    assert best is not None
    _, a, b, u = best
    r = float(np.max(_seg_dist(X, a[None], b[None]))) + delta
    excess = r - float(_axis_depth(solid, a[None], b[None])[0])
    return _Piece(gidx, idx, a, b, r, excess, u)


def _split(
    P: Array, G: Array, owner: np.ndarray, piece: _Piece, axis: Array
) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    """Two clusters of a piece's inner points by 2-means from their ends along ``axis``,
    each with the surface points it owns; None when the piece cannot be split so."""
    Y = G[piece.gidx]
    if len(Y) < 2:
        return None
    t = (Y - Y.mean(axis=0)) @ axis
    m = np.stack([Y[int(np.argmin(t))], Y[int(np.argmax(t))]])
    side = np.zeros(len(Y), dtype=bool)
    for _ in range(8):
        side = np.sum((Y - m[1]) ** 2, axis=1) < np.sum((Y - m[0]) ** 2, axis=1)
        if side.all() or not side.any():
            return None
        m = np.stack([Y[~side].mean(axis=0), Y[side].mean(axis=0)])
    g0, g1 = piece.gidx[~side], piece.gidx[side]
    mine = np.zeros(len(G), dtype=np.int8)
    mine[g1] = 1
    own = mine[owner[piece.idx]].astype(bool)
    i0, i1 = piece.idx[~own], piece.idx[own]
    if len(i0) == 0 or len(i1) == 0:
        return None
    return (g0, i0), (g1, i1)


def _inner_points(solid: _Solid, P: Array) -> tuple[Array, Array]:
    """Points of the solid's inside on a grid and their depths (the surface points, depth
    0, when it is flat or too thin for the grid)."""
    if solid.kind == "surface":
        return P, np.zeros(len(P))
    lo, hi = solid.V.min(axis=0), solid.V.max(axis=0)
    step = float(np.max(hi - lo)) / INNER_CELLS
    axes = [
        np.arange(lo[k] + step / 2, hi[k], step)
        if hi[k] - lo[k] > step
        else np.array([(lo[k] + hi[k]) / 2])
        for k in range(3)
    ]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    d = solid.depth_estimate(grid)
    G, D = grid[d > 0], d[d > 0]
    if len(G) < 8:
        return P, np.zeros(len(P))
    if solid.kind == "mesh":  # the voxel estimate is a cell off: exact depths
        D = solid.depth_exact(G)
        G, D = G[D > 0], D[D > 0]
    return (G, D) if len(G) >= 8 else (P, np.zeros(len(P)))


def _offset_points(solid: _Solid, eps: float) -> tuple[Array, Array]:
    """Sphere candidates under the surface: seeded surface samples moved inward along
    their face's normal by 1, 2 and 4 ``eps``, kept where inside, with exact depths (the
    centres that cover rims and flat faces within the allowance)."""
    import trimesh

    if solid.kind == "surface":
        return np.zeros((0, 3)), np.zeros(0)
    pts, face = trimesh.sample.sample_surface(solid.mesh, SPHERE_CANDIDATES, seed=0)
    n = np.asarray(solid.mesh.face_normals)[face]
    X = np.concatenate([pts - k * eps * n for k in (1.0, 2.0, 4.0)])
    D = solid.depth_exact(X)
    return X[D > 0], D[D > 0]


def _owners(P: Array, G: Array, D: Array) -> np.ndarray:
    """Each surface point's inner point: of its nearest ones, the one whose ball of its
    depth comes closest to it (``|p − g| − D(g)`` smallest), so that a cross-section's
    surface goes to the deep points near its axis, not to the points just beneath it."""
    from scipy.spatial import cKDTree

    k = min(len(G), OWNER_NEIGHBOURS)
    dist, idx = cKDTree(G).query(P, k=k)
    dist, idx = dist.reshape(len(P), k), idx.reshape(len(P), k)
    return idx[np.arange(len(P)), np.argmin(dist - D[idx], axis=1)]


def _pieces(solid: _Solid, P: Array, delta: float, eps: float, budget: int) -> list[_Piece]:
    """Top-down: one capsule for the whole surface, then the piece of largest excess
    split in two (its inner points, each half with the surface points nearest to its
    own) while it exceeds ``eps`` and the budget allows (steps 3 and 4)."""
    G, D = _inner_points(solid, P)
    owner = _owners(P, G, D)
    pieces = [_fit(solid, P, G, np.arange(len(G)), np.arange(len(P)), delta)]
    final: list[_Piece] = []
    # a split can make a piece worse before its halves' own splits make it better: the
    # set with the smallest worst excess seen is the answer
    best = (pieces[0].excess, list(pieces))
    while pieces and len(pieces) + len(final) < budget:
        k = int(np.argmax([p.excess for p in pieces]))
        if pieces[k].excess <= eps:
            break
        worst = pieces.pop(k)
        Y = G[worst.gidx]
        axes = np.linalg.eigh(np.cov((Y - Y.mean(axis=0)).T))[1].T if len(Y) > 3 else [worst.axis]
        two: list[_Piece] | None = None
        for u in axes:
            halves = _split(P, G, owner, worst, u)
            if halves is None:
                continue
            fit = [_fit(solid, P, G, g, i, delta) for g, i in halves]
            if two is None or max(p.excess for p in fit) < max(p.excess for p in two):
                two = fit
        if two is None:
            final.append(worst)
        else:
            pieces.extend(two)
        now = pieces + final
        worst_now = max(p.excess for p in now)
        if worst_now < best[0]:
            best = (worst_now, list(now))
    return best[1]


# ---------------------------------------------------------------------- spheres
def _greedy_spheres(
    P: Array, G: Array, D: Array, delta: float, eps: float, budget: int
) -> tuple[Array, Array] | None:
    """A greedy sphere cover of the surface points: candidates the inner points (depth
    ``D``) and surface points (depth 0), each reaching ``D + eps − delta``; the one
    holding most uncovered points taken, its radius shrunk to its farthest point plus
    ``delta``; uncovered points become candidates themselves, so it always completes.
    Centres and radii, or None past ``budget`` spheres."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(0)
    tree = cKDTree(P)
    n_surf = min(len(P), SPHERE_CANDIDATES)
    pick = rng.choice(len(P), size=n_surf, replace=False)
    inner = np.linspace(0, len(G) - 1, min(len(G), 4 * SPHERE_CANDIDATES)).astype(int)
    cand = np.concatenate([G[inner], P[pick]])
    depth = np.concatenate([D[inner], np.zeros(n_surf)])
    uncovered = np.ones(len(P), dtype=bool)
    centres: list[Array] = []
    radii: list[float] = []
    while uncovered.any():
        reach = np.maximum(depth + eps - delta, 1e-12)
        # a large allowance makes every ball hold most points: fewer candidates then, so
        # that the coverage lists stay within MAX_COVER_ENTRIES
        probe = rng.choice(len(cand), size=min(len(cand), 32), replace=False)
        held = tree.query_ball_point(cand[probe], reach[probe], return_length=True)
        keep_n = int(MAX_COVER_ENTRIES / max(float(np.mean(held)), 1.0))
        if keep_n < len(cand):
            pick = rng.choice(len(cand), size=max(keep_n, 16), replace=False)
            cand, depth, reach = cand[pick], depth[pick], reach[pick]
        lists = tree.query_ball_point(cand, reach)
        lengths = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
        rows = np.repeat(np.arange(len(cand)), lengths)
        # flattened in C (one list of ints per candidate; a generator over tens of
        # millions of ints took most of a robot's cover time)
        cols = (
            np.concatenate([np.asarray(x, dtype=np.int64) for x in lists])
            if len(rows)
            else np.zeros(0, dtype=np.int64)
        )
        keep = uncovered[cols]
        cov = csr_matrix(
            (np.ones(int(keep.sum()), dtype=np.int32), (rows[keep], cols[keep])),
            shape=(len(cand), len(P)),
        )
        covT = cov.T.tocsr()
        counts = np.asarray(cov.sum(axis=1)).ravel().astype(np.int64)
        while counts.max(initial=0) > 0:
            if len(centres) >= budget:
                return None
            best = int(np.argmax(counts))
            row = cov.indices[cov.indptr[best] : cov.indptr[best + 1]]
            new = row[uncovered[row]]
            centres.append(cand[best])
            radii.append(float(np.max(np.linalg.norm(P[new] - cand[best], axis=1))) + delta)
            uncovered[new] = False
            np.subtract.at(counts, covT[new].indices, 1)
        left = np.flatnonzero(uncovered)
        take = left if len(left) <= 500 else rng.choice(left, size=500, replace=False)
        cand, depth = P[take], np.zeros(len(take))
    return np.array(centres), np.array(radii)


def _spheres_within(
    P: Array, G: Array, D: Array, delta: float, eps: float, budget: int
) -> tuple[Array, Array, float]:
    """The greedy sphere cover with the smallest allowance (``eps`` grown geometrically,
    then bisected) that needs at most ``budget`` spheres; with that allowance."""
    lo, hi = None, eps
    found = _greedy_spheres(P, G, D, delta, hi, budget)
    while found is None:
        lo, hi = hi, hi * 2.0
        found = _greedy_spheres(P, G, D, delta, hi, budget)
    if lo is not None:
        for _ in range(5):
            mid = float(np.sqrt(lo * hi))
            trial = _greedy_spheres(P, G, D, delta, mid, budget)
            if trial is None:
                lo = mid
            else:
                hi, found = mid, trial
    return found[0], found[1], hi


# ---------------------------------------------------------------------- steps 5, 6
def _measured_excess(solid: _Solid, a: Array, b: Array, r: Array, h: float) -> Array:
    """Per capsule an upper bound of how far it reaches outside the solid (step 5)."""
    out = np.empty(len(r))
    xs, owner, slack = [], [], []
    for k in range(len(r)):
        L = float(np.linalg.norm(b[k] - a[k]))
        n = max(1, int(np.ceil(L / h)) + 1) if L > 0 else 1
        t = np.linspace(0.0, 1.0, n)
        xs.append(a[k] + t[:, None] * (b[k] - a[k]))
        owner.append(np.full(n, k))
        slack.append(L / (2 * (n - 1)) if n > 1 else 0.0)
    d = solid.depth_exact(np.concatenate(xs))
    own = np.concatenate(owner)
    for k in range(len(r)):
        out[k] = max(0.0, float(r[k] - (np.min(d[own == k]) - slack[k])))
    return out


def _verify(V_in: Array, solid: _Solid, a: Array, b: Array, r: Array) -> int:
    """Every vertex and a dense seeded surface sample inside the union (step 6); the
    points checked."""
    rng = np.random.default_rng(0)
    tri = solid.V[solid.F]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    p = area / area.sum() if area.sum() > 0 else None
    pick = rng.choice(len(solid.F), size=VERIFY_SAMPLES, p=p)
    u, v = rng.random(VERIFY_SAMPLES), rng.random(VERIFY_SAMPLES)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = tri[pick]
    samples = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    pts = np.concatenate([V_in, solid.V, samples])
    ok = np.zeros(len(pts), dtype=bool)
    for s in range(0, len(pts), 4000):
        d = _seg_dist(pts[s : s + 4000, None, :], a[None], b[None]) - r[None]
        ok[s : s + 4000] = (d <= 1e-9).any(axis=1)
    if not ok.all():  # pragma: no cover - the construction holds every point
        raise AssertionError(f"{int((~ok).sum())} points outside the cover")
    return len(V_in) + VERIFY_SAMPLES


def capsule_cover(
    V: Array, F: np.ndarray, target_m: float, budget: int, hull: bool = False
) -> CapsuleCover:
    """Capsules covering the mesh (V, F), at most ``budget`` of them, reaching outside
    its solid by about ``target_m`` or more when the budget needs it (module docstring).
    With ``hull`` the solid is the mesh's convex hull (what PyBullet checks for a moving
    link). Always succeeds on a mesh with at least one triangle."""
    solid = _solid(V, F, hull)
    P, delta = _surface_points(solid, target_m)
    eps = max(target_m, 2.0 * delta)
    budget = max(1, int(budget))
    pieces = _pieces(solid, P, delta, eps, budget)
    a = np.array([p.a for p in pieces])
    b = np.array([p.b for p in pieces])
    r = np.array([p.r for p in pieces])
    h = max(eps / 2.0, 1e-4)
    excess = _measured_excess(solid, a, b, r, h)
    # spheres (zero-length capsules) by greedy set cover, where they do better: thin
    # plates and compact parts
    G, D = _inner_points(solid, P)
    X, DX = _offset_points(solid, eps)
    c, rs, _ = _spheres_within(
        P, np.concatenate([G, X]), np.concatenate([D, DX]), delta, eps, budget
    )
    sphere_excess = _measured_excess(solid, c, c, rs, h)
    if sphere_excess.max() < excess.max():
        a, b, r, excess = c, c.copy(), rs, sphere_excess
    verified = _verify(V, solid, a, b, r)
    return CapsuleCover(
        a,
        b,
        r,
        float(excess.max()),
        float(eps),
        verified,
        solid.kind == "mesh",
        solid.kind,
    )


__all__ = ["CapsuleCover", "capsule_cover"]

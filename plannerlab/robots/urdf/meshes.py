"""Mesh files: found, read, and covered by spheres (robot links) or boxes (obstacles).

Reading is ``trimesh``'s (STL, OBJ, PLY, DAE through ``pycollada``); this module turns
what can go wrong into a :class:`MeshError` that names the file, the place it was named
(a URDF link, an obstacle) and what to do.

Paths (:func:`resolve_mesh`): ``package://pkg/rest`` is looked for as ``base/pkg/rest``
and ``base/rest`` under each search folder given (the ``[robot] mesh_paths``), then the
URDF's folder and its three parents (PyBullet's data and most description packages keep
their meshes there); ``file://`` and plain paths are absolute or relative to the URDF.

Sphere covers (:func:`sphere_cover`), for the capsule model of a robot link:

1. the surface is cut into triangles whose edges are at most ``excess_m``;
2. candidate centres: the points of a grid inside the mesh, each with its depth ``D``
   (exact distance to the surface, ``trimesh.proximity``), and every small triangle's
   centroid (depth 0); a candidate may grow to radius ``D + excess_m``;
3. greedy set cover of the *triangles* (a ball holding a triangle's three corners holds
   the whole triangle, balls being convex): the candidate covering most uncovered
   triangles is taken, its radius then shrunk to the farthest corner it must hold;
4. a sphere of radius ``r`` centred at depth ``D`` lies within ``r - D`` of the solid
   (the ball of radius ``D`` about its centre is inside), so the cover's outward excess
   is at most ``max(r - D)`` (reported, ``<= excess_m`` by construction);
5. verified: every vertex and a dense surface sample (seeded) inside the union.

The surface is covered exactly; the solid's inside is covered where the interior
spheres reach (an obstacle wholly inside a link without touching its surface is not
seen). A mesh that is not watertight has no inside: its convex hull is covered instead
(depths measured to it; PyBullet, too, checks a moving link's mesh as its convex hull),
and the report says so. More than ``max_spheres`` spheres, or a surface
needing more than :data:`MAX_COVER_TRIANGLES` small triangles, is refused
(:class:`MeshError`: raise ``cover_excess_m`` or ``cover_max_spheres``, or simplify).

Covers are cached on disk (``~/.cache/plannerlab/covers``, or ``$XDG_CACHE_HOME``) by a
hash of the file's bytes, the scale, the parameters and :data:`COVER_VERSION`, written
atomically (a temporary file renamed).

Box covers (:func:`box_cover`), for mesh obstacles: the surface is cut into triangles of
edges at most half the voxel pitch, every corner marks its voxel, closed shells are
filled (``scipy.ndimage.binary_fill_holes``), the filled voxels are merged greedily into
boxes, and each box is grown by half a pitch (every surface point lies within half a
pitch of a marked corner): the boxes hold the whole surface and the filled inside. The
pitch grows by a quarter until at most ``max_boxes`` boxes remain.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array

#: files larger than this are refused before reading [bytes]
MAX_MESH_BYTES: int = 200_000_000
#: meshes with more faces than this are refused
MAX_MESH_FACES: int = 2_000_000
#: the most small triangles a sphere cover may cut a surface into
MAX_COVER_TRIANGLES: int = 60_000
#: bump when the cover algorithm changes (part of the cache key)
COVER_VERSION: int = 2
#: surface points checked against every cover (besides every vertex)
VERIFY_SAMPLES: int = 20_000


class MeshError(PlannerlabError):
    """A mesh that cannot be found, read or covered: ``file``, ``where`` it was named
    (``link panda_link3 of panda.urdf``, ``obstacle shelf``) and what to do."""

    def __init__(self, file: str, where: str, problem: str, todo: str) -> None:
        self.file = file
        self.where = where
        self.problem = problem
        self.todo = todo
        super().__init__(f"mesh {file} ({where}): {problem}; {todo}")


# ---------------------------------------------------------------------- paths
def resolve_mesh(
    filename: str, urdf_path: Path, search_paths: tuple[Path, ...], where: str
) -> Path:
    """The file a URDF ``<mesh filename=...>`` names (see the module docstring).

    Raises:
        MeshError: no such file.
    """
    folder = Path(urdf_path).resolve().parent
    if filename.startswith("package://"):
        rest = filename[len("package://") :]
        pkg, _, sub = rest.partition("/")
        bases = [Path(p) for p in search_paths] + [folder, *list(folder.parents)[:3]]
        tried: list[Path] = []
        for b in bases:
            for cand in (b / rest, b / sub) if sub else (b / rest,):
                if cand.is_file():
                    return cand.resolve()
                tried.append(cand)
        raise MeshError(
            filename,
            where,
            f"package {pkg!r} not found under {', '.join(str(b) for b in bases)}",
            f"add the folder that holds package {pkg!r} (or its meshes) to [robot] mesh_paths",
        )
    path = Path(filename[len("file://") :] if filename.startswith("file://") else filename)
    if not path.is_absolute():
        path = folder / path
    if not path.is_file():
        raise MeshError(
            filename,
            where,
            f"{path} does not exist",
            "fix the path in the URDF (relative paths are read from the URDF's folder)",
        )
    return path.resolve()


# ---------------------------------------------------------------------- reading
def load_mesh(path: Path, scale: Array, where: str) -> tuple[Array, np.ndarray]:
    """Vertices (n, 3) [m, in the mesh's frame, scaled] and triangles (m, 3) of a file.

    Raises:
        MeshError: the file is missing, too large, unreadable or holds no triangle.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise MeshError(str(path), where, "the file does not exist", "fix the path")
    size = path.stat().st_size
    if size > MAX_MESH_BYTES:
        raise MeshError(
            str(path),
            where,
            f"{size / 1e6:.0f} MB, more than plannerlab reads ({MAX_MESH_BYTES / 1e6:.0f} MB)",
            "simplify the mesh (a collision mesh needs a few thousand triangles)",
        )
    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh and its loaders raise many kinds
        raise MeshError(
            str(path),
            where,
            f"unreadable ({type(exc).__name__}: {exc})"[:300],
            "give an STL, OBJ, PLY or DAE file trimesh can read",
        ) from None
    V = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=float).reshape(-1, 3)
    F = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
    if len(F) == 0 or len(V) < 3:
        raise MeshError(
            str(path), where, "no triangles in it", "give a mesh with a surface (or remove it)"
        )
    if len(F) > MAX_MESH_FACES:
        raise MeshError(
            str(path),
            where,
            f"{len(F)} triangles, more than {MAX_MESH_FACES}",
            "simplify the mesh (a collision mesh needs a few thousand triangles)",
        )
    if not np.all(np.isfinite(V)) or F.min() < 0 or F.max() >= len(V):
        raise MeshError(str(path), where, "invalid vertices or faces", "repair the mesh")
    s = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
    if not (np.all(np.isfinite(s)) and np.all(s != 0)):
        raise MeshError(str(path), where, f"scale {s.tolist()}", "give a finite non-zero scale")
    if np.prod(s) < 0:  # a mirroring scale turns the triangles inside out
        F = F[:, ::-1]
    return V * s, F


def file_digest(path: Path) -> str:
    """sha256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/plannerlab/covers``, else ``~/.cache/plannerlab/covers``."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "plannerlab" / "covers"


# ---------------------------------------------------------------------- sphere covers
@dataclass(frozen=True)
class SphereCover:
    """Spheres covering a mesh, in the mesh's frame.

    Attributes:
        centres_m: (s, 3) [m].
        radii_m: (s,) [m].
        max_excess_m: the largest distance a point of the cover can lie outside the
            mesh's solid [m] (an upper bound, see the module docstring).
        points_verified: vertices + surface samples checked inside the cover.
        watertight: the depths were measured to the mesh (else to its convex hull).
        cached: read from the disk cache.
    """

    centres_m: Array
    radii_m: Array
    max_excess_m: float
    points_verified: int
    watertight: bool
    cached: bool = False


def _small_triangles(V: Array, F: np.ndarray, edge_m: float, where: str, file: str) -> Array:
    """The surface as triangles (t, 3, 3) with edges <= edge_m."""
    import trimesh

    tri = V[F]
    area = float(
        np.sum(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)) / 2
    )
    # a triangle of edges <= e has area <= e^2 sqrt(3)/4; subdivision reaches about a third
    estimate = len(F) + area / (0.1 * edge_m**2)
    if estimate > MAX_COVER_TRIANGLES:
        raise MeshError(
            file,
            where,
            f"too large to cover within the limits: about {estimate:.0f} triangles of "
            f"{edge_m * 1e3:.3g} mm (at most {MAX_COVER_TRIANGLES})",
            "raise cover_excess_m in [robot], or scale/simplify the mesh",
        )
    Vs, Fs = trimesh.remesh.subdivide_to_size(V, F, max_edge=edge_m, max_iter=30)
    if len(Fs) > 2 * MAX_COVER_TRIANGLES:
        raise MeshError(
            file,
            where,
            f"too large to cover within the limits: {len(Fs)} triangles of {edge_m * 1e3:.3g} mm",
            "raise cover_excess_m in [robot], or scale/simplify the mesh",
        )
    return np.asarray(Vs, dtype=float)[np.asarray(Fs)]


def _depths(V: Array, F: np.ndarray, pts: Array) -> tuple[Array, bool]:
    """Signed depth (positive inside) of points against the mesh when it is watertight,
    else against its convex hull; and whether it was the mesh."""
    import trimesh

    mesh = trimesh.Trimesh(V, F, process=True)
    watertight = bool(mesh.is_watertight and mesh.is_volume)
    if not watertight:
        mesh = mesh.convex_hull
    if len(pts) == 0:
        return np.zeros(0), watertight
    d = np.asarray(trimesh.proximity.signed_distance(mesh, pts), dtype=float)
    return d, watertight


def _compute_sphere_cover(
    V: Array, F: np.ndarray, excess_m: float, max_spheres: int, where: str, file: str
) -> SphereCover:
    import trimesh

    mesh = trimesh.Trimesh(V, F, process=True)
    V_in = V
    if not (mesh.is_watertight and mesh.is_volume):
        # no inside: the convex hull is the solid (as PyBullet sees a moving mesh)
        hull = mesh.convex_hull
        V, F = np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64)
    tris = _small_triangles(V, F, excess_m, where, file)
    corners = tris.reshape(-1, 3)
    lo, hi = V.min(axis=0), V.max(axis=0)
    ext = hi - lo
    step = max(float(ext.max()) / 16.0, excess_m / 2.0)
    axes = [
        np.arange(lo[k] + step / 2, hi[k], step)
        if ext[k] > step
        else np.array([(lo[k] + hi[k]) / 2])
        for k in range(3)
    ]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    depth, watertight = _depths(V, F, grid)
    inner = depth > 1e-6
    centroids = tris.mean(axis=1)
    nT = len(tris)
    rng = np.random.default_rng(0)
    uncovered = np.ones(nT, dtype=bool)
    centres: list[Array] = []
    radii: list[float] = []
    excess: list[float] = []
    # round 0: the inner grid and a sample of centroids; later rounds: the centroids of
    # what is left (each covers at least its own triangle: the cover always completes)
    sample = rng.choice(nT, size=min(nT, 1500), replace=False)
    cand: Array | None = np.concatenate([grid[inner], centroids[sample]])
    D = np.concatenate([depth[inner], np.zeros(len(sample))])
    while uncovered.any():
        left = np.flatnonzero(uncovered)
        if cand is None:
            pick = left if len(left) <= 1500 else rng.choice(left, size=1500, replace=False)
            cand, D = centroids[pick], np.zeros(len(pick))
        sub = tris[left]
        R = D + excess_m
        cov = np.zeros((len(cand), len(left)), dtype=bool)
        chunk = max(1, 4_000_000 // max(len(left), 1))
        for s in range(0, len(cand), chunk):
            c = cand[s : s + chunk]
            far = np.zeros((len(c), len(left)))
            for k in range(3):
                far = np.maximum(far, np.linalg.norm(sub[None, :, k, :] - c[:, None, :], axis=-1))
            cov[s : s + chunk] = far <= R[s : s + chunk, None]
        open_ = np.ones(len(left), dtype=bool)
        counts = cov.sum(axis=1).astype(np.int64)
        while open_.any() and counts.max(initial=0) > 0:
            if len(centres) >= max_spheres:
                raise MeshError(
                    file,
                    where,
                    f"too large to cover within the limits: {max_spheres} spheres leave "
                    f"{int(uncovered.sum())} of {nT} surface pieces uncovered at "
                    f"{excess_m * 1e3:.3g} mm excess",
                    "raise cover_max_spheres or cover_excess_m in [robot]",
                )
            best = int(np.argmax(counts))
            new = cov[best] & open_
            held = sub[new].reshape(-1, 3)
            r = float(np.max(np.linalg.norm(held - cand[best], axis=1)))
            centres.append(cand[best])
            radii.append(r)
            excess.append(max(0.0, r - float(D[best])))
            open_ &= ~new
            uncovered[left[new]] = False
            counts -= cov[:, new].sum(axis=1)
        cand = None
    C, Rr = np.array(centres), np.array(radii)
    # verification: every vertex and a dense seeded surface sample inside the union
    rng = np.random.default_rng(0)
    tri = V[F]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    pick = rng.choice(len(F), size=VERIFY_SAMPLES, p=area / area.sum() if area.sum() > 0 else None)
    u, v = rng.random(VERIFY_SAMPLES), rng.random(VERIFY_SAMPLES)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = tri[pick]
    samples = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    pts = np.concatenate([V_in, V, corners, samples])
    inside = np.zeros(len(pts), dtype=bool)
    for s in range(0, len(pts), 20_000):
        d = np.linalg.norm(pts[s : s + 20_000, None, :] - C[None], axis=-1) - Rr[None]
        inside[s : s + 20_000] = (d <= 1e-9).any(axis=1)
    if not inside.all():  # pragma: no cover - the construction covers every corner
        raise MeshError(file, where, "its sphere cover failed verification", "report this")
    return SphereCover(C, Rr, float(max(excess)), len(V_in) + VERIFY_SAMPLES, watertight)


def sphere_cover(
    path: Path,
    scale: Array,
    excess_m: float,
    max_spheres: int,
    where: str,
    cache_dir: Path | None,
    shipped_dirs: tuple[Path, ...] = (),
) -> SphereCover:
    """The sphere cover of a mesh file (scaled), from the disk cache when there.

    Args:
        cache_dir: the cache folder (:func:`default_cache_dir`), or None: no cache.
        shipped_dirs: read-only folders of covers shipped with a robot (the ``covers/``
            folder beside its URDF: the same file names as the cache's), looked in after
            the cache (only when caching is on); a cover computed here is written to the
            cache only.

    Raises:
        MeshError: the file cannot be read, or cannot be covered within the limits.
    """
    if not (excess_m > 0 and np.isfinite(excess_m)):
        raise MeshError(str(path), where, f"cover_excess_m {excess_m}", "give a positive length")
    if max_spheres < 1:
        raise MeshError(str(path), where, f"cover_max_spheres {max_spheres}", "give at least 1")
    s = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
    key = None
    if cache_dir is not None and Path(path).is_file():
        h = hashlib.sha256()
        h.update(file_digest(Path(path)).encode())
        h.update(np.asarray([*s, excess_m, max_spheres, COVER_VERSION], dtype=float).tobytes())
        key = Path(cache_dir) / f"{h.hexdigest()[:32]}.npz"
        for found in (key, *(Path(d) / key.name for d in shipped_dirs)):
            if not found.is_file():
                continue
            try:
                with np.load(found) as z:
                    return SphereCover(
                        np.array(z["centres"]),
                        np.array(z["radii"]),
                        float(z["excess"]),
                        int(z["verified"]),
                        bool(z["watertight"]),
                        cached=True,
                    )
            except Exception:  # a damaged cache entry: compute again
                pass
    V, F = load_mesh(Path(path), s, where)
    cover = _compute_sphere_cover(V, F, float(excess_m), int(max_spheres), where, str(path))
    if key is not None:
        _atomic_savez(
            key,
            centres=cover.centres_m,
            radii=cover.radii_m,
            excess=np.float64(cover.max_excess_m),
            verified=np.int64(cover.points_verified),
            watertight=np.bool_(cover.watertight),
        )
    return cover


def _atomic_savez(path: Path, **arrays: Any) -> None:
    """np.savez to a temporary file in the same folder, then renamed (readers never see
    half a file); an unwritable cache is skipped."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".cover_", suffix=".npz")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, **arrays)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return


@dataclass(frozen=True)
class MeshCover:
    """How one ``<collision>`` mesh of a URDF link became spheres: the link, the file,
    the number of spheres, the largest outward excess of the cover [m] (an upper bound),
    the points verified inside it, whether depths were measured to the mesh (watertight)
    or its convex hull, and whether it came from the disk cache."""

    link: str
    file: str
    spheres: int
    max_excess_m: float
    points_verified: int
    watertight: bool
    cached: bool


@dataclass(frozen=True)
class CoverSettings:
    """Mesh handling of a URDF: folders searched for ``package://`` paths, the largest
    outward excess of a link's sphere cover [m], the most spheres per mesh, and the
    cover cache folder (None: no cache)."""

    mesh_paths: tuple[Path, ...] = ()
    excess_m: float = 0.01
    max_spheres: int = 256
    cache_dir: Path | None = None
    #: read-only folders of shipped covers (``covers/`` beside the URDF), after the cache
    shipped_dirs: tuple[Path, ...] = ()


# ---------------------------------------------------------------------- box covers
@dataclass(frozen=True)
class BoxCover:
    """Boxes (axis-aligned in the mesh's frame) covering a mesh: centres (b, 3) and half
    sizes (b, 3) [m], the voxel pitch [m] and a bound of how far the boxes reach outside
    the mesh (1.5 sqrt 3 pitch: a voxel diagonal plus the half-pitch growth, whose
    corner is half a diagonal out)."""

    centres_m: Array
    half_m: Array
    pitch_m: float
    max_excess_m: float


def _merge_boxes(occ: np.ndarray) -> list[tuple[tuple[int, int, int], tuple[int, int, int]]]:
    """Greedy merge of filled voxels into boxes: (lower index, upper index exclusive)."""
    todo = occ.copy()
    out = []
    nx, ny, nz = occ.shape
    for i, j, k in zip(*np.nonzero(occ), strict=True):
        if not todo[i, j, k]:
            continue
        i1 = i + 1
        while i1 < nx and todo[i1, j, k]:
            i1 += 1
        j1 = j + 1
        while j1 < ny and todo[i:i1, j1, k].all():
            j1 += 1
        k1 = k + 1
        while k1 < nz and todo[i:i1, j:j1, k1].all():
            k1 += 1
        todo[i:i1, j:j1, k:k1] = False
        out.append(((int(i), int(j), int(k)), (int(i1), int(j1), int(k1))))
    return out


def box_cover(V: Array, F: np.ndarray, max_boxes: int, where: str, file: str) -> BoxCover:
    """Boxes covering the mesh's surface and filled inside (module docstring).

    Raises:
        MeshError: no pitch gives at most ``max_boxes`` boxes.
    """
    import trimesh
    from scipy.ndimage import binary_fill_holes

    lo, hi = V.min(axis=0), V.max(axis=0)
    ext = float((hi - lo).max())
    pitch = max(ext / 48.0, 1e-4)
    tri_area = V[F]
    area = float(
        np.sum(
            np.linalg.norm(
                np.cross(tri_area[:, 1] - tri_area[:, 0], tri_area[:, 2] - tri_area[:, 0]), axis=1
            )
        )
        / 2
    )
    while len(F) + area / (0.1 * (pitch / 2) ** 2) > 4 * MAX_COVER_TRIANGLES:
        pitch *= 2.0
    for _ in range(40):
        Vs, Fs = trimesh.remesh.subdivide_to_size(V, F, max_edge=pitch / 2.0, max_iter=30)
        idx = np.floor((np.asarray(Vs) - lo) / pitch).astype(np.int64)
        shape = tuple(int(n) for n in idx.max(axis=0) + 1)
        occ = np.zeros(shape, dtype=bool)
        occ[idx[:, 0], idx[:, 1], idx[:, 2]] = True
        occ = binary_fill_holes(occ)
        boxes = _merge_boxes(occ)
        if len(boxes) <= max_boxes:
            a = np.array([b[0] for b in boxes], dtype=float)
            b = np.array([b[1] for b in boxes], dtype=float)
            low = lo + a * pitch - pitch / 2.0
            high = lo + b * pitch + pitch / 2.0
            return BoxCover((low + high) / 2.0, (high - low) / 2.0, pitch, 1.5 * 3**0.5 * pitch)
        pitch *= 1.25
    raise MeshError(  # pragma: no cover - a pitch of the whole extent gives one box
        file, where, f"no cover in {max_boxes} boxes", "raise the box limit"
    )


__all__ = [
    "BoxCover",
    "CoverSettings",
    "MeshCover",
    "MeshError",
    "SphereCover",
    "box_cover",
    "default_cache_dir",
    "load_mesh",
    "resolve_mesh",
    "sphere_cover",
]

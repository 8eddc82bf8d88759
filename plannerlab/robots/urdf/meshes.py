"""Mesh files: found, read, and covered by capsules (robot links) or boxes (obstacles).

Reading is ``trimesh``'s (STL, OBJ, PLY, DAE through ``pycollada``); this module turns
what can go wrong into a :class:`MeshError` that names the file, the place it was named
(a URDF link, an obstacle) and what to do.

Paths (:func:`resolve_mesh`): ``package://pkg/rest`` is looked for as ``base/pkg/rest``
and ``base/rest`` under each search folder given (the ``[robot] mesh_paths``), then the
URDF's folder and its three parents (PyBullet's data and most description packages keep
their meshes there); ``file://`` and plain paths are absolute or relative to the URDF.

Link covers (:func:`mesh_cover`): capsules (:mod:`plannerlab.robots.urdf.approx`), at
most ``max_primitives`` per mesh, aiming at an excess of :func:`cover_target_m` and
coarser when the budget needs it; the cover always succeeds (a detailed mesh is never
refused: only a file that cannot be read, or holds no triangle, or is larger than
:data:`MAX_MESH_BYTES`, the memory guard) and reports its measured excess.

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
from plannerlab.robots.urdf.approx import CapsuleCover, capsule_cover

#: files larger than this are refused before reading [bytes]
MAX_MESH_BYTES: int = 200_000_000
#: meshes with more faces than this are refused
MAX_MESH_FACES: int = 5_000_000
#: the most small triangles a box cover cuts a surface into (a quarter of its limit)
MAX_COVER_TRIANGLES: int = 60_000
#: bump when the cover algorithm changes (part of the cache key)
COVER_VERSION: int = 5


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


# ---------------------------------------------------------------------- link covers
def cover_target_m(V: Array, excess_m: float) -> float:
    """The excess aimed at for a mesh: ``excess_m``, but at most 3 % of the mesh's
    bounding-box diagonal (a hobby arm's 3 cm link is not covered to 1 cm), and at
    least 1 mm."""
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    return float(min(excess_m, max(0.03 * diag, 1e-3)))


def mesh_cover(
    path: Path,
    scale: Array,
    excess_m: float,
    max_primitives: int,
    where: str,
    cache_dir: Path | None,
    shipped_dirs: tuple[Path, ...] = (),
    hull: bool = False,
) -> CapsuleCover:
    """The capsule cover of a mesh file (scaled), at most ``max_primitives`` capsules,
    aiming at :func:`cover_target_m` (coarser when the budget asks for it; see
    :mod:`plannerlab.robots.urdf.approx`), from the disk cache when there.

    Args:
        cache_dir: the cache folder (:func:`default_cache_dir`), or None: no cache.
        hull: cover the mesh's convex hull (what PyBullet checks for a moving link),
            not the mesh.
        shipped_dirs: read-only folders of covers shipped with a robot (the ``covers/``
            folder beside its URDF: the same file names as the cache's), looked in after
            the cache (only when caching is on); a cover computed here is written to the
            cache only.

    Raises:
        MeshError: the file cannot be read (a detailed mesh is never refused).
    """
    if not (excess_m > 0 and np.isfinite(excess_m)):
        raise MeshError(str(path), where, f"cover_excess_m {excess_m}", "give a positive length")
    if max_primitives < 1:
        raise MeshError(
            str(path), where, f"cover_max_primitives {max_primitives}", "give at least 1"
        )
    s = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
    key = None
    if cache_dir is not None and Path(path).is_file():
        h = hashlib.sha256()
        h.update(file_digest(Path(path)).encode())
        h.update(np.asarray([*s, excess_m, max_primitives, COVER_VERSION], dtype=float).tobytes())
        if hull:  # (the first covers' keys are unchanged)
            h.update(b"hull")
        key = Path(cache_dir) / f"{h.hexdigest()[:32]}.npz"
        for found in (key, *(Path(d) / key.name for d in shipped_dirs)):
            if not found.is_file():
                continue
            try:
                with np.load(found) as z:
                    return CapsuleCover(
                        np.array(z["a"]),
                        np.array(z["b"]),
                        np.array(z["radii"]),
                        float(z["excess"]),
                        float(z["target"]),
                        int(z["verified"]),
                        bool(z["watertight"]),
                        str(z["solid"]),
                        cached=True,
                    )
            except Exception:  # a damaged cache entry: compute again
                pass
    V, F = load_mesh(Path(path), s, where)
    cover = capsule_cover(V, F, cover_target_m(V, float(excess_m)), int(max_primitives), hull)
    if key is not None:
        _atomic_savez(
            key,
            a=cover.a_m,
            b=cover.b_m,
            radii=cover.radii_m,
            excess=np.float64(cover.max_excess_m),
            target=np.float64(cover.target_excess_m),
            verified=np.int64(cover.points_verified),
            watertight=np.bool_(cover.watertight),
            solid=np.str_(cover.solid),
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
    """How one ``<collision>`` mesh of a URDF link became capsules: the link, the file,
    the number of primitives and how many of them are capsules of non-zero length (the
    rest spheres), the largest outward excess of the cover [m] (an upper bound) and the
    excess aimed at, the points verified inside it, what the excess is measured from
    (``solid``: the mesh, its convex hull when it is not watertight, or its surface when
    flat), and whether it came from the disk cache."""

    link: str
    file: str
    primitives: int
    capsules: int
    max_excess_m: float
    target_excess_m: float
    points_verified: int
    solid: str
    cached: bool


@dataclass(frozen=True)
class CoverSettings:
    """Mesh handling of a URDF: folders searched for ``package://`` paths, the excess
    aimed at for a link's cover [m], the most primitives per mesh, and the cover cache
    folder (None: no cache)."""

    mesh_paths: tuple[Path, ...] = ()
    excess_m: float = 0.01
    max_primitives: int = 32
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
    "CapsuleCover",
    "box_cover",
    "cover_target_m",
    "default_cache_dir",
    "load_mesh",
    "mesh_cover",
    "resolve_mesh",
]

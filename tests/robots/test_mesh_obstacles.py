"""Mesh obstacles (``type = "mesh"``): a box cover for the planners and the core, the real
triangles for FCL (issue 27)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import ProblemError
from plannerlab.problem.load import Problem, problem_from_dict
from plannerlab.problem.scene import Box

ROOT = Path(__file__).resolve().parents[2]
RING = ROOT / "problems" / "urdf" / "meshes" / "ring.stl"
DATA = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One cover cache for the module (the robot's covers are computed once)."""
    return tmp_path_factory.mktemp("cache")


def problem(
    tmp_path: Path, obstacle: dict[str, object], monkeypatch: pytest.MonkeyPatch, cache: Path
) -> Problem:
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache))
    return problem_from_dict(
        {
            "problem": {"name": "ring"},
            "robot": {
                "type": "urdf",
                "urdf": str(DATA / "mesh_arm.urdf"),
                "tip_link": "tool",
                "mesh_paths": "pkgroot",
                "cover_excess_m": 0.02,
            },
            "start": {"q": [0.0, 0.0, 0.0]},
            "goals": [{"name": "g", "q": [0.5, 0.0, 0.0]}],
            "planning": {"safety_margin_m": 0.0},
            "obstacles": [obstacle],
        },
        str(tmp_path / "p.toml"),
    )


RING_OBSTACLE = {
    "name": "ring",
    "type": "mesh",
    "file": str(RING),
    "center_m": [0.3, 0.0, 0.6],
    "rpy_deg": [90.0, 0.0, 30.0],
    "scale": [1.5, 1.5, 1.0],
}


def test_the_cover_boxes_hold_the_mesh_and_stay_near_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cache: Path
) -> None:
    p = problem(tmp_path, RING_OBSTACLE, monkeypatch, cache)
    (mesh,) = p.scene.meshes
    boxes = [o for o in p.scene.obstacles if isinstance(o, Box)]
    assert boxes and all(b.cover_of == "ring" for b in boxes)
    assert len(boxes) <= 64 and p.scene.source_names == ("ring",) * len(boxes)
    tm = trimesh.Trimesh(mesh.vertices_world(), mesh.faces, process=True)
    pts, _ = trimesh.sample.sample_surface(tm, 4000, seed=1)
    pts = np.concatenate([tm.vertices, pts])

    def inside(x: np.ndarray) -> np.ndarray:
        hit = np.zeros(len(x), dtype=bool)
        for b in boxes:
            T = b.T_world_obstacle
            local = (x - T[:3, 3]) @ T[:3, :3]
            hit |= np.all(np.abs(local) <= b.size_m / 2 + 1e-9, axis=1)
        return hit

    assert inside(pts).all()
    # the boxes' surfaces lie within the reported excess of the solid
    rng = np.random.default_rng(0)
    far = 0.0
    for b in boxes:
        u = rng.uniform(-0.5, 0.5, size=(50, 3)) * b.size_m
        k = rng.integers(0, 3, 50)
        u[np.arange(50), k] = np.sign(u[np.arange(50), k]) * b.size_m[k] / 2
        x = u @ b.T_world_obstacle[:3, :3].T + b.T_world_obstacle[:3, 3]
        far = max(far, float(np.max(-trimesh.proximity.signed_distance(tm, x))))
    assert 0 < far <= mesh.cover_excess_m
    # the ring's hole stays open: its centre is in no box
    assert not inside(mesh.T_world_obstacle[:3, 3][None])[0]


def test_fcl_checks_the_triangles_and_the_core_the_cover(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, cache: Path
) -> None:
    p = problem(tmp_path, RING_OBSTACLE, monkeypatch, cache)
    fcl_c = CollisionChecker(p.robot, p.scene, backend="fcl")
    core = CollisionChecker(p.robot, p.scene, backend="core")
    rng = np.random.default_rng(5)
    lo, hi = p.robot.lower, p.robot.upper
    Q = lo + rng.random((300, 3)) * (hi - lo)
    f = np.array([fcl_c.is_valid(q) for q in Q])
    c = core.valid_batch(Q)
    assert not np.any(c & ~f)  # the core never passes what the triangles block
    assert np.any(f & ~c)  # and it is conservative: the cover blocks more
    links = set(p.robot.link_names)
    others = [
        {b for _, b in checker.colliding_pairs(q) if b not in links}
        for checker in (fcl_c, core)
        for q in Q[~f]
    ]
    # a cover box is reported as its mesh, by either backend
    assert set().union(*others) == {"ring"}


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        ({"file": "nowhere.stl"}, "does not exist"),
        ({"file": "garbage.dae"}, "unreadable"),
        ({"file": "empty.stl"}, "no triangles"),
        ({"scale": 0.0}, "positive"),
    ],
)
def test_bad_mesh_obstacles_name_the_obstacle_and_key(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    cache: Path,
    change: dict[str, object],
    expected: str,
) -> None:
    (tmp_path / "garbage.dae").write_bytes(b"<COLLADA broken")
    (tmp_path / "empty.stl").write_bytes(b"solid x\nendsolid x\n")
    obstacle = {**RING_OBSTACLE, **change}
    with pytest.raises(ProblemError) as e:
        problem(tmp_path, obstacle, monkeypatch, cache)
    msg = str(e.value)
    key = "scale" if "scale" in change else "file"
    assert f"obstacles[0].{key}" in msg and expected in msg and str(change[key]) in msg

"""URDFs whose collision geometry is meshes (issue 27): covers, paths, errors, SRDF.

The robot is ``tests/data/mesh_arm``: STL, OBJ and DAE collision meshes, a
``package://`` path found through ``mesh_paths``, a root link with a mesh and a moving
link (``camera``) with only a visual.
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from plannerlab.errors import ProblemError
from plannerlab.problem.load import problem_from_dict
from plannerlab.robots.urdf.meshes import MeshError, sphere_cover
from plannerlab.robots.urdf.model import UrdfChain, UrdfError, read_srdf_disabled
from plannerlab.run.srdf import disabled_pairs, write_srdf

DATA = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"
URDF = DATA / "mesh_arm.urdf"
PKG = DATA / "pkgroot"
#: a coarser cover than the default keeps these tests quick
EXCESS_M = 0.02


@pytest.fixture(scope="module")
def covers(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One cover cache for the tests that only read covers."""
    return tmp_path_factory.mktemp("shared")


def arm(tmp_path: Path, **kw: object) -> UrdfChain:
    args: dict[str, object] = dict(
        mesh_paths=(PKG,), cover_excess_m=EXCESS_M, cover_cache_dir=tmp_path / "covers"
    )
    args.update(kw)
    return UrdfChain(URDF, "tool", **args)  # type: ignore[arg-type]


def _mesh(file: Path) -> trimesh.Trimesh:
    return trimesh.load(str(file), force="mesh", process=True)


@pytest.mark.parametrize("name", ["base.stl", "upper.obj", "fore.dae"])
def test_sphere_cover_holds_the_mesh_and_its_excess_is_bounded(name: str) -> None:
    file = DATA / "meshes" / name
    cover = sphere_cover(file, np.ones(3), EXCESS_M, 256, "test", None)
    C, R = cover.centres_m, cover.radii_m
    assert len(R) <= 256 and cover.max_excess_m <= EXCESS_M + 1e-12
    mesh = _mesh(file)
    # every vertex and an independent surface sample (another seed) lie inside the cover
    pts, _ = trimesh.sample.sample_surface(mesh, 5000, seed=7)
    pts = np.concatenate([mesh.vertices, pts])
    d = np.linalg.norm(pts[:, None] - C[None], axis=-1) - R[None]
    assert np.all(d.min(axis=1) <= 1e-9)
    # the cover's boundary (points on each sphere not inside another) lies within the
    # reported excess of the solid: measured here with trimesh's signed distance
    rng = np.random.default_rng(3)
    u = rng.normal(size=(200, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    surf = (C[:, None, :] + R[:, None, None] * u[None]).reshape(-1, 3)
    inner = (np.linalg.norm(surf[:, None] - C[None], axis=-1) < R[None] - 1e-9).any(axis=1)
    outside = -trimesh.proximity.signed_distance(mesh, surf[~inner])
    assert outside.max() <= cover.max_excess_m + 1e-6
    assert outside.max() > 0.5 * EXCESS_M  # the bound is not slack by orders


def test_mesh_arm_loads_with_every_format_and_the_root_mesh(covers: Path) -> None:
    r = arm(covers)
    assert [c.link for c in r.mesh_covers] == ["base", "upper", "fore", "tool"]
    assert r.mesh_covers[3].file.endswith("pkgroot/mesh_arm_tools/meshes/tool.stl")
    assert all(c.max_excess_m <= EXCESS_M for c in r.mesh_covers)
    n_base = r.mesh_covers[0].spheres
    # the root link's spheres are the fixed links, one zero-length capsule per sphere
    assert r.fixed_links == frozenset(range(n_base))
    assert np.allclose(r._cap_a, r._cap_b)
    assert len(r.link_names) == sum(c.spheres for c in r.mesh_covers)
    assert r.link_names[0] == "base#0" and set(r.link_urdf_names) == {
        "base",
        "upper",
        "fore",
        "tool",
    }


def test_covers_move_with_their_link(covers: Path) -> None:
    r = arm(covers)
    q = np.array([0.4, 0.9, -0.7])
    segs = r.link_segments(q)[:, 0]
    tool = [i for i, n in enumerate(r.link_urdf_names) if n == "tool"]
    T_tool = r.fk(q)[3]  # frames: base, upper, fore, tool, tip
    verts = _mesh(PKG / "mesh_arm_tools" / "meshes" / "tool.stl").vertices + [0, 0, 0.075]
    p = verts @ T_tool[:3, :3].T + T_tool[:3, 3]
    d = np.linalg.norm(p[:, None] - segs[tool][None], axis=-1) - r.link_radii_m[tool][None]
    assert np.all(d.min(axis=1) <= 1e-9)


def test_covers_are_cached_by_hash_and_written_atomically(tmp_path: Path) -> None:
    first = arm(tmp_path)
    files = sorted((tmp_path / "covers").iterdir())
    assert len(files) == 4 and all(f.suffix == ".npz" for f in files)  # no temporaries
    second = arm(tmp_path)
    assert [c.cached for c in first.mesh_covers] == [False] * 4
    assert [c.cached for c in second.mesh_covers] == [True] * 4
    assert np.array_equal(first._cap_a, second._cap_a)
    assert np.array_equal(first.link_radii_m, second.link_radii_m)
    # another excess is another entry
    arm(tmp_path, cover_excess_m=0.03)
    assert len(list((tmp_path / "covers").iterdir())) == 8


def test_covers_shipped_beside_the_urdf_are_read_and_never_written(tmp_path: Path) -> None:
    """A ``covers/`` folder beside the URDF (what the bundled mesh robots ship) answers a
    cover the cache lacks: the robot loads on a new machine without computing any, and
    with the very spheres a computed cover has; nothing is written into that folder."""
    computed = arm(tmp_path / "a")
    robot_dir = tmp_path / "robot"
    shutil.copytree(DATA, robot_dir)
    shutil.copytree(tmp_path / "a" / "covers", robot_dir / "covers")
    shipped_files = sorted(p.name for p in (robot_dir / "covers").iterdir())
    args = dict(mesh_paths=(robot_dir / "pkgroot",), cover_excess_m=EXCESS_M)
    robot = UrdfChain(robot_dir / URDF.name, "tool", cover_cache_dir=tmp_path / "empty", **args)
    assert [c.cached for c in robot.mesh_covers] == [True] * 4
    assert np.array_equal(robot._cap_a, computed._cap_a)
    assert np.array_equal(robot.link_radii_m, computed.link_radii_m)
    assert not (tmp_path / "empty").exists() or not any((tmp_path / "empty").iterdir())
    assert sorted(p.name for p in (robot_dir / "covers").iterdir()) == shipped_files
    # another excess is not shipped: computed, into the cache only
    other = UrdfChain(
        robot_dir / URDF.name,
        "tool",
        cover_cache_dir=tmp_path / "empty",
        **{**args, "cover_excess_m": 0.03},
    )
    assert [c.cached for c in other.mesh_covers] == [False] * 4
    assert len(list((tmp_path / "empty").iterdir())) == 4
    assert sorted(p.name for p in (robot_dir / "covers").iterdir()) == shipped_files


def test_a_moving_link_without_geometry_is_named(
    covers: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING, logger="plannerlab.robots.urdf.model"):
        r = arm(covers)
    assert r.links_without_geometry == ("camera",)
    assert "camera (it has a visual)" in r.notes[0]
    assert any("camera" in rec.getMessage() for rec in caplog.records)


def test_the_simulator_urdf_keeps_the_real_meshes_with_absolute_paths(covers: Path) -> None:
    text = arm(covers).urdf()
    assert f'filename="{PKG / "mesh_arm_tools" / "meshes" / "tool.stl"}"' in text
    assert f'filename="{DATA / "meshes" / "fore.dae"}"' in text
    assert "package://" not in text


# ---------------------------------------------------------------------- bad input
def _copy(tmp_path: Path) -> Path:
    d = tmp_path / "arm"
    shutil.copytree(DATA, d)
    return d


def _problem(urdf: Path, **robot: object) -> dict[str, object]:
    return {
        "problem": {"name": "mesh_arm"},
        "robot": {
            "type": "urdf",
            "urdf": str(urdf),
            "tip_link": "tool",
            "cover_excess_m": EXCESS_M,
            **robot,
        },
        "start": {"q": [0.0, 0.0, 0.0]},
        "goals": [{"name": "g", "q": [0.5, 0.0, 0.0]}],
    }


def test_an_unresolved_package_path_says_which_file_link_and_key(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    with pytest.raises(ProblemError) as e:
        problem_from_dict(_problem(URDF), str(tmp_path / "p.toml"))
    msg = str(e.value)
    assert "package://mesh_arm_tools/meshes/tool.stl" in msg
    assert "link tool of mesh_arm.urdf" in msg and "mesh_paths" in msg


def test_mesh_paths_in_the_robot_table_find_the_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    p = problem_from_dict(_problem(URDF, mesh_paths="pkgroot"), str(tmp_path / "p.toml"))
    assert [c.link for c in p.robot.mesh_covers][-1] == "tool"  # type: ignore[attr-defined]
    assert len(list((tmp_path / "cache" / "plannerlab" / "covers").glob("*.npz"))) == 4
    with pytest.raises(ProblemError, match="robot.mesh_paths"):
        problem_from_dict(_problem(URDF, mesh_paths="nowhere"), str(tmp_path / "p.toml"))


def test_a_missing_mesh_file_is_named_with_its_link(tmp_path: Path) -> None:
    d = _copy(tmp_path)
    (d / "meshes" / "upper.obj").unlink()
    with pytest.raises(UrdfError) as e:
        UrdfChain(d / "mesh_arm.urdf", "tool", mesh_paths=(d / "pkgroot",), cover_cache=False)
    assert "meshes/upper.obj" in str(e.value) and "link upper" in str(e.value)


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (b"\x00\x01garbage that is no mesh", "unreadable"),
        (b"# an OBJ without faces\n", "no triangles"),
    ],
)
def test_an_unreadable_or_empty_mesh_is_refused(
    tmp_path: Path, content: bytes, expected: str
) -> None:
    d = _copy(tmp_path)
    name = "fore.dae" if content.startswith(b"<") else "upper.obj"
    (d / "meshes" / name).write_bytes(content)
    with pytest.raises(UrdfError) as e:
        UrdfChain(d / "mesh_arm.urdf", "tool", mesh_paths=(d / "pkgroot",), cover_cache=False)
    assert expected in str(e.value) and name in str(e.value)
    assert f"link {name.split('.')[0]}" in str(e.value)


def test_a_mesh_too_large_to_cover_within_the_limits_is_refused(tmp_path: Path) -> None:
    with pytest.raises(UrdfError, match="too large to cover.*cover_max_spheres"):
        arm(tmp_path, cover_max_spheres=3, cover_cache=False)
    # a surface needing more small triangles than the limit is refused before covering
    big = trimesh.creation.box((20.0, 20.0, 20.0))
    big.export(tmp_path / "big.stl")
    with pytest.raises(MeshError, match="too large to cover within the limits"):
        sphere_cover(tmp_path / "big.stl", np.ones(3), 0.01, 256, "link x", None)


# ---------------------------------------------------------------------- SRDF
def test_disabled_pairs_are_computed_and_kept_in_an_srdf(covers: Path) -> None:
    r = arm(covers)
    pairs = disabled_pairs(r, np.random.default_rng(0), n_states=200)
    by = {(p.link1, p.link2): p.reason for p in pairs}
    # neighbours, and links sharing a body
    assert by[("base", "upper")] == "Adjacent"
    assert by[("fore", "upper")] == "Adjacent"
    assert by[("fore", "tool")] == "Adjacent"
    # the tool can fold onto the upper arm (j2, j3 up to 2.5 rad): seen colliding
    assert ("tool", "upper") not in by
    # the base and the forearm never meet (the upper arm holds them 0.3 m apart)
    assert by[("base", "fore")] == "Never"
    out = covers / "arm.srdf"
    write_srdf(pairs, out, "mesh_arm")
    assert sorted(read_srdf_disabled(out)) == sorted(by)
    again = disabled_pairs(r, np.random.default_rng(0), n_states=200)
    assert again == pairs


@pytest.mark.parametrize("problem", ["panda_mesh/table", "panda_mesh/shelf", "iiwa_mesh/table"])
def test_the_bundled_mesh_robots_ship_every_cover(
    problem: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bundled mesh robots load with an empty cache from their shipped covers (a
    change of the cover's settings or algorithm must ship new ones:
    ``XDG_CACHE_HOME=$(mktemp -d)``, load the problem, copy the cache's files into the
    URDF's ``covers/``)."""
    from plannerlab.problem.catalog import load_problem

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    root = Path(__file__).resolve().parents[2]
    robot = load_problem(root / "problems" / "urdf" / f"{problem}.toml").robot
    assert robot.mesh_covers and all(c.cached for c in robot.mesh_covers)
    assert not (tmp_path / "plannerlab" / "covers").exists()

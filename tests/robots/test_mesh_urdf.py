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
from plannerlab.robots.urdf.approx import capsule_cover
from plannerlab.robots.urdf.meshes import load_mesh, mesh_cover
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
    # the first covers only (the finer covers for self-collision: test_self_covers.py)
    args: dict[str, object] = dict(
        mesh_paths=(PKG,),
        cover_excess_m=EXCESS_M,
        cover_cache_dir=tmp_path / "covers",
        self_cover_max_primitives=0,
    )
    args.update(kw)
    return UrdfChain(URDF, "tool", **args)  # type: ignore[arg-type]


def _mesh(file: Path) -> trimesh.Trimesh:
    return trimesh.load(str(file), force="mesh", process=True)


def _capsule_surface(a: np.ndarray, b: np.ndarray, r: np.ndarray, n: int) -> np.ndarray:
    """Points on every capsule's boundary (n per capsule, seeded) not inside another."""
    rng = np.random.default_rng(3)
    u = rng.normal(size=(len(r), n, 3))
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    t = rng.random((len(r), n, 1))
    p = a[:, None] + t * (b - a)[:, None] + r[:, None, None] * u
    ab = b - a
    ll = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    # pushed out to the own capsule's boundary along the direction from its axis
    s = np.clip(np.einsum("kpj,kj->kp", p - a[:, None], ab) / ll[:, None], 0, 1)
    foot = a[:, None] + s[..., None] * ab[:, None]
    away = p - foot
    away /= np.maximum(np.linalg.norm(away, axis=2, keepdims=True), 1e-300)
    surf = (foot + r[:, None, None] * away).reshape(-1, 3)
    tt = np.clip(np.einsum("pkj,kj->pk", surf[:, None] - a[None], ab) / ll, 0, 1)
    d = np.linalg.norm(surf[:, None] - (a[None] + tt[..., None] * ab[None]), axis=-1) - r[None]
    return surf[~(d < -1e-9).any(axis=1)]


@pytest.mark.parametrize("name", ["base.stl", "upper.obj", "fore.dae"])
@pytest.mark.parametrize("budget", [1, 4, 32])
def test_capsule_cover_holds_the_mesh_and_its_excess_is_bounded(name: str, budget: int) -> None:
    """Any budget gives a cover (one capsule at worst); it holds every vertex and an
    independent surface sample, and no point of its boundary lies further outside the
    solid than the reported excess (trimesh's signed distance, another measure)."""
    file = DATA / "meshes" / name
    cover = mesh_cover(file, np.ones(3), EXCESS_M, budget, "test", None)
    a, b, r = cover.a_m, cover.b_m, cover.radii_m
    assert 1 <= cover.count <= budget
    mesh = _mesh(file)
    pts, _ = trimesh.sample.sample_surface(mesh, 5000, seed=7)
    pts = np.concatenate([mesh.vertices, pts])
    ab = b - a
    ll = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    t = np.clip(np.einsum("pkj,kj->pk", pts[:, None] - a[None], ab) / ll, 0, 1)
    d = np.linalg.norm(pts[:, None] - (a[None] + t[..., None] * ab[None]), axis=-1) - r[None]
    assert np.all(d.min(axis=1) <= 1e-9)
    solid = mesh if cover.solid == "mesh" else mesh.convex_hull
    outside = -trimesh.proximity.signed_distance(solid, _capsule_surface(a, b, r, 300))
    assert outside.max() <= cover.max_excess_m + 1e-6
    assert outside.max() > 0.3 * cover.max_excess_m  # the bound is not slack by orders


def test_a_larger_budget_never_gives_a_coarser_cover() -> None:
    file = DATA / "meshes" / "base.stl"
    excess = [mesh_cover(file, np.ones(3), 0.005, k, "test", None).max_excess_m for k in (1, 8, 64)]
    assert excess[0] > excess[1] > excess[2]


def test_a_detailed_mesh_is_covered_within_the_budget_not_refused() -> None:
    """A sphere of 80 000 triangles (what a CAD export gives) and a plate with no inside:
    both covered within the budget, the excess measured."""
    ball = trimesh.creation.icosphere(subdivisions=7, radius=0.1)
    assert len(ball.faces) > 80_000
    cover = capsule_cover(np.asarray(ball.vertices), np.asarray(ball.faces), 0.002, 8)
    assert cover.count <= 8 and cover.solid == "mesh"
    assert cover.max_excess_m < 0.02
    plate = trimesh.Trimesh([[0, 0, 0], [0.2, 0, 0], [0, 0.1, 0]], [[0, 1, 2]])
    flat = capsule_cover(np.asarray(plate.vertices), np.asarray(plate.faces), 0.005, 4)
    assert flat.solid == "surface" and 1 <= flat.count <= 4


def test_mesh_arm_loads_with_every_format_and_the_root_mesh(covers: Path) -> None:
    r = arm(covers, self_cover_max_primitives=128)
    assert r.self_covers
    assert [c.link for c in r.mesh_covers] == ["base", "upper", "fore", "tool"]
    assert r.mesh_covers[3].file.endswith("pkgroot/mesh_arm_tools/meshes/tool.stl")
    assert all(c.primitives <= 32 and c.max_excess_m > 0 for c in r.mesh_covers)
    n_base = r.mesh_covers[0].primitives
    n_first = sum(c.primitives for c in r.mesh_covers)
    # the root link's capsules are the fixed links (its first cover, then its finer one)
    fine_base = {i for i in r.self_only_links if r.link_urdf_names[i] == "base"}
    assert r.fixed_links == frozenset(range(n_base)) | fine_base
    assert fine_base == set(range(n_base, n_base + len(fine_base)))
    assert sum(c.capsules for c in r.mesh_covers) > 0
    assert len(r.link_names) == n_first + sum(c.primitives for c in r.self_covers)
    assert r.link_names[0] == "base#0" and set(r.link_urdf_names) == {
        "base",
        "upper",
        "fore",
        "tool",
    }


def test_covers_move_with_their_link(covers: Path) -> None:
    r = arm(covers)
    q = np.array([0.4, 0.9, -0.7])
    tool = [i for i, n in enumerate(r.link_urdf_names) if n == "tool"]
    segs = r.link_segments(q)[tool]
    T_tool = r.fk(q)[3]  # frames: base, upper, fore, tool, tip
    verts = _mesh(PKG / "mesh_arm_tools" / "meshes" / "tool.stl").vertices + [0, 0, 0.075]
    p = verts @ T_tool[:3, :3].T + T_tool[:3, 3]
    a, ab = segs[:, 0], segs[:, 1] - segs[:, 0]
    ll = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    t = np.clip(np.einsum("pkj,kj->pk", p[:, None] - a[None], ab) / ll, 0, 1)
    foot = a[None] + t[..., None] * ab[None]
    d = np.linalg.norm(p[:, None] - foot, axis=-1) - r.link_radii_m[tool][None]
    assert np.all(d.min(axis=1) <= 1e-9)


def test_link_segments_move_every_capsule_by_its_own_body_frame(covers: Path) -> None:
    """``link_segments`` (one matrix product per body) puts every capsule's end points
    where its body's frame from ``fk`` puts them, one state and a batch alike."""
    r = arm(covers)
    a_b, b_b = r.chain_data()[5:7]
    body = r.chain_data()[4]
    assert len(np.unique(body)) >= 3  # several bodies, capsules on each
    rng = np.random.default_rng(7)
    Q = rng.uniform(r.lower, r.upper, size=(5, r.dof))
    batch = r.link_segments(Q)
    assert batch.shape == (5, len(r.link_radii_m), 2, 3)
    for k, q in enumerate(Q):
        F = r.fk(q)[body]  # (L, 4, 4): each capsule's body frame
        a = np.einsum("lij,lj->li", F[:, :3, :3], a_b) + F[:, :3, 3]
        b = np.einsum("lij,lj->li", F[:, :3, :3], b_b) + F[:, :3, 3]
        np.testing.assert_allclose(batch[k, :, 0], a, atol=1e-12)
        np.testing.assert_allclose(batch[k, :, 1], b, atol=1e-12)
        np.testing.assert_allclose(r.link_segments(q), batch[k], atol=1e-12)


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
    args = dict(
        mesh_paths=(robot_dir / "pkgroot",), cover_excess_m=EXCESS_M, self_cover_max_primitives=0
    )
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
            "self_cover_max_primitives": 0,  # the first covers only, as arm()
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


def test_the_excess_grows_as_the_budget_shrinks_and_is_reported(tmp_path: Path) -> None:
    one = arm(tmp_path, cover_max_primitives=1, cover_cache=False)
    many = arm(tmp_path, cover_max_primitives=32, cover_cache=False)
    assert [c.primitives for c in one.mesh_covers] == [1] * 4
    assert all(
        a.max_excess_m > b.max_excess_m
        for a, b in zip(one.mesh_covers, many.mesh_covers, strict=True)
    )


def test_a_mesh_larger_than_plannerlab_reads_is_refused_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import plannerlab.robots.urdf.meshes as meshes

    monkeypatch.setattr(meshes, "MAX_MESH_BYTES", 100)
    big = trimesh.creation.box((0.2, 0.2, 0.2))
    big.export(tmp_path / "big.stl")
    with pytest.raises(meshes.MeshError, match=r"big.stl \(link x\).*simplify"):
        load_mesh(tmp_path / "big.stl", np.ones(3), "link x")


# ---------------------------------------------------------------------- SRDF
def test_disabled_pairs_are_computed_and_kept_in_an_srdf(covers: Path) -> None:
    r = arm(covers)
    # judged on the covers (on the links' hulls: test_self_covers.py)
    pairs = disabled_pairs(r, np.random.default_rng(0), n_states=200, geometry="covers")
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
    again = disabled_pairs(r, np.random.default_rng(0), n_states=200, geometry="covers")
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


def test_a_start_in_collision_is_refused_naming_the_urdf_links(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/problem-format.md: the start must be collision-free, the error names the
    colliding pairs: by the URDF's links, not the capsules of their covers."""
    import plannerlab as pl

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    free = problem_from_dict(_problem(URDF, mesh_paths="pkgroot"), str(tmp_path / "p.toml"))
    p_tip, _ = free.robot.tip(np.zeros(3))
    doc = _problem(URDF, mesh_paths="pkgroot")
    doc["obstacles"] = [
        {"name": "block", "type": "box", "center_m": p_tip.tolist(), "size_m": [0.1] * 3}
    ]
    problem = problem_from_dict(doc, str(tmp_path / "p.toml"))
    with pytest.raises(ProblemError) as e:
        pl.solve(problem, "ompl.rrtconnect", 0)
    assert "tool x block" in str(e.value) and "#" not in str(e.value)

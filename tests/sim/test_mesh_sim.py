"""Execution judged on the real geometry (issue 27): a mesh robot's collision meshes and a
scene's mesh obstacles in PyBullet, whatever covers were planned with."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from plannerlab.problem.load import Problem, problem_from_dict
from plannerlab.record.execution import Execution
from plannerlab.sim import SimWorld, execute

DATA = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("cache")


def arm_problem(cache: Path, obstacles: list[dict[str, object]], goal: list[float]) -> Problem:
    import os

    old = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(cache)
    try:
        return problem_from_dict(
            {
                "problem": {"name": "mesh_arm"},
                "robot": {
                    "type": "urdf",
                    "urdf": str(DATA / "mesh_arm.urdf"),
                    "tip_link": "tool",
                    "mesh_paths": "pkgroot",
                    "cover_excess_m": 0.02,
                },
                "start": {"q": [0.0, 0.0, 0.0]},
                "goals": [{"name": "g", "q": goal, "joint_tol_rad": 0.05}],
                "planning": {"safety_margin_m": 0.0},
                "obstacles": obstacles,
            },
            str(DATA / "p.toml"),
        )
    finally:
        if old is None:
            del os.environ["XDG_CACHE_HOME"]
        else:
            os.environ["XDG_CACHE_HOME"] = old


WALL = {"name": "wall", "type": "box", "center_m": [0.35, 0.0, 0.6], "size_m": [0.1, 0.6, 0.6]}
BALL = {
    "name": "ball",
    "type": "mesh",
    "file": "block.stl",
    "center_m": [0.0, 0.45, 0.6],
    "scale": 1.5,
}


def test_pybullet_holds_the_real_meshes_not_the_covers(cache: Path) -> None:
    p = arm_problem(cache, [BALL], [0.0, 0.0, 0.0])
    with SimWorld(p.robot, p.scene) as w:
        c = w.client
        shapes = {w.urdf_link_names[j]: c.getCollisionShapeData(w.body, j) for j in (-1, 0, 1, 3)}
        assert all(s[0][2] == 5 for s in shapes.values())  # GEOM_MESH, one per link
        assert shapes["fore"][0][4].decode().endswith("fore.dae")
        # the DAE was read: its bounds are the 5 x 5 x 30 cm box's
        lo, hi = c.getAABB(w.body, 1)
        assert np.allclose(np.subtract(hi, lo), [0.05, 0.05, 0.3], atol=0.005)
        # the mesh obstacle is its triangles: an icosphere of radius 1.5 x 5 cm
        (uid,) = [u for u, n in w.obstacle_names.items() if n == "ball"]
        lo, hi = c.getAABB(uid)
        assert np.allclose(np.subtract(hi, lo), 0.15, atol=0.002)
        # no cover box became a body
        assert sorted(w.obstacle_names.values()) == ["ball"]


def test_a_path_into_a_wall_is_never_executed_cleanly_and_says_on_what(cache: Path) -> None:
    p = arm_problem(cache, [WALL], [0.0, 1.2, 0.0])
    path = np.linspace([0.0, 0.0, 0.0], [0.0, 1.2, 0.0], 13)
    ex = execute(p, path, leg=0)
    assert not ex.success and not ex.path_valid
    assert ex.contacts and ex.min_clearance_m < 0
    # contacts and clearance name URDF links (PyBullet's meshes), not cover spheres
    assert {c.link_name for c in ex.contacts} <= {"upper", "fore", "tool"}
    assert "#" not in ex.min_clearance_pair[0]  # type: ignore[index]
    assert ex.geometry["contacts"].startswith("real meshes")
    assert ex.geometry["recheck"].startswith("planning model")
    data = json.loads(json.dumps(ex.to_dict()))
    assert Execution.from_dict(data).geometry == ex.geometry
    del data["geometry"]  # a record written before the field: still read
    assert Execution.from_dict(data).geometry == {}


def test_a_free_path_past_a_mesh_obstacle_is_clean_on_the_meshes(cache: Path) -> None:
    p = arm_problem(cache, [BALL], [0.0, -0.6, 0.0])
    path = np.linspace([0.0, 0.0, 0.0], [0.0, -0.6, 0.0], 7)
    ex = execute(p, path, leg=0)
    assert ex.success, ex.reason
    # the upright arm passes the ball 0.45 m off its axis: PyBullet's distance from the
    # forearm's mesh (2.5 cm half width) to the icosphere (7.5 cm) is about 0.35 m; the
    # clearance sampler reports it only up to its query distance
    assert ex.min_clearance_m > 0.04
    assert "mesh obstacles ball as their triangles" in ex.geometry["min_clearance_m"]


def spheres_problem(sim_urdf: str | None) -> Problem:
    robot: dict[str, object] = {
        "type": "urdf",
        "urdf": str(DATA / "mesh_arm_spheres.urdf"),
        "tip_link": "tool",
        "mesh_paths": "pkgroot",
    }
    if sim_urdf:
        robot["sim_urdf"] = sim_urdf
    return problem_from_dict(
        {
            "problem": {"name": "mesh_arm_spheres"},
            "robot": robot,
            "start": {"q": [0.0, 0.0, 0.0]},
            "goals": [{"name": "g", "q": [0.3, 0.0, 0.0], "joint_tol_rad": 0.05}],
            "planning": {"safety_margin_m": 0.0},
            # 5 mm off the forearm's spheres, 5 mm into its real 5 cm box
            "obstacles": [
                {
                    "name": "post",
                    "type": "box",
                    "center_m": [0.07, 0.0, 0.55],
                    "size_m": [0.1, 0.2, 0.2],
                }
            ],
        },
        str(DATA / "p.toml"),
    )


def test_a_spherized_robot_is_judged_on_its_meshes_with_sim_urdf() -> None:
    """The issue's case: an under-covering spherized model plans a path the real robot
    cannot take. Judged on the spheres it is "executed cleanly"; with ``sim_urdf`` PyBullet
    holds the meshes and the verdict is a contact."""
    path = np.linspace([0.0, 0.0, 0.0], [0.3, 0.0, 0.0], 7)
    blind = spheres_problem(None)
    ex = execute(blind, path, leg=0)
    assert ex.path_valid and ex.success  # the spheres clear the post
    assert ex.geometry["contacts"].startswith("planning model")
    real = spheres_problem("mesh_arm.urdf")
    ex = execute(real, path, leg=0)
    assert ex.path_valid  # the plan is valid on the model planned with ...
    assert not ex.success  # ... and the real forearm runs into the post
    assert {(c.link_name, c.other_name) for c in ex.contacts} == {("fore", "post")}
    assert ex.min_clearance_m < -0.004
    assert (
        ex.geometry["contacts"].startswith("real meshes")
        and "mesh_arm.urdf" in (ex.geometry["contacts"])
    )


def test_a_sim_urdf_without_the_chain_s_links_is_refused(tmp_path: Path) -> None:
    other = tmp_path / "other.urdf"
    text = (DATA / "mesh_arm.urdf").read_text().replace('"fore"', '"forearm"')
    other.write_text(text)
    from plannerlab.errors import ProblemError

    with pytest.raises(ProblemError, match=r"robot.sim_urdf.*lacks.*fore"):
        spheres_problem(str(other))


def test_a_mesh_robots_distances_per_urdf_link_are_its_capsules_reduced(cache: Path) -> None:
    """``link_distances(reach, starts)`` reports per URDF link (its run of capsules) what
    the per-capsule arrays give reduced over each run: the arrays are G, not L, long."""
    p = arm_problem(cache, [WALL, BALL], [0.0, 0.0, 0.0])
    urdf = list(p.robot.link_urdf_names)
    starts = np.array([0] + [i for i in range(1, len(urdf)) if urdf[i] != urdf[i - 1]])
    assert len(starts) < len(urdf)  # some URDF link has several capsules
    rng = np.random.default_rng(3)
    with SimWorld(p.robot, p.scene) as w:
        for q in rng.uniform(-1.5, 1.5, size=(6, p.robot.dof)):
            w.set_state(q)
            scene, names, pair = w.link_distances(0.5)
            g_scene, g_names, g_pair = w.link_distances(0.5, starts)
            assert g_scene.shape == (len(starts),) and g_pair.shape == (len(starts),) * 2
            assert np.array_equal(g_scene, np.minimum.reduceat(scene, starts))
            want = np.minimum.reduceat(np.minimum.reduceat(pair, starts, axis=0), starts, axis=1)
            assert np.array_equal(g_pair, want)
            assert g_names == [names[i] for i in starts]
            assert (g_scene < 0.5).any()  # something is measured, not only the cap

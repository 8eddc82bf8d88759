"""The 3-D viewer without a browser: its geometry (capsules, cones, obstacles), its
timeline from the records, a viewer for each robot family, and the command's errors."""

from __future__ import annotations

import shutil
import socket

import numpy as np
import pytest

import plannerlab as pl
from plannerlab.cli.main import main
from plannerlab.plot.view_scene import (
    EXECUTED_RGB,
    MIN_LINK_SPAN,
    PLANNED_RGB,
    capsule_batch,
    clearance_rgb,
    cone_mesh,
    leg_motions,
    motion_span,
    obstacle_mesh,
    port_free,
    z_to_wxyz,
)


def _rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    w, x, y, z = wxyz
    u = np.array([x, y, z])
    return v + 2 * np.cross(u, np.cross(u, v) + w * v)


@pytest.mark.parametrize(
    "d", [(0, 0, 1), (0, 0, -1), (1, 0, 0), (0.3, -0.4, 0.5), (-1e-3, 0, -1)], ids=str
)
def test_z_to_wxyz_turns_z_onto_the_direction(d):
    d = np.asarray(d, dtype=float)
    q = z_to_wxyz(d[None])[0]
    assert np.linalg.norm(q) == pytest.approx(1.0)
    np.testing.assert_allclose(
        _rotate(q, np.array([0.0, 0.0, 1.0])), d / np.linalg.norm(d), atol=1e-9
    )


def test_capsule_batch_puts_cylinders_between_the_ends_with_the_radii():
    seg = np.array([[[0, 0, 0], [0, 0, 2.0]], [[1, 1, 1], [1, 1, 1]]])  # a sphere: length 0
    b = capsule_batch(seg, np.array([0.1, 0.25]))
    np.testing.assert_allclose(b.cyl_positions, [[0, 0, 1], [1, 1, 1]])
    np.testing.assert_allclose(b.cyl_scales[0], [0.1, 0.1, 2.0])
    assert b.cyl_scales[1, 2] < 1e-5
    np.testing.assert_allclose(b.cap_scales, [0.1, 0.25, 0.1, 0.25])
    np.testing.assert_allclose(b.cap_positions, [[0, 0, 0], [1, 1, 1], [0, 0, 2], [1, 1, 1]])


def test_goal_cone_opens_along_the_normal_at_the_angle():
    apex = np.array([1.0, 2.0, 3.0])
    n = np.array([0.0, 1.0, 0.0])
    v, f = cone_mesh(apex, n, 20.0, 0.5)
    rel = v - apex
    far = rel[np.linalg.norm(rel, axis=1) > 1e-9]
    angles = np.degrees(np.arccos(np.clip(far @ n / np.linalg.norm(far, axis=1), -1, 1)))
    assert np.all(angles <= 20.0 + 1e-6)
    assert np.max(angles) == pytest.approx(20.0, abs=1e-6)
    assert np.max(np.linalg.norm(far, axis=1)) == pytest.approx(0.5)
    assert f.max() < len(v)


def test_obstacle_meshes_fill_their_shapes():
    problem = pl.load_problem("irb6_case1")
    for o in problem.scene.obstacles:
        v, f = obstacle_mesh(o)
        lo, hi = v.min(axis=0), v.max(axis=0)
        c = o.T_world_obstacle[:3, 3]
        h = o.half_extents_world()
        np.testing.assert_allclose((lo + hi) / 2, c, atol=1e-6 + 0.02 * h.max())
        np.testing.assert_allclose((hi - lo) / 2, h, rtol=0.02, atol=1e-6)
        assert f.shape[1] == 3 and f.max() < len(v)


def _still_plan(problem, step: float = 0.2):
    """A one-leg plan: two waypoints near the start (no planner needed)."""
    q0 = np.asarray(problem.q_start, dtype=float)
    q1 = np.where(q0 + step <= problem.robot.upper, q0 + step, q0 - step)
    leg = pl.PlanResult("test", problem.name, 0, problem.goals[0].name, "approximate", "", [q0, q1])
    return pl.Plan(problem.name, problem.source, "test", 0, {}, (leg,))


def test_the_timeline_densifies_the_plan_and_keeps_its_ends():
    problem = pl.load_problem("armz_pocket")
    plan = _still_plan(problem)
    (m,) = leg_motions(problem, plan.legs, (), max_frames=5)
    assert m.frames == 5 and m.q_executed is None
    np.testing.assert_allclose(m.q_planned[0], plan.legs[0].path[0])
    np.testing.assert_allclose(m.q_planned[-1], plan.legs[0].path[-1])
    assert len(m.tips_planned) > 5  # the trace keeps every densified state
    assert m.t_s[0] == 0.0 and m.t_s[-1] == 1.0
    # the panel's path quality: a straight two-state path has roughness 0; its clearance
    # along the path is not in this hand-made record
    assert (
        "smoothness 0 rad²" in m.quality
        and "clearance along the whole path not measured" in m.quality
    )
    measured = plan.legs[0].replace(path_clearance_m=0.0123, roughness_rad2=0.25)
    (m,) = leg_motions(problem, [measured], (), max_frames=5)
    assert "smoothness 0.25 rad²" in m.quality and "whole path 12.3 mm" in m.quality


@pytest.mark.parametrize("name", ["armz_pocket", "irb6_case1", "continuum_case1"])
def test_a_viewer_draws_every_robot_family(name):
    problem = pl.load_problem(name)
    plan = _still_plan(problem, 0.05)
    with pl.view(plan, problem=problem, port=0) as viewer:
        nodes = viewer.scene_nodes
        assert {"/planned/links", "/planned/joints", "/goals/0/ball", "/goals/0/cone"} <= set(nodes)
        assert sum(n.startswith("/scene/") for n in nodes) == len(problem.scene.obstacles)
        L = len(problem.robot.link_radii_m)
        links = viewer._nodes["/planned/links"]
        assert links.batched_positions.shape == (L, 3)
        # true radii; a link too thin to be seen drawn at MIN_LINK_SPAN of the motion's size
        shown = np.maximum(
            problem.robot.link_radii_m, MIN_LINK_SPAN * motion_span(problem, viewer.legs)
        )
        np.testing.assert_allclose(links.batched_scales[:, 0], shown, rtol=1e-6)
        thin = bool(np.any(shown > problem.robot.link_radii_m))
        assert thin == any("drawn that thick" in n for n in viewer.notes)
        before = np.array(links.batched_positions)
        viewer.slider.value = viewer.legs[0].frames - 1
        assert not np.allclose(before, links.batched_positions)
        assert "nearest link" in viewer.info.content
        assert "clearance along the whole path" in viewer.info.content


def test_a_port_in_use_is_an_error(tmp_path, capsys):
    problem = pl.load_problem("armz_pocket")
    plan_file = _still_plan(problem).save(tmp_path / "p.json")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert not port_free("127.0.0.1", port)
        rc = main(["view", str(plan_file), "--port", str(port), "--no-browser"])
    assert rc == 2
    assert f"--port {port}" in capsys.readouterr().err


def test_a_plan_whose_problem_file_is_gone_is_an_error(tmp_path, capsys):
    src = pl.load_problem("armz_pocket").source
    copy = tmp_path / "pocket_copy.toml"
    shutil.copy(src, copy)
    problem = pl.load_problem(copy)
    plan_file = _still_plan(problem).save(tmp_path / "p.json")
    copy.unlink()
    rc = main(["view", str(plan_file), "--port", "0", "--no-browser"])
    assert rc == 2
    err = "".join(capsys.readouterr().err.split())  # the console wraps long lines
    assert "pocket_copy.toml" in err and "nolongerexists" in err


def test_the_leg_selector_switches_the_timeline():
    problem = pl.load_problem("armz_inspection")
    q0 = np.asarray(problem.q_start, dtype=float)
    q1 = np.where(q0 + 0.1 <= problem.robot.upper, q0 + 0.1, q0 - 0.1)
    legs = (
        pl.PlanResult("test", problem.name, 0, problem.goals[0].name, "approximate", "", [q0, q1]),
        pl.PlanResult("test", problem.name, 1, problem.goals[1].name, "approximate", "", [q1, q0]),
    )
    plan = pl.Plan(problem.name, problem.source, "test", 0, {}, legs)
    with pl.view(plan, problem=problem, port=0, max_frames=7) as viewer:
        assert len(viewer.leg_dropdown.options) == 2
        viewer.slider.value = 3
        viewer.leg_dropdown.value = viewer.leg_dropdown.options[1]
        assert viewer.slider.value == 0  # a new leg starts at its first frame
        assert viewer.slider.max == viewer.legs[1].frames - 1
        assert f"leg 1 '{problem.goals[1].name}'" in viewer.info.content
        # the goal of the selected leg stands out
        assert viewer._nodes["/goals/1/ball"].opacity > viewer._nodes["/goals/0/ball"].opacity


def test_the_nearest_link_is_coloured_and_contacts_are_marked():
    import dataclasses

    from plannerlab.record.execution import ContactRecord

    problem = pl.load_problem("armz_pocket")
    plan = _still_plan(problem, 0.05)
    (e,) = pl.execute(plan, problem)
    hit = ContactRecord("module_23", "boulder", False, 0.02, 0.5, (3.0, -0.1, 16.0))
    e = dataclasses.replace(e, contacts=(hit,))
    with pl.view(plan, [e], problem=problem, port=0) as viewer:
        assert {"/executed/links", "/traces/executed", "/contacts/0"} <= set(viewer.scene_nodes)
        np.testing.assert_allclose(viewer._nodes["/contacts/0"].position, hit.p_world_m)
        m = viewer.legs[0]
        for kind, q, rgb in (
            ("planned", m.q_planned[0], PLANNED_RGB),
            ("executed", m.q_executed[0], EXECUTED_RGB),
        ):
            d, other = viewer.clearance(q)
            j = int(np.argmin(d))
            expected = np.tile(rgb, (len(d), 1))
            expected[j] = clearance_rgb(float(d[j]))
            # every link in its motion's colour but the one nearest the scene
            colors = np.asarray(viewer._nodes[f"/{kind}/links"].batched_colors)
            np.testing.assert_array_equal(colors, expected)
            assert f"{kind}: nearest link {problem.robot.link_names[j]} to {other[j]}" in (
                viewer.info.content
            )

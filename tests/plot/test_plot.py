"""Figures and animations show what the kinematics, the scene and the execution say.

The checks read the figures' artists (lines, patches, titles), not file sizes: the arm's
polyline is the chain of capsule axes at the given state, obstacles are their projected
hulls, goal regions are circles of the position tolerance, an execution that ended off the
goal is drawn there and said so, the progress plot names each planner. Budgets are
collision checks.
"""

from __future__ import annotations

import json
import sys
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib import animation
from PIL import Image
from scipy.spatial import ConvexHull

from plannerlab.cli.main import main
from plannerlab.errors import PlannerlabError
from plannerlab.plot.animate import animation_figure, motion_frames, write_animation
from plannerlab.plot.plans import (
    VIEWS,
    chain_points,
    leg_figure,
    obstacle_points,
    progress_figure,
    snapshot_figure,
    trace_figure,
)
from plannerlab.problem.catalog import load_problem
from plannerlab.run.pipeline import solve_legs

#: gradient+rrtconnect solves armz_pocket in ~65 000 checks with the 1-cm margin (edges in metres)
CHECKS = 200_000


@pytest.fixture(scope="module")
def problem():
    return load_problem("armz_pocket")


@pytest.fixture(scope="module")
def plans(problem):
    budget = problem.budget.replace(max_collision_checks=CHECKS)
    return {
        name: solve_legs(problem, name, 0, budget=budget)
        for name in ("gradient", "gradient+rrtconnect")
    }


def _views(fig):
    """The 2D panels by title, with their (i, j) world axes."""
    return {
        ax.get_title(): (ax, VIEWS[ax.get_title()]) for ax in fig.axes if ax.get_title() in VIEWS
    }


def _line(ax, label):
    found = [line for line in ax.get_lines() if line.get_label() == label]
    assert len(found) == 1, [line.get_label() for line in ax.get_lines()]
    return found[0]


def test_snapshot_draws_arm_obstacles_and_goals_where_they_are(problem) -> None:
    q = problem.q_start
    fig = snapshot_figure(problem, [("start", q)], "start")
    chain = chain_points(problem, q)
    views = _views(fig)
    assert set(views) == set(VIEWS)
    for _title, (ax, (i, j)) in views.items():
        line = _line(ax, "start")
        np.testing.assert_allclose(line.get_xdata(), chain[:, i])
        np.testing.assert_allclose(line.get_ydata(), chain[:, j])
        # every obstacle but the ground is a filled hull of its projection, in place
        drawn = sorted(
            tuple(np.round(np.r_[p.get_xy().min(0), p.get_xy().max(0)], 6)) for p in ax.patches
        )
        expected = []
        for o in problem.scene.obstacles:
            if o.name == "ground":
                continue
            pts = obstacle_points(o)[:, [i, j]]
            hull = pts[ConvexHull(pts).vertices]
            expected.append(tuple(np.round(np.r_[hull.min(0), hull.max(0)], 6)))
        assert drawn == sorted(expected)
        # the goal region: a circle of radius pos_tol round the target
        g = problem.goals[0]
        circles = [
            line
            for line in ax.get_lines()
            if len(line.get_xdata()) > 20
            and np.allclose(
                np.hypot(line.get_xdata() - g.p_world_m[i], line.get_ydata() - g.p_world_m[j]),
                g.pos_tol_m,
            )
        ]
        assert len(circles) == 1
        # the view shows the arm and the goal (limits hold them)
        x0, x1 = ax.get_xlim()
        y0, y1 = ax.get_ylim()
        assert x0 <= chain[:, i].min() and chain[:, i].max() <= x1
        assert y0 <= g.p_world_m[j] <= y1
    ax3 = next(ax for ax in fig.axes if ax.name == "3d")
    xs, ys, zs = _line(ax3, "start").get_data_3d()
    np.testing.assert_allclose(np.c_[xs, ys, zs], chain)
    # the legend is the figure's, outside the panels: it covers no arm
    assert fig.legends and not any(ax.get_legend() for ax in fig.axes)


def test_leg_figure_shows_the_way_and_where_pybullet_really_ended(problem, plans) -> None:
    plan = plans["gradient+rrtconnect"]
    r = plan.legs[0]
    assert r.solved
    # an execution record that ended far from the goal (the 11.8 m case)
    q_off = np.array(r.path[len(r.path) // 2])
    executed = np.array(r.path[: len(r.path) // 2 + 1])
    e = SimpleNamespace(
        leg=r.leg,
        q_final_rad=q_off,
        q_actual_rad=executed,
        success=False,
        final_pos_err_m=11.8,
        reason="contact module_12 x boulder",
    )
    fig = leg_figure(plan, problem, r, e)
    title = fig._suptitle.get_text()
    assert "planned: solved" in title and "execution FAILED: ended 11.8 m off the goal" in title
    ax, (i, j) = _views(fig)["front (x-z)"]
    end = _line(ax, "executed end (PyBullet)")
    np.testing.assert_allclose(end.get_xdata(), chain_points(problem, q_off)[:, i])
    planned = _line(ax, "planned end: solved")
    np.testing.assert_allclose(planned.get_ydata(), chain_points(problem, r.path[-1])[:, j])
    # the planned tip trace runs through the tip of every state of the path
    tips = problem.robot.tip(r.path)[0]
    trace = _line(ax, "planned tip trace")
    np.testing.assert_allclose(np.c_[trace.get_xdata(), trace.get_ydata()], tips[:, [i, j]])
    executed_trace = _line(ax, "executed tip trace (PyBullet)")
    assert len(executed_trace.get_xdata()) == len(executed)
    ghosts = [line for line in ax.get_lines() if line.get_color() == "0.55"]
    assert len(ghosts) >= 3  # intermediate poses


def test_progress_figure_names_each_planner_and_shows_the_escape(plans) -> None:
    fig = trace_figure([plans["gradient"].legs[0], plans["gradient+rrtconnect"].legs[0]], "t")
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    # the planners' lines, and what the cross means (the gradient method stalls)
    assert labels == ["gradient", "stalled in a local minimum", "gradient+rrtconnect"]
    assert ax.get_ylim()[0] == 0.0  # a distance: the axis never goes below 0
    hybrid = _line(ax, "gradient+rrtconnect")
    y = np.asarray(hybrid.get_ydata())
    assert y[-1] == 0.0 and y.max() > 1.0  # the drop: stalled far outside, then in
    stalled = _line(ax, "gradient")
    assert np.asarray(stalled.get_ydata())[-1] > 1.0
    # times start at each planner's own 0 (not strung along one axis)
    assert np.asarray(stalled.get_xdata())[0] < 0.5 and np.asarray(hybrid.get_xdata())[0] < 0.5


def test_progress_figure_of_an_ompl_plan_is_not_blank(problem) -> None:
    plan = solve_legs(
        problem, "ompl.rrtconnect", 0, budget=problem.budget.replace(max_collision_checks=CHECKS)
    )
    fig = progress_figure({"ompl.rrtconnect": list(plan.legs)}, "t")
    line = _line(fig.axes[0], "ompl.rrtconnect")
    y = np.asarray(line.get_ydata())
    assert len(y) >= 2 and y[0] > 1.0
    assert (y[-1] == 0.0) == plan.legs[0].solved


def test_animation_frames_end_where_pybullet_ended(problem, plans, tmp_path) -> None:
    plan = plans["gradient+rrtconnect"]
    r = plan.legs[0]
    actual = np.array(r.path) + 0.01  # PyBullet lagging a little behind the plan
    q_final = actual[-1] + 0.02
    e = SimpleNamespace(
        leg=r.leg,
        q_cmd_rad=np.array(r.path),
        q_actual_rad=actual,
        q_final_rad=q_final,
        success=True,
        final_pos_err_m=0.004,
        reason="",
    )
    frames = motion_frames(problem, plan.legs, [e], max_frames=8)
    assert 2 <= len(frames) <= 10
    assert frames[-1].final and np.array_equal(frames[-1].q_executed, q_final)
    fig, update = animation_figure(problem, frames, "t", [e])
    update(len(frames) - 1)
    ax, (i, j) = _views(fig)["top (x-y)"]
    arm = _line(ax, "PyBullet's arm (link axes)")
    np.testing.assert_allclose(arm.get_xdata(), chain_points(problem, q_final)[:, i])
    assert "where PyBullet's arm ended" in fig._suptitle.get_text()
    update(0)
    np.testing.assert_allclose(
        _line(ax, "planned arm (link axes)").get_ydata(), chain_points(problem, r.path[0])[:, j]
    )
    gif = write_animation(fig, update, len(frames), tmp_path / "a.gif", fps=4, hold_s=0)
    with Image.open(gif) as im:
        assert im.n_frames >= 2
        im.seek(0)
        first = np.asarray(im.convert("RGB"), dtype=int)
        im.seek(im.n_frames - 1)
        last = np.asarray(im.convert("RGB"), dtype=int)
    assert np.abs(first - last).sum() > 0  # the arm moved


@pytest.mark.skipif(animation.writers.is_available("ffmpeg"), reason="ffmpeg is installed")
def test_mp4_without_ffmpeg_is_a_clear_error(problem, plans, tmp_path) -> None:
    frames = motion_frames(problem, plans["gradient"].legs, [], max_frames=3)
    fig, update = animation_figure(problem, frames, "t")
    with pytest.raises(PlannerlabError, match="ffmpeg"):
        write_animation(fig, update, len(frames), tmp_path / "a.mp4")


def test_animate_cli_executes_a_plan_without_record(problem, plans, tmp_path, capsys) -> None:
    plan_file = plans["gradient+rrtconnect"].save(tmp_path / "plan.json")
    code = main(["animate", str(plan_file), "--frames", "4", "--fps", "4", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["executed"] is True
    with Image.open(out["animation"]) as im:
        assert im.format == "GIF" and im.n_frames >= 2


def test_gui_without_display_is_a_clear_error(monkeypatch, capsys) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    if not sys.platform.startswith("linux"):
        pytest.skip("DISPLAY is an X11 matter")
    code = main(["solve", "armz_pocket", "--planner", "gradient", "--gui"])
    assert code == 2
    err = capsys.readouterr().err
    assert "needs a display" in err and "DISPLAY" in err

"""Animations of a plan: the planned and the executed motion, frame by frame.

Three panels, as in the static figures (:mod:`plannerlab.plot.plans`): 3D, the paper's
front (x-z) and top (x-y) views, with the obstacles and the goal regions. Each frame shows
the arm where the plan puts it (blue) and, when the plan was executed, where PyBullet's
arm was at that moment (orange), with both tip traces growing behind them. The last frames
hold where PyBullet's arm really ended and say how far from the goal that was.

Drawn with matplotlib (no display needed); written as GIF by Pillow, or MP4 when ffmpeg
is on the machine. Why matplotlib rather than PyBullet's offscreen TinyRenderer: the
paper's orthographic front and top views, the goal regions and the tip traces are what
show whether a motion went round an obstacle or stalled against it; a shaded perspective
image of a 23-module chain hides exactly that, and TinyRenderer takes seconds per frame on
a CPU.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from plannerlab.errors import PlannerlabError
from plannerlab.plot.plans import (
    EXECUTED,
    PLANNED,
    _figure,
    _xy,
    chain_points,
    draw_goals,
    draw_scene_2d,
    draw_scene_3d,
    execution_verdict,
    motion_axes,
    scene_bounds,
    tip_points,
)
from plannerlab.problem.load import Problem
from plannerlab.robots.base import Array
from plannerlab.robots.paths import densify


@dataclass(frozen=True)
class Frame:
    """One frame: the leg, the planned state, the executed state (None: not executed)."""

    leg: int
    goal: str
    q_planned: Array
    q_executed: Array | None
    final: bool = False


def motion_frames(
    problem: Problem, legs: Sequence[Any], executions: Sequence[Any], max_frames: int = 90
) -> list[Frame]:
    """Frames along every leg, about ``max_frames`` in all (shared by leg length, at least
    two a leg). With an execution, a leg's frames pair each commanded waypoint with the
    state PyBullet logged for it; the last frame of an executed leg is where its arm
    settled (``q_final_rad``). Without one, the planned path is densified at the
    problem's joint step."""
    by_leg = {e.leg: e for e in executions}
    tracks: list[tuple[Any, Array, Array | None, Any]] = []
    for r in legs:
        e = by_leg.get(r.leg)
        if e is not None and len(e.q_cmd_rad):
            tracks.append((r, np.asarray(e.q_cmd_rad), np.asarray(e.q_actual_rad), e))
        else:
            dense, _ = densify(np.asarray(r.path), problem.joint_step, problem.robot.continuous)
            tracks.append((r, dense, None, None))
    total = sum(len(t[1]) for t in tracks)
    frames: list[Frame] = []
    for r, planned, actual, e in tracks:
        n = int(np.clip(round(max_frames * len(planned) / max(total, 1)), 2, len(planned)))
        for i in np.unique(np.linspace(0, len(planned) - 1, n).round().astype(int)):
            q_exec = None if actual is None else actual[i]
            frames.append(Frame(r.leg, r.goal, planned[i], q_exec))
        if e is not None:
            frames.append(Frame(r.leg, r.goal, planned[-1], np.asarray(e.q_final_rad), True))
    return frames


def animation_figure(
    problem: Problem,
    frames: Sequence[Frame],
    title: str,
    executions: Sequence[Any] = (),
) -> tuple[Figure, Callable[[int], list[Any]]]:
    """The figure and ``update(i)``, which draws frame ``i`` (and returns the artists it
    changed). Limits are fixed over the animation: the scene, both motions, the goals."""
    planned_all = np.array([f.q_planned for f in frames])
    executed = [f for f in frames if f.q_executed is not None]
    executed_all = np.array([f.q_executed for f in executed]) if executed else None
    tips_p = tip_points(problem, planned_all)
    tips_e = tip_points(problem, executed_all) if executed_all is not None else None
    pts = [tips_p, chain_points(problem, planned_all[0])]
    pts += [chain_points(problem, q) for q in planned_all[:: max(len(frames) // 8, 1)]]
    if executed_all is not None and tips_e is not None:
        pts += [tips_e, chain_points(problem, executed_all[-1])]
    bounds = scene_bounds(problem, np.concatenate(pts))
    fig = _figure(bounds)
    ax3, views = motion_axes(fig, bounds)
    panels: list[tuple[Any, tuple[int, int] | None]] = [(ax3, None), *views]
    draw_scene_3d(ax3, problem)
    draw_goals(ax3, problem, None)
    for ax, dims in views:
        draw_scene_2d(ax, problem, dims)
        draw_goals(ax, problem, dims)
    arms_p, arms_e, trace_p, trace_e = [], [], [], []
    for ax, _dims in panels:
        (tp,) = ax.plot(
            [],
            [],
            *([[]] if ax is ax3 else []),
            color=PLANNED,
            lw=1.0,
            ls="--",
            label="planned tip trace",
        )
        (te,) = ax.plot(
            [],
            [],
            *([[]] if ax is ax3 else []),
            color=EXECUTED,
            lw=1.2,
            label="executed tip trace (PyBullet)",
        )
        (ap,) = ax.plot(
            [],
            [],
            *([[]] if ax is ax3 else []),
            color=PLANNED,
            lw=1.6,
            marker="o",
            ms=2,
            label="planned arm",
            zorder=6,
        )
        (ae,) = ax.plot(
            [],
            [],
            *([[]] if ax is ax3 else []),
            color=EXECUTED,
            lw=4.0,
            alpha=0.7,
            label="PyBullet's arm",
            zorder=5,
        )
        trace_p.append(tp)
        trace_e.append(te)
        arms_p.append(ap)
        arms_e.append(ae)
    handles, labels = views[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncols=4, fontsize=8, frameon=False)
    heading = fig.suptitle(title, fontsize=10)
    by_leg = {e.leg: e for e in executions}
    exec_index = np.cumsum([f.q_executed is not None for f in frames]) - 1

    def set_line(line: Any, points: Array | None, dims: tuple[int, int] | None) -> None:
        if points is None or len(points) == 0:
            points = np.zeros((0, 3))
        data = _xy(points, dims)
        if dims is None:
            line.set_data_3d(*data)
        else:
            line.set_data(*data)

    def update(i: int) -> list[Any]:
        f = frames[i]
        chain_p = chain_points(problem, f.q_planned)
        chain_e = None if f.q_executed is None else chain_points(problem, f.q_executed)
        k = int(exec_index[i])
        for (_ax, dims), ap, ae, tp, te in zip(
            panels, arms_p, arms_e, trace_p, trace_e, strict=True
        ):
            set_line(ap, chain_p, dims)
            set_line(ae, chain_e, dims)
            set_line(tp, tips_p[: i + 1], dims)
            set_line(te, None if tips_e is None or k < 0 else tips_e[: k + 1], dims)
        text = f"{title}\nleg {f.leg} '{f.goal}'"
        e = by_leg.get(f.leg)
        if f.final and e is not None:
            text += f": where PyBullet's arm ended, {execution_verdict(e)}"
        elif f.q_executed is None:
            text += ": planned motion (not executed)"
        heading.set_text(text)
        return [*arms_p, *arms_e, *trace_p, *trace_e, heading]

    update(0)
    return fig, update


def write_animation(
    fig: Figure,
    update: Callable[[int], list[Any]],
    n_frames: int,
    path: str | Path,
    fps: int = 12,
    hold_s: float = 1.5,
    dpi: int = 80,
) -> Path:
    """Write the frames (the last one held ``hold_s``) to ``path``: ``.gif`` by Pillow,
    ``.mp4`` by ffmpeg (an error when ffmpeg is not installed)."""
    from matplotlib import animation

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".gif":
        writer: Any = animation.PillowWriter(fps=fps)
    elif suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise PlannerlabError(
                f"{path}: MP4 needs ffmpeg on the PATH (not found); write a .gif instead"
            )
        writer = animation.FFMpegWriter(fps=fps, codec="h264")
    else:
        raise PlannerlabError(f"{path}: expected a .gif or .mp4 file name")
    order = list(range(n_frames)) + [n_frames - 1] * max(int(hold_s * fps) - 1, 0)
    path.parent.mkdir(parents=True, exist_ok=True)
    with writer.saving(fig, str(path), dpi=dpi):
        for i in order:
            update(i)
            writer.grab_frame()
    return path


def animate_plan(
    plan: Any,
    problem: Problem,
    path: str | Path,
    executions: Sequence[Any] = (),
    max_frames: int = 90,
    fps: int = 12,
) -> Path:
    """Animate a plan (with its executions, if any) into ``path`` (.gif or .mp4)."""
    frames = motion_frames(problem, plan.legs, executions, max_frames)
    title = f"{plan.planner} on {plan.problem} (seed {plan.seed})"
    fig, update = animation_figure(problem, frames, title, executions)
    return write_animation(fig, update, len(frames), path, fps=fps)


__all__ = ["Frame", "animate_plan", "animation_figure", "motion_frames", "write_animation"]

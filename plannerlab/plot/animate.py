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
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from plannerlab.errors import PlannerlabError
from plannerlab.plot.plans import (
    EXECUTED,
    PLANNED,
    _figure,
    _xy,
    capsule_outlines,
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


def capsule_collections(
    panels: Sequence[tuple[Any, tuple[int, int] | None]], has_exec: bool
) -> tuple[list[Any], list[Any]]:
    """Per panel, the (empty) collections the planned and the executed links' capsules are
    drawn in: lines as wide as the links in 3-D, the capsules' outlines in the 2-D views;
    PyBullet's filled orange, the plan's blue outline on top (filled when there is no
    execution)."""
    caps_p, caps_e = [], []
    for ax, dims in panels:
        if dims is None:
            cp: Any = Line3DCollection(
                [], colors=[PLANNED], alpha=0.25 if has_exec else 0.6, capstyle="round", zorder=4
            )
            ce: Any = Line3DCollection(
                [], colors=[EXECUTED], alpha=0.55, capstyle="round", zorder=3
            )
        else:
            cp = PolyCollection(
                [],
                facecolors="none" if has_exec else PLANNED,
                edgecolors=PLANNED,
                linewidths=0.9,
                alpha=0.9 if has_exec else 0.45,
                zorder=5,
            )
            ce = PolyCollection(
                [], facecolors=EXECUTED, edgecolors=EXECUTED, linewidths=0.5, alpha=0.45, zorder=4
            )
        ax.add_collection(cp)
        ax.add_collection(ce)
        caps_p.append(cp)
        caps_e.append(ce)
    return caps_p, caps_e


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
            label="planned arm (link axes)",
            zorder=6,
        )
        (ae,) = ax.plot(
            [],
            [],
            *([[]] if ax is ax3 else []),
            color=EXECUTED,
            lw=1.0,
            alpha=0.9,
            label="PyBullet's arm (link axes)",
            zorder=5,
        )
        trace_p.append(tp)
        trace_e.append(te)
        arms_p.append(ap)
        arms_e.append(ae)
    # the links' capsules with their radii: PyBullet's filled orange, the plan's blue
    # outline on top (filled when there is no execution), so both show where they agree
    radii = np.asarray(problem.robot.link_radii_m, dtype=float)
    has_exec = executed_all is not None
    caps_p, caps_e = capsule_collections(panels, has_exec)
    handles, labels = views[0][0].get_legend_handles_labels()
    handles += [
        Patch(
            facecolor="none" if has_exec else PLANNED,
            edgecolor=PLANNED,
            alpha=0.9 if has_exec else 0.45,
        ),
        Patch(facecolor=EXECUTED, edgecolor=EXECUTED, alpha=0.45),
    ]
    labels += ["planned links (capsules, true radii)", "PyBullet's links (capsules)"]
    if not has_exec:
        handles, labels = handles[:-1], labels[:-1]
    fig.legend(handles, labels, loc="outside lower center", ncols=3, fontsize=8, frameon=False)
    heading = fig.suptitle(f"{title}\n ", fontsize=10)  # room for the leg's line
    # lay the figure out once: constrained layout on every frame took a third of the time
    FigureCanvasAgg(fig).draw()
    fig.set_layout_engine("none")
    # capsule widths in the 3-D panel: the panel's points per metre along its widest side
    box = ax3.get_window_extent()
    span_m = float(np.max(bounds[1] - bounds[0]))
    pts_per_m = 0.75 * min(box.width, box.height) * 72.0 / fig.dpi / max(span_m, 1e-9)
    widths_3d = np.maximum(2.0 * radii * pts_per_m, 0.8)
    caps_p[0].set_linewidths(widths_3d)
    caps_e[0].set_linewidths(widths_3d)
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

    def set_capsules(coll: Any, seg: Array | None, dims: tuple[int, int] | None) -> None:
        if dims is None:
            coll.set_segments([] if seg is None else list(seg))
        else:
            coll.set_verts(
                [] if seg is None else list(capsule_outlines(seg[:, :, list(dims)], radii))
            )

    def update(i: int) -> list[Any]:
        f = frames[i]
        chain_p = chain_points(problem, f.q_planned)
        chain_e = None if f.q_executed is None else chain_points(problem, f.q_executed)
        seg_p = np.asarray(problem.robot.link_segments(f.q_planned), dtype=float)
        seg_e = (
            None
            if f.q_executed is None
            else np.asarray(problem.robot.link_segments(f.q_executed), dtype=float)
        )
        k = int(exec_index[i])
        for (_ax, dims), ap, ae, tp, te, cp, ce in zip(
            panels, arms_p, arms_e, trace_p, trace_e, caps_p, caps_e, strict=True
        ):
            set_line(ap, chain_p, dims)
            set_line(ae, chain_e, dims)
            set_line(tp, tips_p[: i + 1], dims)
            set_line(te, None if tips_e is None or k < 0 else tips_e[: k + 1], dims)
            set_capsules(cp, seg_p, dims)
            set_capsules(ce, seg_e, dims)
        text = f"{title}\nleg {f.leg} '{f.goal}'"
        e = by_leg.get(f.leg)
        if f.final and e is not None:
            text += f": where PyBullet's arm ended, {execution_verdict(e)}"
        elif f.q_executed is None:
            text += ": planned motion (not executed)"
        heading.set_text(text)
        return [*caps_e, *caps_p, *trace_p, *trace_e, *arms_e, *arms_p, heading]

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
    ``.mp4`` by ffmpeg (an error when ffmpeg is not installed).

    A GIF is blitted: what does not move (axes, ticks, scene, goals) is drawn once, and
    each frame redraws only the artists ``update`` returns onto a copy of it."""
    from matplotlib import animation

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise PlannerlabError(f"{path}: expected a .gif or .mp4 file name")
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise PlannerlabError(
                f"{path}: MP4 needs ffmpeg on the PATH (not found); write a .gif instead"
            )
        writer: Any = animation.FFMpegWriter(fps=fps, codec="h264")
        order = list(range(n_frames)) + [n_frames - 1] * max(int(hold_s * fps) - 1, 0)
        with writer.saving(fig, str(path), dpi=dpi):
            for i in order:
                update(i)
                writer.grab_frame()
        return path
    from PIL import Image

    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    moving = update(0)
    for a in moving:
        a.set_animated(True)
    try:
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        images = []
        for i in range(n_frames):
            canvas.restore_region(background)
            for a in update(i):
                if hasattr(a, "do_3d_projection"):  # a 3-D collection: project it first
                    a.do_3d_projection()
                (a.axes or fig).draw_artist(a)
            w, h = canvas.get_width_height()
            rgb = Image.frombuffer("RGBA", (w, h), bytes(canvas.buffer_rgba())).convert("RGB")
            images.append(rgb.quantize(colors=255, method=Image.Quantize.MEDIANCUT))
    finally:
        for a in moving:
            a.set_animated(False)
    frame_ms = 1000.0 / fps
    durations = [frame_ms] * (n_frames - 1) + [frame_ms + 1000.0 * hold_s]
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=durations, loop=0, disposal=1
    )
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

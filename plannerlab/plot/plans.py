"""Figures with matplotlib.

Figures are built as :class:`matplotlib.figure.Figure` objects without pyplot, so nothing
here touches the global backend or pyplot's figure list: the CLI saves them to PNG files,
a notebook displays them.

The arm is drawn as its chain of capsule axes; obstacles as wireframes (3D) and filled
projections (2D). Each snapshot has three panels: 3D, a front view (x–z) and a top view
(x–y), like the paper's Fig. 6.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from scipy.spatial import ConvexHull

from plannerlab.problem.load import Problem
from plannerlab.problem.scene import Box, Cylinder, Obstacle
from plannerlab.robots.base import Array

VIEWS = {"front (x-z)": (0, 2), "top (x-y)": (0, 1)}


def obstacle_points(o: Obstacle, n: int = 24) -> Array:
    """Points on an obstacle's surface (m, 3) in the world, enough for hulls and bounds."""
    T = o.T_world_obstacle
    if isinstance(o, Box):
        h = o.size_m / 2.0
        local = np.array(list(itertools.product(*[(-v, v) for v in h])))
    elif isinstance(o, Cylinder):
        a = np.linspace(0, 2 * np.pi, n, endpoint=False)
        ring = np.stack([o.radius_m * np.cos(a), o.radius_m * np.sin(a)], axis=1)
        local = np.concatenate(
            [np.c_[ring, np.full(n, z)] for z in (-o.length_m / 2, o.length_m / 2)]
        )
    else:
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2))
        local = o.radius_m * np.stack(
            [np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1
        ).reshape(-1, 3)
    return local @ T[:3, :3].T + T[:3, 3]


def _box_edges(o: Box) -> list[Array]:
    pts = obstacle_points(o)
    edges = []
    for i, j in itertools.combinations(range(8), 2):
        if bin(i ^ j).count("1") == 1:
            edges.append(pts[[i, j]])
    return edges


def draw_scene_3d(ax: Any, problem: Problem, skip: Sequence[str] = ("ground",)) -> None:
    for o in problem.scene.obstacles:
        if o.name in skip:
            continue
        if isinstance(o, Box):
            for e in _box_edges(o):
                ax.plot(*e.T, color="0.55", lw=0.6)
        else:
            pts = obstacle_points(o)
            ax.plot(*pts.T, color="0.55", lw=0.4)


def draw_scene_2d(
    ax: Any, problem: Problem, dims: tuple[int, int], skip: Sequence[str] = ("ground",)
) -> None:
    for o in problem.scene.obstacles:
        if o.name in skip:
            continue
        pts = obstacle_points(o)[:, dims]
        try:
            hull = pts[ConvexHull(pts).vertices]
        except Exception:  # degenerate projection (a flat box seen edge-on)
            continue
        ax.fill(*hull.T, color="0.8", alpha=0.5, lw=0.5, edgecolor="0.5")


#: colours: the plan, what PyBullet did, intermediate poses
PLANNED = "tab:blue"
EXECUTED = "tab:orange"
GHOST = "0.55"


def chain_points(problem: Problem, q: Array) -> Array:
    """The arm's chain of capsule axes as points (L + 1, 3) in the world [m]."""
    seg = problem.robot.link_segments(np.asarray(q, dtype=float))  # (L, 2, 3)
    return np.concatenate([seg[:, 0], seg[-1:, 1]])


def capsule_outlines(segments_2d: Array, radii_m: Array, k: int = 10) -> Array:
    """The outlines (L, 2k, 2) of capsules seen along a world axis: the projection of a
    capsule of radius r about the axis a-b is the "stadium" of radius r about the
    projected axis (exact in the orthographic front and top views); a zero-length axis
    gives a circle. ``segments_2d``: (L, 2, 2) projected axis end points [m]."""
    seg = np.asarray(segments_2d, dtype=float)
    r = np.asarray(radii_m, dtype=float)[:, None, None]
    a, b = seg[:, 0], seg[:, 1]
    d = b - a
    n = np.linalg.norm(d, axis=1, keepdims=True)
    u = np.where(n > 1e-12, d / np.where(n > 1e-12, n, 1.0), [[1.0, 0.0]])
    v = np.stack([-u[:, 1], u[:, 0]], axis=1)
    t_b = np.linspace(-np.pi / 2, np.pi / 2, k)
    t_a = t_b + np.pi

    def ring(c: Array, t: Array) -> Array:
        cos, sin = np.cos(t)[None, :, None], np.sin(t)[None, :, None]
        return c[:, None] + r * (cos * u[:, None] + sin * v[:, None])

    return np.concatenate([ring(b, t_b), ring(a, t_a)], axis=1)


def tip_points(problem: Problem, path: Array) -> Array:
    """Tip positions (m, 3) in the world [m] along a joint path (m, dof)."""
    p, _n = problem.robot.tip(np.atleast_2d(np.asarray(path, dtype=float)))
    return np.atleast_2d(p)


def _xy(points: Array, dims: tuple[int, int] | None) -> list[Array]:
    points = np.atleast_2d(points)
    return (
        [points[:, 0], points[:, 1], points[:, 2]]
        if dims is None
        else [
            points[:, dims[0]],
            points[:, dims[1]],
        ]
    )


def draw_arm(
    ax: Any,
    problem: Problem,
    q: Array,
    dims: tuple[int, int] | None,
    color: Any,
    label: str | None = None,
    *,
    lw: float = 2.5,
    alpha: float = 1.0,
    ls: str = "-",
    zorder: float = 3,
) -> Any:
    """The arm at q as a polyline through its capsule axes (the Line2D/Line3D); in a 2-D
    view a main pose (``lw`` >= 2) also gets its links' capsules with their true radii
    (:func:`capsule_outlines`), lightly filled in its colour."""
    if dims is not None and lw >= 2:
        from matplotlib.collections import PolyCollection

        seg = np.asarray(problem.robot.link_segments(np.asarray(q, dtype=float)))
        outlines = capsule_outlines(seg[:, :, list(dims)], problem.robot.link_radii_m)
        ax.add_collection(
            PolyCollection(
                list(outlines),
                facecolors=color,
                edgecolors=color,
                linewidths=0.4,
                alpha=0.22 * alpha,
                zorder=zorder - 0.5,
            )
        )
    (line,) = ax.plot(
        *_xy(chain_points(problem, q), dims),
        color=color,
        lw=lw,
        ls=ls,
        marker="o" if lw >= 2 else None,
        ms=2.5,
        alpha=alpha,
        label=label,
        zorder=zorder,
    )
    return line


def draw_trace(
    ax: Any, points: Array, dims: tuple[int, int] | None, color: Any, label: str, ls: str = "-"
) -> Any:
    """A tip trace (points (m, 3)) as a thin line."""
    (line,) = ax.plot(*_xy(points, dims), color=color, lw=1.2, ls=ls, label=label, zorder=4)
    return line


def draw_goals(ax: Any, problem: Problem, dims: tuple[int, int] | None) -> None:
    """Goal regions: the target, a circle of the position tolerance, the normal, the name."""
    a = np.linspace(0.0, 2 * np.pi, 48)
    for g in problem.goals:
        p, n, r = g.p_world_m, g.n_world, g.pos_tol_m
        if dims is None:
            ax.scatter(*p, color="crimson", s=12, depthshade=False)
            ax.quiver(*p, *(0.5 * n), color="crimson", lw=1)
            ax.text(*p, f" {g.name}", fontsize=7, color="crimson")
        else:
            i, j = dims
            ax.plot(p[i] + r * np.cos(a), p[j] + r * np.sin(a), color="crimson", lw=0.8)
            ax.annotate(
                "",
                xy=(p[i] + 0.5 * n[i], p[j] + 0.5 * n[j]),
                xytext=(p[i], p[j]),
                arrowprops={"arrowstyle": "->", "color": "crimson", "lw": 0.8},
            )
            ax.annotate(f" {g.name}", (p[i], p[j]), fontsize=7, color="crimson")


def scene_bounds(problem: Problem, points: Array, skip: Sequence[str] = ("ground",)) -> Array:
    """(2, 3) lower and upper corner of what a figure shows: the given points (arm, tip
    traces), the goals and the obstacles (the ground left out), padded by 5 %."""
    parts = [np.atleast_2d(points)] + [g.p_world_m[None] for g in problem.goals]
    parts += [obstacle_points(o) for o in problem.scene.obstacles if o.name not in skip]
    allp = np.concatenate(parts)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.05 * max(float(np.max(hi - lo)), 1e-3)
    return np.stack([lo - pad, hi + pad])


def motion_axes(fig: Figure, bounds: Array) -> tuple[Any, list[tuple[Any, tuple[int, int]]]]:
    """The three panels (3D, front x-z, top x-y) sized to the scene: equal scales, each
    2D panel as wide as its view needs, few 3D ticks (no overlapping labels)."""
    from matplotlib.ticker import MaxNLocator

    gs = fig.add_gridspec(1, 3, width_ratios=_width_ratios(bounds))
    ax3 = fig.add_subplot(gs[0, 0], projection="3d")
    ax3.set_xlim(bounds[0, 0], bounds[1, 0])
    ax3.set_ylim(bounds[0, 1], bounds[1, 1])
    ax3.set_zlim(bounds[0, 2], bounds[1, 2])
    ax3.set_box_aspect(tuple(np.maximum(bounds[1] - bounds[0], 1e-3)), zoom=0.95)
    for axis in (ax3.xaxis, ax3.yaxis, ax3.zaxis):
        axis.set_major_locator(MaxNLocator(3))
    ax3.tick_params(labelsize=6, pad=0)
    ax3.set_xlabel("x [m]", fontsize=7, labelpad=-6)
    ax3.set_ylabel("y [m]", fontsize=7, labelpad=-6)
    ax3.set_zlabel("z [m]", fontsize=7, labelpad=-6)
    ax3.view_init(elev=22, azim=-60)
    views = []
    for k, (view, dims) in enumerate(VIEWS.items()):
        ax = fig.add_subplot(gs[0, k + 1])
        ax.set_xlim(bounds[0, dims[0]], bounds[1, dims[0]])
        ax.set_ylim(bounds[0, dims[1]], bounds[1, dims[1]])
        ax.set_aspect("equal", adjustable="box")
        ax.set_title(view, fontsize=9)
        ax.set_xlabel("xyz"[dims[0]] + " [m]", fontsize=8)
        ax.set_ylabel("xyz"[dims[1]] + " [m]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
        views.append((ax, dims))
    return ax3, views


def _width_ratios(bounds: Array) -> list[float]:
    """Panel widths for equal panel heights: each view as wide as its scene (clipped)."""
    span = np.maximum(bounds[1] - bounds[0], 1e-3)
    flat = float(np.sqrt(max(span[0], span[1]) / span[2]))
    views = [float(np.clip(span[i] / span[j], 0.25, 3.0)) for i, j in VIEWS.values()]
    # the 3-D panel at least as wide as the wider view (it was ~250 px in a GIF)
    return [max(float(np.clip(1.3 * flat, 0.8, 2.0)), max(views))] + views


def _figure(bounds: Array, height_in: float = 5.0) -> Figure:
    width_in = min(height_in * sum(_width_ratios(bounds)) + 0.6, 16.0)
    return Figure(figsize=(width_in, height_in), layout="constrained")


def snapshot_figure(
    problem: Problem,
    states: Sequence[tuple[str, Array] | tuple[str, Array, Any]],
    title: str,
    *,
    path: Array | None = None,
    executed: Array | None = None,
    ghosts: int = 6,
) -> Figure:
    """The arm in one or more labelled states (``(label, q)`` or ``(label, q, colour)``)
    in 3D, front and top views, with the obstacles and goal regions. ``path``: a planned
    joint path, drawn as ``ghosts`` intermediate poses and its tip trace (dashed);
    ``executed``: the joint trajectory PyBullet followed, drawn as its tip trace."""
    palette = colormaps["viridis"](np.linspace(0.0, 0.85, max(len(states), 1)))
    items = [
        (s[0], np.asarray(s[1], dtype=float), s[2] if len(s) > 2 else palette[k])
        for k, s in enumerate(states)
    ]
    pts = [chain_points(problem, q) for _, q, _ in items]
    planned_tip = tip_points(problem, path) if path is not None and len(path) > 1 else None
    executed_tip = (
        tip_points(problem, executed) if executed is not None and len(executed) > 1 else None
    )
    pts += [t for t in (planned_tip, executed_tip) if t is not None]
    ghost_qs: list[Array] = []
    if path is not None and len(path) > 2 and ghosts > 0:
        idx = np.unique(np.linspace(0, len(path) - 1, ghosts + 2).round().astype(int))[1:-1]
        ghost_qs = [np.asarray(path[i], dtype=float) for i in idx]
        pts += [chain_points(problem, q) for q in ghost_qs]
    bounds = scene_bounds(problem, np.concatenate(pts))
    fig = _figure(bounds)
    ax3, views = motion_axes(fig, bounds)
    draw_scene_3d(ax3, problem)
    draw_goals(ax3, problem, None)
    for ax_2d, dims_2d in views:
        draw_scene_2d(ax_2d, problem, dims_2d)
        draw_goals(ax_2d, problem, dims_2d)
    panels: list[tuple[Any, tuple[int, int] | None]] = [(ax3, None), *views]
    for ax, dims in panels:
        for k, q in enumerate(ghost_qs):
            draw_arm(
                ax,
                problem,
                q,
                dims,
                GHOST,
                "planned, on the way" if k == 0 else None,
                lw=1.0,
                alpha=0.6,
                zorder=2,
            )
        if planned_tip is not None:
            draw_trace(ax, planned_tip, dims, PLANNED, "planned tip trace", ls="--")
        if executed_tip is not None:
            draw_trace(ax, executed_tip, dims, EXECUTED, "executed tip trace (PyBullet)")
        for label, q, color in items:
            # PyBullet's arm wide and under, the others on top: both show where they agree
            wide = isinstance(color, str) and color == EXECUTED
            draw_arm(
                ax, problem, q, dims, color, label, lw=4.5 if wide else 2.5, zorder=3 if wide else 4
            )
    handles, labels = views[0][0].get_legend_handles_labels()
    fig.legend(
        handles,
        labels,
        loc="outside lower center",
        ncols=min(len(labels), 4),
        fontsize=8,
        frameon=False,
    )
    fig.suptitle(title, fontsize=10)
    return fig


def _leg_offsets(results: Sequence[Any]) -> list[float]:
    out, t = [], 0.0
    for r in results:
        out.append(t)
        t += float(r.time_s) if np.isfinite(r.time_s) else 0.0
    return out


def progress_figure(runs: Mapping[str, Sequence[Any]], title: str) -> Figure:
    """Best goal distance over time, one named curve per planner (its legs one after
    another), from each result's ``progress``; a cross marks a leg that stalled in a
    local minimum. Beside it, for planners that record one, the objective per iteration
    (one curve per planner, each from its own iteration 0)."""
    with_trace = {
        name: rs
        for name, rs in runs.items()
        if any(len(r.trace) > 1 for r in rs) and name.startswith("gradient")
    }
    fig = Figure(figsize=(11 if with_trace else 7, 4.6), layout="constrained")
    ax = fig.add_subplot(1, 2 if with_trace else 1, 1)
    colors = colormaps["tab10"](np.arange(len(runs)) % 10)
    for (name, results), color in zip(runs.items(), colors, strict=True):
        xs, ys = [], []
        for r, t0 in zip(results, _leg_offsets(results), strict=True):
            rows = np.asarray(r.progress, dtype=float).reshape(-1, 4)
            if len(rows):
                xs.append(t0 + rows[:, 0])
                ys.append(rows[:, 2])
        if not xs:
            continue
        x, y = np.concatenate(xs), np.concatenate(ys)
        ax.step(x, y, where="post", color=color, label=name, lw=1.5)
        for r, t0 in zip(results, _leg_offsets(results), strict=True):
            if r.status.value == "local_minimum" and len(r.progress):
                labelled = "stalled in a local minimum" in ax.get_legend_handles_labels()[1]
                ax.scatter(
                    t0 + r.progress[-1, 0],
                    r.progress[-1, 2],
                    marker="x",
                    color="k",
                    zorder=5,
                    label=None if labelled else "stalled in a local minimum",
                )
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("planning time [s] (legs one after another)")
    ax.set_ylabel("best goal distance [x tolerance; 0: in the goal]")
    ax.text(
        0.0,
        -0.2,
        "goal distance: max(position error / pos_tol, angle error / angle_tol) - 1 for a "
        "tip goal,\nmax |q - q_goal| / tol_rad - 1 for a joint goal: a leg to a joint goal "
        "(small tol_rad)\nstarts in the hundreds; that jump is its scale, not a step back",
        transform=ax.transAxes,
        fontsize=7,
        va="top",
        color="0.3",
    )
    ax.set_title("progress", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if with_trace:
        ax2 = fig.add_subplot(1, 2, 2)
        for (name, results), color in zip(runs.items(), colors, strict=True):
            if name not in with_trace:
                continue
            f = np.concatenate([np.asarray(r.trace, dtype=float) for r in results])
            ax2.plot(np.arange(len(f)), np.maximum(f, 1e-6), color=color, label=name)
        ax2.set_yscale("log")
        ax2.set_xlabel("iteration")
        ax2.set_ylabel("objective f")
        ax2.set_title("gradient descent: f per iteration", fontsize=9)
        ax2.grid(alpha=0.3)
        ax2.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return fig


def trace_figure(results: Sequence[Any], title: str) -> Figure:
    """:func:`progress_figure` of results grouped by their planner's name."""
    runs: dict[str, list[Any]] = {}
    for r in results:
        runs.setdefault(r.planner, []).append(r)
    return progress_figure(runs, title)


def save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def execution_verdict(e: Any) -> str:
    """What PyBullet did with a leg, in words for a title."""
    if e.success:
        return f"executed cleanly (tip {e.final_pos_err_m:.3g} m from the target)"
    return f"execution FAILED: ended {e.final_pos_err_m:.3g} m off the goal ({e.reason})"


def leg_figure(plan: Any, problem: Problem, r: Any, execution: Any | None = None) -> Figure:
    """One leg: its start, intermediate poses, planned tip trace and planned end (or
    stall); with ``execution``, where PyBullet's arm really ended and its tip's trace,
    and the execution's verdict in the title."""
    tag = "stall" if r.status.value == "local_minimum" else "end"
    states: list[tuple[str, Array, Any]] = [
        ("leg start", r.path[0], "0.25"),
        (f"planned {tag}: {r.status.value}", r.path[-1], PLANNED),
    ]
    verdict = ""
    executed = None
    if execution is not None:
        states.append(("executed end (PyBullet)", execution.q_final_rad, EXECUTED))
        executed = execution.q_actual_rad
        verdict = "\n" + execution_verdict(execution)
    return snapshot_figure(
        problem,
        states,
        f"{plan.planner} on {plan.problem} (seed {plan.seed}): leg {r.leg} '{r.goal}', "
        f"planned: {r.status.value} after {r.iterations} iterations{verdict}",
        path=r.path,
        executed=executed,
    )


def plot_plan(
    plan: Any, problem: Problem, out_dir: str | Path, executions: Sequence[Any] = ()
) -> list[Path]:
    """PNG files for a plan: the start; per leg its start, intermediate poses, tip trace
    and planned end (and, with ``executions``, where PyBullet's arm really ended and the
    tip's executed trace); ``trace.png``: best goal distance over time."""
    out_dir = Path(out_dir)
    files = []
    title = f"{plan.planner} on {plan.problem} (seed {plan.seed})"
    files.append(
        save(
            snapshot_figure(problem, [("start", plan.legs[0].path[0])], f"{title}: start"),
            out_dir / "start.png",
        )
    )
    by_leg = {e.leg: e for e in executions}
    for r in plan.legs:
        tag = "stall" if r.status.value == "local_minimum" else "end"
        files.append(
            save(
                leg_figure(plan, problem, r, by_leg.get(r.leg)),
                out_dir / f"leg{r.leg}_{r.goal}_{tag}.png",
            )
        )
    files.append(
        save(
            progress_figure({plan.planner: list(plan.legs)}, f"{title}: progress"),
            out_dir / "trace.png",
        )
    )
    return files

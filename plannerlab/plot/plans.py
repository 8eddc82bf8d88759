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
from collections.abc import Sequence
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


def draw_arm(
    ax: Any,
    problem: Problem,
    q: Array,
    dims: tuple[int, int] | None,
    color: str,
    label: str | None = None,
) -> None:
    seg = problem.robot.link_segments(q)  # (L, 2, 3)
    chain = np.concatenate([seg[:, 0], seg[-1:, 1]])
    if dims is None:
        ax.plot(*chain.T, color=color, lw=2.5, marker="o", ms=2.5, label=label)
    else:
        ax.plot(
            chain[:, dims[0]],
            chain[:, dims[1]],
            color=color,
            lw=2.5,
            marker="o",
            ms=2.5,
            label=label,
        )


def draw_goals(ax: Any, problem: Problem, dims: tuple[int, int] | None) -> None:
    for g in problem.goals:
        p, n = g.p_world_m, g.n_world
        if dims is None:
            ax.scatter(*p, color="crimson", s=12)
            ax.quiver(*p, *n, color="crimson", length=0.8)
            ax.text(*p, f" {g.name}", fontsize=7)
        else:
            ax.scatter(p[dims[0]], p[dims[1]], color="crimson", s=12, zorder=5)
            ax.annotate(f"{g.name}", (p[dims[0]], p[dims[1]]), fontsize=7)


def snapshot_figure(problem: Problem, states: Sequence[tuple[str, Array]], title: str) -> Figure:
    """The arm in one or more states: 3D, front and top views."""
    fig = Figure(figsize=(15, 5))
    colors = colormaps["viridis"](np.linspace(0.0, 0.85, max(len(states), 1)))
    ax3 = fig.add_subplot(1, 3, 1, projection="3d")
    draw_scene_3d(ax3, problem)
    draw_goals(ax3, problem, None)
    for (label, q), c in zip(states, colors, strict=True):
        draw_arm(ax3, problem, q, None, c, label)
    ax3.set_xlabel("x [m]")
    ax3.set_ylabel("y [m]")
    ax3.set_zlabel("z [m]")
    ax3.set_aspect("equal")
    ax3.legend(fontsize=7, loc="upper left")
    for k, (view, dims) in enumerate(VIEWS.items()):
        ax = fig.add_subplot(1, 3, k + 2)
        draw_scene_2d(ax, problem, dims)
        draw_goals(ax, problem, dims)
        for (label, q), c in zip(states, colors, strict=True):
            draw_arm(ax, problem, q, dims, c, label)
        ax.set_aspect("equal")
        ax.set_title(view)
        ax.set_xlabel("xyz"[dims[0]] + " [m]")
        ax.set_ylabel("xyz"[dims[1]] + " [m]")
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def trace_figure(results: Sequence[Any], title: str) -> Figure:
    """Objective (or best goal distance) per iteration, one curve per leg, log scale."""
    fig = Figure(figsize=(8, 4))
    ax = fig.add_subplot(1, 1, 1)
    offset = 0
    for r in results:
        if len(r.trace) == 0:
            continue
        x = offset + np.arange(len(r.trace))
        ax.plot(x, np.maximum(r.trace, 1e-6), label=f"{r.goal} ({r.status.value})")
        if r.status.value == "local_minimum":
            ax.scatter(x[-1], max(r.trace[-1], 1e-6), marker="x", color="k", zorder=5)
        offset += len(r.trace)
    ax.set_yscale("log")
    ax.set_xlabel("iteration (legs one after another)")
    ax.set_ylabel("f")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def plot_plan(plan: Any, problem: Problem, out_dir: str | Path) -> list[Path]:
    """PNG files for a plan: the start, each leg's end (marking stalls) and the f trace."""
    out_dir = Path(out_dir)
    files = []
    title = f"{plan.planner} on {plan.problem} (seed {plan.seed})"
    files.append(
        save(
            snapshot_figure(problem, [("start", plan.legs[0].path[0])], f"{title}: start"),
            out_dir / "start.png",
        )
    )
    for r in plan.legs:
        tag = "stall" if r.status.value == "local_minimum" else "end"
        files.append(
            save(
                snapshot_figure(
                    problem,
                    [("leg start", r.path[0]), (f"{tag}: {r.status.value}", r.path[-1])],
                    f"{title}: leg {r.leg} '{r.goal}' {tag} after {r.iterations} iterations",
                ),
                out_dir / f"leg{r.leg}_{r.goal}_{tag}.png",
            )
        )
    files.append(
        save(trace_figure(plan.legs, f"{title}: objective per iteration"), out_dir / "trace.png")
    )
    return files

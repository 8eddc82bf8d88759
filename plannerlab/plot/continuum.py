"""Figures of the chord-arc search in the style of the paper's Fig. 4, and of the robot's
thickness.

Blue lines: obstacle boundaries; red curves: solutions that hold (dropped solutions
dashed grey); green dots: the user's collision points; black dot: the target.
Everything is drawn from the plans' records
(:class:`~plannerlab.record.contact_plan.ContactPlan`): a figure never re-plans.
Figures are built as :class:`matplotlib.figure.Figure` objects without pyplot (no
backend is chosen or changed here) and written to a file; nothing is shown.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon as PolygonPatch

from plannerlab.record.contact_plan import ContactPlan, ContactSolution, PlanarShape
from plannerlab.robots.continuum.model import arc_points_local


def solution_xy(sol: ContactSolution, n: int = 100) -> np.ndarray:
    """Points (k, 2) along a solution's arcs [m], ``n`` per arc."""
    a = np.linspace(0.0, 1.0, n)
    parts = []
    for arc in sol.arcs:
        t = np.asarray(arc.start_tangent, dtype=float)
        right = np.array([t[1], -t[0]])
        loc = arc_points_local(arc.theta_rad, arc.length_m, a)
        parts.append(np.asarray(arc.start_xy_m) + loc[..., :1] * right + loc[..., 1:] * t)
    return np.vstack(parts) if parts else np.zeros((0, 2))


def _obstacles(ax: Axes, obstacles: Sequence[PlanarShape], **style: object) -> None:
    for o in obstacles:
        if o.center_m is not None and o.radius_m is not None:
            ax.add_patch(CirclePatch(o.center_m, o.radius_m, fill=False, **style))
        else:
            ax.add_patch(PolygonPatch(np.array(o.vertices_m), closed=True, fill=False, **style))


def _port_and_target(ax: Axes, plan: ContactPlan) -> None:
    if plan.collision_points_m:
        cp = np.array(plan.collision_points_m)
        ax.plot(cp[:, 0], cp[:, 1], "o", color="tab:green", ms=5, label="collision points")
    ax.plot(*plan.target_xy_m, "o", color="black", ms=6, label="target")
    bx, by = plan.base_xy_m
    tx, ty = plan.base_tangent
    ax.annotate(
        "",
        xy=(bx + 0.03 * tx, by + 0.03 * ty),
        xytext=(bx, by),
        arrowprops={"arrowstyle": "->", "color": "black"},
    )


def _finish(ax: Axes, title: str, legend: bool = True) -> None:
    ax.set_aspect("equal")
    if ax.get_autoscale_on():
        ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=9)
    if legend:
        ax.legend(loc="lower right", fontsize=7)
    ax.grid(alpha=0.3)


def case_figure(plan: ContactPlan, title: str = "", show_dropped: bool = True) -> Figure:
    """Fig. 4 of a case: obstacles, collision points, every solution, target, port.

    Args:
        plan: a ``chord_arc`` leg's contact plan (its obstacles, collision points, kept
            and dropped solutions).
        title: figure title (default: the counts).
        show_dropped: also draw the dropped solutions (dashed grey).
    """
    fig = Figure(figsize=(5.0, 5.0), dpi=120)
    ax = fig.add_subplot()
    _obstacles(ax, plan.obstacles, color="tab:blue")
    if show_dropped:
        for i, d in enumerate(plan.dropped):
            xy = solution_xy(d)
            ax.plot(
                xy[:, 0],
                xy[:, 1],
                "--",
                color="0.6",
                lw=1.0,
                label="dropped" if i == 0 else None,
            )
    for i, sol in enumerate(plan.solutions):
        xy = solution_xy(sol)
        ax.plot(
            xy[:, 0], xy[:, 1], "-", color="tab:red", lw=1.8, label="solutions" if i == 0 else None
        )
    _port_and_target(ax, plan)
    _finish(
        ax,
        title
        or f"{len(plan.solutions)} solution(s), {len(plan.collision_points_m)} collision points",
    )
    fig.tight_layout()
    return fig


def searched(plan: ContactPlan) -> tuple[ContactSolution, ...]:
    """The solutions the search's motion check passed: the kept ones and those the
    chain's check dropped (joint bounds, thickness)."""
    return plan.solutions + tuple(d for d in plan.dropped if d.stage == "chain")


def thickness_figure(thin_plan: ContactPlan, thick_plan: ContactPlan, title: str = "") -> Figure:
    """Where the zero-thickness curve and the real robot part.

    Args:
        thin_plan: the paper's zero-thickness plan (``inflate_by_radius = False``): its
            searched solutions drawn thin red with the robot's width shaded around them,
            and the points where that robot would cut an obstacle (crosses).
        thick_plan: the plan for the robot of its link radius (``inflate_by_radius``):
            its searched solutions drawn dark blue, and the obstacles grown by the radius
            (what the robot's axis must avoid) dotted.
        title: figure title.
    """
    thin = searched(thin_plan)
    thick = searched(thick_plan)
    radius_m = thick_plan.link_radius_m
    cuts_xy_m = [c for s in thin for c in s.cuts_xy_m]
    cuts = np.asarray(cuts_xy_m, dtype=float).reshape(-1, 2)
    clusters: list[np.ndarray] = []  # cuts 2 cm apart or more: one zoom each (at most 2)
    left = cuts
    while len(left) and len(clusters) < 2:
        near = np.linalg.norm(left - left[0], axis=1) < 0.02
        clusters.append(left[near])
        left = left[~near]
    fig = Figure(figsize=(5.0 + 4.0 * len(clusters), 5.5), dpi=120)
    axes = [fig.add_subplot(1, 1 + len(clusters), i + 1) for i in range(1 + len(clusters))]
    full, zooms = axes[0], axes[1:]
    for ax in axes:
        _obstacles(ax, thin_plan.obstacles, color="tab:blue", lw=1.2)
        _obstacles(ax, thick_plan.planning_obstacles, color="tab:blue", lw=0.8, ls=":")
        ax.plot([], [], ":", color="tab:blue", lw=0.8, label=f"grown by r = {radius_m * 1e3:g} mm")
        for i, s in enumerate(thin):
            xy = solution_xy(s, 400)
            t = np.gradient(xy, axis=0)
            nrm = np.stack([-t[:, 1], t[:, 0]], axis=1) / np.linalg.norm(t, axis=1)[:, None]
            band = np.vstack([xy + radius_m * nrm, (xy - radius_m * nrm)[::-1]])
            ax.add_patch(PolygonPatch(band, closed=True, color="tab:red", alpha=0.25, lw=0))
            ax.plot(
                xy[:, 0],
                xy[:, 1],
                "-",
                color="tab:red",
                lw=0.8,
                label="zero-thickness (paper), robot's width shaded" if i == 0 else None,
            )
        for i, s in enumerate(thick):
            xy = solution_xy(s, 400)
            ax.plot(
                xy[:, 0],
                xy[:, 1],
                "-",
                color="navy",
                lw=1.4,
                label=f"axis of the {radius_m * 1e3:g} mm robot" if i == 0 else None,
            )
        if len(cuts):
            ax.plot(cuts[:, 0], cuts[:, 1], "x", color="black", ms=4, label="robot would cut")
        _port_and_target(ax, thin_plan)
    # the working area (not the sleeve behind the port), and a zoom on the cuts
    pts = [np.array([thin_plan.base_xy_m, thin_plan.target_xy_m])]
    pts += [solution_xy(s) for s in (*thin, *thick)]
    if thin_plan.collision_points_m:
        pts.append(np.array(thin_plan.collision_points_m))
    xy = np.vstack(pts)
    lo, hi = xy.min(axis=0) - 0.02, xy.max(axis=0) + 0.02
    full.set_xlim(lo[0], hi[0])
    full.set_ylim(lo[1], hi[1])
    _finish(full, "the working area")
    fig.suptitle(title, fontsize=10)
    for zoom, c in zip(zooms, clusters, strict=True):
        mid = (c.min(axis=0) + c.max(axis=0)) / 2.0
        zoom.set_xlim(mid[0] - 0.012, mid[0] + 0.012)
        zoom.set_ylim(mid[1] - 0.012, mid[1] + 0.012)
        _finish(zoom, f"where they part near ({mid[0]:.3f}, {mid[1]:.3f}) m", legend=False)
    for ax in axes:
        ax.set_autoscale_on(False)
    fig.tight_layout()
    return fig


def save(fig: Figure, png_path: str | Path) -> Path:
    """Write a figure to a PNG (parent folders are created); returns the path."""
    path = Path(png_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path


def draw_case(
    plan: ContactPlan, png_path: str | Path, title: str = "", show_dropped: bool = True
) -> Path:
    """:func:`case_figure` written to ``png_path``; returns the path."""
    return save(case_figure(plan, title, show_dropped), png_path)


__all__ = ["case_figure", "draw_case", "save", "searched", "solution_xy", "thickness_figure"]

"""Figures of the chord-arc search in the style of the paper's Fig. 4.

Blue lines: obstacle boundaries; red curves: solutions that hold (dropped solutions
dashed grey); green dots: the user's collision points; black dot: the target.
Matplotlib with the Agg backend, written to a file; nothing is shown.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle as CirclePatch  # noqa: E402
from matplotlib.patches import Polygon as PolygonPatch  # noqa: E402

from plannerlab.planners.chord_arc_search import (  # noqa: E402
    ChordArcQuery,
    ChordArcResult,
    ChordArcSolution,
    Circle,
)


def _solution_xy(sol: ChordArcSolution, n: int = 100) -> np.ndarray:
    a = np.linspace(0.0, 1.0, n)
    return np.vstack([arc.points(a) for arc in sol.arcs])


def draw_case(
    query: ChordArcQuery,
    result: ChordArcResult,
    png_path: str | Path,
    title: str = "",
    show_dropped: bool = True,
) -> Path:
    """Draw a case (obstacles, collision points, every solution, target) to a PNG.

    Args:
        query: the search input.
        result: :func:`~plannerlab.planners.chord_arc_search.solve_chord_arc` output.
        png_path: file to write (parent folders are created).
        title: figure title.
        show_dropped: also draw solutions the motion check dropped (dashed grey).

    Returns:
        The path written.
    """
    path = Path(png_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(5.0, 5.0), dpi=120)
    try:
        for o in query.obstacles:
            if isinstance(o, Circle):
                ax.add_patch(CirclePatch(o.center_m, o.radius_m, fill=False, color="tab:blue"))
            else:
                ax.add_patch(
                    PolygonPatch(np.array(o.vertices_m), closed=True, fill=False, color="tab:blue")
                )
        if show_dropped:
            for i, d in enumerate(result.dropped):
                xy = _solution_xy(d.solution)
                ax.plot(
                    xy[:, 0],
                    xy[:, 1],
                    "--",
                    color="0.6",
                    lw=1.0,
                    label="dropped by the motion check" if i == 0 else None,
                )
        for i, p in enumerate(result.plans):
            xy = _solution_xy(p.solution)
            ax.plot(
                xy[:, 0],
                xy[:, 1],
                "-",
                color="tab:red",
                lw=1.8,
                label="solutions" if i == 0 else None,
            )
        if query.collision_points_m:
            cp = np.array(query.collision_points_m)
            ax.plot(cp[:, 0], cp[:, 1], "o", color="tab:green", ms=5, label="collision points")
        ax.plot(*query.target_xy_m, "o", color="black", ms=6, label="target")
        bx, by = query.base_xy_m
        tx, ty = query.base_tangent
        ax.annotate(
            "",
            xy=(bx + 0.03 * tx, by + 0.03 * ty),
            xytext=(bx, by),
            arrowprops={"arrowstyle": "->", "color": "black"},
        )
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(
            title
            or f"{len(result.plans)} solution(s), {len(query.collision_points_m)} collision points"
        )
        ax.legend(loc="lower right", fontsize=7)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(path)
    finally:
        plt.close(fig)
    return path


__all__ = ["draw_case"]

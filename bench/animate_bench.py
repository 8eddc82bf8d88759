"""Benchmark of ``plannerlab animate``'s GIF writer: the blitted writer
(:func:`plannerlab.plot.animate.write_animation`: the figure laid out once, the static
background drawn once, each frame redraws only the moving artists) against a baseline
measured in the same run: matplotlib's ``PillowWriter`` grabbing every frame of the same
figure with constrained layout on (what ``animate`` did before: the whole figure laid out
and drawn for every frame).

The plan: RRT-Connect on ``armz_pocket``, seed 0 (solved in the run, a few seconds); no
execution (the motion is the planned one). Prints both wall times, their ratio and the
machine's load average before and after.

    python bench/animate_bench.py [--frames 40]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import plannerlab as pl
from plannerlab.plot.animate import animation_figure, motion_frames, write_animation


def baseline(fig, update, n: int, path: Path, fps: int = 12, dpi: int = 80) -> None:
    """The old road: PillowWriter, constrained layout on every frame."""
    from matplotlib import animation

    fig.set_layout_engine("constrained")
    writer = animation.PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi=dpi):
        for i in range(n):
            update(i)
            writer.grab_frame()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=40)
    args = ap.parse_args()
    load0 = os.getloadavg()
    problem = pl.load_problem("armz_pocket")
    budget = problem.budget.replace(max_collision_checks=20_000)
    plan = pl.solve(problem, "ompl.rrtconnect", 0, budget=budget)
    frames = motion_frames(problem, plan.legs, [], max_frames=args.frames)
    out = Path(tempfile.mkdtemp())
    fig, update = animation_figure(problem, frames, "bench")
    t = time.perf_counter()
    write_animation(fig, update, len(frames), out / "blit.gif", hold_s=0)
    t_blit = time.perf_counter() - t
    fig, update = animation_figure(problem, frames, "bench")
    t = time.perf_counter()
    baseline(fig, update, len(frames), out / "baseline.gif")
    t_base = time.perf_counter() - t
    load1 = os.getloadavg()
    print(f"{len(frames)} frames of armz_pocket (ompl.rrtconnect, seed 0)")
    print(f"baseline (PillowWriter, layout every frame): {t_base:.2f} s")
    print(f"blitted writer:                              {t_blit:.2f} s")
    print(f"ratio blitted / baseline: {t_blit / t_base:.3f}")
    print(f"load average before {load0[0]:.2f}, after {load1[0]:.2f}")


if __name__ == "__main__":
    main()

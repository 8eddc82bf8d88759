"""How close each link of a robot comes to the scene, for the viewer's colours."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from plannerlab.problem.load import Problem
from plannerlab.robots.base import Array


def link_clearance(problem: Problem) -> Callable[[Array], tuple[Array, Sequence[str]]]:
    """``f(q) -> (d_m, other)``: per link of the robot, the smallest signed distance of its
    true capsule (no margin) to the scene's obstacles [m] (negative: penetration; inf for
    a link that never moves, which no planner checks against the scene; an obstacle's
    declared contacts left out) and the name of that obstacle (FCL, the checker's
    reference, so any obstacle it holds counts)."""
    from plannerlab.collision.fcl_checker import CollisionChecker

    robot = problem.robot
    names = problem.scene.names
    checker = CollisionChecker(robot, problem.scene, backend="fcl")
    n_links = len(robot.link_radii_m)
    moving = np.array([i for i in range(n_links) if i not in robot.fixed_links], dtype=int)
    links = np.repeat(moving, len(names))
    others = np.tile(np.arange(len(names)), len(moving))
    is_link = np.zeros(len(links), dtype=bool)
    from plannerlab.problem.scene import touch_mask

    # an obstacle's declared contacts (its touch_links) are no clearance to colour
    touch = touch_mask(robot, problem.scene)[moving]

    def clearance(q: Array) -> tuple[Array, Sequence[str]]:
        d_m = np.full(n_links, np.inf)
        other = [""] * n_links
        if len(links):
            d = checker.fcl_pair_distances(np.asarray(q, dtype=float), links, others, is_link)  # type: ignore[arg-type]
            d = np.where(touch, np.inf, d.reshape(len(moving), len(names)))
            j = np.argmin(d, axis=1)
            d_m[moving] = d[np.arange(len(moving)), j]
            for i, k in zip(moving, j, strict=True):
                other[i] = names[k] if np.isfinite(d_m[i]) else ""
        return d_m, other

    return clearance


__all__ = ["link_clearance"]

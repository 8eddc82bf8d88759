"""Sampling planners compiled end to end (numba): sampling, nearest neighbours, edge
checks on the re-check's grid and shortcut simplification run inside compiled code on the
robot–scene model (:mod:`plannerlab.collision.model`), one call per chunk of iterations,
with no Python call per state.

* ``native.rrtconnect``: RRT-Connect (OMPL's algorithm) from the start to a tree rooted
  at every goal state (the joint goal, or goal states drawn by IK), then random shortcuts.
  Its kernel takes guide states (``guide_bias``, ``guide_sigma_rad``;
  :meth:`~plannerlab.planners.native.planner.NativePlanner.guide_states`).
* ``native.rrtstar``: RRT* (asymptotically optimal, k-nearest rewiring), which spends its
  whole budget shortening its best path.

Modules: ``settings`` (frozen settings), ``kernels`` (the compiled search),
``solve`` (one solve: the goal pool, the chunks and the budget, the re-check, and
RRT-Connect's), ``planner`` (the planner class and the registry's factory),
``rrtstar`` (RRT*'s kernel and solve), ``warm`` (kernels loaded before the clock).
"""

from __future__ import annotations

from plannerlab.planners.native.planner import NativePlanner, make
from plannerlab.planners.native.settings import (
    NativeSettings,
    RRTConnectSettings,
    RRTstarSettings,
)
from plannerlab.planners.native.solve import NativeSolve

__all__ = [
    "NativePlanner",
    "NativeSettings",
    "NativeSolve",
    "RRTConnectSettings",
    "RRTstarSettings",
    "make",
]

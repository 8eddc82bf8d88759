"""Loading the compiled planners' kernels (from numba's cache, or compiling them) before
a leg's clock starts: each kernel is run once on a tiny model of its own types."""

from __future__ import annotations

from typing import Any

import numpy as np


def warm_up(model: Any | None = None) -> None:
    """Run every kernel entry point once, doing no work of note (``model``: a compiled
    model to run them on; default: a two-joint chain in an empty room)."""
    from plannerlab.collision.model import views
    from plannerlab.planners.native import kernels as K

    if model is None:
        model = _tiny_model()
    V, S = views(model)
    dof = model.lower.shape[0]
    Q = np.zeros((4, dof))
    P = np.full(4, -1, dtype=np.int64)
    sizes = np.array([1, 1], dtype=np.int64)
    counters = np.zeros(5, dtype=np.int64)
    rng = np.array([1, 2, 3, 4], dtype=np.uint64)
    buf = np.empty((4, dof))
    guides = np.zeros((0, dof))
    K.rrtc_run(
        model, V, S, Q, P, Q, P, sizes, counters, rng, guides, 0.0, 0.1, 1.0, 0.1, 0, 0, 0, 1, buf
    )
    K.tree_path(Q, P, 0, Q, P, 0, Q.copy())
    K.shortcut_run(Q, 1, model, V, S, 0.1, rng, 0, np.zeros(3, dtype=np.int64), 0, 0, buf)


def _tiny_model() -> Any:
    """The compiled model of a three-module Arm-Z beside one small sphere."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene, Sphere
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans

    scene = Scene((Sphere("far", trans(5.0, 0.0, 0.0), 0.1),))
    return CollisionChecker(ArmZ(n_modules=3), scene, margin_m=0.01).model

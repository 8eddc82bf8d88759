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
    from plannerlab.planners.native import kpiece as KP
    from plannerlab.planners.native import rrtstar as R

    entries = (
        views, K.rrtc_run, K.tree_path, K.shortcut_run, R.rrtstar_run, R.chain, KP.kpiece_run
    )  # fmt: skip
    if model is None and all(getattr(f, "signatures", True) for f in entries):
        return  # loaded in this process already
    if model is None:
        model = _tiny_model()
    V, S = views(model)
    dof = model.lower.shape[0]
    Q = np.zeros((4, dof))
    P = np.full(4, -1, dtype=np.int64)
    sizes = np.array([1, 1], dtype=np.int64)
    counters = np.zeros(6, dtype=np.int64)
    rng = np.array([1, 2, 3, 4], dtype=np.uint64)
    buf = np.empty((4, dof))
    guides = np.zeros((0, dof))
    F = np.ones(4, dtype=np.int8)
    radii = np.full(4, np.inf)
    Kd = np.full((4, 3), -1, dtype=np.int64)
    K.rrtc_run(
        model, V, S, Q, P, F, radii, Q, P, F, radii, Kd, Kd.copy(), sizes, counters, rng,
        guides, 0.0, 0.1,
        1.0, 0.1, 8, np.zeros(3), 0, 0, 0, 1, buf,
    )  # fmt: skip
    K.tree_path(Q, P, 0, Q, P, 0, Q.copy())
    K.shortcut_run(Q, 1, model, V, S, 0.1, rng, 0, np.zeros(4, dtype=np.int64), 0, 0, buf)
    cost = np.zeros(4)
    R.rrtstar_run(
        model, V, S, Q, P, cost, P.copy(), P.copy(), P.copy(), P.copy(), F,
        np.array([1, 0], dtype=np.int64),
        np.array([0, 0, -1, 0], dtype=np.int64), rng, guides, 0.0, guides, 0.0, 0.1, 1.0, 0.1,
        1.0, 0, 0, 0, buf, np.empty(4, dtype=np.int64), np.empty(4), np.empty(4, dtype=np.int64),
    )  # fmt: skip
    R.chain(Q, P, 0, Q.copy())
    _warm_kpiece(model)


def _warm_kpiece(model: Any) -> None:
    """``native.kpiece``'s kernels (:mod:`~plannerlab.planners.native.kpiece`), on a
    search that stops before its first iteration."""
    from plannerlab.planners.native import kpiece as KP
    from plannerlab.planners.native import shim

    dof = model.lower.shape[0]
    T, C = KP.new_motions(4, dof), KP.new_cells(4, 2)
    proj = KP.Projection(matrix=np.zeros((2, dof)), cell_size=np.ones(2))
    counters = np.zeros(KP.N_COUNTERS, dtype=np.int64)
    counters[KP.C_DISC_ITER] = 1
    q = np.zeros(dof)
    goals = np.zeros((1, dof))
    KP.add_motion(T, C, proj, counters, q, -1, 1, 0.0, np.empty(2, dtype=np.int64))
    rng = np.array([1, 2, 3, 4], dtype=np.uint64)
    prm = np.zeros(KP.N_PARAMS)
    prm[KP.P_STRIDE] = 1
    KP.kpiece_run(shim.bundle(model), T, C, proj, goals, prm, counters, rng)
    KP.rehash(C, 1)
    KP.tree_path(T, 0, np.empty((4, dof)))


def _tiny_model() -> Any:
    """The compiled model of a three-module Arm-Z beside one small sphere."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene, Sphere
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans

    scene = Scene((Sphere("far", trans(5.0, 0.0, 0.0), 0.1),))
    robot: Any = ArmZ(n_modules=3)
    return CollisionChecker(robot, scene, margin_m=0.01).model

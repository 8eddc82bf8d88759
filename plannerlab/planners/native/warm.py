"""Loading the compiled planners' kernels (from numba's cache, or compiling them) before
a leg's clock starts: each kernel entry is run once on a tiny model of its own types."""

from __future__ import annotations

from typing import Any

import numpy as np

#: the algorithms whose kernels :func:`warm_up` loads
ALGORITHMS = ("rrtconnect", "rrtstar", "kpiece")


def warm_up(checker: Any | None = None, algorithm: str | None = None) -> None:
    """Run the kernel entry points of one algorithm (``algorithm``, one of
    :data:`ALGORITHMS`; default: every one) once, doing no work of note (``checker``: a
    collision checker whose compiled model to run them on; default: a three-module Arm-Z
    beside a sphere). RRT-Connect's kernels are always loaded: the shortcuts every
    algorithm uses are among them.

    One algorithm alone is what a planner needs before its leg's clock starts: a fresh
    process planning with ``native.rrtconnect`` then compiles (on an empty cache) about a
    quarter less, as RRT* and KPIECE's kernels are left for when they are used.

    Raises:
        ValueError: an unknown ``algorithm``.
    """
    if algorithm is not None and algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm: one of {', '.join(ALGORITHMS)}, got {algorithm!r}")
    from plannerlab.planners.native import kernels as K
    from plannerlab.planners.native import kpiece as KP
    from plannerlab.planners.native import rrtstar as R
    from plannerlab.planners.native.kdtree import split_dims

    wanted = ALGORITHMS if algorithm is None else ("rrtconnect", algorithm)
    entries = {
        "rrtconnect": (K.rrtc_entry, K.tree_path, K.shortcut_entry),
        "rrtstar": (R.rrtstar_entry, R.chain),
        "kpiece": (KP.kpiece_run,),
    }
    todo = [a for a in wanted if not all(getattr(f, "signatures", True) for f in entries[a])]
    if checker is None and not todo:
        return  # loaded in this process already
    if checker is None:
        checker = _tiny_checker()
    P = checker.packed_model
    dof = checker.robot.dof
    rng = np.array([1, 2, 3, 4], dtype=np.uint64)
    ks = (np.empty(6, dtype=np.int64), np.empty(6), np.empty((6, dof)))
    aux = (rng, np.empty((4, dof)), split_dims(checker.model.continuous), ks)
    Q = np.zeros((4, dof))
    P0 = np.full(4, -1, dtype=np.int64)
    F = np.zeros(4, dtype=np.int8)
    radii = np.full(4, np.inf)
    Kd = np.full((4, 3), -1, dtype=np.int64)
    A = K.Tree(Q, P0, F, radii, Kd)
    B = K.Tree(Q.copy(), P0.copy(), F.copy(), radii.copy(), Kd.copy())
    O = K.Options(
        np.zeros((0, dof)), np.array([0.0, 0.1, 1.0, 0.1]), np.zeros(3),
        np.array([0, 1, 1, 0], dtype=np.int64),
    )  # fmt: skip
    limits = np.zeros(2, dtype=np.int64)
    K.rrtc_entry(P, aux, A, B, np.array([1, 1]), O, np.zeros(6, dtype=np.int64), limits)
    K.tree_path(A, 0, B, 0, Q.copy())
    K.shortcut_entry(P, aux, (Q, 1), 0.1, 0, np.zeros(4, dtype=np.int64), limits)
    if "rrtstar" in wanted:
        T = R.StarTree(Q, P0, np.zeros(4), P0.copy(), P0.copy(), P0.copy(), P0.copy(), F)
        X = R.Star(np.zeros((0, dof)), np.zeros(0, dtype=np.int64), np.array([0.0, 1.0]),
                   np.empty(4, dtype=np.int64), np.empty(4))  # fmt: skip
        R.rrtstar_entry(P, aux, T, X, np.array([1, 0]), O, np.array([0, 0, -1, 0]), limits)
        R.chain(Q, P0, 0, Q.copy())
    if "kpiece" in wanted:
        _warm_kpiece(checker)


def _warm_kpiece(checker: Any) -> None:
    """``native.kpiece``'s kernels (:mod:`~plannerlab.planners.native.kpiece`), on a
    search that stops before its first iteration."""
    from plannerlab.planners.native import kpiece as KP
    from plannerlab.planners.native import shim

    dof = checker.robot.dof
    T, C = KP.new_motions(4, dof), KP.new_cells(4, 2)
    proj = KP.Projection(matrix=np.zeros((2, dof)), cell_size=np.ones(2))
    counters = np.zeros(KP.N_COUNTERS, dtype=np.int64)
    counters[KP.C_DISC_ITER] = 1
    q = np.zeros(dof)
    goals = np.zeros((1, dof))
    KP.add_motion(T, C, proj, counters, q, (-1, 1, 0.0), np.empty(2, dtype=np.int64))
    rng = np.array([1, 2, 3, 4], dtype=np.uint64)
    prm = np.zeros(KP.N_PARAMS)
    prm[KP.P_STRIDE] = 1
    KP.kpiece_run(shim.bundle(checker), T, C, proj, goals, prm, counters, rng)
    KP.rehash(C, 1)
    KP.tree_path(T, 0, np.empty((4, dof)))


def _tiny_checker() -> Any:
    """A checker of a three-module Arm-Z beside one small sphere."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene, Sphere
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans

    scene = Scene((Sphere("far", trans(5.0, 0.0, 0.0), 0.1),))
    robot: Any = ArmZ(n_modules=3)
    return CollisionChecker(robot, scene, margin_m=0.01)

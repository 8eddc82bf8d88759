"""One ``native.kpiece`` solve (:func:`kpiece`): the projection, the compiled search of
:mod:`~plannerlab.planners.native.kpiece` in chunks within the budget (the arrays grown
when full), then the shared steps of :class:`~plannerlab.planners.native.solve.
NativeSolve` (shortcuts, re-check)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native import kpiece as KP
from plannerlab.planners.native import shim
from plannerlab.planners.native.settings import KPIECESettings
from plannerlab.planners.native.solve import (
    FIRST_ROWS,
    UNLIMITED,
    NativeSolve,
    space_extent,
)
from plannerlab.robots.base import Array
from plannerlab.robots.paths import path_length


def projection_dims(dof: int, s: KPIECESettings) -> int:
    """The projection's dimensions: the setting, or OMPL's default max(2, ceil(ln dof))."""
    if s.projection_dims:
        return int(s.projection_dims)
    return max(2, math.ceil(math.log(dof))) if dof > 1 else 1


def make_projection(model: Any, s: KPIECESettings, rng: np.random.Generator) -> KP.Projection:
    """A random linear projection (orthonormal rows drawn from ``rng``, as OMPL's default
    for a vector space) and its cells' widths: ``cell_size_sd`` standard deviations of
    the projected coordinate of states uniform in the joint box (exact, no sampling)."""
    dof = int(model.lower.shape[0])
    k = min(projection_dims(dof, s), dof)
    basis, _ = np.linalg.qr(rng.standard_normal((dof, k)))
    matrix = np.ascontiguousarray(basis.T)
    span = np.where(model.continuous, 2.0 * math.pi, model.upper - model.lower)
    sd = np.sqrt((matrix**2) @ (span**2 / 12.0))
    cell = np.maximum(s.cell_size_sd * sd, 1e-9)
    return KP.Projection(matrix=matrix, cell_size=np.ascontiguousarray(cell))


def _grown(T: KP.Motions, C: KP.Cells, rows: int, n_cells: int) -> tuple[KP.Motions, KP.Cells]:
    """The tree and grid with ``rows`` rows, their contents kept (the table rebuilt)."""
    n = T.Q.shape[0]
    T2 = KP.new_motions(rows, T.Q.shape[1])
    for a, b in zip(T, T2, strict=True):
        b[:n] = a
    C2 = KP.new_cells(rows, C.coord.shape[1])
    for name in KP.Cells._fields:
        a, b = getattr(C, name), getattr(C2, name)
        if name == "table":
            continue
        if name == "heap":
            b[:, :n] = a
        else:
            b[:n] = a
    KP.rehash(C2, n_cells)
    return T2, C2


def kpiece(solve: NativeSolve) -> PlanResult:
    """KPIECE from the start to the goal pool (see :mod:`~plannerlab.planners.native.
    kpiece`), then the shared shortcuts and re-check."""
    s = solve.s
    assert isinstance(s, KPIECESettings)
    q0 = solve.q0
    if solve.ctx.start_problem is not None:
        return solve.result(Status.INVALID_START, solve.ctx.start_problem, q0[None])
    model = solve.checker.model
    solve.run.progress.note(float(solve.goal.distance(solve.robot, q0)))
    G, failed = solve.goal_pool()
    if failed is not None:
        return failed
    proj = make_projection(model, s, solve.rng)
    rng_state = K.seed_state(solve.rng)
    ck = shim.bundle(solve.checker)
    dof, k = len(q0), proj.matrix.shape[0]
    range_rad = s.range_rad or 0.2 * space_extent(model)
    prm = np.zeros(KP.N_PARAMS)
    prm[KP.P_GOAL_BIAS] = s.goal_bias
    prm[KP.P_BORDER] = s.border_fraction
    prm[KP.P_FAILED_FACTOR] = s.failed_score_factor
    prm[KP.P_MIN_FRACTION] = s.min_valid_fraction
    prm[KP.P_RANGE] = range_rad
    prm[KP.P_STEP] = solve.step
    prm[KP.P_GOAL_TOL] = _goal_tol(solve)
    prm[KP.P_OCTAVES] = s.range_octaves
    prm[KP.P_STRIDE] = s.lazy_every
    solve.extra.update(range_rad=range_rad, projection_dims=k)
    # per row: the state, parent, flag, cell, previous; a cell's arrays and table slots
    row_bytes = 8 * dof + 25 + 8 * k + 120
    by_memory = int(s.max_tree_mb * 1e6 / row_bytes)
    hard0 = solve.hard_checks()
    cap = max(min(by_memory, hard0 + 2), 2)
    rows = min(cap, FIRST_ROWS)
    T, C = KP.new_motions(rows, dof), KP.new_cells(rows, k)
    counters = np.zeros(KP.N_COUNTERS, dtype=np.int64)
    counters[KP.C_DISC_ITER] = 1
    counters[KP.C_FOUND] = -1
    b = solve.budget
    counters[KP.C_MAX_ITER] = UNLIMITED if b.max_iterations is None else b.max_iterations
    x = np.empty(k, dtype=np.int64)
    dist = KP.goal_distance(q0, G, model.continuous)
    KP.add_motion(T, C, proj, counters, q0, (-1, K.CHECKED, dist), x)
    box: list[Any] = [T, C]
    solve._charged = 0

    def call(soft: int, hard: int) -> int:
        counters[KP.C_SOFT], counters[KP.C_HARD] = soft, hard
        return int(KP.kpiece_run(ck, box[0], box[1], proj, G, prm, counters, rng_state))

    while True:
        code = solve.run_chunks(call, counters)
        solve.iterations = int(counters[KP.C_ITER])
        if code == K.FULL and box[0].Q.shape[0] < cap:
            grown = min(cap, 4 * box[0].Q.shape[0])
            box[0], box[1] = _grown(box[0], box[1], grown, int(counters[KP.C_CELLS]))
            continue
        break
    T = box[0]
    solve.extra.update(
        planning_checks=int(counters[KP.C_CHECKS]),
        nodes=int(counters[KP.C_MOTIONS]),
        cells=int(counters[KP.C_CELLS]),
        exterior_cells=int(counters[KP.C_EXT]),
        goal_tries=int(counters[KP.C_GOAL_TRIES]),
        paths_failing_fine_check=int(counters[KP.C_FAILED]),
        tree_rows=cap,
    )
    if code != K.DONE:
        if code == K.FULL:
            solve.extra["tree_rows"] = int(T.Q.shape[0])
        return solve.stopped(code, f"{int(counters[KP.C_MOTIONS])} tree nodes")
    out = np.empty((int(counters[KP.C_MOTIONS]), dof))
    n = KP.tree_path(T, int(counters[KP.C_FOUND]), out)
    path: Array = out[:n].copy()
    solve.extra["waypoints_raw"] = n
    solve.extra["length_raw"] = path_length(path, solve.robot.continuous)
    if s.simplify:
        path = solve.simplify(path, rng_state)
    return solve.checked(path)


def _goal_tol(solve: NativeSolve) -> float:
    """A state within this of a pool state in every joint reaches the goal [rad]: just
    inside a goal state's tolerance (rounding kept clear of the goal's own test), else a
    hair (the pool's states of a position goal)."""
    tol = getattr(solve.goal, "tol_rad", None)
    return 0.999 * float(tol) if tol is not None else 1e-9

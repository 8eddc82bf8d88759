"""The trajectory optimiser's geometry: the one module that asks the collision core
anything (today :mod:`plannerlab.collision.spheres` on the compiled robot–scene model,
packed as the clearance descent packs it, :class:`~plannerlab.planners.clearance.compiled.
CompiledField`). When the core gives the same queries elsewhere, this module is the one
edit.

Two compiled queries (numba, cached):

* :func:`hinge_terms`: for a batch of states Q (n, dof), the collision hinge of every
  state, ``c = Σ_pairs max(0, d_safe − d)²`` over the sphere pairs (each sphere against
  each obstacle, each sphere against each sphere of a checked link pair), its gradient
  ``−2 Σ h ∇d`` (dof,) and its Gauss-Newton matrix ``2 Σ ∇d ∇dᵀ`` (dof, dof), and the
  smallest pair distance (pairs at least ``d_safe`` apart are reported at ``d_safe``);
* :func:`tip_terms`: the tip's point and normal and their Jacobians at one state.

The spheres are the clearance field's (:class:`~plannerlab.planners.clearance.field.
ClearanceField`: spheres at most ``0.4 r`` apart on every capsule's axis, so the field
under-covers a capsule by at most 2 % of its radius), with the second sphere of a
zero-length link left out (a spherized URDF's links are single spheres: the field would
put two at one point and count every pair twice).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from plannerlab.collision.spheres import (
    SphereChain,
    centres,
    frames,
    kin,
    pair_gradient,
    pairs,
    point_gradient,
    tip_jacobians,
    tip_pose,
)
from plannerlab.planners.clearance.compiled import CompiledField, SphereField
from plannerlab.planners.clearance.field import ClearanceField
from plannerlab.robots.base import Array

__all__ = [
    "PathGeometry",
    "hinge_terms",
    "problem_geometry",
    "speed_terms",
    "tip_terms",
    "warm_up",
]


@njit(cache=True, nogil=True)
def hinge_terms(Q, fld_t, d_safe, want_matrix):
    """The collision hinge of every state of Q (n, dof): cost (n,), gradient (n, dof),
    Gauss-Newton matrix (n, dof, dof; zeros unless ``want_matrix``) and the smallest
    pair distance (n,) [m], clipped at ``d_safe`` (see the module docstring)."""
    fld = SphereField(SphereChain(*fld_t[0]), *fld_t[1:])
    ch = fld.ch
    n, dof = Q.shape
    cost = np.zeros(n)
    grad = np.zeros((n, dof))
    H = np.zeros((n, dof, dof) if want_matrix else (n, 0, 0))
    dmin = np.full(n, d_safe)
    kn = kin(ch)
    g = np.empty(dof)
    for s in range(n):
        Bf = frames(Q[s], ch)
        P = centres(Bf, ch, fld.link, fld.t)
        d, nrm = pairs(
            P,
            fld.r,
            fld.scene_idx,
            (fld.self_a, fld.self_b),
            fld.scene,
            d_safe,
            (fld.lp_of_row, fld.lp_links, fld.ends),
        )
        for i in range(d.shape[0]):
            di = d[i]
            if di < dmin[s]:
                dmin[s] = di
            if di < d_safe:
                h = d_safe - di
                pair_gradient(Bf, kn, P, fld.link, nrm, (fld.A[i], fld.B[i], i), g)
                cost[s] += h * h
                for j in range(dof):
                    grad[s, j] -= 2.0 * h * g[j]
                if want_matrix:
                    for a in range(dof):
                        ga = 2.0 * g[a]
                        if ga != 0.0:
                            for b in range(dof):
                                H[s, a, b] += ga * g[b]
    return cost, grad, H, dmin


@njit(cache=True, nogil=True)
def tip_terms(q, fld_t):
    """The tip at q (dof,): point p (3,), normal n (3,), ∂p/∂q and ∂n/∂q (3, dof)."""
    ch = SphereChain(*fld_t[0])
    Bf = frames(q, ch)
    p, n = tip_pose(Bf, ch)
    Jp, Jn = tip_jacobians(Bf, ch, p, n, q.shape[0])
    return p, n, Jp, Jn


def _single_spheres(field: ClearanceField) -> ClearanceField:
    """``field`` with the second sphere of every zero-length link left out (the pairs
    renumbered): a copy, the field itself when it has none."""
    zero = np.asarray(field._lengths) <= 1e-12
    link, t = np.asarray(field._link), np.asarray(field._t)
    keep = ~(zero[link] & (t > 0.0))
    if keep.all():
        return field
    new_index = np.full(len(keep), -1, dtype=np.int64)
    new_index[keep] = np.arange(int(keep.sum()))
    out = object.__new__(ClearanceField)
    out.__dict__.update(field.__dict__)
    out._link, out._t, out._r = link[keep], t[keep], np.asarray(field._r)[keep]
    scene = np.asarray(field._scene_spheres, dtype=np.int64)
    out._scene_spheres = new_index[scene[keep[scene]]]
    a, b = np.asarray(field._self_a, dtype=np.int64), np.asarray(field._self_b, dtype=np.int64)
    both = keep[a] & keep[b] if len(a) else np.zeros(0, dtype=bool)
    out._self_a, out._self_b = new_index[a[both]], new_index[b[both]]
    return out


class PathGeometry:
    """The geometry of one robot in one scene for the optimiser: the sphere field on the
    compiled model, packed once (see the module docstring). Built in whole-array
    operations (some 1 ms for a Panda); :func:`problem_geometry` keeps one per checker.

    Args:
        robot: the robot (a chain with a tip: ``chain_data()``, ``tip_data()``).
        scene: the obstacles (boxes, cylinders, spheres).
        model: the checker's compiled robot–scene model (:class:`~plannerlab.collision.
            model.CompiledModel`, whose kinematics the spheres ride on; None: the robot's
            chain packed alone, the same numbers).
        stop: asked while the field's pairs are built (the leg's time limit).

    Raises:
        ValueError, ModelError: the robot gives no chain or no tip.
        SetupStopped: ``stop()`` said so while the field was built.
    """

    def __init__(self, robot: Any, scene: Any, model: Any = None, stop: Any = None) -> None:
        field = _single_spheres(ClearanceField(robot, scene, 1.0, stop=stop))
        packed = CompiledField(field, 1.0, model)
        self._plain = packed._plain
        self.spheres = len(field._t)
        self.pairs = len(packed._field.A)

    def hinge(
        self, Q: Array, d_safe_m: float, want_matrix: bool = True
    ) -> tuple[Array, Array, Array, Array]:
        """:func:`hinge_terms` of the states Q (n, dof)."""
        Q = np.ascontiguousarray(Q, dtype=float)
        out: tuple[Array, Array, Array, Array] = hinge_terms(
            Q, self._plain, float(d_safe_m), bool(want_matrix)
        )
        return out

    def speeds(self, Q: Array) -> Array:
        """Per joint, how fast the robot's geometry moves at the states Q (n, dof)
        (:func:`speed_terms`, each component's largest times √3: at least the speed)
        [m per rad, or m per m]: how motion is measured when choosing waypoints."""
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        out: Array = np.sqrt(3.0) * speed_terms(Q, self._plain)
        return out

    def tip(self, q: Array) -> tuple[Array, Array, Array, Array]:
        """:func:`tip_terms` at q (dof,)."""
        out: tuple[Array, Array, Array, Array] = tip_terms(
            np.ascontiguousarray(q, dtype=float), self._plain
        )
        return out


def problem_geometry(checker: Any, stop: Any = None) -> PathGeometry:
    """The :class:`PathGeometry` of a checker's robot and scene, built once per checker (on
    its compiled model when it has one) and kept by it (``checker.derived``): every leg of
    a trial shares the trial's checker, and so the field.

    Raises:
        as :class:`PathGeometry`.
    """
    try:
        model = checker.model
    except ValueError:  # no compiled core (an FCL-only scene): the chain packed alone
        model = None
    return checker.derived(
        "trajopt.PathGeometry",
        lambda: PathGeometry(checker.robot, checker.scene, model, stop),
    )


@njit(cache=True, nogil=True)
def speed_terms(Q, fld_t):
    """Per joint, the fastest any sphere centre moves when that joint alone moves, over
    the states Q (n, dof) [m per rad, or m per m]: ``|z_i × (p − o_i)|`` (``|z_i|`` for a
    sliding joint) through the coupling, the largest over the spheres and states."""
    fld = SphereField(SphereChain(*fld_t[0]), *fld_t[1:])
    ch = fld.ch
    n, dof = Q.shape
    kn = kin(ch)
    out = np.zeros(dof)
    g = np.empty(dof)
    for s in range(n):
        Bf = frames(Q[s], ch)
        P = centres(Bf, ch, fld.link, fld.t)
        for sp in range(P.shape[0]):
            body = ch.link_body[fld.link[sp]]
            for axis in range(3):
                for j in range(dof):
                    g[j] = 0.0
                e0 = 1.0 if axis == 0 else 0.0
                e1 = 1.0 if axis == 1 else 0.0
                e2 = 1.0 if axis == 2 else 0.0
                point_gradient(Bf, kn, body, P[sp], (e0, e1, e2), 1.0, g)
                for j in range(dof):
                    # |∂p/∂q_j| >= each component; the norm over the three is below √3
                    # times the largest: the bound is the norm, summed per axis below
                    out[j] = max(out[j], abs(g[j]))
    return out


def warm_up() -> None:
    """Load (or compile) the kernels once in this process, on a small Arm-Z beside a box
    (before a leg's clock starts, as the collision core is)."""
    from plannerlab.planners.trajopt.path import warm_up as warm_path
    from plannerlab.problem.goals import GoalRegion
    from plannerlab.problem.scene import Box, Scene
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans

    robot = ArmZ(n_modules=4)
    scene = Scene((Box("box", trans(1.0, 0.0, 1.0), np.array([0.5, 0.5, 0.5])),))
    geometry = PathGeometry(robot, scene)
    goal = GoalRegion("warm_up", np.array([0.5, 0.0, 2.0]), np.array([0.0, 0.0, 1.0]), 0.1, 10.0)
    warm_path(geometry, robot, goal)
    geometry.speeds(np.zeros((1, robot.dof)))

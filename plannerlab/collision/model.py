"""The compiled robot–scene model: one typed object that every compiled consumer shares.

A :class:`CompiledModel` is a named tuple of arrays (numba passes it as one argument and
loads the kernels that take it from its cache), built once per (robot, scene, margin) by
:func:`build_model` from the robot's serial chain (``robot.chain_data()``, the format of
:mod:`plannerlab.collision.chain`: every robot family gives it) and the scene's
obstacles. Its fields are named; no consumer indexes packed arrays by position.

* **Kinematics** (``parent``, ``slide``, ``T0``, ``pre``, the coupling ``cpl_*``, and
  ``fold``: a point ``p`` of body ``b``'s own frame is ``fold[b]ᵀ p`` here): each
  joint's axis is turned onto its frame's z axis once (with ``A e_z = u``, a turn about
  ``u`` is ``A Rz(q) Aᵀ``: body frames are kept as ``B · A`` and ``A`` is folded into the
  fixed transforms and the capsules' points), so the one kinematics of
  :mod:`plannerlab.collision.kinematics` turns about z only. ``*_32`` fields are the same
  numbers in float32 for the state test's filter.
* **Capsules** (``cap_*``), sorted by body: body ``b`` holds ``body_caps[b]`` to
  ``body_caps[b + 1]``; ``perm[k]`` is the robot's index of packed capsule ``k``. A
  capsule of zero length is a sphere (``cap_sphere``). Radii against the scene carry the
  whole margin (``r_scene``), between links half of it each (``r_self``: a pair keeps one
  margin).
* **Gates**: a ball per body around its capsules (``gate_c`` in the body's frame,
  ``gate_r_scene``, ``-1`` for a body with no moving capsule, ``gate_r_self``), and the
  checked link pairs by body pair (``bpairs``, their capsule pairs ``cpairs`` from
  ``bpair_start``). Within a body the capsules are ordered by role (scene, other links,
  both: a gate holds capsules of one role), then, for a role of ``_GROUPED_FROM`` or more
  capsules (a mesh's finer cover), by group of at most ``_GROUP`` neighbours, then by
  cluster of at most ``_CLUSTER``: between links a body pair's gate opens its group
  pairs' (``gpairs``, ``cg32``), each group pair's its cluster pairs', so two long links
  side by side test a few group pairs, not every cluster pair.
* **The scene** (``obs_*``): kind (``geometry.BOX``, ``CYLINDER``, ``SPHERE``), rotation
  (9,), centre, half sizes (a box), radius and half length (a cylinder), radius (a
  sphere). **Declared contacts** (an obstacle's ``touch_links``,
  :func:`~plannerlab.problem.scene.touch_mask`): ``obs_touch[o]`` is -1 for an obstacle
  every capsule is tested against, else a row of ``touch_caps`` (R, L) whose True
  capsules (packed order) are never tested against it. Per capsule, not per body: a
  hand's fingers share its rigid body, and any number of bodies (Arm-Z's hundred) fits.
  With no contacts declared every road runs the same arithmetic as before (one branch
  per obstacle or capsule on ``obs_touch``).
* **Motion bounds**: ``lower``, ``upper``, ``continuous``; ``edge_weights`` (per joint,
  how far [m] the robot's points move per radian or metre, divided by the margin: the
  grid of the checker's ``densify``); ``link_rates`` (dof, L): per joint and packed
  capsule the same bound for that capsule alone (:func:`~plannerlab.collision.reach.
  reach_bounds`), with which certified edges grow each capsule by how far it can move.
* ``eps32_m``: a bound of how far the float32 kinematics and tests can be off [m]; the
  filter grows every radius by it, so that "free" in float32 is free in float64
  (:mod:`plannerlab.collision.state_test`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from plannerlab.collision.chain import chain_parts
from plannerlab.collision.geometry import BOX, CYLINDER, SPHERE
from plannerlab.collision.kinematics import SINCOS32_ABS_ERR
from plannerlab.errors import PlannerlabError

_F32_UNIT = 2.0**-24
#: grows every bounding ball beyond rounding: a ball clear is clear
_BOUND_PAD_M = 1e-9


class ModelError(PlannerlabError):
    """A compiled consumer asked for the model of a robot that cannot give one."""


class CompiledModel(NamedTuple):
    """One robot in one scene with a margin, as named arrays (see the module docstring)."""

    # kinematics: chain joints m, bodies m + 1
    parent: np.ndarray  # (m,) int64
    slide: np.ndarray  # (m,) bool
    T0: np.ndarray  # (12,) float64
    pre: np.ndarray  # (m, 12) float64
    fold: np.ndarray  # (m + 1, 3, 3): a point p of body b's own frame is fold[b]ᵀ p here
    T0_32: np.ndarray  # (12,) float32
    pre_32: np.ndarray  # (m, 12) float32
    cpl_start: np.ndarray  # (m + 1,) int64, or (0,): no coupling
    cpl_idx: np.ndarray  # (c,) int64
    cpl_val: np.ndarray  # (c,) float64
    # capsules, by body
    body_caps: np.ndarray  # (m + 2,) int64
    cap_body: np.ndarray  # (L,) int64
    cap_a: np.ndarray  # (L, 3) float64, body frame (axes folded)
    cap_b: np.ndarray  # (L, 3)
    cap_sphere: np.ndarray  # (L,) bool
    cap_moving: np.ndarray  # (L,) bool
    r_scene: np.ndarray  # (L,) float64
    r_self: np.ndarray  # (L,) float64
    perm: np.ndarray  # (L,) int64
    # gates: a ball per body, then per cluster of a few neighbouring capsules
    gate_c: np.ndarray  # (m + 1, 3) float64, body frame
    gate_r_scene: np.ndarray  # (m + 1,) float64, -1: no moving capsule
    gate_r_self: np.ndarray  # (m + 1,) float64
    body_cls: np.ndarray  # (m + 2,) int64: clusters of body b
    cl_caps: np.ndarray  # (K + 1,) int64: capsules of cluster c
    cl_body: np.ndarray  # (K,) int64
    cl_c: np.ndarray  # (K, 3) float64, body frame
    cl_r_scene: np.ndarray  # (K,) float64, -1: no moving capsule
    cl_r_self: np.ndarray  # (K,) float64
    body_order: np.ndarray  # (m + 1,) int64: bodies against the scene, in this order
    bpairs: np.ndarray  # (P, 2) int64 body pairs (u <= v) holding a checked capsule pair
    bpair_start: np.ndarray  # (P + 1,) int64 into clpairs
    clpairs: np.ndarray  # (CP, 2) int64 cluster pairs holding a checked capsule pair
    clpair_start: np.ndarray  # (CP + 1,) int64 into cpairs
    cpairs: np.ndarray  # (Q, 2) int64 packed capsule pairs (i < j)
    # a group level between body and cluster pairs (the self pass only): a body of many
    # capsules is cut into groups of neighbouring clusters, each with its ball
    grp_cls: np.ndarray  # (G + 1,) int64: clusters of group g (consecutive)
    cg_body: np.ndarray  # (K + G,) int64: the clusters' bodies, then the groups'
    cg32: np.ndarray  # (K + G, 8) float32: cls32's rows, then the groups' (row K + g)
    bpair_gstart: np.ndarray  # (P + 1,) int64 into gpairs
    gpairs: np.ndarray  # (GP, 3) int64: rows of cg32 (K + g), gate tested (1) or not (0)
    gpair_start: np.ndarray  # (GP + 1,) int64 into clpairs
    # the self pass's broadphase: body pairs by the pair of groups of SELF_GROUP
    # consecutive bodies they join (g <= h, ng = ceil((m + 1) / SELF_GROUP) groups)
    bpair_gorder: np.ndarray  # (P,) int64: rows of bpairs, by group pair
    gbpair_start: np.ndarray  # (ng * ng + 1,) int64 into bpair_gorder, group pair g ng + h
    # the scene
    obs_kind: np.ndarray  # (n,) int64
    obs_R: np.ndarray  # (n, 9) float64, row-major world <- obstacle
    obs_c: np.ndarray  # (n, 3)
    obs_h: np.ndarray  # (n, 3)
    obs32: np.ndarray  # (n, 24) float32: centre (0:3), half sizes (3:6), rotation (6:15),
    #   the world box around it: half extents (16:19), padded beyond float32's rounding
    obs_touch: np.ndarray  # (n,) int64: -1, or the row of touch_caps of its declared contacts
    touch_caps: np.ndarray  # (R, L) bool: capsules (packed order) never tested against it
    caps32: np.ndarray  # (L, 8) float32: end a (0:3), end b (3:6), r_scene, r_self
    gates32: np.ndarray  # (m + 1, 8) float32: centre (0:3), r_scene, r_self
    cls32: np.ndarray  # (K, 8) float32: centre (0:3), r_scene, r_self
    # bounds and motion
    lower: np.ndarray  # (dof,)
    upper: np.ndarray  # (dof,)
    continuous: np.ndarray  # (dof,) bool
    edge_weights: np.ndarray  # (dof,) [1 / rad or 1 / m]: reach / margin (zeros: none)
    link_rates: np.ndarray  # (dof, L) [m / rad or m / m], packed capsule order
    margin_m: float
    eps32_m: float


def _world_box(kinds: np.ndarray, Rs: np.ndarray, hs: np.ndarray) -> np.ndarray:
    """(n, 8): each obstacle's world axis-aligned box as half extents about its centre
    (0:3; a box: ``Σ_b |R[a, b]| h_b``, a cylinder: the box around it, a sphere: its
    radius), padded by 1e-5 relative and 1e-5 m (beyond float32's rounding of a gate's
    offset from the centre: the state test's prefilter never drops a ball the exact test
    would keep), then zeros."""
    n = len(kinds)
    out = np.zeros((n, 8))
    for o in range(n):
        R = np.abs(Rs[o].reshape(3, 3))
        h = hs[o]
        if kinds[o] == SPHERE:
            e = np.full(3, h[0])
        elif kinds[o] == CYLINDER:
            e = R @ np.array([h[0], h[0], h[1]])
        else:
            e = R @ h[:3]
        out[o, :3] = e * (1.0 + 1e-5) + 1e-5
    return out


def has_chain(robot: Any) -> bool:
    """True when the robot gives its serial chain (``chain_data()``) to compile."""
    return callable(getattr(robot, "chain_data", None))


def _align(u: np.ndarray) -> np.ndarray:
    """A rotation A (3, 3) with A e_z = u (the identity for u = e_z)."""
    z = np.asarray(u, dtype=float)
    if np.array_equal(z, [0.0, 0.0, 1.0]):
        return np.eye(3)
    e = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = np.cross(e, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _ball(points: np.ndarray, reach: np.ndarray) -> tuple[np.ndarray, float]:
    """A ball around points each grown by its own reach: (centre, radius), -1 for none."""
    if len(points) == 0:
        return np.zeros(3), -1.0
    c = (points.min(axis=0) + points.max(axis=0)) / 2.0
    return c, float(np.max(np.linalg.norm(points - c, axis=1) + reach)) + _BOUND_PAD_M


#: consecutive bodies per group of the self pass's broadphase (a box around their gates,
#: built per call, meets another group's before their body pairs are tested)
SELF_GROUP = 4


def _pairs_by_group(bpairs: np.ndarray, nb: int) -> tuple[np.ndarray, np.ndarray]:
    """The body pairs (u <= v) ordered by the pair of groups of ``SELF_GROUP`` consecutive
    bodies they join, and where each group pair (g <= h, key ``g ng + h``) starts."""
    ng = (nb + SELF_GROUP - 1) // SELF_GROUP
    key = (bpairs[:, 0] // SELF_GROUP) * ng + bpairs[:, 1] // SELF_GROUP
    order = np.argsort(key, kind="stable")
    start = np.searchsorted(key[order], np.arange(ng * ng + 1))
    return _f(order, np.int64), _f(start, np.int64)


#: capsules per cluster at most (a cluster's ball gates its capsules)
_CLUSTER = 4
#: capsules per group at most, and the fewest of a role's capsules in a body that are cut
#: into groups (fewer: one group, whose gate the self pass skips when it is the body's)
_GROUP = 16
_GROUPED_FROM = 33


def _clusters(points: np.ndarray, idx: np.ndarray, size: int) -> list[np.ndarray]:
    """idx cut into groups of at most ``size`` neighbours (halved along the widest axis of
    their points, recursively)."""
    if len(idx) <= size:
        return [idx] if len(idx) else []
    p = points[idx]
    axis = int(np.argmax(p.max(axis=0) - p.min(axis=0)))
    by = idx[np.argsort(p[:, axis], kind="stable")]
    half = len(by) // 2
    return _clusters(points, by[:half], size) + _clusters(points, by[half:], size)


def _f(a: Any, dtype: Any = np.float64) -> np.ndarray:
    # a writable C-ordered copy: numba types read-only arrays apart, and every kernel
    # taking the model would be compiled and cached twice
    return np.array(a, dtype=dtype, order="C", copy=True)


class ChainGeometry(NamedTuple):
    """What :func:`build_model` needs of a collision core (its arrays, by name)."""

    radii: np.ndarray  # (L,) capsule radii against the scene, margin included
    radii_self: np.ndarray  # (L,) against each other, half the margin included
    moving: np.ndarray  # (L,) bool
    allowed: np.ndarray  # (L, L) bool, upper triangle: the checked link pairs
    kinds: np.ndarray  # (n,) obstacle kinds
    Rs: np.ndarray  # (n, 3, 3)
    cs: np.ndarray  # (n, 3)
    hs: np.ndarray  # (n, 3)
    #: (L, n) bool, the robot's capsule order: pairs never tested (declared contacts,
    #: :func:`~plannerlab.problem.scene.touch_mask`); None: none
    touch: np.ndarray | None = None


def _touch_rows(touch: Any, perm: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(obs_touch, touch_caps) of the model (see the module) from an (L, n) mask in the
    robot's capsule order (None: no declared contacts)."""
    L = len(perm)
    obs_touch = np.full(n, -1, dtype=np.int64)
    rows: list[np.ndarray] = []
    if touch is not None:
        t = np.asarray(touch, dtype=bool).reshape(L, n)
        for o in range(n):
            if t[:, o].any():
                obs_touch[o] = len(rows)
                rows.append(t[perm, o])
    caps = np.array(rows, dtype=np.bool_).reshape(len(rows), L)
    return _f(obs_touch, np.int64), _f(caps, np.bool_)


def _coupling(coupling: np.ndarray | None, m: int) -> tuple[list[int], list[int], list[float]]:
    """The coupling, sparse: per chain joint its entries (state index, coefficient)."""
    start: list[int] = []
    idx: list[int] = []
    val: list[float] = []
    if coupling is not None:
        start.append(0)
        for i in range(m):
            for col in np.flatnonzero(coupling[i]):
                idx.append(int(col))
                val.append(float(coupling[i, col]))
            start.append(len(idx))
    return start, idx, val


def _folded(parent: Any, pre: Any, axes: Any) -> tuple[list[np.ndarray], np.ndarray]:
    """Each joint's axis turned onto its frame's z axis: the rotations A (body b's frame
    here is the robot's times A[b]) and the fixed transforms with them folded in (m, 3, 4)."""
    m = len(parent)
    A = [np.eye(3)] + [_align(axes[i]) for i in range(m)]
    pre_f = np.empty((m, 3, 4))
    for i in range(m):
        Ap, Ai = np.eye(4), np.eye(4)
        Ap[:3, :3], Ai[:3, :3] = A[int(parent[i])], A[i + 1]
        pre_f[i] = (Ap.T @ np.asarray(pre[i], dtype=float) @ Ai)[:3]
    return A, pre_f


def _packed_order(
    cap_body: np.ndarray, mid: np.ndarray, nb: int, role: np.ndarray
) -> tuple[Any, ...]:
    """The capsules by body, within a body by role (``role``: which tests see the capsule:
    the scene, other links or both; a gate holds capsules of one role), by group of at
    most ``_GROUP`` neighbours (a role of ``_GROUPED_FROM`` capsules or more; else one
    group) and by cluster of at most ``_CLUSTER``: (perm, cluster starts, each body's
    first cluster, each group's first cluster)."""
    perm_l: list[int] = []
    cl_start, body_cl, grp_cl = [0], [0], [0]
    for b in range(nb):
        mine = np.flatnonzero(cap_body == b)
        for r in np.unique(role[mine]):
            idx = mine[role[mine] == r]
            groups = _clusters(mid, idx, _GROUP) if len(idx) >= _GROUPED_FROM else [idx]
            for g in groups:
                for members in _clusters(mid, g, _CLUSTER):
                    perm_l.extend(int(x) for x in members)
                    cl_start.append(len(perm_l))
                grp_cl.append(len(cl_start) - 1)
        body_cl.append(len(cl_start) - 1)
    return np.array(perm_l, dtype=np.int64), cl_start, body_cl, grp_cl


def _balls(
    ends: tuple[np.ndarray, np.ndarray],
    radii: tuple[np.ndarray, np.ndarray, np.ndarray],
    ranges: list[tuple[int, int]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per range of capsules (ends a, b; radii against the scene, between links, which
    move): centre, radius against the scene (moving capsules only; -1: none) and between
    links."""
    ca, cb = ends
    rad, rads, mov = radii
    c, r, rs = np.zeros((len(ranges), 3)), np.full(len(ranges), -1.0), np.zeros(len(ranges))
    for k, (k0, k1) in enumerate(ranges):
        pts = np.concatenate([ca[k0:k1], cb[k0:k1]])
        c[k], rs[k] = _ball(pts, np.tile(rads[k0:k1], 2))
        mv = np.tile(mov[k0:k1], 2)
        if mv.any():
            d = np.linalg.norm(pts[mv] - c[k], axis=1) + np.tile(rad[k0:k1], 2)[mv]
            r[k] = float(np.max(d)) + _BOUND_PAD_M
    return c, r, rs


def _pairs(
    allowed: Any, perm: np.ndarray, body: np.ndarray, cl_of: np.ndarray, grp_of: Any
) -> tuple[Any, ...]:
    """The checked pairs in the packed order (i < j), grouped by body pair, group pair,
    then cluster pair: (bpairs, bpair_start, clpairs, clpair_start, cpairs, bpair_gstart,
    gpairs as group numbers, gpair_start) as arrays."""
    a = np.asarray(allowed, dtype=bool)
    sym = a | a.T
    al = np.triu(sym[np.ix_(perm, perm)], 1)
    ii, jj = np.nonzero(al)
    gr = np.asarray(grp_of)[cl_of]
    keys = sorted(
        (min(body[i], body[j]), max(body[i], body[j]), gr[i], gr[j], cl_of[i], cl_of[j], i, j)
        for i, j in zip(ii.tolist(), jj.tolist(), strict=True)
    )
    bpairs: list[tuple[int, int]] = []
    bpair_start: list[int] = []
    bpair_gstart: list[int] = []
    gpairs: list[tuple[int, int]] = []
    gpair_start: list[int] = []
    clpairs: list[tuple[int, int]] = []
    clpair_start: list[int] = []
    cpairs: list[tuple[int, int]] = []
    for u, v, gu, gv, cu, cv, i, j in keys:
        new_b = not bpairs or bpairs[-1] != (u, v)
        if new_b:
            bpairs.append((int(u), int(v)))
            bpair_start.append(len(clpairs))
            bpair_gstart.append(len(gpairs))
        g = (int(gu), int(gv))
        if new_b or gpairs[-1] != g:
            gpairs.append(g)
            gpair_start.append(len(clpairs))
        if not clpairs or clpairs[-1] != (cu, cv) or gpair_start[-1] == len(clpairs):
            clpairs.append((int(cu), int(cv)))
            clpair_start.append(len(cpairs))
        cpairs.append((int(i), int(j)))
    bpair_start.append(len(clpairs))
    bpair_gstart.append(len(gpairs))
    gpair_start.append(len(clpairs))
    clpair_start.append(len(cpairs))

    def rows(x: list[tuple[int, int]]) -> np.ndarray:
        return _f(np.array(x, dtype=np.int64).reshape(-1, 2), np.int64)

    return (
        rows(bpairs),
        _f(bpair_start, np.int64),
        rows(clpairs),
        _f(clpair_start, np.int64),
        rows(cpairs),
        _f(bpair_gstart, np.int64),
        rows(gpairs),
        _f(gpair_start, np.int64),
    )


def _group_gates(
    gpairs: np.ndarray, grp_cl: list[int], body_cl: list[int], grp_body: np.ndarray, ncl: int
) -> np.ndarray:
    """(GP, 3): each group pair as rows of ``cg32`` (``ncl + g``) and whether its gate is
    worth testing: not when it is one group twice, nor when each group is its whole body
    (the body pair's gate was the same ball)."""
    out = np.zeros((len(gpairs), 3), dtype=np.int64)
    for k, (gu, gv) in enumerate(gpairs.tolist()):
        whole = [
            grp_cl[g] == body_cl[grp_body[g]] and grp_cl[g + 1] == body_cl[grp_body[g] + 1]
            for g in (gu, gv)
        ]
        out[k] = (ncl + gu, ncl + gv, int(gu != gv and not all(whole)))
    return _f(out, np.int64)


class Chain(NamedTuple):
    """A robot's chain folded alone (no scene, no margin): the kinematic fields of
    :class:`CompiledModel` by the same names, and the capsules in the robot's order with
    their ends in their bodies' folded frames. What the one kinematics
    (:mod:`plannerlab.collision.kinematics`) runs on where no checker's model is at hand
    (the sphere field of a robot alone, the IK)."""

    parent: np.ndarray  # (m,) int64
    slide: np.ndarray  # (m,) bool
    T0: np.ndarray  # (12,) float64
    pre: np.ndarray  # (m, 12) float64
    fold: np.ndarray  # (m + 1, 3, 3): body b's folded frame is the robot's times fold[b]
    cpl_start: np.ndarray  # the coupling, sparse (empty: v = q)
    cpl_idx: np.ndarray
    cpl_val: np.ndarray
    cap_body: np.ndarray  # (L,) int64, the robot's order
    cap_a: np.ndarray  # (L, 3) folded
    cap_b: np.ndarray  # (L, 3) folded


def folded_chain(robot: Any) -> Chain:
    """The robot's chain (``chain_data()``) folded as :func:`build_model` folds it: every
    joint's axis turned onto its frame's z axis.

    Raises:
        ModelError: the robot gives no serial chain.
    """
    if not has_chain(robot):
        raise ModelError(
            f"robot type {getattr(robot, 'kind', type(robot).__name__)!r} gives no serial "
            "chain (chain_data()): its kinematics cannot be compiled"
        )
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling = chain_parts(robot)
    m = len(parent)
    cpl_start, cpl_idx, cpl_val = _coupling(coupling, m)
    A, pre_f = _folded(parent, pre, axes)
    body = np.asarray(cap_body, dtype=np.int64)
    ca = np.asarray(cap_a, dtype=float).reshape(-1, 3)
    cb = np.asarray(cap_b, dtype=float).reshape(-1, 3)
    return Chain(
        parent=_f(parent, np.int64),
        slide=_f(prismatic, np.bool_),
        T0=_f(np.asarray(robot.T_world_base, dtype=float)[:3].reshape(12)),
        pre=_f(pre_f.reshape(m, 12)),
        fold=_f(np.array(A).reshape(m + 1, 3, 3)),
        cpl_start=_f(cpl_start, np.int64),
        cpl_idx=_f(cpl_idx, np.int64),
        cpl_val=_f(cpl_val),
        cap_body=_f(body, np.int64),
        cap_a=_f(np.array([A[int(b)].T @ p for b, p in zip(body, ca, strict=True)]).reshape(-1, 3)),
        cap_b=_f(np.array([A[int(b)].T @ p for b, p in zip(body, cb, strict=True)]).reshape(-1, 3)),
    )


def build_model(
    robot: Any,
    geo: ChainGeometry,
    margin_m: float = 0.0,
    edge_weights: np.ndarray | None = None,
    link_rates: np.ndarray | None = None,
    body_order: np.ndarray | None = None,
) -> CompiledModel:
    """The compiled model of a robot's chain in a scene (see the module docstring).

    Args:
        robot: a robot that gives ``chain_data()``.
        geo: the capsules' radii, which move, the checked pairs and the obstacles (a
            :class:`~plannerlab.collision.core.Core` gives them).
        margin_m: the clearance margin the radii carry [m].
        edge_weights: (dof,) the grid's metric weights (None: radian steps only).
        link_rates: (dof, L) per joint and capsule (the robot's order) how fast the
            capsule moves [m per rad or per m] (None: taken from :func:`~plannerlab.
            collision.reach.reach_bounds`).
        body_order: the order in which bodies meet the scene (default: the last first).

    Raises:
        ModelError: the robot gives no serial chain.
    """
    if not has_chain(robot):
        raise ModelError(
            f"robot type {getattr(robot, 'kind', type(robot).__name__)!r} gives no serial "
            "chain (chain_data()): a compiled consumer (native planners, the state test) "
            "cannot run it; give the robot a chain_data() (docs/extending.md)"
        )
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling = chain_parts(robot)
    m = len(parent)
    nb = m + 1
    cpl_start, cpl_idx, cpl_val = _coupling(coupling, m)
    A, pre_f = _folded(parent, pre, axes)
    cap_body = np.asarray(cap_body, dtype=np.int64)
    cap_a = np.asarray(cap_a, dtype=float).reshape(-1, 3)
    cap_b = np.asarray(cap_b, dtype=float).reshape(-1, 3)
    moving = np.asarray(geo.moving, dtype=bool)
    checked = np.asarray(geo.allowed, dtype=bool)
    checked = (checked | checked.T).any(axis=1)
    role = moving.astype(np.int64) + 2 * checked.astype(np.int64)
    perm, cl_start, body_cl, grp_cl = _packed_order(cap_body, (cap_a + cap_b) / 2.0, nb, role)
    body = cap_body[perm]
    L = len(perm)
    ca = np.array([A[int(b)].T @ p for b, p in zip(body, cap_a[perm], strict=True)]).reshape(-1, 3)
    cb = np.array([A[int(b)].T @ p for b, p in zip(body, cap_b[perm], strict=True)]).reshape(-1, 3)
    rad = np.asarray(geo.radii, dtype=float)[perm]
    rads = np.asarray(geo.radii_self, dtype=float)[perm]
    mov = np.asarray(geo.moving, dtype=bool)[perm]
    body_caps = np.searchsorted(body, np.arange(nb + 1)).astype(np.int64)
    ncl = len(cl_start) - 1
    body_ranges = [(int(body_caps[b]), int(body_caps[b + 1])) for b in range(nb)]
    gate_c, gate_r, gate_rs = _balls((ca, cb), (rad, rads, mov), body_ranges)
    cl_ranges = [(cl_start[k], cl_start[k + 1]) for k in range(ncl)]
    cl_c, cl_r, cl_rs = _balls((ca, cb), (rad, rads, mov), cl_ranges)
    ngr = len(grp_cl) - 1
    grp_of = np.repeat(np.arange(ngr), np.diff(grp_cl))
    grp_body = body[np.array(cl_start, dtype=np.int64)[grp_cl[:-1]]] if ngr else np.zeros(0, int)
    grp_ranges = [(cl_start[grp_cl[g]], cl_start[grp_cl[g + 1]]) for g in range(ngr)]
    grp_c, grp_r, grp_rs = _balls((ca, cb), (rad, rads, mov), grp_ranges)
    cl_body = body[np.array(cl_start[:-1], dtype=np.int64)] if ncl else np.zeros(0, int)
    pairs = _pairs(geo.allowed, perm, body, np.repeat(np.arange(ncl), np.diff(cl_start)), grp_of)
    bpairs, bpair_start, clpairs, clpair_start, cpairs, bpair_gstart, gpairs, gpair_start = pairs
    bpair_gorder, gbpair_start = _pairs_by_group(bpairs, nb)
    order = np.arange(nb)[::-1] if body_order is None else np.asarray(body_order)
    kinds = np.asarray(geo.kinds, dtype=np.int64)
    n = len(kinds)
    Rs = np.asarray(geo.Rs, dtype=float).reshape(n, 9)
    cs = np.asarray(geo.cs, dtype=float).reshape(n, 3)
    hs = np.asarray(geo.hs, dtype=float).reshape(n, 3)
    if link_rates is None:
        from plannerlab.collision.reach import reach_bounds

        link_rates = reach_bounds(robot)[1]
    T0 = np.asarray(robot.T_world_base, dtype=float)[:3].reshape(12)
    lower, upper = _f(robot.lower), _f(robot.upper)
    eps = _float32_bound(T0, pre_f, ca, cb, cs, hs, kinds, lower, upper, robot.continuous)
    obs_touch, touch_caps = _touch_rows(geo.touch, perm, n)
    return CompiledModel(
        parent=_f(parent, np.int64),
        slide=_f(prismatic, np.bool_),
        T0=_f(T0),
        pre=_f(pre_f.reshape(m, 12)),
        fold=_f(np.array(A).reshape(nb, 3, 3)),
        T0_32=_f(T0, np.float32),
        pre_32=_f(pre_f.reshape(m, 12), np.float32),
        cpl_start=_f(cpl_start, np.int64),
        cpl_idx=_f(cpl_idx, np.int64),
        cpl_val=_f(cpl_val),
        body_caps=_f(body_caps, np.int64),
        cap_body=_f(body, np.int64),
        cap_a=_f(ca),
        cap_b=_f(cb),
        cap_sphere=_f(np.all(cap_a[perm] == cap_b[perm], axis=1), np.bool_),
        cap_moving=_f(mov, np.bool_),
        r_scene=_f(rad),
        r_self=_f(rads),
        perm=_f(perm, np.int64),
        gate_c=_f(gate_c),
        gate_r_scene=_f(gate_r),
        gate_r_self=_f(gate_rs),
        body_cls=_f(body_cl, np.int64),
        cl_caps=_f(cl_start, np.int64),
        cl_body=_f(cl_body, np.int64),
        cl_c=_f(cl_c),
        cl_r_scene=_f(cl_r),
        cl_r_self=_f(cl_rs),
        body_order=_f(order, np.int64),
        bpairs=bpairs,
        bpair_start=bpair_start,
        clpairs=clpairs,
        clpair_start=clpair_start,
        cpairs=cpairs,
        grp_cls=_f(grp_cl, np.int64),
        cg_body=_f(np.concatenate([cl_body, grp_body]), np.int64),
        cg32=_f(
            np.column_stack(
                [
                    np.concatenate([cl_c, grp_c]),
                    np.concatenate([cl_r, grp_r]),
                    np.concatenate([cl_rs, grp_rs]),
                    np.zeros((ncl + ngr, 3)),
                ]
            ).reshape(ncl + ngr, 8),
            np.float32,
        ),
        bpair_gstart=bpair_gstart,
        gpairs=_group_gates(gpairs, grp_cl, body_cl, grp_body, ncl),
        gpair_start=gpair_start,
        bpair_gorder=bpair_gorder,
        gbpair_start=gbpair_start,
        obs_kind=_f(kinds, np.int64),
        obs_R=_f(Rs),
        obs_c=_f(cs),
        obs_h=_f(hs),
        obs32=_f(
            np.column_stack([cs, hs, Rs, np.zeros((n, 1)), _world_box(kinds, Rs, hs)]).reshape(
                n, 24
            ),
            np.float32,
        ),
        obs_touch=obs_touch,
        touch_caps=touch_caps,
        caps32=_f(np.column_stack([ca, cb, rad, rads]).reshape(L, 8), np.float32),
        gates32=_f(np.column_stack([gate_c, gate_r, gate_rs, np.zeros((nb, 3))]), np.float32),
        cls32=_f(
            np.column_stack([cl_c, cl_r, cl_rs, np.zeros((ncl, 3))]).reshape(ncl, 8), np.float32
        ),
        lower=lower,
        upper=upper,
        continuous=_f(robot.continuous, np.bool_),
        edge_weights=_f(np.zeros(int(robot.dof)) if edge_weights is None else edge_weights),
        link_rates=_f(np.asarray(link_rates, dtype=float)[:, perm]),
        margin_m=float(margin_m),
        eps32_m=eps,
    )


def _float32_bound(
    T0: np.ndarray,
    pre: np.ndarray,
    ca: np.ndarray,
    cb: np.ndarray,
    cs: np.ndarray,
    hs: np.ndarray,
    kinds: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    continuous: Any,
) -> float:
    """A bound [m] of how far the float32 state test's distances can be from float64's.

    The kinematics: ``m`` joints, each a product of 3 x 4 frames (a rotation entry off by
    a few units of float32's last place per product, ``u = 2^-24``) and a turn whose sine
    and cosine are off by at most ``SINCOS32_ABS_ERR`` plus the joint value's own rounding
    to float32 (``|q| u``; continuous joints are wrapped into [-π, π] first). A rotation
    error ``δR`` grows by at most that much per joint, and moves every point behind the
    joint by ``δR`` times its distance from the joint; a translation picks up a few ``u``
    of its size per product. Summed over the chain with ``S`` the sum of every fixed
    offset's length and capsule end's distance from its body, and ``P`` the largest world
    coordinate the chain or the scene reaches:

        ε_fk ≤ (m + 1) δ S + 8 (m + 1) u P,   δ = SINCOS32_ABS_ERR + (|q|_max + 8) u

    The tests then compute a distance from coordinates of size ``P`` with a few more
    roundings (``16 u P``). The sum, doubled, is the bound: far above what the kinematics
    show in practice (``tests/collision/test_state_test.py`` measures the worst seen), far
    below any radius."""
    u = _F32_UNIT
    m = len(pre)
    cont = np.asarray(continuous, dtype=bool)
    qmax = np.where(cont, np.pi, np.maximum(np.abs(lower), np.abs(upper)))
    qmax = np.where(np.isfinite(qmax), qmax, 64.0)
    offs = np.linalg.norm(pre[:, :, 3], axis=1) if m else np.zeros(0)
    caps = float(np.max(np.linalg.norm(np.concatenate([ca, cb]), axis=1), initial=0.0))
    S = float(np.sum(offs)) + caps
    d = SINCOS32_ABS_ERR + (float(np.max(qmax, initial=0.0)) + 8.0) * u
    scene = float(np.max(np.abs(cs) + np.abs(hs).max(axis=1, keepdims=True), initial=0.0))
    P = float(np.abs(T0[[3, 7, 11]]).max()) + S + scene
    eps_fk = (m + 1) * d * S + 8.0 * (m + 1) * u * P
    del kinds  # every kind's test rounds alike
    return float(2.0 * (eps_fk + 16.0 * u * P))


__all__ = [
    "BOX",
    "CYLINDER",
    "SPHERE",
    "Chain",
    "ChainGeometry",
    "CompiledModel",
    "ModelError",
    "SELF_GROUP",
    "build_model",
    "folded_chain",
    "has_chain",
]

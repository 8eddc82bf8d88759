"""How far the robot's geometry can move per unit of joint motion: the metric edge bound.

Between two states ``q`` and ``q + Δ`` on a straight joint-space edge, no point of the
robot's collision geometry (every capsule, radius included) moves further than
``Σ_i |Δ_i| · r_i`` [m], where ``r_i`` is :func:`joint_reach_m`'s bound for joint ``i``:

* a revolute joint turns the links beyond it about its axis, so a point moves at most
  ``|Δ_i| · (its distance from the axis)``; that distance is at most the distance of the
  first moved link's start from the axis, plus the lengths of the moved links and the
  gaps between them (the moved links form a chain), plus the largest moved capsule
  radius: ``r_i`` is that sum, whatever the other joints are;
* a prismatic joint translates them: ``r_i`` is their speed (1 m per m).

Two bounds of it are taken and the smaller kept (both hold): the chain sum over the moved
*capsules* in their index order (:func:`capsule_reach_bounds`), and over the chain's
rigid *bodies* (:func:`body_reach_bounds`, for a robot that gives its chain,
``chain_data()``): a body's capsules move together, so a mesh link covered by 128
capsules adds one body's extent from its joint, not 128 lengths and gaps (the UR10 with
its finer covers: the capsules' sum is 83-171x the fastest point seen, the bodies' 1.0-1.3x;
``bench/mesh_reach_bound.py``).

The capsules' bound holds for every robot family through the Robot contract only
(``link_segments``): per joint, which links move, the axis and the speed come from a
finite difference of the capsule axes, taken at the start of the joint range and at a
fixed set of states (its own seeded generator; link lengths and gaps of prismatic chains
vary with q, so the largest seen is used). The sum over joints is the bound a planner's
edge resolution in metres needs
(:class:`~plannerlab.collision.fcl_checker.CollisionChecker` with a margin).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plannerlab.robots.base import Array, Robot

#: states the bound is taken at besides the start of the range (seeded, fixed)
_SAMPLES = 16
#: finite-difference step [rad or m]
_H = 1e-6
#: a link whose capsule axis moves slower than this per unit of the joint does not move
_MOVES = 1e-6


def _skew(p: Array) -> Array:
    """(k, 3) vectors → (k, 3, 3) matrices of ``x ↦ p × x``."""
    z = np.zeros(len(p))
    return np.stack(
        [
            np.stack([z, -p[:, 2], p[:, 1]], axis=-1),
            np.stack([p[:, 2], z, -p[:, 0]], axis=-1),
            np.stack([-p[:, 1], p[:, 0], z], axis=-1),
        ],
        axis=1,
    )


def _motions(robot: Robot) -> tuple[Array, Array, Array, Array]:
    """The states the bounds are taken at, their capsule axes S (k, L, 2, 3), the axes'
    velocities per joint V (k, dof, L, 2, 3) by a one-sided finite difference, and the
    upper joint limits used (all in two batched ``link_segments`` calls)."""
    dof = robot.dof
    cont = np.asarray(robot.continuous, dtype=bool)
    lo = np.where(cont, -np.pi, robot.lower)
    hi = np.where(cont, np.pi, robot.upper)
    rng = np.random.default_rng(0)
    states = np.vstack(
        [np.clip(np.zeros(dof), robot.lower, robot.upper), rng.uniform(lo, hi, (_SAMPLES, dof))]
    )
    k = len(states)
    S = np.asarray(robot.link_segments(states), dtype=float)
    h = np.where(states + _H <= hi, _H, -_H)  # (k, dof)
    Qp = np.repeat(states[:, None, :], dof, axis=1)
    idx = np.arange(dof)
    Qp[:, idx, idx] += h
    Sp = np.asarray(robot.link_segments(Qp.reshape(k * dof, dof)), dtype=float)
    V = (Sp.reshape((k, dof) + S.shape[1:]) - S[:, None]) / h[:, :, None, None, None]
    return states, S, V, hi


def _chain(robot: Robot) -> tuple[Any, ...] | None:
    """The robot's serial chain (``chain_data()``, :mod:`plannerlab.collision.chain`'s
    format) as (parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling (n, dof)),
    or None for a robot that gives none (or one this module cannot read)."""
    get = getattr(robot, "chain_data", None)
    if not callable(get):
        return None
    data = tuple(get())
    if len(data) not in (7, 8):
        return None
    parent = np.asarray(data[0], dtype=np.int64)
    n, dof = len(parent), int(robot.dof)
    coupling = data[7] if len(data) == 8 else None
    C = np.eye(n) if coupling is None else np.asarray(coupling, dtype=float)
    if C.shape != (n, dof):
        return None
    pre = np.asarray(data[1], dtype=float).reshape(n, 4, 4)
    axes = np.asarray(data[2], dtype=float).reshape(n, 3)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    prismatic = np.asarray(data[3], dtype=bool).reshape(n)
    cap_body = np.asarray(data[4], dtype=np.int64)
    cap_a = np.asarray(data[5], dtype=float).reshape(-1, 3)
    cap_b = np.asarray(data[6], dtype=float).reshape(-1, 3)
    return parent, pre, axes, prismatic, cap_body, cap_a, cap_b, C


def _off_axis(p: Array, u: Array) -> Array:
    """Distances (k,) of points p (k, 3) from the line through the origin along unit u."""
    return np.linalg.norm(p - np.outer(p @ u, u), axis=-1)


def body_reach_bounds(robot: Robot) -> tuple[Array, Array] | None:
    """Per joint and capsule, an upper bound [m per rad, or m per m] of how fast any point
    of the capsule moves when the joint moves alone, per rigid body of the robot's chain
    (``chain_data()``); None for a robot without one.

    A body's capsules move together, so the chain sum runs over bodies, not capsules.
    Chain joint ``i`` moves body ``i + 1`` and the bodies hung from it. Turning, it moves
    a point at its distance from the joint's axis (the line through the joint frame's
    origin, which is body ``i + 1``'s origin): exact for the capsules of body ``i + 1``
    (their ends' distances from the axis in that body's frame, plus the radius; a
    capsule's farthest point from a line is at an end), and for a body further out at
    most its origin's distance (the parent's bound plus the fixed offset of the joint
    between them, plus the travel of a sliding joint, whatever the joint values) plus the
    capsule's extent from its body's origin (end point plus radius). Sliding, it moves
    every point it moves at 1 m per m. A state joint moves chain joint ``i`` by
    ``coupling[i, j]`` per unit (IRb-6's relative angles; the identity elsewhere): the
    bound is the sum of the chain joints' bounds times ``|coupling[i, j]|``.

    Returns ``(reach (dof,), W (dof, L))`` as :func:`reach_bounds`' first two (``reach``
    the largest of ``W``'s row: every point lies on a capsule); inf where a sliding
    joint's travel is unbounded.
    """
    chain = _chain(robot)
    if chain is None:
        return None
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, C = chain
    n = len(parent)
    L = len(cap_body)
    if np.any(parent > np.arange(n)):  # a body's joint before its parent's: not a chain order
        return None
    radii = np.asarray(robot.link_radii_m, dtype=float)
    if len(radii) != L:
        return None
    # each chain joint's travel |v_i| at most (v = C q over the state's bounds)
    lo = np.asarray(robot.lower, dtype=float)
    hi = np.asarray(robot.upper, dtype=float)
    cont = np.asarray(robot.continuous, dtype=bool)
    q_abs = np.where(cont, np.pi, np.maximum(np.abs(lo), np.abs(hi)))
    with np.errstate(invalid="ignore"):
        travel = np.where(C != 0.0, np.abs(C) * q_abs[None, :], 0.0).sum(axis=1)
    # the offset of each joint's body (i + 1) from its parent body's origin, at most
    offset = np.linalg.norm(pre[:, :3, 3], axis=1) + np.where(prismatic, travel, 0.0)
    extent = np.maximum(np.linalg.norm(cap_a, axis=1), np.linalg.norm(cap_b, axis=1)) + radii
    R = np.zeros((n, L))  # per chain joint
    for i in range(n):
        own = i + 1
        if prismatic[i]:
            reach_b = {own: 0.0}
        else:
            reach_b = {own: -1.0}  # body i + 1 itself: exact, below
        for k in range(i + 1, n):
            b = int(parent[k])
            if b not in reach_b:
                continue
            if prismatic[i]:
                reach_b[k + 1] = 0.0
            elif b == own:  # the joint's offset in body i + 1's frame: exact off the axis
                t = pre[k, :3, 3]
                off = float(_off_axis(t[None], axes[i])[0])
                if prismatic[k]:
                    off += travel[k]
                reach_b[k + 1] = off
            else:
                reach_b[k + 1] = reach_b[b] + offset[k]
        for b, d in reach_b.items():
            caps = cap_body == b
            if not caps.any():
                continue
            if prismatic[i]:
                R[i, caps] = 1.0
            elif b == own:
                far = np.maximum(_off_axis(cap_a[caps], axes[i]), _off_axis(cap_b[caps], axes[i]))
                R[i, caps] = far + radii[caps]
            else:
                R[i, caps] = d + extent[caps]
    with np.errstate(invalid="ignore"):
        W = np.where(C.T[:, :, None] != 0.0, np.abs(C.T)[:, :, None] * R[None], 0.0).sum(axis=1)
    reach = W.max(axis=1) if L else np.zeros(robot.dof)
    return reach, W


def joint_reach_m(robot: Robot) -> Array:
    """Per joint, an upper bound [m per rad, or m per m] of how fast any point of the
    robot's collision geometry moves when that joint moves alone (see the module): the
    first of :func:`reach_bounds`."""
    return reach_bounds(robot)[0]


def reach_bounds(robot: Robot) -> tuple[Array, Array, Array]:
    """Per joint and capsule, an upper bound [m per rad, or m per m] of how fast any point
    of that capsule moves when the joint moves alone, and per joint whether it moves the
    links it moves rigidly: the smaller of two bounds of the same speeds
    (:func:`capsule_reach_bounds`, from the ``Robot`` contract alone, and
    :func:`body_reach_bounds`, per rigid body of the robot's chain when it gives one), the
    bodies' alone for a joint that moves its links non-rigidly (the capsules' bound fits
    one rotation to them all, which holds for a rigid motion only: IRb-6's absolute
    angles turn two chain joints at once, and its fitted bound fell below the speed seen).

    Returns ``(reach (dof,), W (dof, L), rigid (dof,) bool)`` as
    :func:`capsule_reach_bounds`.
    """
    reach, W, rigid = capsule_reach_bounds(robot)
    by_body = body_reach_bounds(robot)
    if by_body is not None:
        # the capsules' bound takes one rotation for every moved link: it holds for a joint
        # that moves them rigidly, not for one that turns two chain joints at once (IRb-6's
        # absolute angles), where the bodies' bound alone holds
        reach = np.where(rigid, np.minimum(reach, by_body[0]), by_body[0])
        W = np.where(rigid[:, None], np.minimum(W, by_body[1]), by_body[1])
    return reach, W, rigid


def capsule_reach_bounds(robot: Robot) -> tuple[Array, Array, Array]:
    """Per joint and link, an upper bound [m per rad, or m per m] of how fast any point of
    that link's capsule moves when the joint moves alone, and per joint whether it moves
    the links it moves rigidly (one rotation or translation for all of them).

    From the ``Robot`` contract alone (``link_segments``): a chain sum over the moved
    capsules in their index order, so a rigid link of many capsules (a mesh's cover) is
    summed as a chain of that many links (:func:`body_reach_bounds` sums over bodies).

    Returns ``(reach (dof,), W (dof, L), rigid (dof,) bool)``: ``reach`` is the whole
    chain's bound of the module (:func:`joint_reach_m`). ``W[i, l]`` is
    zero when joint ``i`` never moves link ``l``; ``W[i].max() <= reach[i]``: for a revolute
    joint the chain sum of :func:`joint_reach_m` is stopped at link ``l`` (the first moved
    link's start from the axis, plus the moved links up to ``l`` and the gaps between them,
    plus ``l``'s radius). This is what lets a link near the base, or a link pair joined by
    few joints, take larger steps than the whole chain's bound allows (conservative
    advancement, :mod:`plannerlab.collision.core`). ``rigid``: the moved links keep their
    shapes and relative poses, so the distance between two links that both move with joint
    ``i`` does not change with it.

    Every (state, joint) at once: the rigid motions are fitted in one batched
    pseudo-inverse (:func:`numpy.linalg.pinv` with :func:`numpy.linalg.lstsq`'s cutoff),
    the chain sums are masked cumulative sums over the moved links.
    """
    dof = robot.dof
    _, S, V, _ = _motions(robot)  # S (k, L, 2, 3), V (k, dof, L, 2, 3)
    radii = np.asarray(robot.link_radii_m, dtype=float)
    k, L = S.shape[0], S.shape[1]
    ks = np.arange(k)[:, None]
    js = np.arange(dof)[None, :]
    speed = np.linalg.norm(V, axis=-1)  # (k, dof, L, 2)
    moved = speed.max(axis=-1) > _MOVES  # (k, dof, L)
    n_moved = moved.sum(axis=-1)  # (k, dof)
    f = np.argmax(moved, axis=-1)  # first moved link (k, dof)
    S_f0 = S[ks, f, 0]  # (k, dof, 3)
    V_f0 = V[ks, js, f, 0]  # (k, dof, 3)
    mask = moved[..., None, None]
    P = np.where(mask, S[:, None] - S_f0[:, :, None, None, :], 0.0)  # (k, dof, L, 2, 3)
    Vr = np.where(mask, V - V_f0[:, :, None, None, :], 0.0)
    # rigid motion of the moved links: v(p) = ω × (p − a_f) + v(a_f), least squares over
    # the moved links' end points (the other rows are zero: they change nothing)
    A = -_skew(P.reshape(-1, 3)).reshape(k, dof, L * 2 * 3, 3)
    b = Vr.reshape(k, dof, L * 2 * 3)
    rcond = np.finfo(float).eps * np.maximum(6 * n_moved, 3)  # numpy.linalg.lstsq's
    omega = np.einsum("kjab,kjb->kja", np.linalg.pinv(A, rcond=rcond), b)  # (k, dof, 3)
    w = np.linalg.norm(omega, axis=-1)  # (k, dof)
    # the finite difference is exact to ~h·speed²: a rigid motion fits to that
    tol = 1e-4 * np.maximum(1.0, speed.max(axis=(-2, -1)))
    resid = np.abs(np.einsum("kjra,kja->kjr", A, omega) - b).max(axis=-1)
    any_moved = n_moved > 0
    rigid = ~np.any(any_moved & (resid > tol), axis=0)
    lengths = np.linalg.norm(S[:, :, 1] - S[:, :, 0], axis=-1)  # (k, L)
    # the gap before each moved link: from the previous moved link's end (0 for the first)
    idx = np.where(moved, np.arange(L), -1)
    last = np.maximum.accumulate(idx, axis=-1)
    prev = np.concatenate([np.full((k, dof, 1), -1), last[..., :-1]], axis=-1)
    S_prev_end = S[ks[..., None], np.maximum(prev, 0), 1]  # (k, dof, L, 3)
    gaps = np.where(
        moved & (prev >= 0),
        np.linalg.norm(S[:, None, :, 0] - S_prev_end, axis=-1),
        0.0,
    )
    ml = np.where(moved, lengths[:, None, :], 0.0)
    rotates = w >= 1e-6
    w_safe = np.where(rotates, w, 1.0)
    start = np.linalg.norm(V_f0, axis=-1) / w_safe  # a_f's distance from the axis
    # a rotation about an axis that also slides (none here) adds its speed
    along = np.abs(np.einsum("kja,kja->kj", V_f0, omega)) / w_safe
    chain = start[..., None] + np.cumsum(ml, axis=-1) + np.cumsum(gaps, axis=-1) + radii
    r_max = np.where(moved, radii, 0.0).max(axis=-1)
    whole = start + ml.sum(axis=-1) + gaps.sum(axis=-1) + r_max
    link_speed = speed.max(axis=-1)  # (k, dof, L)
    bound = np.where(rotates[..., None], w[..., None] * chain + along[..., None], link_speed)
    bound = np.where(moved, bound, 0.0)
    reach_kj = np.where(rotates, w * whole + along, np.where(moved, link_speed, 0.0).max(axis=-1))
    reach_kj = np.where(any_moved, reach_kj, 0.0)
    return reach_kj.max(axis=0), bound.max(axis=0), rigid


def link_reach_m(robot: Robot) -> tuple[Array, Array]:
    """``(W, rigid)`` of :func:`reach_bounds`."""
    _, W, rigid = reach_bounds(robot)
    return W, rigid


def pair_rates(W: Array, rigid: Array, allowed: Array) -> Array:
    """Per joint and link pair, an upper bound of how fast the pair's distance changes
    when the joint moves alone: (dof, L, L), zero outside ``allowed`` (upper triangle).

    A joint that moves neither link, or moves both rigidly, does not change it; one that
    moves one link changes it at most by that link's speed; one that moves both
    non-rigidly, at most by the sum of their speeds."""
    moves = W > 0.0
    a = W[:, :, None]
    b = W[:, None, :]
    one = np.where(moves[:, :, None] & ~moves[:, None, :], a, 0.0) + np.where(
        ~moves[:, :, None] & moves[:, None, :], b, 0.0
    )
    loose = np.logical_not(np.asarray(rigid, dtype=bool))
    both = np.where(moves[:, :, None] & moves[:, None, :] & loose[:, None, None], a + b, 0.0)
    return np.where(np.triu(allowed, 1)[None], one + both, 0.0)

"""Spheres on a robot's links, placed by the one forward kinematics
(:func:`plannerlab.collision.kinematics.chain_frames` in float64, numba, cached): the
compiled geometry of the clearance field (:mod:`plannerlab.planners.clearance`) and of
``trajopt.*``, which own none of their own. The chain comes from a checker's compiled
robot–scene model (:func:`model_sphere_chain`: :class:`~plannerlab.collision.model.
CompiledModel`, built once per problem) or from the robot's chain folded alone
(:func:`sphere_chain`: :func:`~plannerlab.collision.model.folded_chain`), in the same
folded frames and under the same field names.

A :class:`SphereChain` is the chain (its base, fixed transforms with the joints' axes
folded onto z, sliding joints and coupling, the model's fields) with each link's capsule
axis in its body's folded frame, in the robot's link order, and the tip (body, point,
normal: ``robot.tip_data()``). The kernels below:

* :func:`frames`: the body frames (nb, 3, 4) of one state, by ``chain_frames``;
* :func:`link_ends`, :func:`centres`: the links' axes and the sphere centres
  ``a + t (b − a)`` on them; :func:`tip_pose`: the tip's point and normal;
* :func:`point_gradient`: ``n · ∂p/∂q`` of a point p on a body (sign times, added into a
  state gradient): joint ``i`` turns about its body's z axis ``z_i`` through its origin
  ``o_i`` (``∂p/∂v_i = z_i × (p − o_i)``) or slides along it (``z_i``), the bodies'
  joints found by walking up the parents, and the coupling ``∂v/∂q`` applied;
  :func:`tip_jacobians` the same for the tip's point and normal (3, dof each);
* :func:`pairs`: every sphere pair's distance and direction (sphere against box,
  cylinder or sphere; sphere against sphere) in the field's order, with its culls, and
  :func:`pair_spheres` its fixed bookkeeping.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.kinematics import chain_frames, chain_values
from plannerlab.collision.model import folded_chain

#: obstacle kinds of :func:`pairs`
BOX, CYLINDER, SPHERE = 0, 1, 2


class SphereChain(NamedTuple):
    """A robot's chain for the sphere kernels (see the module docstring)."""

    T0: np.ndarray  # (12,) the base in the world, 3 x 4 rows
    parent: np.ndarray  # (n,) the body each chain joint hangs from
    slide: np.ndarray  # (n,) bool: the joint slides
    pre: np.ndarray  # (n, 12) parent body -> joint frame, the axis folded onto z
    cpl_start: np.ndarray  # the coupling, sparse (empty: v = q)
    cpl_idx: np.ndarray
    cpl_val: np.ndarray  # (k,) its coefficients
    link_body: np.ndarray  # (L,) each link's body
    link_a: np.ndarray  # (L, 3) its axis' ends in the body's folded frame
    link_b: np.ndarray
    tip_body: int
    tip_p: np.ndarray  # (3,) the tip point and normal in its body's folded frame
    tip_n: np.ndarray
    #: every joint turns and hangs from the body before it, no coupling: the joints
    #: below body b are 0 … b − 1 (the gradients' loops run straight)
    serial: bool


def _sphere_chain(ch: Any, link: tuple[Any, Any, Any], robot: Any) -> SphereChain:
    """The :class:`SphereChain` of the folded chain ``ch`` (the model's kinematic fields:
    :class:`~plannerlab.collision.model.CompiledModel` or
    :class:`~plannerlab.collision.model.Chain`), the links' bodies and axes (robot order,
    folded frames) and the robot's tip."""
    tip_body, p_bt, n_bt = robot.tip_data()
    tip_body = int(tip_body)
    A = np.asarray(ch.fold[tip_body], dtype=float)
    parent = np.asarray(ch.parent, dtype=np.int64)
    slide = np.asarray(ch.slide, dtype=np.bool_)
    cpl_start = np.asarray(ch.cpl_start, dtype=np.int64)
    m = len(parent)
    f = np.ascontiguousarray
    return SphereChain(
        T0=f(np.asarray(ch.T0, dtype=float).reshape(12)),
        parent=f(parent),
        slide=f(slide),
        pre=f(np.asarray(ch.pre, dtype=float).reshape(m, 12)),
        cpl_start=f(cpl_start),
        cpl_idx=f(np.asarray(ch.cpl_idx, dtype=np.int64)),
        cpl_val=f(np.asarray(ch.cpl_val, dtype=float)),
        link_body=f(np.asarray(link[0], dtype=np.int64)),
        link_a=f(np.asarray(link[1], dtype=float)),
        link_b=f(np.asarray(link[2], dtype=float)),
        tip_body=tip_body,
        tip_p=f(A.T @ np.asarray(p_bt, dtype=float)),
        tip_n=f(A.T @ np.asarray(n_bt, dtype=float)),
        serial=bool(
            len(cpl_start) == 0 and not np.any(slide) and np.array_equal(parent, np.arange(m))
        ),
    )


def sphere_chain(robot: Any) -> SphereChain:
    """The :class:`SphereChain` of ``robot`` from its chain folded alone
    (:func:`~plannerlab.collision.model.folded_chain`: no scene, no checker), its capsules
    in the robot's link order, and the robot's tip (``tip_data()``).

    Raises:
        ModelError: the robot gives no serial chain.
        ValueError: the chain's capsules are not the robot's links one to one.
    """
    ch = folded_chain(robot)
    L = len(np.asarray(robot.link_radii_m))
    if len(ch.cap_body) != L:
        raise ValueError(
            f"robot {getattr(robot, 'kind', '?')!r}: its chain has {len(ch.cap_body)} capsules "
            f"for {L} links; the sphere field needs one capsule per link"
        )
    return _sphere_chain(ch, (ch.cap_body, ch.cap_a, ch.cap_b), robot)


def model_sphere_chain(model: Any, robot: Any) -> SphereChain:
    """The :class:`SphereChain` of ``robot`` from the checker's compiled robot–scene model
    (:class:`~plannerlab.collision.model.CompiledModel`, built once per problem): its
    kinematics, its capsules back in the robot's link order and the robot's tip
    (``tip_data()``), in whole-array operations (no chain folded again).

    Raises:
        ValueError: the model's capsules are not the robot's links one to one.
    """
    L = len(np.asarray(robot.link_radii_m))
    perm = np.asarray(model.perm, dtype=np.int64)
    if len(perm) != L:
        raise ValueError(
            f"robot {getattr(robot, 'kind', '?')!r}: its compiled model has {len(perm)} "
            f"capsules for {L} links; the sphere field needs one capsule per link"
        )
    packed = np.empty(L, dtype=np.int64)  # link l is packed capsule packed[l]
    packed[perm] = np.arange(L)
    link = (
        np.asarray(model.cap_body, dtype=np.int64)[packed],
        np.asarray(model.cap_a, dtype=float)[packed],
        np.asarray(model.cap_b, dtype=float)[packed],
    )
    return _sphere_chain(model, link, robot)


# ---------------------------------------------------------------------- kinematics
@njit(cache=True, nogil=True, inline="always")
def frames(q, ch):
    """The body frames (nb, 3, 4) of state q (dof,): the one kinematics
    (:func:`~plannerlab.collision.kinematics.chain_frames`, float64), through the
    coupling's joint values when there is one."""
    n = ch.parent.shape[0]
    F = np.empty(12 * (n + 1))
    if ch.cpl_start.shape[0] == 0:
        chain_frames(F, q, ch.T0, ch.pre, ch.parent, ch.slide)
    else:
        v = np.empty(n)
        chain_values(q, (ch.cpl_start, ch.cpl_idx, ch.cpl_val), v)
        chain_frames(F, v, ch.T0, ch.pre, ch.parent, ch.slide)
    return F.reshape((n + 1, 3, 4))


@njit(cache=True, nogil=True, inline="always")
def _affine(Bf, b, x, out, k):
    """out[k] = body b's frame applied to the point x (3,)."""
    for a in range(3):
        out[k, a] = Bf[b, a, 0] * x[0] + Bf[b, a, 1] * x[1] + Bf[b, a, 2] * x[2] + Bf[b, a, 3]


@njit(cache=True, nogil=True, inline="always")
def link_ends(Bf, ch):
    """Each link's axis in the world: its two ends, (L, 3) each."""
    L = ch.link_body.shape[0]
    Ea = np.empty((L, 3))
    Eb = np.empty((L, 3))
    for l in range(L):
        _affine(Bf, ch.link_body[l], ch.link_a[l], Ea, l)
        _affine(Bf, ch.link_body[l], ch.link_b[l], Eb, l)
    return Ea, Eb


@njit(cache=True, nogil=True, inline="always")
def centres(Bf, ch, link, t):
    """Sphere centres (s, 3): on link ``link[s]``, ``a + t[s] (b − a)`` of its axis."""
    Ea, Eb = link_ends(Bf, ch)
    S = link.shape[0]
    P = np.empty((S, 3))
    for s in range(S):
        li = link[s]
        for k in range(3):
            a = Ea[li, k]
            b = Eb[li, k]
            P[s, k] = a + t[s] * (b - a)
    return P


@njit(cache=True, nogil=True, inline="always")
def tip_pose(Bf, ch):
    """The tip's point p (3,) and normal n (3,) in the world."""
    b = ch.tip_body
    p = np.empty(3)
    n = np.empty(3)
    for a in range(3):
        p[a] = (
            Bf[b, a, 0] * ch.tip_p[0] + Bf[b, a, 1] * ch.tip_p[1] + Bf[b, a, 2] * ch.tip_p[2]
        ) + Bf[b, a, 3]
        n[a] = Bf[b, a, 0] * ch.tip_n[0] + Bf[b, a, 1] * ch.tip_n[1] + Bf[b, a, 2] * ch.tip_n[2]
    return p, n


@njit(cache=True, nogil=True, inline="always")
def _to_state(cpl, i, x, sign, out):
    """Add ``sign · x`` (the derivative by chain joint i) into ``out`` (dof,), through the
    coupling ``cpl`` (start, idx, val; empty: none)."""
    cpl_start, cpl_idx, cpl_val = cpl
    if cpl_start.shape[0] == 0:
        out[i] += sign * x
        return
    for k in range(cpl_start[i], cpl_start[i + 1]):
        out[cpl_idx[k]] += sign * (cpl_val[k] * x)


@njit(cache=True, nogil=True, inline="always")
def point_gradient(Bf, kn, body, p, nv, sign, out):
    """Add ``sign · n · ∂p/∂q`` into ``out`` (dof,) for the point p (3,) on ``body``
    (``kn``: the chain's :func:`kin`; ``nv`` = (n0, n1, n2), three floats)."""
    n0, n1, n2 = nv
    parent, slide, cpl, _, serial = kn
    if serial:  # joints 0 … body − 1, each turning about its body's z
        for i in range(body):
            b = i + 1
            zx, zy, zz = Bf[b, 0, 2], Bf[b, 1, 2], Bf[b, 2, 2]
            dx = p[0] - Bf[b, 0, 3]
            dy = p[1] - Bf[b, 1, 3]
            dz = p[2] - Bf[b, 2, 3]
            g = n0 * (zy * dz - zz * dy) + n1 * (zz * dx - zx * dz) + n2 * (zx * dy - zy * dx)
            out[i] += sign * g
        return
    b = body
    while b > 0:
        i = b - 1  # the joint that moves body b
        zx, zy, zz = Bf[b, 0, 2], Bf[b, 1, 2], Bf[b, 2, 2]
        if slide[i]:
            g = n0 * zx + n1 * zy + n2 * zz
        else:
            dx = p[0] - Bf[b, 0, 3]
            dy = p[1] - Bf[b, 1, 3]
            dz = p[2] - Bf[b, 2, 3]
            g = n0 * (zy * dz - zz * dy) + n1 * (zz * dx - zx * dz) + n2 * (zx * dy - zy * dx)
        _to_state(cpl, i, g, sign, out)
        b = parent[i]


@njit(cache=True, nogil=True, inline="always")
def kin(ch):
    """The arrays :func:`point_gradient` and :func:`pair_gradient` walk the chain with:
    (parent, slide, coupling, each link's body, serial), taken out of the chain once."""
    return ch.parent, ch.slide, (ch.cpl_start, ch.cpl_idx, ch.cpl_val), ch.link_body, ch.serial


@njit(cache=True, nogil=True, inline="always")
def tip_jacobians(Bf, ch, p, n, dof):
    """The tip's Jacobians (3, dof) each: ∂p/∂q and ∂n/∂q (``z_i × (p − o_i)`` and
    ``z_i × n`` for a turning joint i, ``z_i`` and 0 for a sliding one)."""
    Jp = np.zeros((3, dof))
    Jn = np.zeros((3, dof))
    parent, slide, cpl, _, _ = kin(ch)
    cpl_start, cpl_idx, cpl_val = cpl
    coupled = cpl_start.shape[0] > 0
    b = ch.tip_body
    while b > 0:
        i = b - 1
        zx, zy, zz = Bf[b, 0, 2], Bf[b, 1, 2], Bf[b, 2, 2]
        if slide[i]:
            p0, p1, p2 = zx, zy, zz
            m0, m1, m2 = 0.0, 0.0, 0.0
        else:
            dx = p[0] - Bf[b, 0, 3]
            dy = p[1] - Bf[b, 1, 3]
            dz = p[2] - Bf[b, 2, 3]
            p0 = zy * dz - zz * dy
            p1 = zz * dx - zx * dz
            p2 = zx * dy - zy * dx
            m0 = zy * n[2] - zz * n[1]
            m1 = zz * n[0] - zx * n[2]
            m2 = zx * n[1] - zy * n[0]
        if not coupled:
            Jp[0, i], Jp[1, i], Jp[2, i] = p0, p1, p2
            Jn[0, i], Jn[1, i], Jn[2, i] = m0, m1, m2
        else:
            for k in range(cpl_start[i], cpl_start[i + 1]):
                c = cpl_val[k]
                j = cpl_idx[k]
                Jp[0, j] += c * p0
                Jp[1, j] += c * p1
                Jp[2, j] += c * p2
                Jn[0, j] += c * m0
                Jn[1, j] += c * m1
                Jn[2, j] += c * m2
        b = parent[i]
    return Jp, Jn


# ---------------------------------------------------------------------- pairs
@njit(cache=True, nogil=True)
def pairs(P, r, scene_idx, self_ab, scene, far_m, cull):
    """Every sphere pair, in ``ClearanceField._pairs``' order: distance d (m,), direction
    n (m, 3). ``scene``: the obstacles (kinds, Rs, cs, pars, bound, touch: (n, s) bool,
    sphere ``scene_idx[ii]``'s link a declared contact of obstacle o: the pair is never
    measured and gets d = ``far_m``, as a far one). A pair at least
    ``far_m`` apart gets d = ``far_m`` and no direction (the descent asks nothing of it:
    only pairs closer than the margin cost, and only pairs closer than the clearance
    floor are held); an obstacle's pairs are skipped by its bounding sphere (radius
    ``bound``) when they are that far. The self pairs of two links whose sphere chains are
    that far apart (their midpoints farther than both half-lengths, radii and ``far_m``)
    are skipped together (``lp_of_row``: each self pair's link pair, ``lp_links`` (k, 2)
    its links, ``ends`` (L, 2) each link's first and last sphere; :func:`pair_spheres`):
    ``self_ab`` = (self_a, self_b), ``cull`` = (lp_of_row, lp_links, ends)."""
    self_a, self_b = self_ab
    lp_of_row, lp_links, ends = cull
    kinds, Rs, cs, pars, bound, touch = scene
    n_scene = scene_idx.shape[0]
    n_obs = kinds.shape[0]
    m = n_obs * n_scene + self_a.shape[0]
    d = np.empty(m)
    nrm = np.empty((m, 3))
    loc = np.empty(3)
    g = np.empty(3)
    row = 0
    for o in range(n_obs):
        R = Rs[o]
        c = cs[o]
        kind = kinds[o]
        for ii in range(n_scene):
            s = scene_idx[ii]
            if touch[o, ii]:  # a declared contact: never measured
                d[row] = far_m
                row += 1
                continue
            dx = P[s, 0] - c[0]
            dy = P[s, 1] - c[1]
            dz = P[s, 2] - c[2]
            reach = bound[o] + r[s] + far_m
            if dx * dx + dy * dy + dz * dz >= reach * reach:
                d[row] = far_m
                row += 1
                continue
            if kind == SPHERE:
                nd = math.sqrt(dx * dx + dy * dy + dz * dz)
                dist = nd - pars[o, 0]
                den = nd if nd > 1e-12 else 1.0
                g[0], g[1], g[2] = dx / den, dy / den, dz / den
            else:
                for k in range(3):
                    loc[k] = dx * R[0, k] + dy * R[1, k] + dz * R[2, k]
                gl0 = gl1 = gl2 = 0.0
                if kind == BOX:
                    q0 = abs(loc[0]) - pars[o, 0]
                    q1 = abs(loc[1]) - pars[o, 1]
                    q2 = abs(loc[2]) - pars[o, 2]
                    o0, o1, o2 = max(q0, 0.0), max(q1, 0.0), max(q2, 0.0)
                    on = math.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
                    dist = on + min(max(q0, max(q1, q2)), 0.0)
                    s0 = 1.0 if loc[0] >= 0 else -1.0
                    s1 = 1.0 if loc[1] >= 0 else -1.0
                    s2 = 1.0 if loc[2] >= 0 else -1.0
                    if on > 1e-12:
                        gl0, gl1, gl2 = s0 * o0 / on, s1 * o1 / on, s2 * o2 / on
                    else:  # inside: the face nearest (argmax, first on ties)
                        if q0 >= q1 and q0 >= q2:
                            gl0 = s0
                        elif q1 >= q2:
                            gl1 = s1
                        else:
                            gl2 = s2
                else:  # CYLINDER: pars = radius, half length
                    rho = math.hypot(loc[0], loc[1])
                    if rho > 1e-12:
                        r0, r1 = loc[0] / rho, loc[1] / rho
                    else:
                        r0, r1 = 1.0, 0.0
                    ax = 1.0 if loc[2] >= 0 else -1.0
                    q0 = rho - pars[o, 0]
                    q1 = abs(loc[2]) - pars[o, 1]
                    o0, o1 = max(q0, 0.0), max(q1, 0.0)
                    on = math.sqrt(o0 * o0 + o1 * o1)
                    dist = on + min(max(q0, q1), 0.0)
                    if on > 1e-12:
                        w0, w1 = o0 / on, o1 / on
                        gl0, gl1, gl2 = w0 * r0, w0 * r1, w1 * ax
                    elif q0 >= q1:
                        gl0, gl1 = r0, r1
                    else:
                        gl2 = ax
                for k in range(3):
                    g[k] = R[k, 0] * gl0 + R[k, 1] * gl1 + R[k, 2] * gl2
            dist = dist - r[s]
            if dist >= far_m:
                d[row] = far_m
            else:
                d[row] = dist
                nrm[row, 0], nrm[row, 1], nrm[row, 2] = g[0], g[1], g[2]
            row += 1
    n_links = ends.shape[0]
    mid = np.empty((n_links, 3))
    reach_l = np.empty(n_links)
    for li in range(n_links):
        s0, s1 = ends[li, 0], ends[li, 1]
        if s0 < 0:
            continue
        hx = 0.5 * (P[s1, 0] - P[s0, 0])
        hy = 0.5 * (P[s1, 1] - P[s0, 1])
        hz = 0.5 * (P[s1, 2] - P[s0, 2])
        mid[li, 0], mid[li, 1], mid[li, 2] = P[s0, 0] + hx, P[s0, 1] + hy, P[s0, 2] + hz
        reach_l[li] = math.sqrt(hx * hx + hy * hy + hz * hz) + r[s0]
    n_lp = lp_links.shape[0]
    lp_far = np.empty(n_lp, dtype=np.bool_)
    for k in range(n_lp):
        i, j = lp_links[k, 0], lp_links[k, 1]
        dx = mid[i, 0] - mid[j, 0]
        dy = mid[i, 1] - mid[j, 1]
        dz = mid[i, 2] - mid[j, 2]
        reach = reach_l[i] + reach_l[j] + far_m
        lp_far[k] = dx * dx + dy * dy + dz * dz >= reach * reach * (1.0 + 1e-12)
    for ii in range(self_a.shape[0]):
        if lp_far[lp_of_row[ii]]:
            d[row] = far_m
            row += 1
            continue
        a = self_a[ii]
        b = self_b[ii]
        dx = P[a, 0] - P[b, 0]
        dy = P[a, 1] - P[b, 1]
        dz = P[a, 2] - P[b, 2]
        reach = far_m + r[a] + r[b]
        sq = dx * dx + dy * dy + dz * dz
        if sq >= reach * reach:
            d[row] = far_m
        else:
            nd = math.sqrt(sq)
            d[row] = nd - r[a] - r[b]
            den = nd if nd > 1e-12 else 1.0
            nrm[row, 0], nrm[row, 1], nrm[row, 2] = dx / den, dy / den, dz / den
        row += 1
    return d, nrm


def pair_spheres(
    scene_idx: np.ndarray, n_obstacles: int, self_a: np.ndarray, self_b: np.ndarray, link
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The fixed bookkeeping of :func:`pairs`: the spheres of every pair in its order,
    a (m,) and b (m,) (−1: an obstacle); each self pair's link pair, the link pairs' links
    (k, 2, in order) and each link's first and last sphere (L, 2; −1 for a link without
    spheres). Whole-array operations only (a field is built in a leg's time)."""
    scene_idx = np.asarray(scene_idx, dtype=np.int64)
    self_a = np.asarray(self_a, dtype=np.int64)
    self_b = np.asarray(self_b, dtype=np.int64)
    a = np.concatenate([np.tile(scene_idx, n_obstacles), self_a])
    b = np.concatenate([np.full(len(scene_idx) * n_obstacles, -1, dtype=np.int64), self_b])
    link = np.asarray(link, dtype=np.int64)
    n_links = int(link.max()) + 1 if len(link) else 0
    ends = np.full((n_links, 2), -1, dtype=np.int64)
    if len(link):
        idx = np.arange(len(link), dtype=np.int64)
        first = np.full(n_links, len(link), dtype=np.int64)
        np.minimum.at(first, link, idx)
        np.maximum.at(ends[:, 1], link, idx)
        ends[:, 0] = np.where(first < len(link), first, -1)
    if len(self_a):
        la, lb = link[self_a], link[self_b]
        code = la * max(n_links, 1) + lb
        codes, lp_of_row = np.unique(code, return_inverse=True)
        lp_links = np.stack([codes // max(n_links, 1), codes % max(n_links, 1)], axis=1)
    else:
        lp_of_row = np.zeros(0, dtype=np.int64)
        lp_links = np.zeros((0, 2), dtype=np.int64)
    return (
        np.ascontiguousarray(a),
        np.ascontiguousarray(b),
        np.ascontiguousarray(lp_of_row, dtype=np.int64).reshape(-1),
        np.ascontiguousarray(lp_links, dtype=np.int64).reshape(-1, 2),
        ends,
    )


@njit(cache=True, nogil=True, inline="always")
def pair_gradient(Bf, kn, P, link, nrm, pair, out):
    """∇d (dof,) of one pair into ``out``: n · ∂p_a/∂q (− n · ∂p_b/∂q for a self pair;
    b = −1: an obstacle) with p_s sphere s's centre (:func:`point_gradient`; ``kn``:
    :func:`kin` of the chain; ``pair`` = (a, b, row))."""
    a, b, row = pair
    link_body = kn[3]
    n0, n1, n2 = nrm[row, 0], nrm[row, 1], nrm[row, 2]
    for j in range(out.shape[0]):
        out[j] = 0.0
    point_gradient(Bf, kn, link_body[link[a]], P[a], (n0, n1, n2), 1.0, out)
    if b >= 0:
        point_gradient(Bf, kn, link_body[link[b]], P[b], (n0, n1, n2), -1.0, out)

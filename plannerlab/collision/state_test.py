"""The state test: is the robot free at these states? One test per robot, in vector lanes.

Every planner spends its time here. :func:`test_lanes` tests up to eight states side by
side (the *lanes* of :mod:`plannerlab.collision.simd`: one float32 vector per quantity)
on the compiled model (:class:`~plannerlab.collision.model.CompiledModel`), in two stages:

1. **A float32 filter in the lanes**: the kinematics of
   :mod:`plannerlab.collision.kinematics`, then against each obstacle a box around
   ``GROUP`` consecutive bodies (built per call), then per body a gate (a ball around
   its capsules) against each obstacle; between links, a box around ``GROUP``
   consecutive bodies (built per call) against each other group's, then each body's
   gate against the other's, its groups' gates (a body of many capsules), its clusters'
   (a few neighbours each) and each sphere's against the other cluster's ball; then the
   capsules behind a gate that is not clear. Every radius is grown by
   the model's bound ``eps32_m`` of how far float32 can be off: a lane whose every pair
   is clear by more than that is **free** (certainly: in float64 too), a lane with a
   pair closer than its radius by more than that has **hit** (certainly), and a lane in
   the thin band between is **unsure**.
2. **A float64 confirmation** of the unsure lanes, state by state (:func:`exact_state`):
   the same kinematics in float64 and the exact tests of
   :mod:`plannerlab.collision.geometry` (FCL's verdicts to 1e-6 m). The verdicts are the
   exact float64 ones; the filter decides quickly where deciding is easy.

**Distances in the lanes** are those of :mod:`plannerlab.collision.lane_geometry`.

**Growth for certified edges.** Each lane carries a growth ``grow[k]`` [1] and each
capsule a rate ``rate[l]`` [m]: lane ``k`` tests capsule ``l`` with its radius grown by
``grow[k] · rate[l]`` (a link pair by both). A state free with every capsule grown by how
far it can move along a stretch of an edge proves the whole stretch free
(:mod:`plannerlab.collision.edges`). ``grow = 0`` is the plain test.

**Modes.** ``ANY_HIT`` stops at the first lane of growth 0 that has certainly hit (an edge
is then invalid: nothing else need be known); ``EVERY_LANE`` gives every lane's verdict.
Lane verdicts travel as bit masks (bit k: lane k), so a pass returns two integers.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.exact import exact_state
from plannerlab.collision.kinematics import chain_frames, chain_values, place
from plannerlab.collision.lane_geometry import (
    _box_meets,
    _boxes_meet,
    _ends,
    _gap2,
    _grade_bounds,
    _grade_d2,
    _group_box,
    _in_box,
    _near,
    _point_d2,
    _segment_obstacle,
    _segments,
    _self_boxes,
    _slot3,
)
from plannerlab.collision.model import SELF_GROUP
from plannerlab.collision.simd import (
    LANES,
    bits_mask,
    fma,
    inline_kernel,
    kernel,
    load,
    mask_bits,
    splat,
    store,
    unliteral,
    vmax,
)

#: lanes of one call
W = LANES
#: mode: every lane's verdict
EVERY_LANE = 0
#: mode: stop once a lane of growth 0 has certainly hit
ANY_HIT = 1
_ALL = (1 << LANES) - 1
#: bodies of ``body_order`` in a group of the scene pass's broadphase (a box around their
#: gates, built per call, meets each obstacle's world box before the bodies do; the self
#: pass's groups are the model's ``SELF_GROUP`` consecutive bodies)
GROUP = 4
_F4 = np.float32


class Lanes(NamedTuple):
    """The scratch of the state test and the edge check (made once per search by
    :func:`lanes`); flat float32 arrays of 8-lane slots, then the float64 confirmation's
    one state (``e_*``), then the edge check's (``edge_*``)."""

    Q: np.ndarray  # (dof * W,) the states, continuous joints wrapped
    V: np.ndarray  # (m * W,) the chain's joint values (a coupled chain)
    F: np.ndarray  # (nb * 12 * W,) body frames
    G: np.ndarray  # (nb * 3 * W,) body gate centres
    K: np.ndarray  # ((ncl + G) * 3 * W,) cluster gate centres, then the groups'
    X: np.ndarray  # (L * 6 * W,) capsule ends a (xyz), b (xyz)
    placed: np.ndarray  # (ncl + G,) int64: 0 nothing, 1 the centre, 2 its capsules
    grow: np.ndarray  # (W,) float32: each lane's growth
    rate: np.ndarray  # (L,) float32: each capsule's rate [m] (packed order)
    crate: np.ndarray  # (ncl + G,) float32: each cluster's (then group's) largest rate
    brate: np.ndarray  # (nb,) float32: each body's largest rate
    Q64: np.ndarray  # (W, dof) float64: the states as given (the confirmation's)
    grow64: np.ndarray  # (W,) float64
    rate64: np.ndarray  # (L,) float64
    brate64: np.ndarray  # (nb,) float64
    e_Q: np.ndarray  # (dof,) the confirmation's state
    e_V: np.ndarray  # (m,)
    e_F: np.ndarray  # (nb * 12,) its frames
    e_XA: np.ndarray  # (L, 3) its capsule ends
    e_XB: np.ndarray  # (L, 3)
    e_placed: np.ndarray  # (nb,) int64
    e_w: np.ndarray  # (64,) the exact tests' scratch
    e_R: np.ndarray  # (n, 3, 3) the obstacles' rotations as matrices
    edge_d: np.ndarray  # (dof,) an edge's direction
    edge_q: np.ndarray  # (dof,) a grid state
    edge_rate: np.ndarray  # (L,) the capsules' motion per grid step [m]
    edge_stack: np.ndarray  # (S, 2) int64 stretches still to prove
    edge_marks: np.ndarray  # (3, W) int64 the stretches of one call
    SB: np.ndarray  # (ng * 6 * W,) the self pass's box around each group of SELF_GROUP bodies


@njit(cache=True, nogil=True)
def lanes(m):
    """The scratch of the state test and the edge check for the model m."""
    dof = m.lower.shape[0]
    nj = m.parent.shape[0]
    nb = nj + 1
    L = max(m.cap_body.shape[0], 1)
    ncl = max(m.cg_body.shape[0], 1)  # the clusters, then the groups
    n = m.obs_kind.shape[0]
    ng = (nb + SELF_GROUP - 1) // SELF_GROUP
    R = np.empty((n, 3, 3))
    for o in range(n):
        for a in range(3):
            for b in range(3):
                R[o, a, b] = m.obs_R[o, 3 * a + b]
    f4 = np.float32
    return Lanes(
        np.zeros(dof * W, dtype=f4),
        np.zeros(max(nj, 1) * W, dtype=f4),
        np.zeros(nb * 12 * W, dtype=f4),
        np.zeros(nb * 3 * W, dtype=f4),
        np.zeros(ncl * 3 * W, dtype=f4),
        np.zeros(L * 6 * W, dtype=f4),
        np.zeros(ncl, dtype=np.int64),
        np.zeros(W, dtype=f4),
        np.zeros(L, dtype=f4),
        np.zeros(ncl, dtype=f4),
        np.zeros(nb, dtype=f4),
        np.zeros((W, dof)),
        np.zeros(W),
        np.zeros(L),
        np.zeros(nb),
        np.zeros(dof),
        np.zeros(max(nj, 1)),
        np.zeros(nb * 12),
        np.zeros((L, 3)),
        np.zeros((L, 3)),
        np.zeros(nb, dtype=np.int64),
        np.zeros(64),
        R,
        np.zeros(dof),
        np.zeros(dof),
        np.zeros(L),
        np.zeros((4096, 2), dtype=np.int64),
        np.zeros((3, W), dtype=np.int64),
        np.zeros(ng * 6 * W, dtype=f4),
    )


# ------------------------------------------------------------------ loading the lanes
@kernel
def load_state(Z, k, q, continuous):
    """Lane k holds state q (dof,): its float64 copy, and in float32 with continuous
    joints wrapped into [-π, π] (the filter's kinematics stay accurate)."""
    for i in range(q.shape[0]):
        x = q[i]
        Z.Q64[k, i] = x
        if continuous[i]:
            x = x - 2.0 * math.pi * math.floor(x / (2.0 * math.pi) + 0.5)
        Z.Q[i * W + k] = np.float32(x)


@kernel
def fill_lanes(Z, n):
    """Lanes n..W-1 repeat lane 0 (a call tests W lanes whatever is asked; a copy is
    harmless and is not reported)."""
    dof = Z.Q64.shape[1]
    for k in range(n, W):
        for i in range(dof):
            Z.Q64[k, i] = Z.Q64[0, i]
            Z.Q[i * W + k] = Z.Q[i * W]
        Z.grow[k] = Z.grow[0]
        Z.grow64[k] = Z.grow64[0]


@kernel
def set_plain(Z):
    """Every lane grows by nothing (the plain test)."""
    for k in range(W):
        Z.grow[k] = 0.0
        Z.grow64[k] = 0.0


@kernel
def set_rates(m, Z, rate64):
    """Every capsule's rate [m] for grown lanes (packed order), and each cluster's and
    body's largest (their gates grow by it). The float32 copies are rounded up, so a
    grown radius is never short."""
    up = np.float32(1.0 + 2.0**-20)
    for b in range(Z.brate.shape[0]):
        Z.brate[b] = 0.0
        Z.brate64[b] = 0.0
    for c in range(m.cl_body.shape[0]):
        Z.crate[c] = 0.0
        for l in range(m.cl_caps[c], m.cl_caps[c + 1]):
            r = rate64[l]
            r32 = np.float32(r) * up
            Z.rate64[l] = r
            Z.rate[l] = r32
            b = m.cap_body[l]
            Z.crate[c] = max(Z.crate[c], r32)
            Z.brate[b] = max(Z.brate[b], r32)
            Z.brate64[b] = max(Z.brate64[b], r)
    for g in range(m.grp_cls.shape[0] - 1):  # the groups' after the clusters'
        k, Z.crate[m.cl_body.shape[0] + g] = m.cl_body.shape[0] + g, 0.0
        for c in range(m.grp_cls[g], m.grp_cls[g + 1]):
            Z.crate[k] = max(Z.crate[k], Z.crate[c])


@inline_kernel
def frames32(m, Z):
    """Every body's frame in the eight lanes, and the body gates' centres."""
    if m.cpl_start.shape[0] > 0:
        chain_values(Z.Q, (m.cpl_start, m.cpl_idx, m.cpl_val), Z.V)
        chain_frames(Z.F, Z.V, m.T0_32, m.pre_32, m.parent, m.slide)
    else:
        chain_frames(Z.F, Z.Q, m.T0_32, m.pre_32, m.parent, m.slide)
    F, G, gates = Z.F, Z.G, m.gates32
    for b in range(gates.shape[0]):
        x, y, z = place(F, b, gates, b, 0)
        store(G, 3 * b * W, x)
        store(G, (3 * b + 1) * W, y)
        store(G, (3 * b + 2) * W, z)


@kernel
def _place_cluster(F, X, K, c, tables, placed):
    """Cluster c's gate centre (placed 1), or its capsules' ends too (placed 2: ``placed``
    asks which): tables = (cls32, caps32, cl_caps, cl_body, cap_sphere, state)."""
    cls, caps, cl_caps, cl_body, sphere, state = tables
    b = cl_body[c]
    if state[c] == 0:
        x, y, z = place(F, b, cls, c, 0)
        store(K, 3 * c * W, x)
        store(K, (3 * c + 1) * W, y)
        store(K, (3 * c + 2) * W, z)
        state[c] = 1
    if placed < 2 or state[c] == 2:
        return
    for l in range(cl_caps[c], cl_caps[c + 1]):
        x, y, z = place(F, b, caps, l, 0)
        o = 6 * l * W
        store(X, o, x)
        store(X, o + W, y)
        store(X, o + 2 * W, z)
        if not sphere[l]:
            x, y, z = place(F, b, caps, l, 3)
        store(X, o + 3 * W, x)
        store(X, o + 4 * W, y)
        store(X, o + 5 * W, z)
    state[c] = 2


@njit(cache=True, nogil=True, inline="always")
def _stop(hit, mode):
    """The mode's stop: a lane has hit (ANY_HIT), or every lane has."""
    if mode == ANY_HIT:
        return hit != 0
    return hit == _ALL


@inline_kernel
def _scene_pass(m, Z, mode, hu):
    """Every moving capsule against every obstacle (but its declared contacts: the model's
    ``obs_touch``, ``touch_caps``), behind three gates: a box around a
    group of ``GROUP`` consecutive bodies of ``body_order`` (built per call from the
    kinematics), its bodies' gates, and their clusters' gates. The lane masks ``hu``
    (see :func:`_grade_d2`) updated, and whether the mode's stop came."""
    O, kinds, caps, cls, gates = m.obs32, m.obs_kind, m.caps32, m.cls32, m.gates32
    F, G, K, X = Z.F, Z.G, Z.K, Z.X
    tables = (cls, caps, m.cl_caps, m.cl_body, m.cap_sphere, Z.placed)
    grow = load(Z.grow, 0)
    eps = splat(m.eps32_m)
    nb = m.body_order.shape[0]
    for k0 in range(0, nb, GROUP):
        k1 = min(k0 + GROUP, nb)
        B = _group_box(gates, G, Z.brate, m.body_order, k0, k1, grow, eps)
        if not B[6]:
            continue
        for o in range(kinds.shape[0]):
            if not _box_meets(O, o, B, _ALL & ~hu[0]):
                continue
            kind = kinds[o]
            touch = m.obs_touch[o]  # -1, or the row of its declared contacts
            for kb in range(k0, k1):
                b = m.body_order[kb]
                if gates[b, 3] < 0.0:
                    continue
                gx, gy, gz = _slot3(G, b)
                rb = fma(grow, splat(Z.brate[b]), splat(gates[b, 3]) + eps)
                if not _in_box(O, o, gx, gy, gz, rb, _ALL & ~hu[0]):
                    continue
                if not _near(_point_d2(kind, O, o, gx, gy, gz), rb, _ALL & ~hu[0]):
                    continue
                for c in range(m.body_cls[b], m.body_cls[b + 1]):
                    if cls[c, 3] < 0.0:
                        continue
                    _place_cluster(F, X, K, c, tables, unliteral(1))
                    kx, ky, kz = _slot3(K, c)
                    rc = fma(grow, splat(Z.crate[c]), splat(cls[c, 3]) + eps)
                    if not _near(_point_d2(kind, O, o, kx, ky, kz), rc, _ALL & ~hu[0]):
                        continue
                    _place_cluster(F, X, K, c, tables, unliteral(2))
                    for l in range(m.cl_caps[c], m.cl_caps[c + 1]):
                        if not m.cap_moving[l]:
                            continue
                        if touch >= 0 and m.touch_caps[touch, l]:
                            continue  # a declared contact: never tested
                        r0 = splat(caps[l, 6])
                        r = fma(grow, splat(Z.rate[l]), r0)
                        if m.cap_sphere[l]:
                            o6 = 6 * l * W
                            d2 = _point_d2(
                                kind, O, o, load(X, o6), load(X, o6 + W), load(X, o6 + 2 * W)
                            )
                            hu = _grade_d2(d2, r0, r, eps, hu)
                        else:
                            lo, hi_d = _segment_obstacle(kind, O, o, _ends(X, l))
                            hu = _grade_bounds(lo, hi_d, r0, r, eps, hu)
            if _stop(hu[0], mode):
                return hu, True
    return hu, False


@njit(cache=True, nogil=True, inline="always")
def _pairs_in(T, q0, q1, cv, eps, grow, plain, hm):
    """Capsule pairs ``q0:q1`` (of a cluster pair whose second cluster is ``cv``: row of
    ``cg32``) graded into the lane masks ``hm`` = (hit, unsure grown, unsure plain), kept
    as vector masks (the tests of :func:`_grade_d2` and :func:`_grade_bounds`); ``T`` =
    (X, cpairs, caps32, rate, cap_sphere, K, cg32, crate); ``plain``: every lane's growth
    is 0 (the grown radius is the plain one). The pairs of one sphere ``i`` (a run of
    ``cpairs``) are tested only if the sphere meets ``cv``'s ball (its gate: a sphere
    clear of the ball is clear of every capsule in it) in some lane."""
    X, cpairs, caps, rate, sphere, K, cls, crate = T
    mh, mg, m0 = hm
    zero = splat(0.0)
    run, skip = -1, False
    for q in range(q0, q1):
        i, j = cpairs[q, 0], cpairs[q, 1]
        if i != run:  # a sphere's pairs with cv: its gate first
            run, skip = i, False
            if sphere[i]:
                rg = splat(caps[i, 7] + cls[cv, 4]) + eps
                if not plain:
                    rg = fma(grow, splat(rate[i] + crate[cv]), rg)
                skip = not _near(_gap2(X, 6 * i * W, K, 3 * cv * W), rg, unliteral(_ALL))
        if skip:
            continue
        r0 = splat(caps[i, 7] + caps[j, 7])
        h0 = r0 + eps
        if plain:
            hg = h0
        else:
            hg = fma(grow, splat(rate[i] + rate[j]), r0) + eps
        if sphere[i] and sphere[j]:
            lo = vmax(r0 - eps, zero)
            d2 = _gap2(X, 6 * i * W, X, 6 * j * W)
            mh = mh | (d2 < lo * lo)
            mg = mg | (d2 <= hg * hg)
            m0 = m0 | (d2 <= h0 * h0)
            continue
        if sphere[i]:  # the first a segment (a sphere: one of zero length)
            i, j = j, i
        lo_d, hi_d = _segments(_ends(X, i), _ends(X, j))
        mh = mh | (hi_d < r0 - eps)
        mg = mg | (lo_d <= hg)
        m0 = m0 | (lo_d <= h0)
    return mh, mg, m0


@inline_kernel
def _self_pass(m, Z, mode, hu):
    """Every checked link pair behind the boxes around groups of ``SELF_GROUP``
    consecutive bodies (built per call: two groups apart in every live lane skip their
    body pairs, taken group pair by group pair), then its body, group and cluster pairs'
    gates (hu, stop)."""
    caps, cls, gates = m.caps32, m.cg32, m.gates32  # cg32: the clusters, then the groups
    F, G, K, X, cr = Z.F, Z.G, Z.K, Z.X, Z.crate
    tables = (cls, caps, m.cl_caps, m.cg_body, m.cap_sphere, Z.placed)
    grow = load(Z.grow, 0)
    plain = mask_bits(grow > splat(0.0)) == 0
    eps = splat(m.eps32_m)
    none = bits_mask(0)
    pair_tables = (X, m.cpairs, caps, Z.rate, m.cap_sphere, K, cls, cr)
    # the broadphase: a box per group of SELF_GROUP consecutive bodies; the body pairs
    # of two groups whose boxes meet in no live lane are skipped (one branch a group pair)
    ng = _self_boxes(gates, G, Z.brate, Z.SB, SELF_GROUP, grow, eps)
    for gh in range(ng * ng):
        g, h = gh // ng, gh % ng
        b0, b1 = m.gbpair_start[gh], m.gbpair_start[gh + 1]
        if b0 == b1:
            continue
        meet = _boxes_meet(Z.SB, g, h) & ~hu[0]
        if meet == 0:
            continue
        for kp in range(b0, b1):
            p = m.bpair_gorder[kp]
            u, v = m.bpairs[p, 0], m.bpairs[p, 1]
            if u != v:
                r = fma(grow, splat(Z.brate[u] + Z.brate[v]), splat(gates[u, 4] + gates[v, 4]))
                if not _near(_gap2(G, 3 * u * W, G, 3 * v * W), r + eps, meet & ~hu[0]):
                    continue
            hm = (none, none, none)
            for gp in range(m.bpair_gstart[p], m.bpair_gstart[p + 1]):
                gu, gv = m.gpairs[gp, 0], m.gpairs[gp, 1]
                if m.gpairs[gp, 2]:  # a group's centre is placed like a cluster's (placed 1)
                    _place_cluster(F, X, K, gu, tables, unliteral(1))
                    _place_cluster(F, X, K, gv, tables, unliteral(1))
                    r = fma(grow, splat(cr[gu] + cr[gv]), splat(cls[gu, 4] + cls[gv, 4]) + eps)
                    if not _near(_gap2(K, 3 * gu * W, K, 3 * gv * W), r, meet & ~hu[0]):
                        continue
                for cp in range(m.gpair_start[gp], m.gpair_start[gp + 1]):
                    cu, cv = m.clpairs[cp, 0], m.clpairs[cp, 1]
                    if cu != cv:
                        _place_cluster(F, X, K, cu, tables, unliteral(1))
                        _place_cluster(F, X, K, cv, tables, unliteral(1))
                        r = fma(grow, splat(cr[cu] + cr[cv]), splat(cls[cu, 4] + cls[cv, 4]) + eps)
                        if not _near(_gap2(K, 3 * cu * W, K, 3 * cv * W), r, meet & ~hu[0]):
                            continue
                    _place_cluster(F, X, K, cu, tables, unliteral(2))
                    _place_cluster(F, X, K, cv, tables, unliteral(2))
                    q0, q1 = m.clpair_start[cp], m.clpair_start[cp + 1]
                    hm = _pairs_in(pair_tables, q0, q1, cv, eps, grow, plain, hm)
            hu = (
                hu[0] | mask_bits(hm[0]),
                hu[1] | mask_bits(hm[1]),
                hu[2] | mask_bits(hm[2]),
            )
            if _stop(hu[0], mode):
                return hu, True
    return hu, False


@kernel
def test_lanes(m, Z, mode):
    """Test the eight lanes' states (loaded by :func:`load_state`, grown by ``Z.grow``).

    Returns ``(free, hit, confirmed)``, bit masks over the lanes and a count:

    * ``hit``: the lane's state itself (not grown) collides: the exact float64 verdict;
      a lane not in it is free (not grown), exactly;
    * ``free``: free even with every capsule grown by the lane's growth (proved; a lane
      of growth 0 is in it exactly when it is not in ``hit``);
    * ``confirmed``: lanes whose plain verdict the float64 confirmation decided.

    With ``ANY_HIT`` it returns as soon as any lane has hit (its state is invalid); lanes
    not yet decided are then in neither mask."""
    for c in range(Z.placed.shape[0]):
        Z.placed[c] = 0
    frames32(m, Z)
    hu, stop = _scene_pass(m, Z, mode, unliteral((0, 0, 0)))
    if stop:
        return 0, hu[0], 0
    hu, stop = _self_pass(m, Z, mode, hu)
    hit, unsure_g, unsure_0 = hu
    if stop:
        return 0, hit, 0
    confirmed = 0
    todo = unsure_0 & ~hit  # the plain state near a surface: float64 decides
    for k in range(W):
        if (todo >> k) & 1:
            confirmed += 1
            if not exact_state(m, Z, Z.Q64[k], 0.0):
                hit |= 1 << k
                if mode == ANY_HIT:
                    return 0, hit, confirmed
            elif Z.grow[k] == 0.0:
                unsure_g &= ~(1 << k)  # a plain lane: free is its verdict
    return _ALL & ~hit & ~unsure_g, hit, confirmed


# ------------------------------------------------------------------ entry points
@njit(cache=True, nogil=True)
def valid_batch(m, Q, out):
    """Validity of states Q (k, dof) -> out (k,) bool, eight a call. Returns the number of
    states the float64 confirmation decided."""
    Z = lanes(m)
    set_plain(Z)
    confirmed = 0
    for s0 in range(0, Q.shape[0], W):
        nn = min(W, Q.shape[0] - s0)
        for j in range(nn):
            load_state(Z, j, Q[s0 + j], m.continuous)
        fill_lanes(Z, nn)
        free, _, c = test_lanes(m, Z, unliteral(EVERY_LANE))
        confirmed += c
        for j in range(nn):
            out[s0 + j] = (free >> j) & 1
    return confirmed


@kernel
def valid_one(m, Z, q):
    """One state q (dof,) is valid (in lane 0; Z's growth must be plain)."""
    load_state(Z, unliteral(0), q, m.continuous)
    fill_lanes(Z, 1)
    free, _, _ = test_lanes(m, Z, unliteral(ANY_HIT))
    return (free & 1) != 0


@njit(cache=True, nogil=True)
def exact_batch(m, Q, out):
    """The float64 verdicts alone (no filter) of Q (k, dof) -> out (k,): the reference the
    filter's verdicts equal."""
    Z = lanes(m)
    for s in range(Q.shape[0]):
        out[s] = exact_state(m, Z, Q[s], 0.0)
    return out

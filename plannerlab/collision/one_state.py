"""The state test of ONE state, in vector lanes: eight of its capsules at once.

The batch road (:mod:`plannerlab.collision.state_test`) puts eight *states* in the eight
float32 lanes; asked about one state, it fills seven lanes with copies and pays for eight.
This road fills the lanes with one state's geometry instead (the tables of
:mod:`plannerlab.collision.one_lanes`):

1. **Kinematics**: every joint's sine and cosine at once, eight to a float32 vector (the
   batch road's polynomial, on values wrapped into [-π, π] in float64), then the one
   kinematics (:func:`~plannerlab.collision.kinematics.chain_frames`) in float64 from
   them; every body's gate centre placed in float64 (and rounded into float32 lanes), a
   world box around each block of eight bodies' gates.
2. **The scene pass**, per obstacle: a block's box against the obstacle's world box
   (scalar), then eight bodies' gates against the obstacle (one vector test), then, for
   a body whose gate meets it, its capsules eight at a time (placed in float32 from the
   body's frame when first needed, one vector per coordinate).
3. **The self pass**: a body's gate against eight others' it is paired with (one vector
   test), then each meeting body pair's runs: capsule ``i`` (splat) against up to eight
   capsules of the other body (one vector load each), a sphere ``i`` first against the
   other body's gate (scalar).

Every test grades as the batch road's does, with the same distances
(:mod:`plannerlab.collision.lane_geometry`) and the model's float32 bound ``eps32_m``:
a pair closer than its radius by more than ``eps32_m`` has certainly hit (the road returns
at once: the state is invalid), a pair farther than its radius by more than it is
certainly clear, and a pair in the band between makes the state *unsure*, decided at the
end by the float64 test (:func:`~plannerlab.collision.exact.exact_state`: FCL's
verdicts). The verdicts are therefore exactly the float64 ones, as the batch road's.

**Why ``eps32_m`` still bounds the error.** The model's bound covers float32 frames built
joint by joint from the polynomial's sines (the batch road's: ``δ`` per joint, see
:func:`~plannerlab.collision.model.build_model`). Here the same sines meet float64
products (smaller errors than float32's), and a capsule's end is placed in float32 from
the frame rounded once to float32 (three fused multiply-adds per coordinate: a few ``u``
of the coordinates' size ``P``), its body-frame point rounded to float32: inside
``eps32_m = 2 (ε_fk + 16 u P)`` with ``ε_fk ≥ 8 (m + 1) u P``; the tests' own roundings
are the batch road's. ``tests/collision/test_one_state.py`` holds every place within half
of ``eps32_m`` of float64's, so a gate of two places (a sphere against a body's ball) is
within ``eps32_m``. Tests that skip whole bodies are float64 on these places or float32
grown by ``eps32_m``: a body is skipped only when it is clear in float64 too.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plannerlab.collision.exact import exact_state
from plannerlab.collision.kinematics import chain_frames, chain_values, place, sincos
from plannerlab.collision.lane_geometry import _point_d2, _segment_obstacle, _segments
from plannerlab.collision.one_lanes import open_one
from plannerlab.collision.queries import open_packed
from plannerlab.collision.simd import (
    LANES,
    fma,
    inline_kernel,
    kernel,
    load,
    mask_bits,
    splat,
    store,
    vmax,
)

W = LANES
_TWO_PI = 2.0 * math.pi
#: a pass's outcomes: every pair certainly clear / some pair in the band (unsure) / a
#: pair certainly hit
CLEAR, UNSURE, HIT = 0, 1, 2


@inline_kernel
def _gates(m, Z, T):
    """The state's body frames (float64, in ``Z.e_F``), each gated body's gate centre
    (``T.G64``, and rounded into ``T.GW``), each body block's world box (``T.BB``:
    the gates' balls against the scene, grown by ``eps32_m``); no capsule placed yet."""
    G64, GW, BB = T.G64, T.GW, T.BB
    nb = m.gate_c.shape[0]
    NB8 = T.GRS.shape[0]
    for k in range(NB8 // W):
        for a in range(3):
            BB[6 * k + a] = 1e300
            BB[6 * k + 3 + a] = -1e300
    for b in range(nb):
        T.placed[b] = 0
        x, y, z = place(Z.e_F, b, m.gate_c, b, 0)
        G64[3 * b], G64[3 * b + 1], G64[3 * b + 2] = x, y, z
        k = b // W
        o = 3 * k * W + b % W
        GW[o], GW[o + W], GW[o + 2 * W] = x, y, z
        r = m.gate_r_scene[b]
        if r >= 0.0:
            r += m.eps32_m
            BB[6 * k] = min(BB[6 * k], x - r)
            BB[6 * k + 1] = min(BB[6 * k + 1], y - r)
            BB[6 * k + 2] = min(BB[6 * k + 2], z - r)
            BB[6 * k + 3] = max(BB[6 * k + 3], x + r)
            BB[6 * k + 4] = max(BB[6 * k + 4], y + r)
            BB[6 * k + 5] = max(BB[6 * k + 5], z + r)


@inline_kernel
def _place_body(F, b, T):
    """Body b's capsule ends in the world (``T.WX``), eight slots a vector, in float32 from
    its float64 frame ``F`` (``Z.e_F``)."""
    if T.placed[b]:
        return
    T.placed[b] = 1
    o = 12 * b
    f = (
        splat(F[o]), splat(F[o + 1]), splat(F[o + 2]), splat(F[o + 3]),
        splat(F[o + 4]), splat(F[o + 5]), splat(F[o + 6]), splat(F[o + 7]),
        splat(F[o + 8]), splat(F[o + 9]), splat(F[o + 10]), splat(F[o + 11]),
    )  # fmt: skip
    LX, WX = T.LX, T.WX
    S8 = T.RS.shape[0]
    for s in range(T.slot0[b], T.slot0[b + 1], W):
        for e in range(2):
            if e == 1 and T.bsph[s // W]:
                for c in range(3):
                    store(WX, (3 + c) * S8 + s, load(WX, c * S8 + s))
                break
            px = load(LX, 3 * e * S8 + s)
            py = load(LX, (3 * e + 1) * S8 + s)
            pz = load(LX, (3 * e + 2) * S8 + s)
            for c in range(3):
                v = fma(f[4 * c], px, fma(f[4 * c + 1], py, fma(f[4 * c + 2], pz, f[4 * c + 3])))
                store(WX, (3 * e + c) * S8 + s, v)


@njit(cache=True, nogil=True, inline="always")
def _ends_at(WX, S8, s):
    """The world ends (a, b) of the eight slots from s: six vectors."""
    return (
        load(WX, s), load(WX, S8 + s), load(WX, 2 * S8 + s),
        load(WX, 3 * S8 + s), load(WX, 4 * S8 + s), load(WX, 5 * S8 + s),
    )  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def _box_clear(BB, k, O, o):
    """Body block k's world box (float64) is clear of obstacle o's world box."""
    for a in range(3):
        c, h = float(O[o, a]), float(O[o, 16 + a])
        if BB[6 * k + a] > c + h or BB[6 * k + 3 + a] < c - h:
            return True
    return False


@njit(cache=True, nogil=True, inline="always")
def _touch_bits(m, row, b, k0):
    """The bits of the eight slots of body b from its capsule k0 whose capsules are
    declared contacts of the obstacle of ``touch_caps`` row ``row`` (never tested)."""
    bits = 0
    l0 = m.body_caps[b] + k0
    for j in range(min(W, m.body_caps[b + 1] - l0)):
        if m.touch_caps[row, l0 + j]:
            bits |= 1 << j
    return bits


@inline_kernel
def _scene(m, Z, T):
    """Every moving capsule against every obstacle (but its declared contacts: the
    model's ``touch_caps``), behind the bodies' block boxes and gates: :data:`CLEAR`,
    :data:`UNSURE` or :data:`HIT` (returned at the first)."""
    O, kinds = m.obs32, m.obs_kind
    eps = splat(m.eps32_m)
    zero = splat(0.0)
    S8 = T.RS.shape[0]
    nb = m.gate_c.shape[0]
    out = CLEAR
    for o in range(kinds.shape[0]):
        kind = kinds[o]
        touch = m.obs_touch[o]  # -1, or the row of its declared contacts
        for k in range(T.bgated.shape[0]):
            live = T.bgated[k]
            if live == 0 or _box_clear(T.BB, k, O, o):
                continue
            g = 3 * k * W
            gx, gy, gz = load(T.GW, g), load(T.GW, g + W), load(T.GW, g + 2 * W)
            rb = load(T.GRS, k * W) + eps
            near = _point_d2(kind, O, o, gx, gy, gz) <= rb * rb
            live &= mask_bits(near)
            if live == 0:
                continue
            for j in range(W):
                if not (live >> j) & 1:
                    continue
                b = k * W + j
                if b >= nb:
                    break
                _place_body(Z.e_F, b, T)
                for s in range(T.slot0[b], T.slot0[b + 1], W):
                    move = T.bmove[s // W]
                    if touch >= 0:
                        move &= ~_touch_bits(m, touch, b, s - T.slot0[b])
                    if move == 0:
                        continue
                    r0 = load(T.RS, s)
                    if T.bsph[s // W]:
                        x, y, z = load(T.WX, s), load(T.WX, S8 + s), load(T.WX, 2 * S8 + s)
                        d2 = _point_d2(kind, O, o, x, y, z)
                        lo = vmax(r0 - eps, zero)
                        h0 = r0 + eps
                        if mask_bits(d2 < lo * lo) & move:
                            return HIT
                        if mask_bits(d2 <= h0 * h0) & move:
                            out = UNSURE
                    else:
                        lo_d, hi_d = _segment_obstacle(kind, O, o, _ends_at(T.WX, S8, s))
                        if mask_bits(hi_d < r0 - eps) & move:
                            return HIT
                        if mask_bits(lo_d <= r0 + eps) & move:
                            out = UNSURE
    return out


@inline_kernel
def _runs(T, p, v, eps_s, out):
    """Body pair p's runs (v: its second body): capsule i (splat) against up to eight of
    the other body's (one vector load each), a sphere i first against v's gate ball
    (float64 on its float32 place, grown by ``eps_s``): :data:`CLEAR`, :data:`UNSURE` or
    :data:`HIT` (returned at once); ``out`` the outcome so far."""
    G64, WX, RL = T.G64, T.WX, T.RL
    eps = splat(eps_s)
    zero = splat(0.0)
    S8 = RL.shape[0]
    gv = 3 * v
    rv = float(T.GRL[v])
    run_i, skip = -1, False
    ax, ay, az, bx, by, bz, ri = zero, zero, zero, zero, zero, zero, zero
    for r in range(T.run_start[p], T.run_start[p + 1]):
        si, j0, bits, allsph = T.runs[r, 0], T.runs[r, 1], T.runs[r, 2], T.runs[r, 3]
        if si != run_i:
            run_i, skip = si, False
            if T.runs[r, 4]:  # a sphere against the other body's ball (its gate)
                x, y, z = float(WX[si]), float(WX[S8 + si]), float(WX[2 * S8 + si])
                dx, dy, dz = x - G64[gv], y - G64[gv + 1], z - G64[gv + 2]
                rg = float(RL[si]) + rv + eps_s
                skip = dx * dx + dy * dy + dz * dz > rg * rg
            if not skip:
                ax, ay, az = splat(WX[si]), splat(WX[S8 + si]), splat(WX[2 * S8 + si])
                bx, by, bz = splat(WX[3 * S8 + si]), splat(WX[4 * S8 + si]), splat(WX[5 * S8 + si])
                ri = splat(RL[si])
        if skip:
            continue
        r0 = ri + load(RL, j0)
        if allsph:
            ex = load(WX, j0) - ax
            ey = load(WX, S8 + j0) - ay
            ez = load(WX, 2 * S8 + j0) - az
            d2 = fma(ex, ex, fma(ey, ey, ez * ez))
            lo = vmax(r0 - eps, zero)
            h0 = r0 + eps
            if mask_bits(d2 < lo * lo) & bits:
                return HIT
            if mask_bits(d2 <= h0 * h0) & bits:
                out = UNSURE
        else:
            lo_d, hi_d = _segments(_ends_at(WX, S8, j0), (ax, ay, az, bx, by, bz))
            if mask_bits(hi_d < r0 - eps) & bits:
                return HIT
            if mask_bits(lo_d <= r0 + eps) & bits:
                out = UNSURE
    return out


@inline_kernel
def _self(m, Z, T):
    """Every checked link pair behind its body pair's gate (body u's gate against eight
    others' at once, float32 grown by ``eps32_m``), then its runs (:func:`_runs`):
    :data:`CLEAR`, :data:`UNSURE` or :data:`HIT` (returned at the first)."""
    GW, GRL, B = T.GW, T.GRL, T.brows
    eps_s = m.eps32_m
    eps = splat(eps_s)
    out = CLEAR
    for row in range(B.shape[0]):
        u, k = B[row, 0], B[row, 1]
        gu = 3 * (u // W) * W + u % W
        g = 3 * k * W
        x = load(GW, g) - splat(GW[gu])
        y = load(GW, g + W) - splat(GW[gu + W])
        z = load(GW, g + 2 * W) - splat(GW[gu + 2 * W])
        rr = load(GRL, k * W) + (splat(GRL[u]) + eps)
        near = mask_bits(fma(x, x, fma(y, y, z * z)) <= rr * rr) & B[row, 2]
        if near == 0:
            continue
        _place_body(Z.e_F, u, T)
        for j in range(W):
            if not (near >> j) & 1:
                continue
            v = k * W + j
            _place_body(Z.e_F, v, T)
            out = _runs(T, B[row, 3 + j], v, eps_s, out)
            if out == HIT:
                return HIT
    return out


@njit(cache=True, nogil=True, inline="always")
def _sincos8(X, i0, S, C):
    """The sines and cosines of eight joint values X[i0:i0 + 8] (float32 polynomial)."""
    s, c = sincos(load(X, i0))
    store(S, i0, s)
    store(C, i0, c)


@inline_kernel
def _frames(m, Z, T, q):
    """Every body's frame of q (dof,) into ``Z.e_F`` by the one kinematics in float64, every
    joint's sine and cosine taken first eight at once in float32 (:func:`_sincos8`, the
    batch road's polynomial, its error inside the model's float32 bound)."""
    for i in range(q.shape[0]):
        Z.e_Q[i] = q[i]
    V = Z.e_Q
    if m.cpl_start.shape[0] > 0:
        chain_values(Z.e_Q, (m.cpl_start, m.cpl_idx, m.cpl_val), Z.e_V)
        V = Z.e_V
    nj = m.parent.shape[0]
    VT = T.VT
    for i in range(nj):
        x = V[i]
        VT[i, 0] = x
        if not m.slide[i]:
            x = x - _TWO_PI * math.floor(x / _TWO_PI + 0.5)
        T.X32[i] = np.float32(x)
    for i0 in range(0, nj, W):
        _sincos8(T.X32, i0, T.S32, T.C32)
    for i in range(nj):
        VT[i, 1] = T.S32[i]
        VT[i, 2] = T.C32[i]
    chain_frames(Z.e_F, VT, m.T0, m.pre, m.parent, m.slide)


@inline_kernel
def one_valid(m, Z, T, q):
    """Is the one state q (dof,) free (model m, the state test's scratch Z, the opened
    one-state tables T: :func:`~plannerlab.collision.one_lanes.open_one`)? Exactly the
    float64 verdict (see the module). Inlined into its callers: out of line, a call
    would take the model, the scratch and the tables (some hundred arrays) on the stack."""
    _frames(m, Z, T, q)
    _gates(m, Z, T)
    s = _scene(m, Z, T)
    if s == HIT:
        return False
    s2 = _self(m, Z, T)
    if s2 == HIT:
        return False
    if s == CLEAR and s2 == CLEAR:
        return True
    return exact_state(m, Z, q, 0.0)


@kernel
def valid_state(P, t32, t64i, t64, q):
    """Is the one state q (dof,) free? ``P``: a checker's packed model
    (``checker.packed_model``); ``t32, t64i, t64``: its one-state tables
    (:func:`~plannerlab.collision.one_lanes.checker_tables`), three arrays, not a tuple
    (numba types a tuple from Python slowly: ~1 µs a call). Returns 1 (free), 0 (not), or
    -1 when q holds a value that is not finite (nothing tested). The compiled entry of
    the public checker's ``valid(q)``."""
    for i in range(q.shape[0]):
        if not math.isfinite(q[i]):
            return -1
    m, Z = open_packed(P)
    return 1 if one_valid(m, Z, open_one((t32, t64i, t64)), q) else 0


@kernel
def valid_each(P, T, Q, out):
    """Each of the states Q (k, dof) tested alone by the one-state road -> out (k,) bool
    (benches and tests: the road's verdicts and cost, state by state)."""
    m, Z = open_packed(P)
    O = open_one(T)
    for s in range(Q.shape[0]):
        out[s] = one_valid(m, Z, O, Q[s])
    return out


__all__ = ["CLEAR", "HIT", "UNSURE", "one_valid", "valid_each", "valid_state"]

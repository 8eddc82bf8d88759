"""The state test's float64 confirmation: one state, the exact tests, FCL's verdicts.

The float32 filter of :mod:`plannerlab.collision.state_test` leaves to this the states in
its thin band of doubt (a pair closer than its radius plus the filter's float32 bound):
the same kinematics (:mod:`plannerlab.collision.kinematics`) in float64 and the exact
capsule tests of :mod:`plannerlab.collision.geometry`, behind the body gates (grown by a
rounding's pad), capsules grown by ``grow · rate`` when asked. ``exact_batch`` gives its
verdicts alone (the reference the tests hold the filter to).
"""

from __future__ import annotations

import math

from plannerlab.collision.geometry import BOX, SPHERE, capsule_obstacle_hit, seg_seg
from plannerlab.collision.kinematics import chain_frames, chain_values, place
from plannerlab.collision.simd import kernel


@kernel
def _place64(m, Z, b):
    for l in range(m.body_caps[b], m.body_caps[b + 1]):
        x, y, z = place(Z.e_F, b, m.cap_a, l, 0)
        Z.e_XA[l, 0], Z.e_XA[l, 1], Z.e_XA[l, 2] = x, y, z
        x, y, z = place(Z.e_F, b, m.cap_b, l, 0)
        Z.e_XB[l, 0], Z.e_XB[l, 1], Z.e_XB[l, 2] = x, y, z
    Z.e_placed[b] = 1


@kernel
def _clear64(m, o, x, y, z, r):
    """A ball (centre x, radius r) is clear of obstacle o by a rounding's margin."""
    c, h, R = m.obs_c[o], m.obs_h[o], m.obs_R[o]
    x0, x1, x2 = x - c[0], y - c[1], z - c[2]
    kind = m.obs_kind[o]
    if kind == SPHERE:
        rr = r + h[0] + 1e-9
        return x0 * x0 + x1 * x1 + x2 * x2 > rr * rr
    u = R[0] * x0 + R[3] * x1 + R[6] * x2
    v = R[1] * x0 + R[4] * x1 + R[7] * x2
    w = R[2] * x0 + R[5] * x1 + R[8] * x2
    if kind == BOX:
        du = max(abs(u) - h[0], 0.0)
        dv = max(abs(v) - h[1], 0.0)
        dw = max(abs(w) - h[2], 0.0)
    else:
        du = max(math.sqrt(u * u + v * v) - h[0], 0.0)
        dv = max(abs(w) - h[1], 0.0)
        dw = 0.0
    rr = r + 1e-9
    return du * du + dv * dv + dw * dw > rr * rr


@kernel
def frames64(m, Z, q):
    """Every body's frame of one state q (dof,) in float64 into Z.e_F (the one kinematics)."""
    for i in range(q.shape[0]):
        Z.e_Q[i] = q[i]
    if m.cpl_start.shape[0] > 0:
        chain_values(Z.e_Q, (m.cpl_start, m.cpl_idx, m.cpl_val), Z.e_V)
        chain_frames(Z.e_F, Z.e_V, m.T0, m.pre, m.parent, m.slide)
    else:
        chain_frames(Z.e_F, Z.e_Q, m.T0, m.pre, m.parent, m.slide)


@kernel
def exact_state(m, Z, q, grow):
    """One state q (dof,) is free with every capsule grown by ``grow · rate`` (float64,
    the exact tests of ``geometry``: FCL's verdicts; an obstacle's declared contacts, the
    model's ``touch_caps``, never tested); ``Z.rate64``, ``Z.brate64``: the capsules' and
    bodies' rates."""
    rate, brate = Z.rate64, Z.brate64
    frames64(m, Z, q)
    for b in range(Z.e_placed.shape[0]):
        Z.e_placed[b] = 0
    for kb in range(m.body_order.shape[0]):
        b = m.body_order[kb]
        gr = m.gate_r_scene[b]
        if gr < 0.0:
            continue
        x, y, z = place(Z.e_F, b, m.gate_c, b, 0)
        gb = gr + grow * brate[b]
        for o in range(m.obs_kind.shape[0]):
            if _clear64(m, o, x, y, z, gb):
                continue
            if Z.e_placed[b] == 0:
                _place64(m, Z, b)
            touch = m.obs_touch[o]  # -1, or the row of its declared contacts
            for l in range(m.body_caps[b], m.body_caps[b + 1]):
                if touch >= 0 and m.touch_caps[touch, l]:
                    continue  # a declared contact: never tested
                if m.cap_moving[l] and capsule_obstacle_hit(
                    m.obs_kind[o], Z.e_R[o], m.obs_c[o], m.obs_h[o], Z.e_XA[l], Z.e_XB[l],
                    m.r_scene[l] + grow * rate[l], Z.e_w,
                ):  # fmt: skip
                    return False
    for p in range(m.bpairs.shape[0]):
        u, v = m.bpairs[p, 0], m.bpairs[p, 1]
        if u != v:
            xu, yu, zu = place(Z.e_F, u, m.gate_c, u, 0)
            xv, yv, zv = place(Z.e_F, v, m.gate_c, v, 0)
            rr = m.gate_r_self[u] + m.gate_r_self[v] + grow * (brate[u] + brate[v]) + 1e-9
            dx, dy, dz = xu - xv, yu - yv, zu - zv
            if dx * dx + dy * dy + dz * dz > rr * rr:
                continue
        if Z.e_placed[u] == 0:
            _place64(m, Z, u)
        if Z.e_placed[v] == 0:
            _place64(m, Z, v)
        for q2 in range(m.clpair_start[m.bpair_start[p]], m.clpair_start[m.bpair_start[p + 1]]):
            i, j = m.cpairs[q2, 0], m.cpairs[q2, 1]
            rr = m.r_self[i] + m.r_self[j] + grow * (rate[i] + rate[j])
            d2, _, _ = seg_seg(Z.e_XA[i], Z.e_XB[i], Z.e_XA[j], Z.e_XB[j])
            if d2 <= rr * rr:
                return False
    return True

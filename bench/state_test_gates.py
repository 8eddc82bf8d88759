"""How many gate and pair tests a batch state test makes per call of eight lanes (issue 32):
the scene and self passes' gate loops of ``collision/state_test.py`` replayed with
counters (the plain test, no early stop), on uniform random states.

    PYTHONPATH=. .venv/bin/python bench/state_test_gates.py PROBLEM [PROBLEM ...]

Printed per 8-lane call: body-gate against obstacle tests (behind the group boxes of
``GROUP`` consecutive bodies, counted last) and how many let a lane through,
cluster-gate tests and the capsules then tested, body pairs (behind the self pass's
boxes around groups of ``SELF_GROUP`` consecutive bodies, whose pair tests are counted
last) and how many pass, cluster-pair gates and the
capsule pairs then tested (behind each sphere's gate against the other cluster's ball;
the pairs behind the cluster-pair gates and those sphere gates are counted last). (The
world-box prefilter of the body gates is not counted: it passes a superset of what the
gate passes.)
"""

import sys

import numpy as np
from numba import njit

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.model import SELF_GROUP
from plannerlab.collision.queries import open_packed
from plannerlab.collision.state_test import (
    _ALL,
    GROUP,
    W,
    _box_meets,
    _boxes_meet,
    _gap2,
    _group_box,
    _near,
    _place_cluster,
    _point_d2,
    _self_boxes,
    _slot3,
    frames32,
    load_state,
    set_plain,
    splat,
)
from plannerlab.problem.catalog import load_problem


@njit(cache=True)
def counts(P, Q):
    m, Z = open_packed(P)
    set_plain(Z)
    c = np.zeros(14, np.int64)
    O, kinds, cls, gates = m.obs32, m.obs_kind, m.cls32, m.gates32
    tables = (cls, m.caps32, m.cl_caps, m.cl_body, m.cap_sphere, Z.placed)
    eps = splat(m.eps32_m)
    for s0 in range(0, Q.shape[0], W):
        for j in range(W):
            load_state(Z, j, Q[s0 + j], m.continuous)
        for q in range(Z.placed.shape[0]):
            Z.placed[q] = 0
        frames32(m, Z)
        nb = m.body_order.shape[0]
        for k0 in range(0, nb, GROUP):
            k1 = min(k0 + GROUP, nb)
            B = _group_box(gates, Z.G, Z.brate, m.body_order, k0, k1, splat(0.0), eps)
            if not B[6]:
                continue
            for o in range(kinds.shape[0]):
                c[8] += 1
                if not _box_meets(O, o, B, _ALL):
                    continue
                c[9] += 1
                for kb in range(k0, k1):
                    b = m.body_order[kb]
                    if gates[b, 3] < 0.0:
                        continue
                    gx, gy, gz = _slot3(Z.G, b)
                    rb = splat(gates[b, 3]) + eps
                    c[0] += 1
                    if not _near(_point_d2(kinds[o], O, o, gx, gy, gz), rb, _ALL):
                        continue
                    c[1] += 1
                    for cc in range(m.body_cls[b], m.body_cls[b + 1]):
                        if cls[cc, 3] < 0.0:
                            continue
                        _place_cluster(Z.F, Z.X, Z.K, cc, tables, 1)
                        kx, ky, kz = _slot3(Z.K, cc)
                        c[2] += 1
                        if not _near(
                            _point_d2(kinds[o], O, o, kx, ky, kz), splat(cls[cc, 3]) + eps, _ALL
                        ):
                            continue
                        c[3] += m.cl_caps[cc + 1] - m.cl_caps[cc]
        ng = _self_boxes(gates, Z.G, Z.brate, Z.SB, SELF_GROUP, splat(0.0), eps)
        for gh in range(ng * ng):
            b0, b1 = m.gbpair_start[gh], m.gbpair_start[gh + 1]
            if b0 == b1:
                continue
            c[10] += 1
            if _boxes_meet(Z.SB, gh // ng, gh % ng) == 0:
                continue
            c[11] += 1
            for kp in range(b0, b1):
                p = m.bpair_gorder[kp]
                u, v = m.bpairs[p, 0], m.bpairs[p, 1]
                c[4] += 1
                if u != v:
                    r = splat(gates[u, 4] + gates[v, 4]) + eps
                    if not _near(_gap2(Z.G, 3 * u * W, Z.G, 3 * v * W), r, _ALL):
                        continue
                c[5] += 1
                for cp in range(m.bpair_start[p], m.bpair_start[p + 1]):
                    cu, cv = m.clpairs[cp, 0], m.clpairs[cp, 1]
                    if cu != cv:
                        _place_cluster(Z.F, Z.X, Z.K, cu, tables, 1)
                        _place_cluster(Z.F, Z.X, Z.K, cv, tables, 1)
                        c[6] += 1
                        r = splat(cls[cu, 4] + cls[cv, 4]) + eps
                        if not _near(_gap2(Z.K, 3 * cu * W, Z.K, 3 * cv * W), r, _ALL):
                            continue
                    _place_cluster(Z.F, Z.X, Z.K, cu, tables, 2)
                    _place_cluster(Z.F, Z.X, Z.K, cv, tables, 2)
                    c[12] += m.clpair_start[cp + 1] - m.clpair_start[cp]
                    run, skip = -1, False
                    for q in range(m.clpair_start[cp], m.clpair_start[cp + 1]):
                        i = m.cpairs[q, 0]
                        if i != run:
                            run, skip = i, False
                            if m.cap_sphere[i]:
                                c[13] += 1
                                r = splat(m.caps32[i, 7] + cls[cv, 4]) + eps
                                skip = not _near(_gap2(Z.X, 6 * i * W, Z.K, 3 * cv * W), r, _ALL)
                        if not skip:
                            c[7] += 1
    return c


for name in sys.argv[1:]:
    pr = load_problem(name)
    ch = problem_checker(pr)
    m = ch.model
    Q = np.random.default_rng(0).uniform(pr.robot.lower, pr.robot.upper, (8000, pr.robot.dof))
    c = counts(ch.packed_model, Q) / 1000.0
    print(
        name,
        "bodies",
        m.gates32.shape[0],
        "clusters",
        m.cls32.shape[0],
        "caps",
        m.caps32.shape[0],
        "obs",
        m.obs_kind.shape[0],
        "bpairs",
        m.bpairs.shape[0],
        "clpairs",
        m.clpairs.shape[0],
        "cpairs",
        m.cpairs.shape[0],
    )
    labels = (
        "body-obstacle gates (behind the group boxes)", "let through",
        "cluster-obstacle gates", "capsules tested",
        "body pairs", "pass", "cluster-pair gates", "capsule pairs tested",
        "group-obstacle box tests", "let through",
        "self group-pair box tests", "let through",
        "capsule pairs behind the cluster-pair gates", "sphere-cluster gates before them",
    )  # fmt: skip
    print("  per 8-lane call: " + ", ".join(f"{k} {v:.1f}" for k, v in zip(labels, c, strict=True)))

"""The self pass's broadphase (issue 32): a box around each group of ``SELF_GROUP``
consecutive bodies, built per call in float32 lanes (``lane_geometry._self_boxes``), lets
a body pair through in a lane only where the boxes of its two groups meet. The gate must be
conservative: each box holds its bodies' gate balls (their radii between links) as the
float64 kinematics place them, every body pair whose balls meet (or nearly: near contact)
is let through, and the verdicts stay float64's and FCL's on self-colliding and
near-contact states."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PROBLEMS
from numba import njit
from test_model import _coiled, _exact_valid, _model_valid, _near_contact

from plannerlab.collision.exact import frames64
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.kinematics import place
from plannerlab.collision.lane_geometry import _boxes_meet, _self_boxes
from plannerlab.collision.model import SELF_GROUP as GROUP
from plannerlab.collision.queries import open_packed
from plannerlab.collision.simd import splat
from plannerlab.collision.state_test import W, frames32, load_state, set_plain
from plannerlab.problem.load import parse_problem
from plannerlab.problem.scene import Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.continuum.model import ContinuumChain


@njit(cache=True)
def _boxes_near_and_gates(P, Q):
    """Per state: each group's self box (lo, hi) in float32, the lanes' near table as
    bits per state (ng, ng), and every body's gate centre in float64."""
    m, Z = open_packed(P)
    set_plain(Z)
    nb = m.gates32.shape[0]
    ng = (nb + GROUP - 1) // GROUP
    boxes = np.zeros((Q.shape[0], ng, 6))
    near = np.zeros((Q.shape[0], ng, ng), dtype=np.bool_)
    gates64 = np.zeros((Q.shape[0], nb, 3))
    eps = splat(m.eps32_m)
    for s0 in range(0, Q.shape[0], W):
        for j in range(W):
            load_state(Z, j, Q[s0 + j], m.continuous)
        frames32(m, Z)
        ng = _self_boxes(m.gates32, Z.G, Z.brate, Z.SB, GROUP, splat(0.0), eps)
        for g in range(ng):
            for a in range(6):
                v = Z.SB[(6 * g + a) * W : (6 * g + a + 1) * W]
                for j in range(W):
                    boxes[s0 + j, g, a] = v[j]
            for h in range(ng):
                bits = _boxes_meet(Z.SB, g, h)
                for j in range(W):
                    near[s0 + j, g, h] = (bits >> j) & 1
        for j in range(W):
            frames64(m, Z, Q[s0 + j])
            for b in range(nb):
                x, y, z = place(Z.e_F, b, m.gate_c, b, 0)
                gates64[s0 + j, b, 0], gates64[s0 + j, b, 1], gates64[s0 + j, b, 2] = x, y, z
    return boxes, near, gates64


def _check_broadphase(checker, Q):
    """Every box holds its bodies' float64 gate balls and is not loose; every body pair
    whose float64 balls meet (what its own gate lets through) is let through. Returns
    (pairs let through, pairs skipped) over the states."""
    m = checker.model
    boxes, near, gates64 = _boxes_near_and_gates(checker.packed_model, Q)
    nb = m.gates32.shape[0]
    for g in range(boxes.shape[1]):
        bodies = [b for b in range(g * GROUP, min(g * GROUP + GROUP, nb)) if m.gate_r_self[b] >= 0]
        if not bodies:
            assert np.all(boxes[:, g, :3] > boxes[:, g, 3:])  # empty: meets nothing
            continue
        r = m.gate_r_self[bodies][None, :, None]
        lo = (gates64[:, bodies] - r).min(axis=1)
        hi = (gates64[:, bodies] + r).max(axis=1)
        assert np.all(boxes[:, g, :3] <= lo) and np.all(boxes[:, g, 3:] >= hi)
        slack = 3.0 * m.eps32_m + 1e-5 * max(1.0, float(np.abs(hi).max()))
        assert np.all(lo - boxes[:, g, :3] <= slack) and np.all(boxes[:, g, 3:] - hi <= slack)
    through = skipped = 0
    for u, v in m.bpairs:
        if u == v:
            continue
        gap = np.linalg.norm(gates64[:, u] - gates64[:, v], axis=1)
        close = gap <= m.gate_r_self[u] + m.gate_r_self[v]
        let = near[:, u // GROUP, v // GROUP]
        assert np.all(let[close]), f"body pair {u, v} skipped where its balls meet"
        through += int(let.sum())
        skipped += int((~let).sum())
    return through, skipped


def _panda():
    problem = parse_problem(PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml")
    return problem.robot, problem_checker(problem)


SELF = {
    "armz": lambda: ArmZ(n_modules=24),
    "continuum_chain": lambda: ContinuumChain(n_links=30, link_radius_m=0.004),
}


@pytest.mark.parametrize("kind", ["panda", *sorted(SELF)])
def test_the_self_boxes_hold_their_bodies_and_skip_no_meeting_pair(kind):
    rng = np.random.default_rng(61)
    if kind == "panda":
        robot, checker = _panda()
        Q = rng.uniform(robot.lower, robot.upper, (1600, robot.dof))
    else:
        robot = SELF[kind]()
        checker = CollisionChecker(robot, Scene(), margin_m=0.02)
        lo, hi = robot.lower, robot.upper
        spread = (0.1, 0.35) if kind == "continuum_chain" else (-0.3, 0.3)
        Q = np.vstack(
            [rng.uniform(lo, hi, (800, robot.dof)), _coiled(lo, hi, 800, rng, spread, 0.2)]
        )
    through, skipped = _check_broadphase(checker, Q)
    assert through > 0
    if kind != "panda":  # a long chain: the broadphase skips pairs (it does something)
        assert skipped > through


@pytest.mark.parametrize("kind", sorted(SELF))
def test_verdicts_stay_fcls_near_self_contact_behind_the_self_boxes(kind):
    """Self-colliding chains in an empty scene: random, coiled, and near-contact states
    (either side of the boundary by 2e-4 rad, and at it) keep float64's and FCL's
    verdicts, and the broadphase lets every near-contact pair through."""
    robot = SELF[kind]()
    rng = np.random.default_rng(67)
    lo, hi = robot.lower, robot.upper
    spread = (0.1, 0.35) if kind == "continuum_chain" else (-0.3, 0.3)
    Q = _coiled(lo, hi, 1500, rng, spread, 0.2)
    checker = CollisionChecker(robot, Scene(), margin_m=0.02)
    core = checker._core
    fcl = CollisionChecker(robot, Scene(), backend="fcl", margin_m=0.02)
    v = _model_valid(core, Q)
    assert 0.02 < (~v).mean() < 0.98
    assert np.array_equal(v, _exact_valid(core, Q))
    assert np.array_equal(v, fcl.valid_batch(Q))
    inside, outside = _near_contact(core, lo, hi, Q, 40, rng)
    assert len(inside) == 40
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()
    assert _model_valid(core, inside).all() and not _model_valid(core, outside).any()
    at_lo, at_hi = _near_contact(core, lo, hi, Q, 40, rng, offset=0.0)
    both = np.vstack([at_lo, at_hi, inside, outside])
    assert np.array_equal(_model_valid(core, both), _exact_valid(core, both))
    assert [core.is_valid(q) for q in both] == _exact_valid(core, both).tolist()
    _check_broadphase(checker, both)


@njit(cache=True)
def _capsules_and_clusters64(P, Q):
    """Per state, in float64: every packed capsule's ends and every cluster's centre."""
    m, Z = open_packed(P)
    L, K = m.cap_body.shape[0], m.cl_body.shape[0]
    ends = np.zeros((Q.shape[0], L, 2, 3))
    centres = np.zeros((Q.shape[0], K, 3))
    for s in range(Q.shape[0]):
        frames64(m, Z, Q[s])
        for c in range(L):
            b = m.cap_body[c]
            ends[s, c, 0, 0], ends[s, c, 0, 1], ends[s, c, 0, 2] = place(Z.e_F, b, m.cap_a, c, 0)
            ends[s, c, 1, 0], ends[s, c, 1, 1], ends[s, c, 1, 2] = place(Z.e_F, b, m.cap_b, c, 0)
        for c in range(K):
            x, y, z = place(Z.e_F, m.cl_body[c], m.cl_c, c, 0)
            centres[s, c, 0], centres[s, c, 1], centres[s, c, 2] = x, y, z
    return ends, centres


def _point_segment(p, a, b):
    """Distances from points p (n, 3) to segments a b (n, 3 each)."""
    e = b - a
    ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-30)
    t = np.clip(np.einsum("ij,ij->i", p - a, e) / ee, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * e), axis=1)


def test_a_spheres_gate_against_the_other_cluster_holds_every_pair_it_gates():
    """The self pass tests a sphere's pairs with cluster ``cv`` only if the sphere meets
    ``cv``'s ball (radius between links): on the Panda's random and near-contact states
    (either side of the boundary by 2e-4 rad), every checked pair that meets in float64
    has its sphere meeting that ball in float64 (so the float32 gate, grown by eps, lets
    it through); and some gates are clear (the gate does something)."""
    robot, checker = _panda()
    m, core = checker.model, checker._core
    rng = np.random.default_rng(71)
    Q = rng.uniform(robot.lower, robot.upper, (1500, robot.dof))
    inside, outside = _near_contact(core, robot.lower, robot.upper, Q, 40, rng)
    Q = np.vstack([Q, inside, outside])
    ends, centres = _capsules_and_clusters64(checker.packed_model, Q)
    meeting = clear = 0
    for cp, (cu, cv) in enumerate(m.clpairs):
        del cu
        for q in range(m.clpair_start[cp], m.clpair_start[cp + 1]):
            i, j = m.cpairs[q]
            if not m.cap_sphere[i]:
                continue
            xi = ends[:, i, 0]
            d = _point_segment(xi, ends[:, j, 0], ends[:, j, 1])
            meets = d <= m.r_self[i] + m.r_self[j]
            to_ball = np.linalg.norm(xi - centres[:, cv], axis=1)
            gate = to_ball <= m.r_self[i] + m.cl_r_self[cv]
            assert np.all(gate[meets]), f"pair {i, j} meets behind a clear gate"
            meeting += int(meets.sum())
            clear += int((~gate).sum())
    assert meeting > 0 and clear > 0
    v = _model_valid(core, Q)
    assert np.array_equal(v, _exact_valid(core, Q))

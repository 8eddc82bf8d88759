"""The one-state road (``collision/one_state.py``: one state's capsules eight to a float32
vector, close calls confirmed in float64) gives the float64 verdicts and FCL's: random,
near-contact, at-the-boundary and self-colliding states of every family and a mesh
robot's covers; its float32 places lie within the model's float32 bound; the public
checker's ``valid(q)`` and the native planners' shim answer by it."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PROBLEMS
from test_model import FAMILY_PROBLEMS, SELF, _exact_valid, _near_contact, _problem, _sample

import plannerlab as pl
from plannerlab.collision.exact import frames64
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.kinematics import place
from plannerlab.collision.one_lanes import checker_tables, open_one
from plannerlab.collision.one_state import _frames, _gates, _place_body, valid_each
from plannerlab.collision.queries import open_packed
from plannerlab.collision.simd import kernel
from plannerlab.planners.native import shim
from plannerlab.problem.load import parse_problem
from plannerlab.problem.scene import Scene

MESH = PROBLEMS / "urdf" / "iiwa_mesh" / "table.toml"


def _one(checker, Q: np.ndarray) -> np.ndarray:
    """The one-state road's verdicts, state by state."""
    Q = np.ascontiguousarray(Q, dtype=float)
    out = np.empty(len(Q), dtype=np.bool_)
    return valid_each(checker.packed_model, checker_tables(checker), Q, out)


def _agree_near_contact(checker, robot, Q, fcl, rng, n):
    """Either side of the contact boundary (2e-4 rad) and at it (1e-6 rad): the road
    says what float64 says, and FCL where the states are apart from it."""
    core = checker._core
    inside, outside = _near_contact(core, robot.lower, robot.upper, Q, n, rng)
    assert len(inside) == n
    assert _one(checker, inside).all() and not _one(checker, outside).any()
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()
    lo_side, hi_side = _near_contact(core, robot.lower, robot.upper, Q, n, rng, offset=0.0)
    both = np.vstack([lo_side, hi_side])
    assert np.array_equal(_one(checker, both), _exact_valid(core, both))


@pytest.mark.parametrize("kind", [*sorted(FAMILY_PROBLEMS), "mesh"])
def test_the_one_state_roads_verdicts_are_float64s_and_fcls(kind):
    problem = parse_problem(MESH) if kind == "mesh" else _problem(kind)
    robot, margin = problem.robot, float(problem.safety_margin_m)
    checker = problem_checker(problem)
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=margin)
    rng = np.random.default_rng(29)
    Q = _sample(checker._core, robot, problem.q_start, 1200, rng)
    v = _one(checker, Q)
    assert 0.02 < v.mean() < 0.98  # both verdicts are there
    assert np.array_equal(v, _exact_valid(checker._core, Q))
    assert np.array_equal(v, checker.valid_batch(Q))  # the batch road's (eight a call)
    if kind == "mesh":
        # python-fcl's checker of a mesh robot is not the core's capsule covers: the batch
        # road, float64's equal, differs from it on a few states (2 of 1 000 uniform ones)
        core = checker._core
        lo_side, hi_side = _near_contact(core, robot.lower, robot.upper, Q, 40, rng, offset=0.0)
        both = np.vstack([lo_side, hi_side])
        assert len(lo_side) == 40
        assert np.array_equal(_one(checker, both), _exact_valid(core, both))
        return
    assert np.array_equal(v, fcl.valid_batch(Q))
    _agree_near_contact(checker, robot, Q, fcl, rng, 40)


@pytest.mark.parametrize("kind", sorted(SELF))
def test_the_one_state_road_finds_self_collisions_as_float64_and_fcl_do(kind):
    robot, margin, sampler = SELF[kind]()
    rng = np.random.default_rng(31)
    lo, hi = robot.lower, robot.upper
    Q = rng.uniform(lo, hi, (2000, robot.dof)) if sampler is None else sampler(lo, hi, 2000, rng)
    checker = CollisionChecker(robot, Scene(), margin_m=margin)
    fcl = CollisionChecker(robot, Scene(), backend="fcl", margin_m=margin)
    v = _one(checker, Q)
    assert 0.02 < (~v).mean() < 0.98  # self-colliding states are there (the scene is empty)
    assert np.array_equal(v, _exact_valid(checker._core, Q))
    assert np.array_equal(v, fcl.valid_batch(Q))
    _agree_near_contact(checker, robot, Q, fcl, rng, 20)


@kernel
def _places(P, T, q, out):
    """The road's float32 places of q's capsule ends (a, b per capsule, packed order) and
    gate centres into out[:, 0], float64's (the one kinematics with math's sine and
    cosine) into out[:, 1]: out (2 L + nb, 2, 3)."""
    m, Z = open_packed(P)
    O = open_one(T)
    _frames(m, Z, O, q)
    _gates(m, Z, O)
    S8 = O.RS.shape[0]
    nb = m.gate_c.shape[0]
    L = m.cap_body.shape[0]
    for b in range(nb):
        _place_body(Z.e_F, b, O)
        for l in range(m.body_caps[b], m.body_caps[b + 1]):
            s = O.slot0[b] + l - m.body_caps[b]
            for e in range(2):
                for c in range(3):
                    out[2 * l + e, 0, c] = O.WX[(3 * e + c) * S8 + s]
        g = 3 * (b // 8) * 8 + b % 8
        for c in range(3):
            out[2 * L + b, 0, c] = O.GW[g + 8 * c]
    frames64(m, Z, q)
    for b in range(nb):
        for l in range(m.body_caps[b], m.body_caps[b + 1]):
            x, y, z = place(Z.e_F, b, m.cap_a, l, 0)
            out[2 * l, 1, 0], out[2 * l, 1, 1], out[2 * l, 1, 2] = x, y, z
            x, y, z = place(Z.e_F, b, m.cap_b, l, 0)
            out[2 * l + 1, 1, 0], out[2 * l + 1, 1, 1], out[2 * l + 1, 1, 2] = x, y, z
        x, y, z = place(Z.e_F, b, m.gate_c, b, 0)
        out[2 * L + b, 1, 0], out[2 * L + b, 1, 1], out[2 * L + b, 1, 2] = x, y, z
    return out


@pytest.mark.parametrize("kind", [*sorted(FAMILY_PROBLEMS), "mesh"])
def test_the_roads_float32_places_lie_within_the_models_float32_bound(kind):
    """Every capsule end and gate centre the road places in float32 (float32 sines, float64
    frames, float32 places) is within half the model's float32 bound ``eps32_m`` of
    float64's, on random states (continuous joints far out of [-pi, pi] too): the bound
    by which the road's gates and grades grow every radius."""
    problem = parse_problem(MESH) if kind == "mesh" else _problem(kind)
    checker = problem_checker(problem)
    m, robot = checker.model, problem.robot
    rng = np.random.default_rng(37)
    lo = np.where(robot.continuous, -20.0, robot.lower)
    hi = np.where(robot.continuous, 20.0, robot.upper)
    L, nb = len(m.cap_body), len(m.gate_c)
    worst = 0.0
    for q in rng.uniform(lo, hi, (200, robot.dof)):
        out = _places(
            checker.packed_model, checker_tables(checker), q, np.zeros((2 * L + nb, 2, 3))
        )
        worst = max(worst, float(np.abs(out[:, 0] - out[:, 1]).max()))
    assert 0.0 < worst < 0.5 * m.eps32_m


def test_the_public_checkers_one_state_answer_is_the_roads_and_counts():
    problem = _problem("urdf")
    check = pl.checker(problem)
    rng = np.random.default_rng(5)
    Q = rng.uniform(check.lower, check.upper, (300, check.dof))
    batch = check.valid(Q)
    before = check.checks
    one = [check.valid(q) for q in Q]
    assert one == batch.tolist() and check.checks == before + len(Q)
    assert all(isinstance(x, bool) for x in one)
    assert 0.05 < np.mean(one) < 0.95


def test_the_native_shim_answers_by_the_road():
    problem = _problem("armz")
    checker = problem_checker(problem)
    ck = shim.opened(checker)
    rng = np.random.default_rng(7)
    Q = rng.uniform(problem.robot.lower, problem.robot.upper, (400, problem.robot.dof))
    v = np.array([shim.state_valid(ck, q) for q in Q])
    assert np.array_equal(v, _exact_valid(checker._core, Q))
    assert 0.05 < v.mean() < 0.95

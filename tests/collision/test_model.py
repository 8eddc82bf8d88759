"""The compiled robot–scene model (collision/model.py) for every robot family: its chain
gives the robot's capsules, its verdicts are FCL's (random, near-contact and
self-colliding states) and the generic kernels' (the road IRb-6 and the continuum chain
took before), its edge check visits exactly the checker's grid, and a robot without a
chain gets a clear error."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.core import Core
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.kernels import valid_batch
from plannerlab.collision.model_old import (
    CompiledModel,
    ModelError,
    edge_ok,
    edge_state,
    edge_visits,
    segments,
    state_ok,
    valid_states,
    views,
)
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import parse_problem
from plannerlab.problem.scene import Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.continuum.model import ContinuumChain
from plannerlab.robots.irb6.model import IRb6
from plannerlab.robots.registry import DEFAULT_MODEL, FAMILIES, model_builder

PANDA = PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml"
FAMILY_PROBLEMS = {
    "armz": "armz_inspection",
    "irb6": "irb6_case1",
    "continuum_chain": "continuum_case1",
    "urdf": "panda",
}


def _problem(kind: str):
    name = FAMILY_PROBLEMS[kind]
    return parse_problem(PANDA) if name == "panda" else load_problem(name)


def _model_valid(m: CompiledModel, Q: np.ndarray) -> np.ndarray:
    kernel = valid_states
    return kernel(np.ascontiguousarray(Q), m, np.empty(len(Q), dtype=np.bool_))


# ---------------------------------------------------------------------- chains
ROBOTS = {
    "armz": lambda: ArmZ(
        n_modules=24, T_world_base=pose_matrix([1.0, -2.0, 0.5], [0.1, -0.2, 0.3])
    ),
    "irb6": lambda: IRb6(T_world_base=pose_matrix([0.3, -0.2, 0.1], [0.0, 0.0, 0.7])),
    "irb6_plus_z": lambda: IRb6(dead_wedge_side="+z"),
    "continuum_chain": lambda: ContinuumChain(
        n_links=30, T_world_base=pose_matrix([0.2, 0.1, 0.0], [0.0, 0.0, 40.0])
    ),
}


@pytest.mark.parametrize("which", sorted(ROBOTS))
def test_every_familys_chain_gives_its_capsules_to_1e12(which):
    robot = ROBOTS[which]()
    core = Core(robot, Scene(), margin_m=0.01)
    Q = np.random.default_rng(5).uniform(robot.lower, robot.upper, (300, robot.dof))
    ref = robot.link_segments(Q)
    out = np.empty_like(ref)
    assert np.abs(segments(Q, core.model, out) - ref).max() < 1e-12
    assert np.abs(core.segments(Q) - ref).max() < 1e-12


def test_irb6s_coupling_maps_its_absolute_angles_onto_the_urdfs_relative_ones():
    robot = IRb6()
    coupling = robot.chain_data()[7]
    Q = np.random.default_rng(2).uniform(robot.lower, robot.upper, (20, 6))
    assert np.allclose(Q @ coupling.T, robot.urdf_joint_positions(Q), rtol=0.0, atol=1e-15)


def test_the_panda_model_gives_its_capsules_to_1e12():
    problem = parse_problem(PANDA)
    robot = problem.robot
    Q = np.random.default_rng(6).uniform(robot.lower, robot.upper, (200, robot.dof))
    ref = robot.link_segments(Q)
    out = np.empty_like(ref)
    assert np.abs(segments(Q, problem_checker(problem).model, out) - ref).max() < 1e-12


# ---------------------------------------------------------------------- registry
@dataclass(frozen=True)
class _NoChain:
    """A robot built in code without ``chain_data`` (its capsules from numpy only)."""

    inner: ArmZ
    kind: str = "lab_arm"

    def __getattr__(self, name: str):
        if name == "chain_data":
            raise AttributeError(name)
        return getattr(self.inner, name)


def test_every_family_registers_the_generic_builder_and_a_chainless_robot_is_refused():
    assert {f.model for f in FAMILIES.values()} == {DEFAULT_MODEL}
    assert model_builder("no_such_kind").__name__ == "model_of_core"
    robot = _NoChain(ArmZ(n_modules=6))
    core = Core(robot, Scene())  # the checks still run, on the robot's numpy kinematics
    assert core.is_valid(np.zeros(5))
    with pytest.raises(ModelError, match="'lab_arm'.*chain_data"):
        _ = core.model


# ---------------------------------------------------------------------- verdicts
def _sample(m, robot, q_start, n, rng):
    """n states: half uniform in the bounds, half from a random walk from the start (one
    to three joints moved a little a step, the step kept when the model finds it valid):
    the states it reached and the ones it refused, so that a robot in a sleeve or a
    cavity, seldom valid elsewhere, has both verdicts."""
    lo, hi = robot.lower, robot.upper
    walk = [np.asarray(q_start, dtype=float)]
    q = walk[0]
    while len(walk) < n - n // 2:
        p = q.copy()
        idx = rng.choice(robot.dof, rng.integers(1, 4), replace=False)
        step = rng.normal(0.0, 0.05, len(idx)) * (hi - lo)[idx]
        p[idx] = np.clip(p[idx] + step, lo[idx], hi[idx])
        walk.append(p)
        if _model_valid(m, p[None])[0]:
            q = p
    return np.vstack([rng.uniform(lo, hi, (n // 2, robot.dof)), walk])


def _near_contact(m, lo, hi, A, n, rng, edge_tol=1e-6, offset=2e-4):
    """States either side of the model's contact boundary: edges from a valid state of A
    to an invalid one bisected until their ends are ``edge_tol`` rad apart, then moved
    ``offset`` rad (along the edge, by its largest joint) inside and outside."""
    A = np.repeat(A[_model_valid(m, A)], 8, axis=0)
    B = np.clip(A + rng.normal(0.0, 0.4, A.shape), lo, hi)
    keep = _model_valid(m, A) & ~_model_valid(m, B)
    A, B = A[keep][:n], B[keep][:n]
    D = B - A
    span = np.abs(D).max(axis=1)
    t_lo, t_hi = np.zeros(len(A)), np.ones(len(A))
    while np.any((t_hi - t_lo) * span > edge_tol):
        t = 0.5 * (t_lo + t_hi)
        v = _model_valid(m, A + t[:, None] * D)
        t_lo, t_hi = np.where(v, t, t_lo), np.where(v, t_hi, t)
    dt = offset / span
    inside = A + np.clip(t_lo - dt, 0.0, 1.0)[:, None] * D
    outside = A + np.clip(t_hi + dt, 0.0, 1.0)[:, None] * D
    return inside, outside


@pytest.mark.parametrize("kind", sorted(FAMILY_PROBLEMS))
def test_the_models_verdicts_are_fcls_on_random_and_near_contact_states(kind):
    problem = _problem(kind)
    robot, margin = problem.robot, float(problem.safety_margin_m)
    checker = problem_checker(problem)
    m = checker.model
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=margin)
    rng = np.random.default_rng(17)
    Q = _sample(m, robot, problem.q_start, 1500, rng)
    v = _model_valid(m, Q)
    assert 0.02 < v.mean() < 0.98  # both verdicts are there
    assert np.array_equal(v, fcl.valid_batch(Q))
    V, S = views(m)
    assert [state_ok(q, V, S) for q in Q[:300]] == v[:300].tolist()
    # the generic kernels on the robot's own numpy capsules (the road before the model)
    old = valid_batch(
        np.ascontiguousarray(robot.link_segments(Q)), *checker._core._geo, np.empty(len(Q), bool)
    )
    assert np.array_equal(v, old)
    inside, outside = _near_contact(m, robot.lower, robot.upper, Q, 60, rng)
    assert len(inside) == 60
    assert _model_valid(m, inside).all() and not _model_valid(m, outside).any()
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()
    # the batch runs in vector lanes (collision/lanes.py): the one-state test agrees
    assert all(state_ok(q, V, S) for q in inside) and not any(state_ok(q, V, S) for q in outside)


def _coiled(lo, hi, n, rng, centre_rad, spread_rad):
    """States whose joints all bend one way by about ``centre_rad`` (a random sign per
    state), clipped to the bounds: the chain closes on itself."""
    sign = rng.choice([-1.0, 1.0], (n, 1))
    Q = sign * rng.uniform(*centre_rad, (n, 1)) + rng.normal(0.0, spread_rad, (n, len(lo)))
    Q[:, 0] = rng.uniform(lo[0], hi[0], n)
    return np.clip(Q, lo, hi)


#: robots that can touch themselves in an empty scene, their margin and a sampler that
#: finds such states (IRb-6 with a short shoulder and a wide column: wrist against column
#: and rail)
SELF = {
    "armz": lambda: (
        ArmZ(n_modules=24),
        0.05,
        lambda lo, hi, n, rng: _coiled(lo, hi, n, rng, (-0.3, 0.3), 0.2),
    ),
    "irb6": lambda: (IRb6(shoulder_height_m=0.4, column_radius_m=0.3), 0.02, None),
    "continuum_chain": lambda: (
        ContinuumChain(n_links=30, link_radius_m=0.004),
        0.0,
        lambda lo, hi, n, rng: _coiled(lo, hi, n, rng, (0.1, 0.35), 0.05),
    ),
}


@pytest.mark.parametrize("kind", sorted(SELF))
def test_the_models_verdicts_are_fcls_on_self_colliding_states(kind):
    robot, margin, sampler = SELF[kind]()
    rng = np.random.default_rng(23)
    lo, hi = robot.lower, robot.upper
    Q = rng.uniform(lo, hi, (3000, robot.dof)) if sampler is None else sampler(lo, hi, 3000, rng)
    m = CollisionChecker(robot, Scene(), margin_m=margin).model
    fcl = CollisionChecker(robot, Scene(), backend="fcl", margin_m=margin)
    v = _model_valid(m, Q)
    assert np.array_equal(v, fcl.valid_batch(Q))
    assert 0.02 < (~v).mean() < 0.98  # self-colliding states are there (the scene is empty)
    V, S = views(m)  # the lanes' verdicts are the one-state test's
    assert [state_ok(q, V, S) for q in Q] == v.tolist()
    inside, outside = _near_contact(m, lo, hi, Q, 30, rng)
    assert len(inside) == 30
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()


# ---------------------------------------------------------------------- edges
@pytest.mark.parametrize("kind", ["armz", "urdf"])
def test_edge_ok_checks_exactly_the_checkers_grid_once_each(kind):
    problem = _problem(kind)
    robot = problem.robot
    checker = problem_checker(problem)
    m = checker.model
    V, S = views(m)
    rng = np.random.default_rng(29)
    step = 0.05
    seen = {0: 0, 1: 0}
    for _ in range(40):
        q_a = rng.uniform(robot.lower, robot.upper)
        q_b = np.clip(q_a + rng.normal(0.0, 0.3, robot.dof), robot.lower, robot.upper)
        states, _ = checker.densify(np.vstack([q_a, q_b]), step)
        n = len(states) - 1
        rec = np.full(n + 1, -1, dtype=np.int64)
        status, checks = edge_visits(q_a, q_b, step, m, 1 << 40, rec)
        grid_ok = _model_valid(m, states[1:])
        if status == 0:
            # every grid state once, the end first
            assert checks == n and rec[0] == n and sorted(rec[:n]) == list(range(1, n + 1))
            assert grid_ok.all()
        else:
            assert status == 1 and not grid_ok[rec[checks - 1] - 1]
            assert grid_ok[rec[: checks - 1] - 1].all() and len(set(rec[:checks])) == checks
        seen[status] += 1
        # its states are densify's, bit for bit, and edge_ok says what edge_visits says
        d, q = np.empty(robot.dof), np.empty(robot.dof)
        assert edge_ok(q_a, q_b, step, m, V, S, d, q, 1 << 40) == (status, checks)
        for j in rec[:checks]:
            edge_state(q_a, d, j, n, q)
            assert np.array_equal(q, states[j])
        if status == 0 and n > 1:
            # a limit below the count stops it without a verdict
            assert edge_visits(q_a, q_b, step, m, n - 1, rec) == (2, n - 1)
    assert seen[0] >= 5 and seen[1] >= 5  # both outcomes were exercised

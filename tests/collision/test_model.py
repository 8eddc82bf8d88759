"""The compiled robot–scene model (collision/model.py) and its one state test
(collision/state_test.py) for every robot family: its one kinematics gives the robot's
capsules, its verdicts are FCL's (random, near-contact and self-colliding states), the
float32 filter's verdicts are the float64 test's alone (near contact included: the
filter's bound holds), its certified edges give the grid's verdicts, and a robot
without a chain gets a clear error."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from conftest import PROBLEMS
from numba import njit

from plannerlab.collision.core import Core
from plannerlab.collision.exact import frames64
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.kinematics import place
from plannerlab.collision.model import ModelError
from plannerlab.collision.queries import open_packed
from plannerlab.collision.simd import lane, splat
from plannerlab.collision.state_test import (
    GROUP,
    W,
    _group_box,
    exact_batch,
    frames32,
    load_state,
    set_plain,
)
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import parse_problem
from plannerlab.problem.scene import Scene
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.continuum.model import ContinuumChain
from plannerlab.robots.irb6.model import IRb6

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


def _model_valid(core: Core, Q: np.ndarray) -> np.ndarray:
    """The state test's verdicts (the float32 filter, float64 confirming)."""
    return core.valid(Q)


def _exact_valid(core: Core, Q: np.ndarray) -> np.ndarray:
    """The float64 test's verdicts alone (no filter)."""
    return exact_batch(core.model, np.ascontiguousarray(Q), np.empty(len(Q), dtype=np.bool_))


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
    assert np.abs(problem_checker(problem)._core.segments(Q) - ref).max() < 1e-12


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


def test_a_chainless_robot_is_refused_by_name_and_checked_by_fcl():
    from plannerlab.collision.model import ChainGeometry, build_model

    robot = _NoChain(ArmZ(n_modules=6))
    checker = CollisionChecker(robot, Scene())  # no chain: FCL answers
    assert checker.backend == "fcl" and checker.is_valid(np.zeros(5))
    with pytest.raises(ValueError, match="compiled model needs the core"):
        _ = checker.model
    L = len(robot.link_radii_m)
    geo = ChainGeometry(
        np.ones(L), np.ones(L), np.ones(L, bool), np.zeros((L, L), bool),
        np.zeros(0, np.int64), np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
    )  # fmt: skip
    with pytest.raises(ModelError, match="'lab_arm'.*chain_data"):
        build_model(robot, geo)


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
    m = checker._core
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=margin)
    rng = np.random.default_rng(17)
    Q = _sample(m, robot, problem.q_start, 1500, rng)
    v = _model_valid(m, Q)
    assert 0.02 < v.mean() < 0.98  # both verdicts are there
    assert np.array_equal(v, fcl.valid_batch(Q))
    assert np.array_equal(v, _exact_valid(m, Q))  # the filter says what float64 says
    assert [m.is_valid(q) for q in Q[:300]] == v[:300].tolist()  # one state: the same
    inside, outside = _near_contact(m, robot.lower, robot.upper, Q, 60, rng)
    assert len(inside) == 60
    assert _model_valid(m, inside).all() and not _model_valid(m, outside).any()
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()
    # right at the boundary (1e-6 rad apart): the filter leaves it to float64, and agrees
    lo_side, hi_side = _near_contact(m, robot.lower, robot.upper, Q, 60, rng, offset=0.0)
    both = np.vstack([lo_side, hi_side])
    assert np.array_equal(_model_valid(m, both), _exact_valid(m, both))
    assert all(m.is_valid(q) == e for q, e in zip(both, _exact_valid(m, both), strict=True))


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
    m = CollisionChecker(robot, Scene(), margin_m=margin)._core
    fcl = CollisionChecker(robot, Scene(), backend="fcl", margin_m=margin)
    v = _model_valid(m, Q)
    assert np.array_equal(v, fcl.valid_batch(Q))
    assert 0.02 < (~v).mean() < 0.98  # self-colliding states are there (the scene is empty)
    assert np.array_equal(v, _exact_valid(m, Q))
    assert [m.is_valid(q) for q in Q] == v.tolist()  # one state at a time: the same
    inside, outside = _near_contact(m, lo, hi, Q, 30, rng)
    assert len(inside) == 30
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()


# ---------------------------------------------------------------------- edges
@pytest.mark.parametrize("kind", ["armz", "urdf", "irb6"])
def test_certified_edges_give_the_grids_verdict_in_fewer_tests(kind):
    """The certified edge check says what checking every grid state says, on edges free
    and blocked, and never tests more states than the grid has (a few percent more at
    most, on edges near a surface all along)."""
    problem = _problem(kind)
    robot = problem.robot
    checker = problem_checker(problem)
    core = checker._core
    rng = np.random.default_rng(29)
    step = problem.joint_step / 4
    lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    Q = rng.uniform(lo, hi, (4000, robot.dof))
    V = Q[core.valid(Q)][:161]
    seen = {0: 0, 1: 0}
    tests = grid = 0
    for k in range(160):
        q_a = V[k]
        q_b = q_a + (V[k + 1] - q_a) * (0.1 if k % 3 == 0 else 0.5 if k % 3 == 1 else 1.0)
        n, bad = core.edge_first_invalid(q_a, q_b, step)
        status, made, n2 = core.edge_certified(q_a, q_b, step)
        assert n2 == n
        assert status == (0 if bad < 0 else 1)
        seen[status] += 1
        if status == 0:
            tests += made
            grid += n
        # a free edge needs every one of its tests: one fewer stops it without a verdict;
        # a blocked one gives its verdict again within the tests it made
        if status == 0 and made > 1:
            assert core.edge_certified(q_a, q_b, step, made - 1)[0] == 2
        if status == 1:
            assert core.edge_certified(q_a, q_b, step, made)[:2] == (1, made)
    assert seen[0] >= 3 and seen[1] >= 3  # both outcomes were exercised
    assert tests <= 1.3 * grid


def _frame(p_world: np.ndarray, x_axis: np.ndarray) -> np.ndarray:
    """A pose at p_world whose x axis is x_axis (unit)."""
    e = np.eye(3)[int(np.argmin(np.abs(x_axis)))]
    u = np.cross(x_axis, e)
    u /= np.linalg.norm(u)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x_axis, u, np.cross(x_axis, u), p_world
    return T


@pytest.mark.parametrize("thickness_m", [0.002, 0.02])
def test_a_thin_wall_is_never_tunnelled_with_a_margin(thickness_m):
    """A thin Arm-Z (4 cm capsules) swings its tip through a sheet of 2 mm or 2 cm placed
    between two states of a 0.3 rad grid: that grid's states are all clear of the sheet
    (checking radian steps alone would pass through it), FCL finds the swing crossing it,
    and with a 2 cm margin the grid steps so that no point moves more than the margin:
    the certified edge (the grid's verdict) finds the sheet, as does the re-check."""
    from plannerlab.problem.scene import Box
    from plannerlab.robots.paths import interpolate_edge

    robot = ArmZ(n_modules=6, collision_radius_m=0.04)
    q_a = np.full(robot.dof, np.pi)
    q_a[1] -= 1.2
    q_b = q_a.copy()
    q_a[0] -= 0.5
    q_b[0] += 0.5  # the base twist swings the bent arm's tip about 0.6 m
    coarse = interpolate_edge(q_a, q_b, 0.3, robot.continuous)
    t_mid = 1.5 / (len(coarse) - 1)  # halfway between the coarse states 1 and 2
    ts = (t_mid - 1e-3, t_mid, t_mid + 1e-3)
    tips = np.array([robot.tip(q_a + s * (q_b - q_a))[0] for s in ts])
    direction = (tips[2] - tips[0]) / np.linalg.norm(tips[2] - tips[0])
    sheet = Box("sheet", _frame(tips[1], direction), (thickness_m, 0.2, 0.2))
    scene = Scene((sheet,))
    checker = CollisionChecker(robot, scene, margin_m=0.02)
    assert checker.is_valid(q_a) and checker.is_valid(q_b)
    radian = CollisionChecker(robot, scene, margin_m=0.0)
    assert radian.valid_batch(coarse).all()  # radian steps alone pass through the sheet
    fcl = CollisionChecker(robot, scene, backend="fcl")
    assert not fcl.valid_batch(np.linspace(q_a, q_b, 20001)).all()  # the swing crosses it
    status, _, n = checker._core.edge_certified(q_a, q_b, 0.3)
    assert status == 1 and n > 10 * len(coarse)
    assert not checker.check_path(np.vstack([q_a, q_b]), 0.3).valid
    assert not checker.check_path(np.vstack([q_a, q_b]), 0.3, mode="grid").valid


def test_float32s_bound_covers_what_the_kinematics_show():
    """The model's float32 bound is far above the float32 kinematics' worst error seen on
    random states of every family (and far below any radius)."""
    from plannerlab.collision.kinematics import chain_frames
    from plannerlab.collision.state_test import W, frames32, lanes, load_state

    for kind in sorted(FAMILY_PROBLEMS):
        problem = _problem(kind)
        robot = problem.robot
        core = problem_checker(problem)._core
        m = core.model
        Z = lanes(m)
        rng = np.random.default_rng(31)
        lo = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
        hi = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
        worst = 0.0
        for _ in range(40):
            Q = rng.uniform(lo, hi, (W, robot.dof))
            for k in range(W):
                load_state(Z, k, Q[k], m.continuous)
            frames32(m, Z)
            F32 = Z.F.reshape(-1, 12, W)
            for k in range(W):
                F64 = np.zeros(len(F32) * 12)
                V = Q[k] if len(m.cpl_start) == 0 else robot.chain_data()[7] @ Q[k]
                chain_frames(F64, np.ascontiguousarray(V), m.T0, m.pre, m.parent, m.slide)
                pos64 = F64.reshape(-1, 12)[:, [3, 7, 11]]
                pos32 = F32[:, [3, 7, 11], k]
                worst = max(worst, float(np.abs(pos32 - pos64).max()))
        assert worst < m.eps32_m / 4, (kind, worst, m.eps32_m)
        assert m.eps32_m < 0.15 * float(np.min(robot.link_radii_m))  # far below a radius


# ---------------------------------------------------------------------- the prefilter
def _tilted_scene(robot, rng):
    """Thin boxes and cylinders tilted about every axis (their world boxes far larger
    than they are), and a sphere, each centred two thirds of the way from the base to the
    tip of the robot at a random state (a 24-module Arm-Z reaches about 15 m)."""
    from plannerlab.problem.scene import Box, Cylinder, Sphere

    obstacles = []
    for k in range(12):
        p = robot.tip(rng.uniform(robot.lower, robot.upper))[0] / 1.5
        T = pose_matrix(p, rng.uniform(-90, 90, 3))
        if k == 11:
            obstacles.append(Sphere("s", T, 1.5))
        elif k % 2:
            obstacles.append(Box(f"b{k}", T, (8.0, 0.2, 4.0)))
        else:
            obstacles.append(Cylinder(f"c{k}", T, 0.3, 8.0))
    return Scene(tuple(obstacles))


def test_each_obstacles_world_box_holds_it():
    """The world box the state test's prefilter meets first (``obs32[:, 16:19]``) holds
    every corner of a tilted box and every rim point of a tilted cylinder."""
    rng = np.random.default_rng(5)
    robot = ArmZ(n_modules=24)
    scene = _tilted_scene(robot, rng)
    m = CollisionChecker(robot, scene)._core.model
    for o, ob in enumerate(scene.obstacles):
        T = ob.T_world_obstacle
        if ob.kind == "box":
            pts = np.array(np.meshgrid(*[[-0.5, 0.5]] * 3)).reshape(3, -1).T * ob.size_m
        elif ob.kind == "cylinder":
            a = np.linspace(0.0, 2.0 * np.pi, 721)
            ring = np.column_stack([np.cos(a), np.sin(a)]) * ob.radius_m
            pts = np.vstack([np.column_stack([ring, np.full(len(a), z)]) for z in
                             (-ob.length_m / 2.0, ob.length_m / 2.0)])  # fmt: skip
        else:
            pts = np.vstack([np.eye(3), -np.eye(3)]) * ob.radius_m
        world = pts @ T[:3, :3].T + T[:3, 3]
        half = m.obs32[o, 16:19].astype(float)
        assert np.all(np.abs(world - m.obs_c[o]) <= half)
        assert np.all(half < 1.5 * np.abs(world - m.obs_c[o]).max(axis=0) + 1e-4)  # not loose


def test_the_prefilter_culls_no_real_hit_near_tilted_obstacles():
    """Against tilted thin boxes and cylinders (where a gate ball meets the world box far
    from the obstacle), the state test's verdicts are FCL's and float64's on random and
    near-contact states: the world-box prefilter drops no hit."""
    rng = np.random.default_rng(31)
    robot = ArmZ(n_modules=24)
    scene = _tilted_scene(robot, rng)
    m = CollisionChecker(robot, scene, margin_m=0.01)._core
    fcl = CollisionChecker(robot, scene, backend="fcl", margin_m=0.01)
    Q = rng.uniform(robot.lower, robot.upper, (2000, robot.dof))
    v = _model_valid(m, Q)
    assert 0.05 < v.mean() < 0.95
    assert np.array_equal(v, fcl.valid_batch(Q))
    assert np.array_equal(v, _exact_valid(m, Q))
    inside, outside = _near_contact(m, robot.lower, robot.upper, Q, 40, rng)
    assert len(inside) == 40
    assert fcl.valid_batch(inside).all() and not fcl.valid_batch(outside).any()
    both = np.vstack([inside, outside])
    assert np.array_equal(_model_valid(m, both), _exact_valid(m, both))
    assert [m.is_valid(q) for q in both] == _exact_valid(m, both).tolist()


@njit(cache=True)
def _group_boxes_and_gates(P, Q):
    """Per state (lanes of eight) and group of the scene pass's broadphase: its box in
    float32 (lo, hi), and every body's gate centre in float64 (the exact kinematics)."""
    m, Z = open_packed(P)
    set_plain(Z)
    nb = m.body_order.shape[0]
    ng = (nb + GROUP - 1) // GROUP
    boxes = np.zeros((Q.shape[0], ng, 6))
    gates64 = np.zeros((Q.shape[0], nb, 3))
    eps = splat(m.eps32_m)
    for s0 in range(0, Q.shape[0], W):
        for j in range(W):
            load_state(Z, j, Q[s0 + j], m.continuous)
        frames32(m, Z)
        for g in range(ng):
            k0, k1 = g * GROUP, min(g * GROUP + GROUP, nb)
            B = _group_box(m.gates32, Z.G, Z.brate, m.body_order, k0, k1, splat(0.0), eps)
            for j in range(W):
                boxes[s0 + j, g, 0], boxes[s0 + j, g, 3] = lane(B[0], j), lane(B[3], j)
                boxes[s0 + j, g, 1], boxes[s0 + j, g, 4] = lane(B[1], j), lane(B[4], j)
                boxes[s0 + j, g, 2], boxes[s0 + j, g, 5] = lane(B[2], j), lane(B[5], j)
        for j in range(W):
            frames64(m, Z, Q[s0 + j])
            for b in range(nb):
                x, y, z = place(Z.e_F, b, m.gate_c, b, 0)
                gates64[s0 + j, b, 0], gates64[s0 + j, b, 1], gates64[s0 + j, b, 2] = x, y, z
    return boxes, gates64


@pytest.mark.parametrize("kind", ["armz", "urdf"])
def test_each_group_box_holds_its_bodies_gates_in_float64(kind):
    """The scene pass's broadphase box around ``GROUP`` consecutive bodies (float32, built
    per call) holds every one of its bodies' gate balls as float64 places them (so a
    group clear of an obstacle's world box leaves no hit behind), and is no looser than
    the balls' box by more than the float32 bound and its pad."""
    problem = _problem(kind)
    checker = problem_checker(problem)
    m = checker.model
    robot = problem.robot
    Q = np.random.default_rng(41).uniform(robot.lower, robot.upper, (800, robot.dof))
    boxes, gates64 = _group_boxes_and_gates(checker.packed_model, Q)
    nb = len(m.body_order)
    tested = 0
    for g in range(boxes.shape[1]):
        bodies = [b for b in m.body_order[g * GROUP : (g + 1) * GROUP] if m.gate_r_scene[b] >= 0]
        if not bodies:
            continue
        r = m.gate_r_scene[bodies][None, :, None]
        lo = (gates64[:, bodies] - r).min(axis=1)
        hi = (gates64[:, bodies] + r).max(axis=1)
        assert np.all(boxes[:, g, :3] <= lo) and np.all(boxes[:, g, 3:] >= hi)
        slack = 2.0 * m.eps32_m + 1e-5 * max(1.0, float(np.abs(hi).max()))
        assert np.all(lo - boxes[:, g, :3] <= slack) and np.all(boxes[:, g, 3:] - hi <= slack)
        tested += len(bodies)
    assert tested == int(np.sum(m.gate_r_scene >= 0)) and tested <= nb

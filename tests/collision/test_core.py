"""The compiled core: kinematics, verdicts and distances against FCL and independent routes."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.collision.agreement import KINDS, compare, sample_states
from plannerlab.collision.core import Core
from plannerlab.collision.edges import edge_count, edge_delta, edge_state
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.paths import densify, interpolate_edge

SCENES = ("armz_inspection", "armz_pocket", "irb6_track_obstacle", "continuum_case3")


@pytest.mark.parametrize("n_modules", [12, 24, 96])
def test_armz_kinematics_match_the_numpy_model_to_1e12(n_modules):
    robot = ArmZ(n_modules=n_modules, T_world_base=pose_matrix([1.0, -2.0, 0.5], [0.1, -0.2, 0.3]))
    core = Core(robot, Scene())
    Q = np.random.default_rng(3).uniform(-np.pi, np.pi, (50, robot.dof))
    assert np.abs(core.segments(Q) - robot.link_segments(Q)).max() < 1e-12
    for q in Q[:10]:  # the tip from the same frames
        p, n = core.tip(q)
        p_ref, n_ref = robot.tip(q)
        assert np.abs(p - p_ref).max() < 1e-12 and np.abs(n - n_ref).max() < 1e-12


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.parametrize("kind", KINDS)
def test_core_agrees_with_fcl_and_with_an_independent_minimisation(name, kind):
    p = load_problem(name)
    core = Core(p.robot, p.scene)
    ref = CollisionChecker(p.robot, p.scene, backend="fcl")
    rng = np.random.default_rng(11)
    Q = sample_states(core, kind, 150, rng)
    a = compare(core, ref, Q, distance_states=30, reference_pairs=20, rng=rng)
    # FCL's GJK decides states within its tolerance of contact either way: any verdict that
    # differs must belong to a state that close to contact.
    bad = np.flatnonzero(core.valid(Q) != ref.valid_batch(Q))
    assert len(bad) == a.verdict_mismatches
    for s in bad:
        assert abs(core.clearance(Q[s])) < 1e-6
    assert a.verdict_mismatches <= 2
    if a.pairs_compared:
        assert a.max_err_ref_m < 1e-9


def test_contact_states_lie_within_a_millimetre_of_contact():
    p = load_problem("armz_inspection")
    core = Core(p.robot, p.scene)
    Q = sample_states(core, "contact", 100, np.random.default_rng(0))
    c = np.array([core.clearance(q) for q in Q])
    assert np.all(np.abs(c) <= 1.5e-3)
    assert 0.1 < np.mean(c > 0) < 0.9


def test_shapes_at_hand_worked_distances():
    robot = ArmZ()
    column = np.full(robot.dof, np.pi)  # straight up along x = 0, y = δy
    r = robot.collision_radius_m
    y = robot.delta_y_m
    tip = robot.fk(column)[-1, :3, 3]
    scene = Scene(
        (
            Box("box", pose_matrix([r + 0.3 + 0.5, y, 5.0], [0.4, 0, 0]), [1.0, 1.0, 1.0]),
            Cylinder("post", pose_matrix([-(r + 0.2 + 0.25), y, 6.0], [0, 0, 0]), 0.25, 2.0),
            # a ball straight above the tip: the tip is the capsule axis's nearest point
            Sphere("ball", pose_matrix(tip + [0.0, 0.0, r + 0.7 + 0.1], [0, 0, 0]), 0.1),
            # a cylinder lying across above the top, its rim 0.4 m over the tip's capsule
            Cylinder("bar", pose_matrix([0.0, y, 40.0], [0, np.pi / 2, 0]), 0.5, 40.0),
        )
    )
    core = Core(robot, scene)
    pd = core.pair_distances(column, np.inf)
    tip_z = robot.fk(column)[-1, 2, 3]
    best = {}
    for k in range(len(pd.d_m)):
        if not pd.other_is_link[k]:
            name = scene.names[pd.other[k]]
            best[name] = min(best.get(name, np.inf), pd.d_m[k])
    # the box is tilted about x: its face towards the column stays the plane x = r + 0.3
    assert best["box"] == pytest.approx(0.3, abs=1e-12)
    assert best["post"] == pytest.approx(0.2, abs=1e-12)
    assert best["ball"] == pytest.approx(0.7, abs=1e-12)
    assert best["bar"] == pytest.approx(40.0 - 0.5 - tip_z - r, abs=1e-9)


def _same_pair(pds, ref, k):
    """Distance in ``pds`` of the pair ``k`` of ``ref``."""
    m = (
        (pds.link == ref.link[k])
        & (pds.other == ref.other[k])
        & (pds.other_is_link == ref.other_is_link[k])
    )
    return pds.d_m[m][0]


def test_pair_distance_gradient_matches_finite_differences():
    p = load_problem("armz_inspection")
    core = Core(p.robot, p.scene)
    rng = np.random.default_rng(5)
    Q = sample_states(core, "coiled", 15, rng)
    h = 1e-7
    checked = 0
    for q in Q:
        pd = core.pair_distances(q, 0.5)
        for k in np.flatnonzero(pd.d_m > 0.01)[:3]:
            seg = core.segments(q)[0]
            grad = np.empty(len(q))
            for j in range(len(q)):
                dq = np.zeros(len(q))
                dq[j] = h
                sp = core.segments(q + dq)[0]
                dl = (1 - pd.t_link[k]) * (sp[pd.link[k], 0] - seg[pd.link[k], 0]) + pd.t_link[
                    k
                ] * (sp[pd.link[k], 1] - seg[pd.link[k], 1])
                g = pd.n_world[k] @ dl
                if pd.other_is_link[k]:
                    o = pd.other[k]
                    do = (1 - pd.t_other[k]) * (sp[o, 0] - seg[o, 0]) + pd.t_other[k] * (
                        sp[o, 1] - seg[o, 1]
                    )
                    g -= pd.n_world[k] @ do
                grad[j] = g / h
            fd = np.empty(len(q))
            for j in range(len(q)):
                dq = np.zeros(len(q))
                dq[j] = h
                pp = core.pair_distances(q + dq, 1.0)
                pm = core.pair_distances(q - dq, 1.0)

                fd[j] = (_same_pair(pp, pd, k) - _same_pair(pm, pd, k)) / (2 * h)
            assert np.allclose(grad, fd, atol=1e-5)
            checked += 1
    assert checked >= 5


def test_checker_counts_one_check_per_state_on_both_backends():
    p = load_problem("armz_inspection")
    Q = np.random.default_rng(2).uniform(p.robot.lower, p.robot.upper, (200, p.robot.dof))
    results = {}
    for backend in ("core", "fcl"):
        c = CollisionChecker(p.robot, p.scene, backend=backend)
        assert c.backend == backend
        v = c.valid_batch(Q)
        assert c.checks == 200
        first = c.first_invalid(Q)
        assert c.checks == 200 + first + 1
        check = c.check_path(Q[:3], 0.05)
        assert check.backend == backend
        results[backend] = (v, first, check.states_checked, check.pairs)
    assert np.array_equal(results["core"][0], results["fcl"][0])
    assert results["core"][1:] == results["fcl"][1:]


def test_checker_picks_the_core_by_default_and_refuses_unknown_backends():
    p = load_problem("armz_inspection")
    assert CollisionChecker(p.robot, p.scene).backend == "core"
    with pytest.raises(ValueError, match="backend"):
        CollisionChecker(p.robot, p.scene, backend="gpu")


@pytest.mark.parametrize("name", ["armz_inspection", "irb6_track_obstacle", "continuum_case3"])
def test_one_call_edge_check_equals_interpolating_then_checking(name):
    p = load_problem(name)
    r = p.robot
    core = CollisionChecker(r, p.scene, backend="core", edge_check="grid")
    certified = CollisionChecker(r, p.scene, backend="core")
    assert certified.edge_check == "certified"
    ref = CollisionChecker(r, p.scene, backend="fcl")
    rng = np.random.default_rng(4)
    bad_seen = 0
    for k in range(30):
        a = rng.uniform(r.lower, r.upper)
        b = np.clip(a + rng.normal(0.0, 0.4, r.dof), r.lower - 1.0, r.upper + 1.0)
        limit = (None, 0, 2, 10**6)[k % 4]
        states = interpolate_edge(a, b, 0.05, r.continuous)[1:]
        n, bad = core.check_edge(a, b, 0.05, limit)
        assert n == len(states)
        m = len(states) if limit is None else min(limit, len(states))
        expect = ref.first_invalid(states[:m]) if m else None
        assert bad == expect
        c0, f0 = core.checks, ref.checks
        assert ref.check_edge(a, b, 0.05, limit) == (n, bad)
        core.check_edge(a, b, 0.05, limit)
        assert core.checks - c0 == ref.checks - f0 == (m if bad is None else bad + 1)
        if limit is None:  # certified: the same verdict, fewer tests
            tests, cbad = certified.check_edge(a, b, 0.05)
            assert (cbad is None) == (bad is None)
            assert tests <= 1.3 * n + 8
        bad_seen += bad is not None
    assert bad_seen > 0


def test_edge_states_are_bit_identical_to_interpolate_edge():
    rng = np.random.default_rng(8)
    for _ in range(300):
        dof = int(rng.integers(1, 9))
        a, b = rng.uniform(-4.0, 4.0, (2, dof))
        cont = rng.random(dof) < 0.5
        step = float(rng.choice([0.05, 0.3, 2.0]))
        d = np.empty(dof)
        edge_delta(a, b, cont, d)
        n = edge_count(d, step, np.zeros(dof))
        Q = np.empty((n, dof))
        for j in range(1, n + 1):
            edge_state(a, d, j, n, Q[j - 1])
        ref = interpolate_edge(a, b, step, cont)[1:]
        assert n == len(ref) and np.array_equal(Q, ref)


def test_densify_is_edge_by_edge_interpolation_bit_for_bit():
    rng = np.random.default_rng(9)
    for _ in range(200):
        dof, m = int(rng.integers(1, 8)), int(rng.integers(1, 7))
        path = rng.uniform(-4.0, 4.0, (m, dof))
        if m > 2:
            path[2] = path[1]  # a zero-length edge still yields one state
        cont = rng.random(dof) < 0.5
        step = float(rng.choice([0.05, 0.3, 2.0]))
        states, owners = densify(path, step, cont)
        chunks, own = [path[:1]], [np.zeros(1, dtype=int)]
        for i in range(m - 1):
            pts = interpolate_edge(path[i], path[i + 1], step, cont)[1:]
            chunks.append(pts)
            own.append(np.full(len(pts), i))
        assert np.array_equal(states, np.concatenate(chunks))
        assert np.array_equal(owners, np.concatenate(own))


@pytest.mark.parametrize("backend", ["core", "fcl"])
def test_edge_checks_refuse_what_interpolate_edge_refuses(backend):
    p = load_problem("armz_inspection")
    c = CollisionChecker(p.robot, p.scene, backend=backend)
    a = np.zeros(p.robot.dof)
    b = np.full(p.robot.dof, 1.0)
    with pytest.raises(PlannerlabError, match="more than the limit"):
        c.check_edge(a, b, 1e-6)
    with pytest.raises(PlannerlabError, match="joint_step must be a positive"):
        c.check_edge(a, b, 0.0)
    with pytest.raises(PlannerlabError, match="more than the limit"):
        densify(np.stack([a, b]), 1e-6, p.robot.continuous)
    assert c.checks == 0


@pytest.mark.parametrize("n_modules", [24, 60])
def test_every_colliding_pair_is_found_in_the_checkers_order(n_modules):
    # coiled Arm-Z states collide with themselves in many places at once: the tree
    # traversal must find every pair the FCL checker finds, reported in the same order
    p = load_problem("armz_inspection")
    robot = ArmZ(n_modules=n_modules)
    core = CollisionChecker(robot, p.scene, backend="core")
    ref = CollisionChecker(robot, p.scene, backend="fcl")
    Q = sample_states(core._core, "coiled", 40, np.random.default_rng(6))
    many = 0
    for q in Q:
        pairs = core.colliding_pairs(q)
        assert pairs == ref.colliding_pairs(q)
        many += len(pairs) >= 5
    assert many >= 10


@pytest.mark.parametrize("name", ["armz_pocket", "irb6_track_obstacle", "continuum_case3"])
def test_path_measurements_in_one_call_equal_the_state_by_state_ones(name):
    p = load_problem(name)
    checker = CollisionChecker(p.robot, p.scene, margin_m=0.01)
    rng = np.random.default_rng(5)
    q0 = np.asarray(p.q_start, dtype=float)
    Q = np.clip(q0 + rng.normal(0.0, 0.05, (40, p.robot.dof)), p.robot.lower, p.robot.upper)
    for include_self in (True, False):
        c0 = checker.checks
        one_call = checker.min_clearance(Q, include_self)
        assert checker.checks - c0 == len(Q)  # one check per state, as clearance counts
        each = min(checker.clearance(q, include_self) for q in Q)
        assert one_call == pytest.approx(each, abs=1e-12)
    assert checker.min_clearance(Q[:0]) == np.inf
    # the tip from the checker (compiled for Arm-Z) is the robot's, and costs no check
    c0 = checker.checks
    for q in Q[:10]:
        p_c, n_c = checker.tip(q)
        p_r, n_r = p.robot.tip(q)
        assert np.abs(p_c - p_r).max() < 1e-9 and np.abs(n_c - n_r).max() < 1e-12
    assert checker.checks == c0
    # the grid is counted without being made
    path = np.vstack([q0, Q[:6]])
    for step in (p.joint_step, p.joint_step / 4.0):
        assert checker.grid_states(path, step) == len(checker.densify(path, step)[0])
    assert checker.grid_states(path[:1], p.joint_step) == 1


def test_a_panda_paths_clearance_in_one_call_is_the_state_by_state_minimum(tmp_path):
    """The one-call path clearance skips the pairs whose bounding boxes are further apart
    than the smallest distance found so far: on the Panda's ~60 spheres in a shelf scene,
    along a path that passes in and out of collision and through free states, it is the
    minimum of the state-by-state measurements (which measure every pair)."""
    from conftest import ROOT

    from plannerlab.problem.load import parse_problem
    from plannerlab.problem.mbm import problem_toml

    panda, data = ROOT / "problems" / "urdf" / "panda", ROOT / "tests" / "data" / "mbm"
    out = tmp_path / "shelf.toml"
    out.write_text(
        problem_toml(
            data / "scene_shelf.yaml",
            data / "request_shelf.yaml",
            out_path=out,
            urdf=panda / "panda_spherized.urdf",
            srdf=panda / "panda.srdf",
            tip_link="panda_hand",
        ),
        encoding="utf-8",
    )
    p = parse_problem(out)
    checker = CollisionChecker(p.robot, p.scene)
    rng = np.random.default_rng(8)
    waypoints = rng.uniform(p.robot.lower, p.robot.upper, (6, p.robot.dof))
    Q = densify(waypoints, 0.05, p.robot.continuous)[0]
    valid = checker.valid_batch(Q)
    assert 0.1 < valid.mean() < 0.9  # in and out of collision
    free = Q[valid]
    for states in (Q, free, free[::-1], Q[:1]):
        for include_self in (True, False):
            each = min(checker.clearance(q, include_self) for q in states)
            assert checker.min_clearance(states, include_self) == pytest.approx(each, abs=1e-12)
    assert checker.min_clearance(free) > 0.0 > checker.min_clearance(Q)

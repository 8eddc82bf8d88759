"""Planar continuum robot: section kinematics, the chain model, the chord-arc search.

Paper: ``003_d410ec97f064abf9.txt`` (``docs/papers.md`` §3).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plannerlab.planners.chord_arc.geometry import (
    ChordArcInputError,
    ChordArcQuery,
    Circle,
    ConvexPolygon,
)
from plannerlab.planners.chord_arc.motion import MotionStep, solve_chord_arc
from plannerlab.planners.chord_arc.search import prepare, search_chord_arc
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.robots.base import Robot, pose_matrix
from plannerlab.robots.continuum.model import (
    ContinuumChain,
    arc_points,
    arc_points_local,
    chord_length,
    planar_frame,
    section_ik,
    section_tip,
)

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
T0 = planar_frame([0.0, 0.0], [0.0, 1.0])  # section frame = world: tangent along +y


def _problem(case: int):
    from plannerlab.problem.catalog import load_problem

    return load_problem(f"continuum_case{case}")


def _query(case: int) -> ChordArcQuery:
    """The paper's query of a case (the problem's own obstacles and collision points,
    zero thickness), built by the planner from the one problem loader."""
    from plannerlab.planners import make_planner

    return make_planner("chord_arc").query(_problem(case), 0)


# --------------------------------------------------------------------------- section math


@pytest.mark.parametrize("theta", [-2.5, -1.0, -1e-3, 0.7, 3.0])
def test_tip_at_a1_is_the_chord_end(theta: float) -> None:
    L = 0.3
    T = section_tip(T0, theta, L)
    H = L * math.sin(theta / 2) / (theta / 2)  # the paper's chord length
    np.testing.assert_allclose(
        T[:2, 2], H * np.array([math.sin(theta / 2), math.cos(theta / 2)]), atol=1e-15
    )
    # the tangent (y axis) turned by θ toward +x; eq. (2) H(a) = H sin(aθ/2)/sin(θ/2)
    np.testing.assert_allclose(T[:2, 1], [math.sin(theta), math.cos(theta)], atol=1e-15)
    a = np.linspace(0.1, 1.0, 7)
    np.testing.assert_allclose(
        chord_length(theta, L, a), H * np.sin(a * theta / 2) / math.sin(theta / 2), rtol=1e-12
    )
    # every point of the arc lies on the circle of radius L/θ centred at (L/θ, 0)
    R = L / theta
    pts = arc_points(T0, theta, L, np.linspace(0.0, 1.0, 50))
    np.testing.assert_allclose(np.hypot(pts[:, 0] - R, pts[:, 1]), abs(R), rtol=1e-12)
    # vectorised over a: the frames of section_tip agree with arc_points
    np.testing.assert_allclose(
        section_tip(T0, theta, L, a)[:, :2, 2], arc_points(T0, theta, L, a), atol=1e-15
    )


def test_zero_bend_is_a_straight_segment() -> None:
    L = 0.25
    a = np.linspace(0.0, 1.0, 11)
    np.testing.assert_array_equal(
        arc_points_local(0.0, L, a), np.stack([np.zeros(11), a * L], axis=1)
    )
    np.testing.assert_allclose(section_tip(T0, 0.0, L), [[1, 0, 0], [0, 1, L], [0, 0, 1]])
    for theta in (1e-9, -1e-9, 1e-15):
        T = section_tip(T0, theta, L)
        assert np.all(np.isfinite(T))
        np.testing.assert_allclose(T[:2, 2], [0.0, L], atol=1e-9 * L)
    theta, length = section_ik(np.array([0.0, 0.4]))
    assert theta == 0.0 and length == 0.4


@settings(max_examples=200, deadline=None)
@given(
    theta=st.floats(-1.9 * math.pi, 1.9 * math.pi),
    L=st.floats(0.01, 2.0),
    x=st.floats(-1, 1),
    y=st.floats(-1, 1),
    phi=st.floats(-math.pi, math.pi),
)
def test_inverse_of_forward_is_identity(
    theta: float, L: float, x: float, y: float, phi: float
) -> None:
    T = planar_frame([x, y], [math.cos(phi), math.sin(phi)])
    tip_world = section_tip(T, theta, L)[:2, 2]
    local = np.linalg.solve(T, np.append(tip_world, 1.0))[:2]
    th, ln = section_ik(local)
    assert th == pytest.approx(theta, abs=1e-9)
    assert ln == pytest.approx(L, rel=1e-9, abs=1e-12)


def test_bend_sign_convention() -> None:
    # θ > 0 bends toward +x of the section frame (the right of the tangent, clockwise)
    assert section_tip(T0, 1.0, 0.2)[0, 2] > 0
    assert section_tip(T0, -1.0, 0.2)[0, 2] < 0
    th, _ = section_ik(np.array([[0.1, 0.3], [-0.1, 0.3]]))
    assert th[0] == -th[1] > 0


# --------------------------------------------------------------------------- chain robot


@pytest.fixture(scope="module")
def chain() -> ContinuumChain:
    return ContinuumChain(
        n_links=12,
        length_m=0.48,
        link_radius_m=0.003,
        T_world_base=pose_matrix([0.1, -0.2, 0.0], [0.0, 0.0, 1.2]),
    )


def _random_q(chain: ContinuumChain, rng: np.random.Generator, k: int) -> np.ndarray:
    return rng.uniform(chain.lower, chain.upper, size=(k, chain.dof))


def test_chain_is_a_robot(chain: ContinuumChain) -> None:
    assert isinstance(chain, Robot)
    assert chain.kind == "continuum_chain"
    assert chain.dof == 13 and len(chain.joint_names) == 13
    assert len(chain.link_frame_names) == chain.fk(np.zeros(chain.dof)).shape[0]


def test_chain_fk_batched_equals_looped(chain: ContinuumChain) -> None:
    Q = _random_q(chain, np.random.default_rng(1), 9)
    F = chain.fk(Q)
    assert F.shape == (9, chain.n_links + 2, 4, 4)
    for i, q in enumerate(Q):
        np.testing.assert_array_equal(F[i], chain.fk(q))
    p, n = chain.tip(Q)
    np.testing.assert_allclose(p, F[:, -1, :3, 3])
    np.testing.assert_allclose(n, F[:, -1, :3, 0])
    seg = chain.link_segments(Q)
    assert seg.shape == (9, chain.n_links, 2, 3)
    np.testing.assert_allclose(
        np.linalg.norm(seg[..., 1, :] - seg[..., 0, :], axis=-1), chain.link_length_m
    )
    np.testing.assert_allclose(seg[:, -1, 1], p)


def test_chain_straight_and_insertion(chain: ContinuumChain) -> None:
    q = np.zeros(chain.dof)
    q[0] = 0.3
    p, n = chain.tip(q)
    x = chain.T_world_base[:3, 0]
    np.testing.assert_allclose(p, chain.T_world_base[:3, 3] + 0.3 * x, atol=1e-15)
    np.testing.assert_allclose(n, x, atol=1e-15)


def test_chain_jacobian_matches_finite_differences(chain: ContinuumChain) -> None:
    rng = np.random.default_rng(2)
    for q in _random_q(chain, rng, 4):
        J_p, J_n = chain.tip_jacobian(q)
        h = 1e-6
        for j in range(chain.dof):
            dq = np.zeros(chain.dof)
            dq[j] = h
            (pp, np_), (pm, nm) = chain.tip(q + dq), chain.tip(q - dq)
            np.testing.assert_allclose(J_p[:, j], (pp - pm) / (2 * h), atol=1e-8)
            np.testing.assert_allclose(J_n[:, j], (np_ - nm) / (2 * h), atol=1e-8)


def test_q_from_arcs_follows_the_arcs() -> None:
    chain = ContinuumChain(
        n_links=40, length_m=0.5, T_world_base=pose_matrix([0, 0, 0], [0, 0, math.pi / 2])
    )
    arcs = [(0.9, 0.2), (-1.6, 0.15), (0.4, 0.1)]
    q = chain.q_from_arcs(arcs)
    assert q[0] == pytest.approx(0.45)  # insertion = Σ L; 0.05 m stays behind the port
    # exact end of the arcs (world = section frame here: tangent +y)
    T = T0
    for th, L in arcs:
        T = section_tip(T, th, L)
    p, _ = chain.tip(q)
    assert np.hypot(*(p[:2] - T[:2, 2])) < 5e-4  # 40 links: well under a millimetre
    # every joint between the port and the tip lies near the curve
    a = np.linspace(0, 1, 400)
    curve, T = [], T0
    for th, L in arcs:
        curve.append(arc_points(T, th, L, a))
        T = section_tip(T, th, L)
    curve = np.vstack(curve)
    joints = chain.fk(q)[2:, :2, 3]
    out = joints[:, 1] > 1e-9  # in front of the port
    d = np.min(np.hypot(*(joints[out, None, :] - curve[None]).transpose(2, 0, 1)), axis=1)
    assert d.max() < 5e-4
    # the uninserted part is straight behind the port
    assert np.all(q[1:][(np.arange(40) + 1) * chain.link_length_m < 0.05] == 0.0)
    np.testing.assert_array_equal(chain.q_from_arcs([])[1:], 0.0)


def test_urdf_matches_fk_in_pybullet(chain: ContinuumChain, tmp_path: Path) -> None:
    pb = pytest.importorskip("pybullet")
    path = tmp_path / "chain.urdf"
    path.write_text(chain.urdf())
    cid = pb.connect(pb.DIRECT)
    try:
        T = chain.T_world_base
        quat = pb.getQuaternionFromEuler([0.0, 0.0, chain.base_yaw_rad], physicsClientId=cid)
        body = pb.loadURDF(
            str(path),
            basePosition=T[:3, 3].tolist(),
            baseOrientation=quat,
            useFixedBase=True,
            physicsClientId=cid,
        )
        joints, links = {}, {}
        for j in range(pb.getNumJoints(body, physicsClientId=cid)):
            info = pb.getJointInfo(body, j, physicsClientId=cid)
            joints[info[1].decode()] = j
            links[info[12].decode()] = j
        assert [n for n in chain.joint_names if n not in joints] == []
        for q in _random_q(chain, np.random.default_rng(3), 3):
            for name, v in zip(chain.joint_names, q, strict=True):
                pb.resetJointState(body, joints[name], float(v), physicsClientId=cid)
            F = chain.fk(q)
            for i, name in enumerate(chain.link_frame_names):
                st_ = pb.getLinkState(
                    body, links[name], computeForwardKinematics=True, physicsClientId=cid
                )
                np.testing.assert_allclose(st_[4], F[i, :3, 3], atol=1e-6)
                R = np.array(pb.getMatrixFromQuaternion(st_[5], physicsClientId=cid))
                np.testing.assert_allclose(R.reshape(3, 3), F[i, :3, :3], atol=1e-6)
    finally:
        pb.disconnect(physicsClientId=cid)


# --------------------------------------------------------------------------- search: hand scene


def _wall_query(target=(0.0, 0.35)) -> ChordArcQuery:
    wall = ConvexPolygon.rectangle((0.0, 0.2), (0.1, 0.04), 0.0, "wall")
    corners = ((-0.05, 0.22), (0.05, 0.22), (0.05, 0.18), (-0.05, 0.18))
    return ChordArcQuery((0.0, 0.0), (0.0, 1.0), 0.6, (wall,), corners, target)


def _two_arcs(c: tuple[float, float], target: tuple[float, float]) -> tuple[float, float]:
    """Bend angles of port (0, 0, tangent +y) → c → target, by hand."""
    th1 = 2 * math.atan2(c[0], c[1])
    t = np.array([math.sin(th1), math.cos(th1)])
    r = np.array([t[1], -t[0]])
    d = np.array(target) - np.array(c)
    return th1, 2 * math.atan2(d @ r, d @ t)


def test_hand_scene_solutions() -> None:
    """A wall with its four corners as collision points, the target straight behind it.

    By symmetry the robot passes either lower corner (backward-constrained: it arrives
    bent outward and bends back round the corner): two plans, mirror images. The two
    branches that also touch an upper corner arrive there wrapped round the wall's end
    (forward-constrained) and must then bend less: dropped.
    """
    q = _wall_query()
    res = solve_chord_arc(q)
    assert [s.contact_indices for s in res.search.solutions] == [(2,), (3,), (2, 1), (3, 0)]
    assert [p.solution.contact_indices for p in res.plans] == [(2,), (3,)]
    for plan, c in zip(res.plans, [(0.05, 0.18), (-0.05, 0.18)], strict=True):
        th1, th2 = _two_arcs(c, (0.0, 0.35))
        np.testing.assert_allclose(plan.solution.theta_rad, (th1, th2), atol=1e-12)
        (contact,) = plan.contacts
        assert contact.contact_type == "backward" and contact.ok
        assert contact.obstacle == "wall"
    assert res.plans[0].solution.theta_rad[0] == -res.plans[1].solution.theta_rad[0]
    assert [d.solution.contact_indices for d in res.dropped] == [(2, 1), (3, 0)]
    for d in res.dropped:
        assert "contact 2" in d.reason and "forward-constrained" in d.reason
        assert "bends less" in d.reason
    s = res.search
    assert (s.expansions, s.arcs_built, s.arcs_checked, s.depth_reached) == (9, 25, 17, 5)
    assert not s.budget_exhausted
    # no single arc: the straight line to the target crosses the wall
    assert all(sol.contact_indices for sol in s.solutions)


def test_leftover_length_and_budget() -> None:
    q = _wall_query()
    sol = solve_chord_arc(q).plans[0].solution
    assert sol.total_length_m == pytest.approx(sum(a.length_m for a in sol.arcs))
    assert sol.leftover_m == pytest.approx(0.6 - sol.total_length_m)
    short = ChordArcQuery(
        q.base_xy_m, q.base_tangent, 0.38, q.obstacles, q.collision_points_m, q.target_xy_m
    )
    r = search_chord_arc(short)  # the one-contact shapes need 0.388 m
    assert [s.contact_indices for s in r.solutions] == [(2, 1), (3, 0)]
    assert r.arcs_rejected_length > 0
    capped = search_chord_arc(q, ChordArcSettings(max_expansions=1))
    assert capped.budget_exhausted and capped.expansions == 1 and capped.solutions == ()
    shallow = search_chord_arc(q, ChordArcSettings(max_depth=2))
    assert [s.contact_indices for s in shallow.solutions] == [(2,), (3,)]


def test_forward_constrained_contact_holds_when_bending_further() -> None:
    """The robot bends right onto a corner of a box on its right, then curls round it."""
    box = ConvexPolygon.rectangle((0.10, 0.15), (0.10, 0.10), 0.0, "box")
    pts = ((0.05, 0.20),)
    near = solve_chord_arc(ChordArcQuery((0, 0), (0, 1), 0.5, (box,), pts, (0.10, 0.24)))
    (plan,) = near.plans
    (c,) = plan.contacts
    assert (c.contact_type, c.side, c.ok) == ("forward", 1, True)
    assert c.kappa_out_per_m > c.kappa_in_per_m > 0
    np.testing.assert_allclose(plan.solution.theta_rad, _two_arcs(pts[0], (0.10, 0.24)), atol=1e-12)
    far = solve_chord_arc(ChordArcQuery((0, 0), (0, 1), 0.5, (box,), pts, (0.20, 0.45)))
    assert far.plans == ()
    (d,) = far.dropped
    assert d.contacts[0].contact_type == "forward" and not d.contacts[0].ok
    assert "bends less" in d.reason


def test_motion_sequence_follows_the_final_shape() -> None:
    q = _query(2)
    res = solve_chord_arc(q)
    geo = prepare(q, ChordArcSettings()).geometry
    for plan in res.plans:
        steps = plan.motion
        n_contacts = len(plan.solution.contact_indices)
        assert [s.kind for s in steps] == ["follow"] + ["push", "rebend", "follow"] * n_contacts
        assert steps[0].start_shape == ((0.0, 0.0),)
        assert steps[-1].end_shape == plan.solution.shape
        for prev, nxt in zip(steps, steps[1:], strict=False):
            assert _shape_end(prev.end_shape) == pytest.approx(_shape_end(nxt.start_shape))
        for s in steps:
            if s.kind == "push":  # a = 1 + l/L: the same curvature, a longer arc
                (t0, l0), (t1, l1) = s.start_shape[-1], s.end_shape[-1]
                assert t1 / l1 == pytest.approx(t0 / l0)
                assert t1 / t0 == pytest.approx(1 + (l1 - l0) / l0)
            for a in np.linspace(0, 1, 6):
                assert not geo.inside_any(_shape_points(s.shape_at(float(a))), 1e-6).any()


def _shape_points(shape: tuple[tuple[float, float], ...]) -> np.ndarray:
    T, pts = T0, []
    for th, L in shape:
        if L > 0:
            pts.append(arc_points(T, th, L, np.linspace(0, 1, 200)))
            T = section_tip(T, th, L)
    return np.vstack(pts) if pts else np.zeros((0, 2))


def _shape_end(shape: tuple[tuple[float, float], ...]) -> tuple[float, float]:
    T = T0
    for th, L in shape:
        T = section_tip(T, th, L)
    return float(T[0, 2]), float(T[1, 2])


# --------------------------------------------------------------------------- the three cases

EXPECTED = {
    1: dict(
        points=8,
        geometric=5,
        plans={
            (0,): (-0.8364486591584583, 2.600192536318529),
            (1,): (0.8364486591584581, -2.600192536318528),
        },
    ),
    2: dict(
        points=6,
        geometric=4,
        plans={
            (0,): (-0.6435011087932845, 3.0113423269210218),
            (1, 4): (1.3220863377013738, -1.6058804469097023, -1.646709217171524),
        },
    ),
    3: dict(
        points=5,
        geometric=3,
        plans={
            (1,): (0.5222975784932253, -0.9301031842318502),
        },
    ),
}


@pytest.mark.parametrize("case", [1, 2, 3], ids=lambda c: f"case{c}")
def test_paper_cases_regression(case: int) -> None:
    problem = _problem(case)
    chain = problem.robot
    assert isinstance(chain, ContinuumChain)
    q = _query(case)
    exp = EXPECTED[case]
    assert len(q.collision_points_m) == exp["points"]
    res = solve_chord_arc(q)
    assert len(res.search.solutions) == exp["geometric"]
    assert not res.search.budget_exhausted
    got = {p.solution.contact_indices: p.solution.theta_rad for p in res.plans}
    assert list(got) == list(exp["plans"])
    for key, thetas in exp["plans"].items():
        np.testing.assert_allclose(got[key], thetas, rtol=0, atol=1e-9)
    assert len(res.dropped) == exp["geometric"] - len(exp["plans"])
    assert all(d.reason for d in res.dropped)
    # unsolvable for a single section without contact
    assert all(s.contact_indices for s in res.search.solutions)
    # every plan fits the robot and maps onto the chain within its joint bounds
    goal = problem.goal(0)
    for p in res.plans:
        assert p.solution.total_length_m <= chain.length_m
        qj = chain.q_from_arcs(p.solution.shape)
        assert np.all(qj >= chain.lower) and np.all(qj <= chain.upper)
        tip, _ = chain.tip(qj)
        assert np.linalg.norm(tip - goal.p_world_m) < goal.pos_tol_m


def test_one_contact_solutions_are_the_two_arc_geometry() -> None:
    """Golden values from geometry, not from a run: a one-contact solution is the arc
    from the port (tangent +y) through the corner, then the arc tangent to it from the
    corner to the target; :func:`_two_arcs` computes both bends in closed form."""
    for case, key in ((1, (0,)), (1, (1,)), (2, (0,)), (3, (1,))):
        q = _query(case)
        corner = q.collision_points_m[key[0]]
        np.testing.assert_allclose(
            EXPECTED[case]["plans"][key], _two_arcs(corner, q.target_xy_m), atol=1e-9
        )


def test_the_planner_has_one_settings_class() -> None:
    from plannerlab.planners import make_planner

    assert type(make_planner("chord_arc").settings) is ChordArcSettings
    with pytest.raises(ChordArcInputError, match="choose must be one of"):
        ChordArcSettings(choose="best")
    assert ChordArcSettings().inflate_by_radius  # the robot's radius by default


def test_batched_arcs_to_joints_equal_the_single_version() -> None:
    chain = _problem(2).robot
    rng = np.random.default_rng(3)
    th = rng.uniform(-2.0, 2.0, (20, 3))
    ln = rng.uniform(0.01, 0.15, (20, 3))
    ref = np.array(
        [chain.q_from_arcs(list(zip(a, b, strict=True))) for a, b in zip(th, ln, strict=True)]
    )
    np.testing.assert_allclose(chain.q_from_arcs_batch(th, ln), ref, atol=1e-12)
    # a zero-length arc adds nothing
    z = chain.q_from_arcs_batch([[0.7, 1.3, -0.2]], [[0.1, 0.0, 0.05]])
    np.testing.assert_allclose(z[0], chain.q_from_arcs([(0.7, 0.1), (-0.2, 0.05)]), atol=1e-12)


@pytest.mark.parametrize("case", [1, 2, 3], ids=lambda c: f"case{c}")
def test_batched_capsule_contacts_equal_fcl(case: int) -> None:
    """The planner's one-call planar contact test gives, state by state, exactly the
    (link, obstacle) pairs python-fcl reports for the 3-D capsules and boxes."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.planners import make_planner
    from plannerlab.planners.chord_arc.scene import capsule_distances

    problem = _problem(case)
    chain = problem.robot
    planner = make_planner("chord_arc", {"inflate_by_radius": False})
    r = planner.solve(problem, 0, problem.budget, np.random.default_rng(0))
    path = r.path[::3]
    q = planner.query(problem, 0)
    names = [o.name for o in q.obstacles]
    dist = capsule_distances(chain.link_segments(path)[..., :2], q.obstacles, chain.link_radius_m)
    checker = CollisionChecker(chain, problem.scene)
    pairs_fcl, pairs_planar = set(), set()
    for k, state in enumerate(path):
        pairs_fcl |= {(k, link, other) for link, other in checker.colliding_pairs(state)}
        for li, o in zip(*np.nonzero(dist[k] < chain.link_radius_m), strict=True):
            pairs_planar.add((k, chain.link_names[li], names[o]))
    assert pairs_planar  # the path touches its corners by design
    assert pairs_planar == pairs_fcl


# --------------------------------------------------------------------------- bad input


def test_collision_point_off_the_boundary_is_named() -> None:
    q = _wall_query()
    bad = ChordArcQuery(
        q.base_xy_m,
        q.base_tangent,
        0.6,
        q.obstacles,
        (q.collision_points_m[0], (0.05, 0.23)),
        q.target_xy_m,
    )
    with pytest.raises(
        ChordArcInputError,
        match=r"collision point 1 at \(0\.05, 0\.23\).*"
        r"not on an obstacle boundary.*'wall'",
    ):
        solve_chord_arc(bad)
    inside = ChordArcQuery(
        q.base_xy_m, q.base_tangent, 0.6, q.obstacles, ((0.0, 0.2),), q.target_xy_m
    )
    with pytest.raises(ChordArcInputError, match="collision point 0"):
        search_chord_arc(inside)


def test_target_inside_an_obstacle_is_an_error() -> None:
    with pytest.raises(
        ChordArcInputError,
        match=r"target \(0\.01, 0\.2\) m lies inside "
        r"obstacle 'wall'",
    ):
        solve_chord_arc(_wall_query(target=(0.01, 0.2)))
    pillar = Circle((0.0, 0.3), 0.05, "pillar")
    with pytest.raises(ChordArcInputError, match="inside obstacle 'pillar'"):
        solve_chord_arc(ChordArcQuery((0, 0), (0, 1), 0.5, (pillar,), ((0.0, 0.25),), (0.01, 0.31)))


def test_bad_obstacles_and_settings() -> None:
    with pytest.raises(ChordArcInputError, match="not strictly convex"):
        ConvexPolygon(((0, 0), (1, 0), (0.2, 0.2), (0, 1)))
    with pytest.raises(ChordArcInputError, match="radius"):
        Circle((0, 0), -1.0)
    with pytest.raises(ChordArcInputError, match="max_expansions"):
        ChordArcSettings(max_expansions=0)
    cw = ConvexPolygon(((0, 0), (0, 1), (1, 1), (1, 0)))  # clockwise: reordered
    assert cw.vertices_m == ((1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0))


def test_motion_step_interpolates_the_last_arc() -> None:
    s = MotionStep("follow", 0, "", ((0.0, 0.0),), ((1.0, 0.2),))
    assert s.shape_at(0.5) == ((0.5, 0.1),)


# --------------------------------------------------------------------------- glue


@pytest.mark.parametrize("case", [1, 2, 3], ids=lambda c: f"case{c}")
def test_problem_files_load_as_continuum_chains(case: int) -> None:
    from plannerlab.problem.load import parse_problem

    problem = parse_problem(PROBLEMS / f"continuum_case{case}.toml")
    robot = problem.robot
    assert isinstance(robot, ContinuumChain) and robot.dof == 41
    np.testing.assert_allclose(robot.T_world_base[:3, 0], [0.0, 1.0, 0.0], atol=1e-15)


def test_case_figure_draws_the_contact_plan(tmp_path: Path) -> None:
    """The figure is drawn from the leg's record (no search), and the record's arcs are
    the search's curves."""
    from matplotlib.patches import Polygon

    from plannerlab.planners import make_planner
    from plannerlab.plot.continuum import case_figure, draw_case, solution_xy
    from plannerlab.problem.catalog import load_problem
    from plannerlab.run.pipeline import leg_rng

    problem = load_problem("continuum_case1")
    planner = make_planner("chord_arc")
    r = planner.solve(problem, 0, problem.budget, leg_rng(0, 0))
    plan = r.contact_plan
    assert plan is not None and plan.solutions
    _, res = planner.search(problem, 0)
    by_points = {p.solution.contact_indices: p.solution for p in res.plans}
    for sol in plan.solutions:
        a = np.linspace(0.0, 1.0, 100)
        curve = np.vstack([arc.points(a) for arc in by_points[sol.contact_indices].arcs])
        np.testing.assert_allclose(solution_xy(sol), curve, atol=1e-12)
    fig = case_figure(plan)
    (ax,) = fig.axes
    polys = [p for p in ax.patches if isinstance(p, Polygon)]
    assert len(polys) == sum(1 for o in plan.obstacles if not o.is_disc)
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    np.testing.assert_allclose(lines["collision points"].get_xydata(), plan.collision_points_m)
    np.testing.assert_allclose(lines["target"].get_xydata(), [plan.target_xy_m])
    red = [ln for ln in ax.get_lines() if ln.get_color() == "tab:red"]
    assert len(red) == len(plan.solutions)
    for ln, sol in zip(red, plan.solutions, strict=True):
        np.testing.assert_allclose(ln.get_xydata(), solution_xy(sol))
    grey = [ln for ln in ax.get_lines() if ln.get_color() == "0.6"]
    assert len(grey) == len(plan.dropped)
    out = draw_case(plan, tmp_path / "fig" / "case1.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_module_leaves_the_backend_alone() -> None:
    import subprocess
    import sys

    code = (
        "import matplotlib; b = matplotlib.get_backend(); "
        "import plannerlab.plot.continuum; "
        "assert matplotlib.get_backend() == b, (b, matplotlib.get_backend()); "
        "assert 'matplotlib.pyplot' not in __import__('sys').modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True, env={"MPLBACKEND": "svg"})


def test_the_zero_thickness_plan_records_where_the_robot_would_cut() -> None:
    """Case 2 (the paper's two solutions, one lost for a 2 mm robot): the thickness figure
    needs no search of its own, the zero-thickness leg's record says where a robot of the
    link's radius along the lost curve would cut the obstacles."""
    from plannerlab.planners import make_planner
    from plannerlab.plot.continuum import searched
    from plannerlab.problem.catalog import load_problem
    from plannerlab.run.pipeline import leg_rng

    problem = load_problem("continuum_case2")
    plans = {
        thick: make_planner("chord_arc", {"inflate_by_radius": thick})
        .solve(problem, 0, problem.budget, leg_rng(0, 0))
        .contact_plan
        for thick in (False, True)
    }
    thin = {s.contact_indices: s for s in searched(plans[False])}
    thick = {s.contact_indices for s in searched(plans[True])}
    lost = set(thin) - thick
    assert len(thin) == 2 and len(thick) == 1 and len(lost) == 1
    assert thin[lost.pop()].cuts_xy_m  # the lost one cuts a corner
    assert all(not s.cuts_xy_m for s in searched(plans[True]))  # the axis plan records none
    assert plans[True].inflated_by_m == problem.robot.link_radius_m > 0
    assert plans[False].inflated_by_m == 0.0

"""A mesh robot's self-collision judged on a second, finer cover (issue 35): two box
meshes 3 cm apart whose one-capsule covers overlap, but whose finer covers do not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.scene import Scene
from plannerlab.robots.urdf.model import UrdfChain
from plannerlab.run.srdf import disabled_pairs

#: the gap between the two boxes at q = 0 [m]
GAP_M = 0.03

URDF = """<?xml version="1.0"?>
<robot name="two_boxes">
  <link name="base">
    <collision><origin xyz="0 0 0.05"/><geometry><mesh filename="box.stl"/></geometry></collision>
  </link>
  <link name="turn">
    <!-- a small knob on the joint: with no geometry, base and slider would be adjacent
         (MoveIt's rule) and never checked against each other -->
    <collision><origin xyz="0 0 0.3"/><geometry><box size="0.01 0.01 0.01"/></geometry></collision>
  </link>
  <link name="slider">
    <collision><origin xyz="{x} 0 0.05"/><geometry><mesh filename="box.stl"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="turn"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="10" velocity="1"/>
  </joint>
  <joint name="j2" type="prismatic">
    <parent link="turn"/><child link="slider"/><axis xyz="1 0 0"/>
    <limit lower="{low}" upper="0.1" effort="10" velocity="1"/>
  </joint>
</robot>
"""


@pytest.fixture(scope="module")
def urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two 10 cm cubes, the slider's GAP_M beyond the base's along x at q = 0."""
    d = tmp_path_factory.mktemp("two_boxes")
    trimesh.creation.box((0.1, 0.1, 0.1)).export(str(d / "box.stl"))
    (d / "two_boxes.urdf").write_text(URDF.format(x=0.1 + GAP_M, low=-0.1), encoding="utf-8")
    # the slider never nearer: the base lies in a disc of radius 7.1 cm about the turn axis,
    # the slider beyond 8 cm of it: the meshes never meet
    (d / "apart.urdf").write_text(URDF.format(x=0.1 + GAP_M, low=0.0), encoding="utf-8")
    return d / "two_boxes.urdf"


def chain(urdf: Path, fine: int) -> UrdfChain:
    return UrdfChain(
        urdf,
        "slider",
        cover_max_primitives=1,
        self_cover_max_primitives=fine,
        cover_cache_dir=urdf.parent / "covers",
    )


def mesh_distance_m(robot: UrdfChain, q: np.ndarray) -> float:
    """The boxes' signed distance at q (negative: their penetration)."""
    F = robot.fk(q)
    names = robot.link_frame_names
    boxes = []
    for link, dz in (("base", 0.05), ("slider", 0.05)):
        T = F[names.index(link)].copy()
        off = np.array([0.1 + GAP_M if link == "slider" else 0.0, 0.0, dz])
        T[:3, 3] = T[:3, :3] @ off + T[:3, 3]
        boxes.append(trimesh.creation.box((0.1, 0.1, 0.1), transform=T))
    m = trimesh.collision.CollisionManager()
    m.add_object("a", boxes[0])
    return float(m.min_distance_single(boxes[1]))


def test_covers_that_overlap_where_the_meshes_do_not_are_judged_by_the_finer_cover(
    urdf: Path,
) -> None:
    coarse = chain(urdf, 0)
    fine = chain(urdf, 128)
    q0 = np.zeros(2)
    assert mesh_distance_m(fine, q0) == pytest.approx(GAP_M, abs=1e-6)
    # one capsule a cube reaches beyond its faces by more than half the gap
    assert coarse.mesh_covers[0].max_excess_m > GAP_M / 2
    assert not CollisionChecker(coarse, Scene()).is_valid(q0)
    # the finer cover: the gap is left free, and each cover is within a third of it
    assert len(fine.self_covers) == 2
    assert all(c.max_excess_m < GAP_M / 3 for c in fine.self_covers)
    for backend in ("core", "fcl"):
        assert CollisionChecker(fine, Scene(), backend=backend).is_valid(q0), backend
    # boxes that intersect: invalid on either
    q_in = np.array([0.0, -0.06])
    assert mesh_distance_m(fine, q_in) < 0.0
    for robot in (coarse, fine):
        assert not CollisionChecker(robot, Scene()).is_valid(q_in)


def test_the_finer_cover_is_conservative_and_judges_self_collision_only(urdf: Path) -> None:
    """Every state the finer cover calls free has its meshes apart (seeded states across
    the contact); its capsules are never checked against the scene, nor the first
    cover's against the other link."""
    fine = chain(urdf, 128)
    n_first = sum(c.primitives for c in fine.mesh_covers)
    assert len(fine.scene_only_links) == n_first
    assert not fine.scene_only_links & fine.self_only_links
    # the first covers, the joint's knob (a box: a capsule of both roles), the finer covers
    assert len(fine.link_names) == n_first + 1 + len(fine.self_only_links)
    assert all("#s" in fine.link_names[i] for i in fine.self_only_links)
    # each URDF link's capsules one run, its first cover first
    order = ["base", "turn", "slider"]
    assert fine.link_urdf_names == tuple(sorted(fine.link_urdf_names, key=order.index))
    assert fine.link_names[0] == "base" and fine.link_names[1] == "base#s0"
    Q = np.random.default_rng(0).uniform(fine.lower, fine.upper, size=(200, 2))
    valid = CollisionChecker(fine, Scene()).valid_batch(Q)
    d = np.array([mesh_distance_m(fine, q) for q in Q])
    assert valid.any() and (~valid).any()
    assert np.all(d[valid] > 0.0)
    # the pairs checked: none between first-cover capsules of the two links
    ck = CollisionChecker(fine, Scene(), backend="fcl")
    pairs = {tuple(p) for p in ck._self_pairs.tolist()}
    assert pairs and all(i in fine.self_only_links and j in fine.self_only_links for i, j in pairs)


def test_the_group_gates_over_the_finer_capsules_hold_them_and_change_no_verdict(
    urdf: Path,
) -> None:
    """The state test's group level (``collision/model.py``: a body's many finer capsules
    cut into groups of neighbouring clusters, a group pair's ball opening its cluster
    pairs): each group's ball holds its capsules, every checked capsule pair lies under
    its group pair, and the filter's verdicts are float64's, on random states, across the
    contact and on certified (grown) edges."""
    from plannerlab.collision.state_test import exact_batch

    fine = chain(urdf, 128)
    core = CollisionChecker(fine, Scene(), backend="core")._core
    m = core.model
    ncl = len(m.cl_body)
    assert len(m.grp_cls) - 1 > 2 and m.gpairs[:, 2].sum() > 4  # groups, gates tested
    for g in range(len(m.grp_cls) - 1):  # each group's ball (self radius) holds its capsules
        c0, c1 = m.grp_cls[g], m.grp_cls[g + 1]
        l0, l1 = m.cl_caps[c0], m.cl_caps[c1]
        centre, r = m.cg32[ncl + g, :3].astype(float), float(m.cg32[ncl + g, 4])
        reach = np.linalg.norm(np.vstack([m.cap_a[l0:l1], m.cap_b[l0:l1]]) - centre, axis=1)
        assert np.all(reach + np.tile(m.r_self[l0:l1], 2) <= r + 1e-6)
    for gp in range(len(m.gpairs)):  # each cluster pair under its groups
        gu, gv = m.gpairs[gp, :2] - ncl
        for cp in range(m.gpair_start[gp], m.gpair_start[gp + 1]):
            cu, cv = m.clpairs[cp]
            assert m.grp_cls[gu] <= cu < m.grp_cls[gu + 1]
            assert m.grp_cls[gv] <= cv < m.grp_cls[gv + 1]
    rng = np.random.default_rng(3)
    Q = rng.uniform(fine.lower, fine.upper, size=(400, 2))
    v = core.valid(Q)
    assert 0.05 < v.mean() < 0.95
    assert np.array_equal(v, exact_batch(m, Q, np.empty(len(Q), dtype=np.bool_)))
    # across the contact: each valid state moved towards an invalid one by bisection
    A, B = Q[v][:40], Q[~v][:40]
    t_lo, t_hi = np.zeros(len(A)), np.ones(len(A))
    for _ in range(40):
        t = 0.5 * (t_lo + t_hi)
        ok = core.valid(A + t[:, None] * (B - A))
        t_lo, t_hi = np.where(ok, t, t_lo), np.where(ok, t_hi, t)
    near = np.vstack([A + t_lo[:, None] * (B - A), A + t_hi[:, None] * (B - A)])
    ref = exact_batch(m, near, np.empty(len(near), dtype=np.bool_))
    assert np.array_equal(core.valid(near), ref) and ref[: len(A)].all() and not ref[len(A) :].any()
    # certified edges (grown lanes, the groups' rates) give the grid's verdict
    step = 0.002
    seen = set()
    for a, b in zip(Q[:-1:4], Q[1::4], strict=True):
        n, bad = core.edge_first_invalid(a, b, step)
        status, _, n2 = core.edge_certified(a, b, step)
        assert n2 == n and status == (0 if bad < 0 else 1)
        seen.add(status)
    assert seen == {0, 1}


def test_pairs_that_never_collide_are_found_on_the_meshes_not_the_covers(urdf: Path) -> None:
    """MoveIt's "Never": judged on the links' meshes, a pair that only the covers bring
    together is disabled; judged on the one-capsule covers, it is not."""
    apart = chain(urdf.parent / "apart.urdf", 0)
    Q = np.random.default_rng(1).uniform(apart.lower, apart.upper, size=(50, 2))
    assert min(mesh_distance_m(apart, q) for q in Q) > 0.0
    on_meshes = disabled_pairs(apart, np.random.default_rng(0), n_states=100)
    knob = [("base", "turn", "Adjacent"), ("slider", "turn", "Adjacent")]  # the joint's knob
    assert [(p.link1, p.link2, p.reason) for p in on_meshes] == [*knob, ("base", "slider", "Never")]
    on_covers = disabled_pairs(apart, np.random.default_rng(0), n_states=100, geometry="covers")
    got = [(p.link1, p.link2, p.reason) for p in on_covers]
    assert got == [*knob, ("base", "slider", "Default")]
    # a pair that does meet is kept checked on the meshes too
    meeting = chain(urdf, 0)
    got = disabled_pairs(meeting, np.random.default_rng(0), n_states=100)
    assert [(p.link1, p.link2, p.reason) for p in got] == knob


@pytest.mark.parametrize("planner", ["native.rrtconnect", "ompl.rrtconnect"])
def test_a_start_in_self_collision_is_refused_naming_the_urdf_links(
    urdf: Path, planner: str
) -> None:
    """docs/problem-format.md: the error names the colliding pairs by the URDF's links,
    not by the capsules of the covers (``slider#s3``)."""
    import plannerlab as pl
    from plannerlab.errors import ProblemError
    from plannerlab.problem.load import problem_from_dict

    doc = {
        "problem": {"name": "two_boxes"},
        "robot": {
            "type": "urdf",
            "urdf": str(urdf),
            "tip_link": "slider",
            "cover_max_primitives": 1,
        },
        "start": {"q": [0.0, -0.06]},
        "goals": [{"name": "out", "q": [0.0, 0.05]}],
    }
    problem = problem_from_dict(doc, str(urdf.parent / "p.toml"))
    with pytest.raises(ProblemError) as e:
        pl.solve(problem, planner, 0, budget=pl.Budget(time_limit_s=5.0))
    assert "base x slider" in str(e.value) and "#" not in str(e.value)

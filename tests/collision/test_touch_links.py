"""Declared contacts (an obstacle's ``touch_links``, issue 35 item 4): MotionBenchMaker's
Panda (spheres) holds a box between its fingers. The fingers overlap it: invalid without
``touch_links``, valid with them, on every road (the batch lanes, the one-state road, the
float64 road, the colliding pairs, the distances, the certified and grid edges) and on
FCL; the hand, not named, still collides with the box; another obstacle at the same place
still collides with the fingers."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from conftest import PROBLEMS

from plannerlab.collision.exact import frames64  # noqa: F401  (compiled with the model)
from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.one_lanes import checker_tables
from plannerlab.collision.one_state import valid_each
from plannerlab.collision.state_test import exact_batch
from plannerlab.problem.load import problem_from_dict

PANDA = PROBLEMS / "urdf" / "panda"
#: MotionBenchMaker's Panda start: the hand points down, its fingers at y = ±0.08 m and
#: ±0.073 m, z = 0.51 m and 0.488 m (x = 0.307 m), the hand's spheres from z = 0.516 m up
Q0 = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
FINGERS = ["panda_leftfinger", "panda_rightfinger"]


def _box(name: str, touch: list[str] | None, z_m: float = 0.48) -> dict[str, Any]:
    """A 4 x 15 x 4 cm box across the fingers (both overlap it; 6 mm below the hand's
    spheres grown by the 1 cm margin), its top at ``z_m`` + 2 cm."""
    o: dict[str, Any] = {
        "name": name,
        "type": "box",
        "center_m": [0.307, 0.0, z_m],
        "size_m": [0.04, 0.15, 0.04],
    }
    if touch is not None:
        o["touch_links"] = touch
    return o


def _problem(obstacles: list[dict[str, Any]]) -> Any:
    data = {
        "problem": {"name": "grasp"},
        "robot": {
            "type": "urdf",
            "urdf": "panda_spherized.urdf",
            "tip_link": "panda_hand",
            "srdf": "panda.srdf",
        },
        "start": {"q": [0.0, -0.785, 0.0, -1.9, 0.0, 1.571, 0.785]},
        "obstacles": obstacles,
        "goals": [{"name": "grasp", "q": Q0}],
    }
    return problem_from_dict(data, str(PANDA / "grasp.toml"))


def _roads(checker: CollisionChecker, Q: np.ndarray) -> dict[str, np.ndarray]:
    """Every road's verdicts on the states Q (k, dof)."""
    Q = np.ascontiguousarray(Q, dtype=float)
    core = checker._core
    assert core is not None
    out = np.empty(len(Q), dtype=np.bool_)
    return {
        "lanes": checker.valid_batch(Q),
        "lanes_one": np.array([checker.is_valid(q) for q in Q]),
        "one_state": valid_each(checker.packed_model, checker_tables(checker), Q, out.copy()),
        "float64": exact_batch(core.model, Q, out.copy()),
        "hits": np.array([len(core.hits(q)) == 0 for q in Q]),
        "pair_distances": np.array([core.clearance(q) >= 0.0 for q in Q]),
    }


def _checkers(problem: Any) -> tuple[CollisionChecker, CollisionChecker]:
    m = float(problem.safety_margin_m)
    return problem_checker(problem), CollisionChecker(
        problem.robot, problem.scene, backend="fcl", margin_m=m
    )


@pytest.fixture(scope="module")
def grasped() -> Any:
    return _problem([_box("cup", FINGERS)])


@pytest.fixture(scope="module")
def undeclared() -> Any:
    return _problem([_box("cup", None)])


def test_the_grasp_state_is_invalid_without_touch_links_and_valid_with_them(
    grasped: Any, undeclared: Any
) -> None:
    q = np.array([Q0])
    core, fcl = _checkers(undeclared)
    pairs = core.colliding_pairs(q[0])
    # the fingers, and nothing else, overlap the box
    assert {a for a, _ in pairs} == {"panda_leftfinger#0", "panda_leftfinger#1",
                                      "panda_rightfinger#0", "panda_rightfinger#1"}  # fmt: skip
    assert {b for _, b in pairs} == {"cup"}
    for name, v in _roads(core, q).items():
        assert not v[0], name
    assert not fcl.valid_batch(q)[0]
    core, fcl = _checkers(grasped)
    for name, v in _roads(core, q).items():
        assert v[0], name
    assert fcl.valid_batch(q)[0]
    assert core.colliding_pairs(q[0]) == () == fcl.colliding_pairs(q[0])
    # the clearance measures skip the declared pairs: the hand's 6 mm (its 1 cm margin
    # included: -4 mm of true gap + 1 cm) is what is left against the box
    c_core, c_fcl = core.min_clearance(q), fcl.min_clearance(q)
    assert c_core > 0.0 and c_fcl > 0.0
    assert abs(c_core - c_fcl) < 1e-6
    pd = core.pair_distances(q[0], 0.05)
    fingers = [i for i, n in enumerate(grasped.robot.link_urdf_names) if n in FINGERS]
    assert not np.isin(pd.link[~pd.other_is_link], fingers).any()


def test_every_road_agrees_with_fcl_and_float64_around_the_grasp(grasped: Any) -> None:
    core, fcl = _checkers(grasped)
    rng = np.random.default_rng(35)
    Q = np.asarray(Q0) + rng.normal(0.0, 0.08, size=(300, 7))
    roads = _roads(core, Q)
    ref = fcl.valid_batch(Q)
    assert 0.1 < ref.mean() < 0.9  # both verdicts are there
    for name, v in roads.items():
        assert np.array_equal(v, roads["float64"]), name
    assert np.array_equal(roads["float64"], ref)


def test_other_links_still_collide_with_the_obstacle() -> None:
    # only the left finger declared: the right one still collides
    problem = _problem([_box("cup", ["panda_leftfinger"])])
    core, fcl = _checkers(problem)
    q = np.array([Q0])
    assert {a.split("#")[0] for a, _ in core.colliding_pairs(q[0])} == {"panda_rightfinger"}
    for name, v in _roads(core, q).items():
        assert not v[0], name
    assert not fcl.valid_batch(q)[0]
    # the box 2.5 cm higher, into the hand (not declared): invalid with the fingers declared
    problem = _problem([_box("cup", FINGERS, z_m=0.505)])
    core, fcl = _checkers(problem)
    assert {a.split("#")[0] for a, _ in core.colliding_pairs(q[0])} == {"panda_hand"}
    for name, v in _roads(core, q).items():
        assert not v[0], name
    assert not fcl.valid_batch(q)[0]


def test_other_obstacles_still_collide_with_the_declared_links() -> None:
    problem = _problem([_box("cup", FINGERS), _box("other", None, z_m=0.47)])
    core, fcl = _checkers(problem)
    q = np.array([Q0])
    pairs = core.colliding_pairs(q[0])
    assert {b for _, b in pairs} == {"other"}
    assert {a.split("#")[0] for a, _ in pairs} == set(FINGERS)
    for name, v in _roads(core, q).items():
        assert not v[0], name
    assert not fcl.valid_batch(q)[0]
    assert fcl.colliding_pairs(q[0]) == pairs


def test_an_edge_through_the_obstacle_with_the_declared_links_only_is_valid(
    grasped: Any, undeclared: Any
) -> None:
    # the wrist turns by 0.6 rad: the fingers sweep through the box, the hand above it
    qa = np.asarray(Q0)
    qb = qa.copy()
    qb[6] += 0.6
    path = np.array([qa, qb])
    for problem, valid in ((grasped, True), (undeclared, False)):
        core, fcl = _checkers(problem)
        step = float(problem.joint_step)
        assert core.edge_check == "certified"
        for mode in ("certified", "grid"):
            assert core.check_path(path, step, mode=mode).valid is valid, mode
        assert (core._core.edge_certified(qa, qb, step)[0] == 0) is valid
        assert (core._core.edge_first_invalid(qa, qb, step)[1] < 0) is valid
        assert fcl.check_path(path, step).valid is valid
    # the hand lowered into the box on the way (joint 4 by -0.15 rad: the tip 3 cm down):
    # invalid with the fingers declared, and the hand is named
    qc = qa.copy()
    qc[3] -= 0.15
    for checker in _checkers(grasped):
        pc = checker.check_path(np.array([qa, qc]), float(grasped.joint_step))
        assert not pc.valid
        assert "panda_hand" in {a.split("#")[0] for a, _ in pc.pairs}


def test_the_sphere_fields_skip_the_declared_pairs(grasped: Any, undeclared: Any) -> None:
    """The clearance descent's field (numpy and compiled) and the trajectory optimiser's
    hinge measure no (declared link, obstacle) pair: the fingers' penetration of the box
    is there without ``touch_links`` and gone with them."""
    from plannerlab.planners.clearance.compiled import CompiledField, step_rule
    from plannerlab.planners.clearance.field import ClearanceField
    from plannerlab.planners.trajopt.geometry import PathGeometry

    q = np.asarray(Q0)
    far = 0.05
    least = {}
    for label, problem in (("declared", grasped), ("undeclared", undeclared)):
        core, _ = _checkers(problem)
        field = ClearanceField(problem.robot, problem.scene, far)
        d_np = field.distances(q)[0]
        compiled = CompiledField(field, far, core.model)
        rule = step_rule(1.0, 1.0, 1.0, False, 0.1, 0.0)
        d_c = compiled.evaluate(q, problem.goals[0], rule, False).distances_m
        hinge = PathGeometry(problem.robot, problem.scene, core.model).hinge(q[None], far)[3][0]
        least[label] = (float(np.min(d_np)), float(np.min(d_c)), float(hinge))
        # the numpy field and the compiled one: the same pairs (far ones at far_m)
        assert np.allclose(np.minimum(d_np, far), d_c, atol=1e-9)
    assert max(least["undeclared"]) < -0.005
    assert min(least["declared"]) > 0.0


def test_the_viewers_link_clearance_leaves_the_declared_pairs_out(
    grasped: Any, undeclared: Any
) -> None:
    from plannerlab.run.clearance import link_clearance

    fingers = [i for i, n in enumerate(grasped.robot.link_urdf_names) if n in FINGERS]
    d, other = link_clearance(undeclared)(np.asarray(Q0))
    assert np.all(d[fingers] < 0.0) and {other[i] for i in fingers} == {"cup"}
    d, other = link_clearance(grasped)(np.asarray(Q0))
    assert np.all(d[fingers] == np.inf) and {other[i] for i in fingers} == {""}


def test_a_mesh_obstacles_cover_boxes_carry_its_touch_links() -> None:
    from plannerlab.problem.scene import touch_mask

    cup = {
        "name": "cup",
        "type": "mesh",
        "file": "../meshes/cup.obj",
        "center_m": [0.307, 0.0, 0.48],
        "touch_links": FINGERS,
    }
    problem = _problem([cup])
    (mesh,) = problem.scene.meshes
    assert mesh.touch_links == tuple(FINGERS)
    boxes = problem.scene.obstacles
    assert len(boxes) > 1 and all(b.touch_links == tuple(FINGERS) for b in boxes)
    mask = touch_mask(problem.robot, problem.scene)
    fingers = np.array([n in FINGERS for n in problem.robot.link_urdf_names])
    assert np.array_equal(mask, np.repeat(fingers[:, None], len(boxes), axis=1))

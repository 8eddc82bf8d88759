"""The ``urdf`` robot family (any serial chain from a URDF), joint-state goals and the
MotionBenchMaker importer, on the spherized Panda of ``problems/urdf/panda`` (from the
vamp-planner 0.6.4 source distribution, Apache-2.0)."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.problem.goals import JointGoal
from plannerlab.problem.load import parse_problem
from plannerlab.problem.mbm import problem_toml, quaternion_matrix
from plannerlab.robots.base import pose_matrix, rpy_to_matrix
from plannerlab.robots.urdf.model import UrdfChain

PANDA = ROOT / "problems" / "urdf" / "panda"
URDF = PANDA / "panda_spherized.urdf"
SRDF = PANDA / "panda.srdf"
MBM = Path(__file__).resolve().parents[1] / "data" / "mbm"


@pytest.fixture(scope="module")
def panda() -> UrdfChain:
    return UrdfChain(URDF, "panda_hand", srdf_path=SRDF)


def test_the_panda_chain_is_read_from_the_urdf(panda):
    assert panda.dof == 7
    assert panda.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    # the URDF's limits, e.g. joint 4 in [-3.1416, 0.0873]
    assert panda.lower[3] == pytest.approx(-3.1416) and panda.upper[3] == pytest.approx(0.0873)
    assert not panda.continuous.any()
    # every collision element is a sphere: 59 capsules of zero length
    seg = panda.link_segments(np.zeros(7))
    assert seg.shape == (59, 2, 3)
    assert np.allclose(seg[:, 0], seg[:, 1])
    # the base sphere is fixed; the panda_link0 x panda_link2 pair is disabled by the SRDF
    names = panda.link_names
    assert panda.fixed_links == frozenset({names.index("panda_link0")})
    i0 = names.index("panda_link0")
    i2 = [i for i, n in enumerate(names) if n.startswith("panda_link2")]
    assert all((i0, j) in panda.excluded_pairs for j in i2)
    # link 1 and link 5 are neither neighbours nor disabled: checked
    i1 = [i for i, n in enumerate(names) if n.startswith("panda_link1")]
    i5 = [i for i, n in enumerate(names) if n.startswith("panda_link5")]
    assert not any((a, b) in panda.excluded_pairs for a in i1 for b in i5)


def test_tip_is_the_hand_and_its_normal_the_hand_z_axis(panda):
    p, n = panda.tip(np.zeros(7))
    # at q = 0 the hand hangs 0.088 m out in x, 0.926 m up, its z axis pointing down
    assert p == pytest.approx([0.088, 0.0, 0.926], abs=1e-9)
    assert n == pytest.approx([0.0, 0.0, -1.0], abs=1e-9)


def test_tip_jacobian_matches_finite_differences(panda):
    rng = np.random.default_rng(3)
    h = 1e-6
    for q in rng.uniform(panda.lower, panda.upper, (20, 7)):
        J_p, J_n = panda.tip_jacobian(q)
        for i in range(7):
            e = np.zeros(7)
            e[i] = h
            (pp, np_), (pm, nm) = panda.tip(q + e), panda.tip(q - e)
            assert np.allclose((pp - pm) / (2 * h), J_p[:, i], atol=1e-7)
            assert np.allclose((np_ - nm) / (2 * h), J_n[:, i], atol=1e-7)


@pytest.mark.parametrize("tilted", [False, True])
def test_panda_fk_matches_pybullet_on_1000_random_states(tilted):
    from plannerlab.sim.world import SimWorld

    T = pose_matrix([0.3, -0.2, 0.1], [0.1, 0.2, 0.3]) if tilted else np.eye(4)
    robot = UrdfChain(URDF, "panda_hand", srdf_path=SRDF, T_world_base=T)
    Q = np.random.default_rng(1).uniform(robot.lower, robot.upper, (1000, 7))
    F_fk = robot.fk(Q)
    worst_m = worst_rot = 0.0
    with SimWorld(robot) as world:
        for q, F in zip(Q, F_fk, strict=True):
            world.set_state(q)
            F_sim = world.link_frames()
            worst_m = max(worst_m, float(np.max(np.abs(F_sim[:, :3, 3] - F[:, :3, 3]))))
            worst_rot = max(worst_rot, float(np.max(np.abs(F_sim[:, :3, :3] - F[:, :3, :3]))))
    assert worst_m <= 1e-9
    assert worst_rot <= 1e-9


def test_a_cylinder_and_a_box_become_capsules_that_cover_them(tmp_path):
    urdf = tmp_path / "two.urdf"
    urdf.write_text(
        """<robot name="two">
  <link name="base"><collision><geometry><box size="0.2 0.1 0.4"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0.5 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.05" length="1.0"/></geometry></collision></link>
  <link name="slider"/>
  <joint name="turn" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="1 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.3" effort="1" velocity="1"/>
  </joint>
</robot>
""",
        encoding="utf-8",
    )
    robot = UrdfChain(urdf, "slider")
    assert robot.dof == 2 and robot.continuous.tolist() == [True, False]
    assert robot.lower.tolist() == [-np.pi, 0.0] and robot.upper.tolist() == [np.pi, 0.3]
    seg = robot.link_segments(np.array([np.pi / 2, 0.1]))
    # box 0.2 x 0.1 x 0.4: along z (its longest edge), radius the half-diagonal of x, y
    assert seg[0] == pytest.approx(np.array([[0, 0, -0.2], [0, 0, 0.2]]), abs=1e-12)
    assert robot.link_radii_m[0] == pytest.approx(np.hypot(0.1, 0.05))
    # the cylinder along the arm, turned 90° about z: from (0, 0, 0.2) to (0, 1, 0.2)
    assert np.sort(seg[1][:, 1]) == pytest.approx([0.0, 1.0], abs=1e-12)
    assert robot.link_radii_m[1] == pytest.approx(0.05)
    # the tip: the slider at 1 + 0.1 m along the arm
    p, _ = robot.tip(np.array([np.pi / 2, 0.1]))
    assert p == pytest.approx([0.0, 1.1, 0.2], abs=1e-12)
    assert robot.max_reach_m >= 1.3 + 0.2


# ---------------------------------------------------------------- joint goals
def test_a_joint_goal_contains_states_within_its_tolerance(panda):
    q_goal = np.array([1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9])
    goal = JointGoal.at(panda, "g", q_goal, 0.01)
    assert bool(goal.contains(panda, q_goal + 0.009))
    assert not bool(goal.contains(panda, q_goal + np.eye(7)[3] * 0.011))
    assert float(goal.distance(panda, q_goal + np.eye(7)[0] * 0.03)) == pytest.approx(2.0)
    # its tip target is the tip at the goal state; the tip tolerance covers the joint box
    p, n = panda.tip(q_goal)
    assert goal.p_world_m == pytest.approx(p) and goal.n_world == pytest.approx(n)
    rng = np.random.default_rng(0)
    Q = q_goal + rng.uniform(-0.01, 0.01, (200, 7))
    pos_err, _ = goal.errors(panda, Q)
    assert np.max(pos_err) <= goal.pos_tol_m


# ---------------------------------------------------------------- the importer
def _import(tmp_path: Path, which: str) -> Path:
    out = tmp_path / f"{which}.toml"
    out.write_text(
        problem_toml(
            MBM / f"scene_{which}.yaml",
            MBM / f"request_{which}.yaml",
            out_path=out,
            urdf=URDF,
            srdf=SRDF,
            tip_link="panda_hand",
        ),
        encoding="utf-8",
    )
    return out


def test_the_importer_reads_a_shelf_scene_and_its_request(tmp_path):
    path = _import(tmp_path, "shelf")
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    # the URDF by a path relative to the written file
    assert (path.parent / data["robot"]["urdf"]).resolve() == URDF.resolve()
    # the scene's allowed pairs among the robot's links (hand x link7, link0 x link1)
    assert sorted(map(sorted, data["robot"]["allowed_collisions"])) == [
        ["panda_hand", "panda_link7"],
        ["panda_link0", "panda_link1"],
    ]
    problem = parse_problem(path)
    # start: the robot's joints only (the fingers left out), in the robot's order
    assert problem.q_start.tolist() == [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
    # the goal's constraints were listed out of order
    (goal,) = problem.goals
    assert isinstance(goal, JointGoal)
    assert goal.q_rad.tolist() == [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]
    assert goal.tol_rad == pytest.approx(1e-3)  # none given: the default
    by_name = {o.name: o for o in problem.scene.obstacles}
    shelf, can, ball = by_name["shelf_top"], by_name["can"], by_name["ball"]
    assert shelf.kind == "box" and shelf.size_m.tolist() == [0.4, 0.8, 0.04]
    R = quaternion_matrix([0, 0, 0.3826834323650898, 0.9238795325112867])  # 45° about z
    assert shelf.T_world_obstacle[:3, :3] == pytest.approx(R, abs=1e-12)
    assert shelf.T_world_obstacle[:3, 3].tolist() == [0.65, 0.0, 0.9]
    # MoveIt's cylinder dimensions are [height, radius]
    assert can.kind == "cylinder" and (can.radius_m, can.length_m) == (0.03, 0.14)
    assert ball.kind == "sphere" and ball.radius_m == 0.05


def test_the_importer_composes_an_object_pose_with_its_primitive_poses(tmp_path):
    problem = parse_problem(_import(tmp_path, "table"))
    top, leg = problem.scene.obstacles
    assert (top.name, leg.name) == ("table#0", "table#1")
    # the object stands at (0.6, 0, 0) turned 90° about z: the leg's (0.2, 0, 0.15) is
    # at (0.6, 0.2, 0.15), and the top's long edge runs along world y
    assert leg.T_world_obstacle[:3, 3] == pytest.approx([0.6, 0.2, 0.15], abs=1e-12)
    assert top.T_world_obstacle[:3, :3] == pytest.approx(rpy_to_matrix([0, 0, np.pi / 2]))
    (goal,) = problem.goals
    assert goal.tol_rad == pytest.approx(0.002)  # the constraints' tolerance


def test_an_imported_problem_is_solved_by_rrtconnect_on_a_fixed_seed(tmp_path):
    path = _import(tmp_path, "shelf")
    problem = parse_problem(path)
    checker = problem_checker(problem)
    assert checker.is_valid(problem.q_start) and checker.is_valid(problem.goals[0].q_rad)
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "plannerlab",
            "solve",
            str(path),
            "--planner",
            "ompl.rrtconnect",
            "--seed",
            "0",
            "--max-checks",
            "50000",
            "--json",
            "--out",
            str(tmp_path / "plan.json"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    leg = json.loads(out.stdout)["legs"][0]
    assert leg["status"] == "solved", leg["reason"]
    assert leg["collision_checks"] <= 50000
    path_q = np.array(leg["path"], dtype=float)
    assert path_q[0] == pytest.approx(problem.q_start)
    assert bool(problem.goals[0].contains(problem.robot, path_q[-1]))
    # re-checked here, densified, with FCL
    fcl = CollisionChecker(problem.robot, problem.scene, backend="fcl")
    assert fcl.check_path(path_q, problem.joint_step / 4).valid


# ---------------------------------------------------------------- the compiled core
def test_the_core_checks_a_urdf_chain_as_fcl_does(tmp_path):
    """Compiled chain kinematics + capsule tests against FCL on random Panda states in an
    imported shelf scene (spheres against a box, a cylinder and a sphere)."""
    problem = parse_problem(_import(tmp_path, "shelf"))
    core = CollisionChecker(problem.robot, problem.scene, backend="core", margin_m=0.01)
    fcl = CollisionChecker(problem.robot, problem.scene, backend="fcl", margin_m=0.01)
    Q = np.random.default_rng(5).uniform(problem.robot.lower, problem.robot.upper, (3000, 7))
    assert core._core is not None
    assert np.allclose(core._core.segments(Q), problem.robot.link_segments(Q), atol=1e-12)
    v_core, v_fcl = core.valid_batch(Q), fcl.valid_batch(Q)
    assert 0.2 < v_core.mean() < 0.95  # both kinds of state are there
    assert np.array_equal(v_core, v_fcl)
    assert [core.is_valid(q) for q in Q[:300]] == v_fcl[:300].tolist()


def test_the_gradient_method_descends_on_joint_distance_to_a_goal_state(tmp_path):
    """In free space the paper's descent (analytic gradient) walks straight to a goal
    state: the joint distance shrinks to the tolerance."""
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    text = f"""
[problem]
name = "free"
[robot]
type = "urdf"
urdf = "{URDF.as_posix()}"
srdf = "{SRDF.as_posix()}"
tip_link = "panda_hand"
[start]
q = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
[[goals]]
name = "g"
q = [0.5, -0.5, 0.3, -2.0, 0.2, 1.8, 0.6]
joint_tol_rad = 0.01
"""
    path = tmp_path / "free.toml"
    path.write_text(text, encoding="utf-8")
    problem = parse_problem(path)
    r = make_planner("gradient.analytic").solve(
        problem, 0, Budget(max_iterations=2000), np.random.default_rng(0)
    )
    assert r.status.value == "solved", r.reason
    goal = problem.goals[0]
    assert float(goal.joint_error(r.path[-1])) <= 0.01
    # straight in joint space: every state on the way is closer than the start
    d = goal.joint_error(r.path)
    assert np.all(np.diff(d) <= 1e-12)


def test_the_reach_bound_holds_for_random_panda_states(panda):
    Q = np.random.default_rng(2).uniform(panda.lower, panda.upper, (2000, 7))
    p, _ = panda.tip(Q)
    dist = np.linalg.norm(p - panda.T_world_base[:3, 3], axis=1)
    assert np.max(dist) <= panda.max_reach_m
    assert np.max(dist) >= 0.7 * panda.max_reach_m  # and it is not loose


def test_import_mbm_on_the_command_line_writes_a_problem_that_loads(tmp_path, capsys):
    from plannerlab.cli.main import main

    code = main(
        [
            "import",
            "mbm",
            str(MBM / "scene_table.yaml"),
            str(MBM / "request_table.yaml"),
            "--urdf",
            str(URDF),
            "--srdf",
            str(SRDF),
            "--name",
            "table_test",
            "--out",
            str(tmp_path / "out"),
        ]
    )
    assert code == 0, capsys.readouterr().err
    problem = parse_problem(tmp_path / "out" / "table_test.toml")
    assert problem.name == "table_test" and len(problem.scene.obstacles) == 2
    assert problem.safety_margin_m == 0.0 and problem.joint_step == pytest.approx(0.02)


def _bare_middle(tmp_path, bare: bool):
    """base -(turn)- housing -(tilt)- arm: the housing bare or with a small box; the arm's
    cylinder starts inside the base's box, as a joint housing's neighbours are built."""
    box = '<geometry><box size="0.02 0.02 0.02"/></geometry>'
    housing = "" if bare else f"<collision>{box}</collision>"
    limit = 'effort="1" velocity="1"'
    urdf = tmp_path / f"bare_{bare}.urdf"
    urdf.write_text(
        f"""<robot name="bare">
  <link name="base"><collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision></link>
  <link name="housing">{housing}</link>
  <link name="arm"><collision><origin xyz="0 0 0.3"/>
    <geometry><cylinder radius="0.05" length="0.8"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="housing"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" {limit}/></joint>
  <joint name="tilt" type="revolute"><parent link="housing"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" {limit}/></joint>
</robot>
""",
        encoding="utf-8",
    )
    return UrdfChain(urdf, "arm")


def test_links_joined_through_a_bare_body_are_adjacent_as_moveit_counts_them(tmp_path):
    """The arm hangs from the base through a housing with no collision geometry: MoveIt
    calls base and arm adjacent ("adjacent with no geometry links between them"); checked,
    they would collide in every state. A housing with geometry keeps them checked."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene

    robot = _bare_middle(tmp_path, bare=True)
    names = list(robot.link_urdf_names)
    base, arm = names.index("base"), names.index("arm")
    assert (min(base, arm), max(base, arm)) in robot.excluded_pairs
    checker = CollisionChecker(robot, Scene())
    assert checker.is_valid(np.array([0.3, 0.2]))
    solid = _bare_middle(tmp_path, bare=False)
    names = list(solid.link_urdf_names)
    base, arm = names.index("base"), names.index("arm")
    assert (min(base, arm), max(base, arm)) not in solid.excluded_pairs
    assert not CollisionChecker(solid, Scene()).is_valid(np.array([0.3, 0.2]))

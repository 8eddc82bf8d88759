"""The fused validity check of a URDF chain (collision/chain.py: ``ChainValidity``) gives
the compiled core's verdicts (core.py's generic kernels) and FCL's, on the spherized Panda
in imported MotionBenchMaker-form scenes and on a small chain of capsules that turns about
x, y and an oblique axis and slides."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from plannerlab.collision.chain_check import ChainValidity
from plannerlab.collision.core import Core
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.load import Problem, parse_problem
from plannerlab.problem.mbm import problem_toml
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.urdf.model import UrdfChain

PANDA = ROOT / "problems" / "urdf" / "panda"
MBM = ROOT / "tests" / "data" / "mbm"


def _imported(tmp_path: Path, which: str) -> Problem:
    out = tmp_path / f"{which}.toml"
    out.write_text(
        problem_toml(
            MBM / f"scene_{which}.yaml",
            MBM / f"request_{which}.yaml",
            out_path=out,
            urdf=PANDA / "panda_spherized.urdf",
            srdf=PANDA / "panda.srdf",
            tip_link="panda_hand",
        ),
        encoding="utf-8",
    )
    return parse_problem(out)


@pytest.mark.parametrize("which", ["shelf", "table"])
@pytest.mark.parametrize("margin_m", [0.0, 0.01])
def test_the_fused_check_gives_the_cores_verdicts_on_panda_states(tmp_path, which, margin_m):
    problem = _imported(tmp_path, which)
    robot = problem.robot
    core = Core(robot, problem.scene, margin_m=margin_m)
    fused = ChainValidity.of(core)
    Q = np.random.default_rng(7).uniform(robot.lower, robot.upper, (6000, robot.dof))
    v_core = core.valid(Q)
    assert 0.2 < v_core.mean() < 0.97  # both kinds of state are there
    assert np.array_equal(fused.valid(Q), v_core)
    assert [fused.is_valid(q) for q in Q[:400]] == v_core[:400].tolist()
    bad = int(np.flatnonzero(~v_core)[0])
    assert fused.first_invalid(Q) == core.first_invalid(Q) == bad
    assert fused.first_invalid(Q[v_core][:50]) == -1
    # its own kinematics (every joint axis turned onto z) give the robot's capsules
    assert np.abs(fused.segments(Q[:200]) - robot.link_segments(Q[:200])).max() < 1e-12


def test_the_fused_check_agrees_with_fcl_on_panda_states(tmp_path):
    problem = _imported(tmp_path, "shelf")
    fcl = CollisionChecker(problem.robot, problem.scene, backend="fcl", margin_m=0.01)
    fused = ChainValidity.of(Core(problem.robot, problem.scene, margin_m=0.01))
    Q = np.random.default_rng(8).uniform(problem.robot.lower, problem.robot.upper, (3000, 7))
    v_fcl = fcl.valid_batch(Q)
    assert 0.2 < v_fcl.mean() < 0.97
    assert np.array_equal(fused.valid(Q), v_fcl)


def test_states_a_hair_from_contact_get_the_cores_verdicts(tmp_path):
    """Bisected to 1e-10 rad between a valid and an invalid state, pairs of states a hair
    either side of first contact: the bounding balls never hide a contact."""
    problem = _imported(tmp_path, "table")
    robot = problem.robot
    core = Core(robot, problem.scene, margin_m=0.0)
    fused = ChainValidity.of(core)
    Q = np.random.default_rng(9).uniform(robot.lower, robot.upper, (400, robot.dof))
    v = core.valid(Q)
    good, bad = Q[v][:60], Q[~v][:60]
    lo, hi = good.copy(), bad.copy()  # lo valid, hi invalid, along the segment
    for _ in range(40):
        mid = (lo + hi) / 2.0
        ok = core.valid(mid)
        lo[ok], hi[~ok] = mid[ok], mid[~ok]
    assert np.abs(hi - lo).max() < 1e-10
    edge = np.concatenate([lo, hi])
    assert core.valid(lo).all() and not core.valid(hi).any()
    assert np.array_equal(fused.valid(edge), core.valid(edge))


_OBLIQUE_URDF = """<robot name="oblique">
  <link name="base"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="a"><collision><origin xyz="0 0 0.3"/>
    <geometry><cylinder radius="0.05" length="0.6"/></geometry></collision></link>
  <link name="b"><collision><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.04" length="0.5"/></geometry></collision>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.06"/></geometry></collision>
  </link>
  <link name="c"><collision><origin xyz="0 0.2 0"/>
    <geometry><box size="0.06 0.4 0.06"/></geometry></collision></link>
  <link name="d"><collision><origin xyz="0 0.1 0.1"/>
    <geometry><cylinder radius="0.03" length="0.2"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.6" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="j3" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="0.5 0 0"/><axis xyz="0.6 0.8 0"/></joint>
  <joint name="j4" type="prismatic"><parent link="c"/><child link="d"/>
    <origin xyz="0 0.4 0"/><axis xyz="0 0.6 -0.8"/>
    <limit lower="-0.2" upper="0.3" effort="1" velocity="1"/></joint>
</robot>
"""


def test_a_chain_of_capsules_turning_about_any_axis_and_sliding(tmp_path):
    """Capsules (not spheres: segment tests), axes x, y, oblique, a prismatic joint; a box,
    a cylinder and a sphere in the scene; with and without margin."""
    urdf = tmp_path / "oblique.urdf"
    urdf.write_text(_OBLIQUE_URDF, encoding="utf-8")
    robot = UrdfChain(urdf, "d")
    scene = Scene(
        obstacles=(
            Box("wall", pose_matrix([0.6, 0.2, 0.6], [0.2, 0.1, 0.4]), np.array([0.1, 0.8, 1.2])),
            Cylinder("post", pose_matrix([-0.4, 0.5, 0.5], [0.5, 0.0, 0.2]), 0.08, 1.0),
            Sphere("ball", pose_matrix([0.0, -0.6, 0.9], [0.0, 0.0, 0.0]), 0.15),
        )
    )
    Q = np.random.default_rng(10).uniform(robot.lower, robot.upper, (5000, robot.dof))
    for margin_m in (0.0, 0.02):
        core = Core(robot, scene, margin_m=margin_m)
        fused = ChainValidity.of(core)
        v_core = core.valid(Q)
        assert 0.2 < v_core.mean() < 0.95
        assert np.array_equal(fused.valid(Q), v_core)
        assert np.abs(fused.segments(Q[:200]) - robot.link_segments(Q[:200])).max() < 1e-12
    fcl = CollisionChecker(robot, scene, backend="fcl", margin_m=0.02)
    assert np.array_equal(fused.valid(Q[:1500]), fcl.valid_batch(Q[:1500]))


def test_a_state_of_the_wrong_size_is_refused(tmp_path):
    fused = ChainValidity.of(Core(_imported(tmp_path, "shelf").robot, Scene()))
    with pytest.raises(ValueError, match="7 joints"):
        fused.valid(np.zeros((3, 6)))
    with pytest.raises(ValueError, match="7 joints"):
        fused.is_valid(np.zeros(8))
    with pytest.raises(ValueError, match="one state"):
        fused.is_valid(np.zeros((2, 7)))

"""The compiled core on a URDF chain (its one kinematics, :mod:`plannerlab.collision.
kinematics`, and its state test) gives the robot's own capsules and FCL's verdicts, on the
spherized Panda in imported MotionBenchMaker-form scenes and on a small chain of capsules
that turns about x, y and an oblique axis and slides."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

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
def test_the_core_agrees_with_fcl_on_panda_states(tmp_path, which):
    problem = _imported(tmp_path, which)
    robot = problem.robot
    fcl = CollisionChecker(robot, problem.scene, backend="fcl", margin_m=0.01)
    core = Core(robot, problem.scene, margin_m=0.01)
    Q = np.random.default_rng(8).uniform(robot.lower, robot.upper, (3000, robot.dof))
    v_fcl = fcl.valid_batch(Q)
    assert 0.2 < v_fcl.mean() < 0.97  # both kinds of state are there
    assert np.array_equal(core.valid(Q), v_fcl)
    # the one kinematics (every joint axis turned onto z) gives the robot's capsules
    assert np.abs(core.segments(Q[:200]) - robot.link_segments(Q[:200])).max() < 1e-9


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
    a cylinder and a sphere in the scene; with and without margin: the core's kinematics
    give the robot's capsules and its verdicts are FCL's."""
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
    Q = np.random.default_rng(10).uniform(robot.lower, robot.upper, (1500, robot.dof))
    for margin_m in (0.0, 0.02):
        core = Core(robot, scene, margin_m=margin_m)
        fcl = CollisionChecker(robot, scene, backend="fcl", margin_m=margin_m)
        v_core = core.valid(Q)
        assert 0.2 < v_core.mean() < 0.95
        assert np.array_equal(v_core, fcl.valid_batch(Q))
        assert np.abs(core.segments(Q[:200]) - robot.link_segments(Q[:200])).max() < 1e-9

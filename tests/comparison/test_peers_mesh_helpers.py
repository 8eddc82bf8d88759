"""The pure helpers of ``bench/peers_mesh.py`` (issue 35, the peers beside plannerlab on
mesh problems): a frozen joint folded into a fixed joint's origin, the referee's cut of a
path, a peer's path over a continuous joint unwrapped and its ends judged."""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
import peers_mesh  # noqa: E402

# a unit axis: yourdfpy moves a prismatic joint by the axis as written, plannerlab (and
# peers_mesh) by the axis normalised
URDF = """<robot name="two">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="{kind}">
    <parent link="a"/><child link="b"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.4 -0.5 0.6"/>
    <axis xyz="0.36 0.48 -0.8"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>"""


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_a_frozen_joint_folded_into_a_fixed_origin_places_its_child_as_yourdfpy_does(
    tmp_path: Path, kind: str
) -> None:
    value = 0.7
    moving = tmp_path / "moving.urdf"
    moving.write_text(URDF.format(kind=kind))
    ref = yourdfpy.URDF.load(str(moving), build_scene_graph=True, load_meshes=False)
    ref.update_cfg({"j": value})
    T_ref = ref.get_transform("b", "a")

    root = ET.fromstring(URDF.format(kind=kind))
    joint = root.find("joint")
    assert joint is not None
    xyz, rpy = peers_mesh._fixed_origin(joint, value)
    fixed = URDF.format(kind="fixed").replace('xyz="0.1 -0.2 0.3" rpy="0.4 -0.5 0.6"', "")
    fixed = fixed.replace("<origin />", f'<origin xyz="{xyz}" rpy="{rpy}"/>')
    fixed = fixed.replace("<origin/>", f'<origin xyz="{xyz}" rpy="{rpy}"/>')
    (tmp_path / "fixed.urdf").write_text(fixed)
    got = yourdfpy.URDF.load(str(tmp_path / "fixed.urdf"), build_scene_graph=True)
    np.testing.assert_allclose(got.get_transform("b", "a"), T_ref, atol=1e-12)
    # the motion is really folded in: not the origin at the joint's zero
    ref.update_cfg({"j": 0.0})
    assert np.max(np.abs(ref.get_transform("b", "a") - T_ref)) > 0.05


def test_the_referee_cut_keeps_every_joint_step_within_the_step_and_the_ends() -> None:
    P = np.array([[0.0, 0.0], [0.1, -0.023], [0.1, -0.023], [-0.05, 0.4]])
    Q = peers_mesh.interpolate(P, 0.005)
    assert np.max(np.abs(np.diff(Q, axis=0))) <= 0.005 + 1e-12
    np.testing.assert_array_equal(Q[0], P[0])
    np.testing.assert_allclose(Q[-1], P[-1], atol=1e-15)
    assert len(Q) == 1 + 20 + 1 + 85  # ceil of the largest joint move / step, a zero edge 1


def test_a_peer_path_over_a_continuous_joint_is_unwrapped_and_its_ends_judged() -> None:
    query = {"continuous": [True, False], "q_start": [3.0, 0.5], "q_goal": [-3.0, 0.6]}
    # the peer crosses +-pi the short way: 3.0 -> 3.1 -> -3.1 -> -3.0
    P = np.array([[3.0, 0.5], [3.1, 0.55], [-3.1, 0.58], [-3.0, 0.6]])
    U, ends = peers_mesh.path_checks(P, query)
    assert ends == "ends ok"
    assert np.max(np.abs(np.diff(U[:, 0]))) < 0.2  # not a sweep through 0
    np.testing.assert_allclose(U[-1, 0], -3.0 + 2 * np.pi)
    np.testing.assert_array_equal(U[:, 1], P[:, 1])  # the revolute joint untouched
    _, ends = peers_mesh.path_checks(P[:-1], query)
    assert ends.startswith("does not end at the goal")
    _, ends = peers_mesh.path_checks(P[1:], query)
    assert ends.startswith("does not start at the start")

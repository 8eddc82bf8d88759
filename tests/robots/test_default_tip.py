"""The default tip link (:func:`plannerlab.robots.urdf.tip.default_tip_link`): the tool
centre frame where the URDF names one, else the hand, never a single moving jaw, and the
last link of a plain chain stays its end.

Synthetic URDFs (box and cylinder geometry) pin each rule; the arms of ``pybullet_data``
(installed with PyBullet) pin it on files as they ship.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from plannerlab.errors import PlannerlabError
from plannerlab.robots.urdf.tip import default_tip_link


def _link(name: str, geometry: str = "", xyz: str = "0 0 0") -> str:
    if not geometry:
        return f'<link name="{name}"/>'
    return (
        f'<link name="{name}"><collision><origin xyz="{xyz}"/><geometry>{geometry}'
        f"</geometry></collision></link>"
    )


def _joint(name: str, kind: str, parent: str, child: str, xyz: str, axis: str = "0 0 1") -> str:
    lim = '<limit lower="-1.5" upper="1.5" effort="1" velocity="1"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{lim}</joint>'
    )


def _arm(tmp_path: Path, end: list[str], name: str = "arm") -> Path:
    """A 3-joint arm (base, two links along x) ending in a wrist whose roll axis is x,
    then the parts in ``end`` (links and joints hung on ``wrist``)."""
    body = [
        _link("base", '<box size="0.2 0.2 0.1"/>'),
        _link("l1", '<box size="0.4 0.06 0.06"/>', "0.2 0 0"),
        _link("l2", '<box size="0.4 0.06 0.06"/>', "0.2 0 0"),
        _link("wrist", '<cylinder radius="0.04" length="0.05"/>'),
        _joint("j1", "revolute", "base", "l1", "0 0 0.1", "0 0 1"),
        _joint("j2", "revolute", "l1", "l2", "0.4 0 0", "0 1 0"),
        _joint("j3", "revolute", "l2", "wrist", "0.4 0 0", "1 0 0"),
        *end,
    ]
    f = tmp_path / f"{name}.urdf"
    f.write_text(f'<robot name="{name}">' + "".join(body) + "</robot>")
    return f


# a hand along x with a fixed jaw reaching 0.10 m out, pivot of the moving jaw at 0.04 m
HAND = [
    _link("hand", '<box size="0.04 0.08 0.06"/>', "0.02 0 0"),
    _joint("hand_fix", "fixed", "wrist", "hand", "0.03 0 0"),
    _link("fixed_jaw", '<box size="0.06 0.01 0.04"/>', "0.03 0 0"),
    _joint("fixed_jaw_fix", "fixed", "hand", "fixed_jaw", "0.04 -0.03 0"),
]
# a jaw swinging about z at its pivot: a lever 0.06 m long along x
JAW = [
    _link("jaw", '<box size="0.06 0.01 0.04"/>', "0.03 0 0"),
    _joint("jaw_pivot", "revolute", "hand", "jaw", "0.04 0.03 0", "0 0 1"),
]
TCP = [_link("tcp"), _joint("tcp_fix", "fixed", "hand", "tcp", "0.09 0 0")]
CAMERA = [_link("camera"), _joint("camera_fix", "fixed", "hand", "camera", "0.0 0.0 0.08")]


def test_a_single_moving_jaw_is_not_the_tip_its_hand_is(tmp_path: Path) -> None:
    assert default_tip_link(_arm(tmp_path, HAND + JAW)) == "hand"


def test_the_tool_frame_on_the_wrist_axis_is_the_tip(tmp_path: Path) -> None:
    assert default_tip_link(_arm(tmp_path, HAND + JAW + TCP)) == "tcp"


def test_a_sensor_frame_off_the_wrist_axis_is_not_the_tip(tmp_path: Path) -> None:
    """Below the hand a joint still moves (the jaw): only frames on the wrist's axis."""
    assert default_tip_link(_arm(tmp_path, HAND + JAW + CAMERA)) == "hand"
    assert default_tip_link(_arm(tmp_path, HAND + JAW + CAMERA + TCP, "both")) == "tcp"


def test_a_jaw_without_its_counterpart_is_the_chains_last_link(tmp_path: Path) -> None:
    """The same lever on a hand without the fixed jaw: a plain chain's last link."""
    hand = HAND[:2]
    assert default_tip_link(_arm(tmp_path, hand + JAW)) == "jaw"


def test_a_roll_flange_stays_the_tip(tmp_path: Path) -> None:
    """A leaf turned about its own axis (a flange) with a fixed jaw-like part beside it."""
    flange = [
        _link("flange", '<cylinder radius="0.03" length="0.02"/>'),
        _joint("roll", "revolute", "hand", "flange", "0.05 0 0", "1 0 0"),
    ]
    assert default_tip_link(_arm(tmp_path, HAND + flange)) == "flange"


def test_two_fingers_stop_at_the_hand(tmp_path: Path) -> None:
    fingers = [
        _link("f1", '<box size="0.06 0.01 0.02"/>', "0.03 0 0"),
        _link("f2", '<box size="0.06 0.01 0.02"/>', "0.03 0 0"),
        _joint("f1_slide", "prismatic", "hand", "f1", "0.04 0.02 0", "0 1 0"),
        _joint("f2_slide", "prismatic", "hand", "f2", "0.04 -0.02 0", "0 -1 0"),
    ]
    assert default_tip_link(_arm(tmp_path, HAND[:2] + fingers)) == "hand"
    assert default_tip_link(_arm(tmp_path, HAND[:2] + fingers + TCP, "tcp")) == "tcp"


def test_a_file_without_movable_joints_is_refused_with_its_name(tmp_path: Path) -> None:
    f = tmp_path / "rigid.urdf"
    f.write_text(
        '<robot name="r"><link name="a"/><link name="b"/>'
        + _joint("j", "fixed", "a", "b", "0 0 0")
        + "</robot>"
    )
    with pytest.raises(PlannerlabError, match="rigid.urdf: expected movable joints"):
        default_tip_link(f)


@pytest.mark.parametrize(
    ("rel", "tip"),
    [
        ("kuka_iiwa/model.urdf", "lbr_iiwa_link_7"),  # a flange: kept
        ("xarm/xarm6_robot.urdf", "link6"),  # a flange: kept
        ("franka_panda/panda.urdf", "panda_grasptarget"),  # fingers branch; the TCP frame
    ],
)
def test_pybullet_data_arms(rel: str, tip: str) -> None:
    import pybullet_data

    assert default_tip_link(Path(pybullet_data.getDataPath()) / rel) == tip

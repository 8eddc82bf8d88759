"""The ``[robot]`` table of an IRb-6 on the LP-1 track (``type = "irb6"``): its keys and
its constructor.

Every key is optional; the defaults are the model's (``docs/papers.md`` §2). Lengths in
metres, joint ranges as ``[lower, upper]`` in degrees (the track range in metres), the
station frame's pose in the world as ``base_xyz_m`` [m] and ``base_rpy_deg`` (URDF roll,
pitch, yaw) [deg]. The table in ``docs/problem-format.md`` lists the same keys.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from plannerlab.errors import PlannerlabError
from plannerlab.robots.irb6.model import IRb6
from plannerlab.robots.schema import Key, RobotTable, TableValueError, base_pose, base_pose_keys

#: keys holding a positive length [m], passed to the model as they are
_LENGTHS = (
    "shoulder_height_m",
    "lower_arm_m",
    "upper_arm_m",
    "wrist_to_flange_m",
    "rail_radius_m",
    "column_radius_m",
    "lower_arm_radius_m",
    "upper_arm_radius_m",
    "wrist_radius_m",
)


def build(values: Mapping[str, Any]) -> IRb6:
    """An IRb-6 from the table's validated values (joint ranges in degrees, as in the file).

    Raises:
        TableValueError: when the model rejects the combination (the ranges let the wrist
            pass the column axis, θ1 spans more than 360°, ...), on the key the model's
            message names (``theta3_range_deg`` for the column axis, else ``base_rpy_deg``).
    """
    model: dict[str, Any] = {name: values[name] for name in _LENGTHS}
    model["rail_height_m"] = values["rail_height_m"]
    lo, hi = values["track_range_m"]
    model["track_range_m"] = (float(lo), float(hi))
    for j in range(1, 6):
        lo, hi = values[f"theta{j}_range_deg"]
        model[f"theta{j}_range_rad"] = (math.radians(lo), math.radians(hi))
    try:
        return IRb6(
            dead_wedge_side=values["dead_wedge_side"], T_world_base=base_pose(values), **model
        )
    except PlannerlabError as exc:  # a combination the model rejects: name the table key
        message = str(exc)
        key = next(
            (k for k in TABLE.names if k.replace("_deg", "_rad") in message),
            "theta3_range_deg" if "column axis" in message else "base_rpy_deg",
        )
        raise TableValueError(key, f"a valid IRb-6 parameter set ({message})") from None


def _length(name: str, default: float, meaning: str) -> Key:
    return Key(name, "number", default, "m", meaning, positive=True)


def _angle_range(j: int, default: tuple[float, float], meaning: str) -> Key:
    return Key(f"theta{j}_range_deg", "vector", default, "deg", meaning, length=2, ordered=True)


TABLE = RobotTable(
    type="irb6",
    keys=(
        _length("shoulder_height_m", 0.700, "λ1, shoulder axis above the track frame"),
        _length("lower_arm_m", 0.455, "l2, shoulder → elbow"),
        _length("upper_arm_m", 0.670, "l3, elbow → wrist point"),
        _length("wrist_to_flange_m", 0.095, "λ5, wrist point → flange along the approach vector"),
        Key(
            "track_range_m",
            "vector",
            (0.0, 0.851),
            "m",
            "λ0 range [lower, upper]",
            length=2,
            ordered=True,
        ),
        _angle_range(1, (-170.0, 170.0), "column rotation (the rest is the 20° dead wedge)"),
        _angle_range(2, (-40.0, 40.0), "lower-arm tilt from vertical, positive outward"),
        _angle_range(3, (-40.0, 25.0), "upper-arm elevation above horizontal (absolute)"),
        _angle_range(4, (-90.0, 90.0), "approach-vector elevation (absolute)"),
        _angle_range(5, (-180.0, 180.0), "flange roll about the approach vector"),
        Key(
            "dead_wedge_side",
            "string",
            "-z",
            "",
            "on which side of the track the 20° wedge lies (the paper's: -z)",
            choices=("-z", "+z"),
        ),
        Key("rail_height_m", "number", 0.10, "m", "height of the rail's collision capsule"),
        _length("rail_radius_m", 0.10, "capsule radius of the rail"),
        _length("column_radius_m", 0.15, "capsule radius of the column"),
        _length("lower_arm_radius_m", 0.08, "capsule radius of the lower arm"),
        _length("upper_arm_radius_m", 0.07, "capsule radius of the upper arm"),
        _length("wrist_radius_m", 0.05, "capsule radius of the wrist"),
        *base_pose_keys("station frame"),
    ),
    build=build,
)

__all__ = ["TABLE", "build"]

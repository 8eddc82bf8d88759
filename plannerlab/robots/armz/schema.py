"""The ``[robot]`` table of an Arm-Z (``type = "armz"``): its keys and its constructor.

Defaults are the paper's arm (``docs/papers.md`` §1); the table in
``docs/problem-format.md`` lists the same keys.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.schema import Key, RobotTable, base_pose, base_pose_keys

#: largest ``n_modules`` a problem file may ask for (the paper's arm has 24)
MAX_MODULES = 100


def build(values: Mapping[str, Any]) -> ArmZ:
    """An Arm-Z from the table's validated values (angles in degrees, as in the file)."""
    return ArmZ(
        n_modules=values["n_modules"],
        zeta_rad=float(np.deg2rad(values["zeta_deg"])),
        delta_y_m=values["delta_y_m"],
        delta_z_m=values["delta_z_m"],
        collision_radius_m=values["collision_radius_m"],
        self_exclude_within=values["self_exclude_within"],
        T_world_base=base_pose(values),
        module_mass_kg=values["module_mass_kg"],
        joint_torque_limit_nm=values["joint_torque_limit_nm"],
    )


TABLE = RobotTable(
    type="armz",
    keys=(
        Key(
            "n_modules",
            "integer",
            24,
            meaning="modules including the fixed base (n_modules - 1 joints)",
            minimum=2,
            maximum=MAX_MODULES,
            why_maximum="collision checking grows with the square of the module count: "
            "500 modules took 44 s for 3 gradient iterations, 10 000 ran out of memory",
        ),
        Key(
            "zeta_deg",
            "number",
            22.5,
            "deg",
            "angle between a module's bottom and top face",
            positive=True,
        ),
        Key("delta_y_m", "number", -0.1397, "m", "offset of a module's top frame along y"),
        Key(
            "delta_z_m",
            "number",
            0.7023,
            "m",
            "offset of a module's top frame along z",
            positive=True,
        ),
        Key(
            "collision_radius_m",
            "number",
            0.75,
            "m",
            "capsule radius around each module's chord",
            positive=True,
        ),
        Key(
            "self_exclude_within",
            "integer",
            5,
            "",
            "modules fewer than this apart are not checked against each other",
            minimum=1,
        ),
        Key("module_mass_kg", "number", 1.0, "kg", "mass of a module (simulation)", positive=True),
        Key(
            "joint_torque_limit_nm",
            "number",
            100.0,
            "N·m",
            "torque limit of each joint (simulation)",
            positive=True,
        ),
        *base_pose_keys("base"),
    ),
    build=build,
)

__all__ = ["MAX_MODULES", "TABLE", "build"]

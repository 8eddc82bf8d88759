"""The ``[robot]`` table of the planar continuum robot (``type = "continuum_chain"``):
its keys and its constructor. The table in ``docs/problem-format.md`` lists the same keys.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from plannerlab.robots.base import matrix_to_rpy
from plannerlab.robots.continuum.model import ContinuumChain
from plannerlab.robots.schema import Key, RobotTable, TableValueError, base_pose, base_pose_keys

#: largest ``n_links`` a problem file may ask for (the bundled problems use 40)
MAX_LINKS = 400


def build(values: Mapping[str, Any]) -> ContinuumChain:
    """A chain from the table's validated values (angles in degrees, as in the file).

    Raises:
        TableValueError: on ``base_rpy_deg`` when the base is rolled or pitched (the chain
            is planar).
    """
    T = base_pose(values)
    rpy = matrix_to_rpy(T[:3, :3])
    if abs(rpy[0]) > 1e-9 or abs(rpy[1]) > 1e-9:
        raise TableValueError("base_rpy_deg", "roll = pitch = 0 (the continuum chain is planar)")
    return ContinuumChain(
        n_links=values["n_links"],
        length_m=values["length_m"],
        link_radius_m=values["link_radius_m"],
        max_joint_rad=float(np.deg2rad(values["max_joint_deg"])),
        T_world_base=T,
        link_mass_kg=values["link_mass_kg"],
    )


TABLE = RobotTable(
    type="continuum_chain",
    keys=(
        Key(
            "n_links",
            "integer",
            40,
            meaning="rigid links of the chain",
            minimum=1,
            maximum=MAX_LINKS,
            why_maximum="collision checking and simulation grow with the link count",
        ),
        Key("length_m", "number", 0.5, "m", "total length", positive=True),
        Key("link_radius_m", "number", 0.002, "m", "capsule radius of each link", positive=True),
        Key("max_joint_deg", "number", 90.0, "deg", "joint limit, symmetric", positive=True),
        Key("link_mass_kg", "number", 0.01, "kg", "mass per link (simulation)", positive=True),
        *base_pose_keys("base port"),
    ),
    build=build,
)

__all__ = ["MAX_LINKS", "TABLE", "build"]

"""The ``[robot]`` table of a robot read from a URDF (``type = "urdf"``): its keys and
its constructor.

``urdf`` (a path relative to the problem file) and ``tip_link`` are required; the tip is
the point ``tip_offset_m`` of the tip link's frame, its normal ``tip_axis`` in that frame.
``srdf`` (optional, a path relative to the problem file) and ``allowed_collisions`` (URDF
link pairs) name link pairs whose self-collision is not checked, besides links on one body
and neighbouring bodies. Collision meshes become capsule covers
(:mod:`plannerlab.robots.urdf.meshes`): ``mesh_paths`` are more folders searched for
``package://`` paths, ``cover_excess_m`` is the excess aimed at, ``cover_max_primitives``
the budget of capsules per mesh (the excess grows when the budget needs it). The root
link's pose in the world is ``base_xyz_m`` [m] and ``base_rpy_deg`` [deg]. The table in
``docs/problem-format.md`` lists the same keys.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from plannerlab.robots.schema import Key, RobotTable, TableValueError, base_pose, base_pose_keys
from plannerlab.robots.urdf.model import UrdfChain, UrdfError


def build(values: Mapping[str, Any]) -> UrdfChain:
    """The chain from the table's validated values (paths already resolved).

    Raises:
        TableValueError: the URDF or SRDF cannot be read or used, or a link named in
            ``tip_link`` or ``allowed_collisions`` is not in it (on that key).
    """
    srdf = values["srdf"]
    urdf_folder = Path(values["urdf"]).parent
    mesh_paths = tuple(
        (urdf_folder / p).resolve() for p in str(values["mesh_paths"]).split(os.pathsep) if p
    )
    missing = [str(p) for p in mesh_paths if not p.is_dir()]
    if missing:
        raise TableValueError(
            "mesh_paths",
            f"existing folders (relative to the URDF's folder, separated by "
            f"{os.pathsep!r}); {', '.join(missing)} is not one",
        )
    try:
        return UrdfChain(
            urdf_path=Path(values["urdf"]),
            tip_link=values["tip_link"],
            tip_axis=tuple(float(v) for v in values["tip_axis"]),  # type: ignore[arg-type]
            tip_offset_m=tuple(float(v) for v in values["tip_offset_m"]),  # type: ignore[arg-type]
            srdf_path=Path(srdf) if srdf else None,
            allowed_collisions=tuple((str(a), str(b)) for a, b in values["allowed_collisions"]),
            T_world_base=base_pose(values),
            mesh_paths=mesh_paths,
            cover_excess_m=float(values["cover_excess_m"]),
            cover_max_primitives=int(values["cover_max_primitives"]),
            self_cover_excess_m=float(values["self_cover_excess_m"]),
            self_cover_max_primitives=int(values["self_cover_max_primitives"]),
            sim_urdf_path=Path(values["sim_urdf"]) if values["sim_urdf"] else None,
        )
    except UrdfError as exc:
        raise TableValueError(exc.key, exc.expected) from None


TABLE = RobotTable(
    type="urdf",
    keys=(
        Key("urdf", "path", "", "", "the URDF file, relative to the problem file", required=True),
        Key("tip_link", "string", "", "", "the URDF link carrying the tip", required=True),
        Key(
            "tip_axis",
            "vector",
            (0.0, 0.0, 1.0),
            "",
            "the tip normal, in the tip link's frame",
            length=3,
        ),
        Key(
            "tip_offset_m",
            "vector",
            (0.0, 0.0, 0.0),
            "m",
            "the tip point, in the tip link's frame",
            length=3,
        ),
        Key(
            "srdf",
            "path",
            "",
            "",
            "an SRDF whose disable_collisions pairs are not checked, relative to the problem file",
        ),
        Key(
            "allowed_collisions",
            "pairs",
            (),
            "",
            "URDF link pairs whose self-collision is not checked",
        ),
        Key(
            "mesh_paths",
            "string",
            "",
            "",
            "folders searched for package:// mesh paths, relative to the URDF's folder, "
            "separated by ':'",
        ),
        Key(
            "cover_excess_m",
            "number",
            0.01,
            "m",
            "the distance a mesh link's cover aims to reach outside the mesh at most (at most "
            "3 % of the mesh's size; more when cover_max_primitives needs it)",
            positive=True,
            maximum=0.5,
            why_maximum="a cover is an approximation of the link, not a blob around it",
        ),
        Key(
            "cover_max_primitives",
            "integer",
            32,
            "",
            "the most capsules covering one collision mesh",
            minimum=1,
            maximum=1024,
            why_maximum="every capsule is one more to check",
        ),
        Key(
            "self_cover_excess_m",
            "number",
            0.004,
            "m",
            "the distance a mesh link's second, finer cover (judging self-collision only) "
            "aims to reach outside the mesh at most",
            positive=True,
            maximum=0.5,
            why_maximum="a cover is an approximation of the link, not a blob around it",
        ),
        Key(
            "self_cover_max_primitives",
            "integer",
            128,
            "",
            "the most capsules of a mesh's finer cover, which judges self-collision (links "
            "that pass within millimetres of each other: a UR10's wrists); 0: none (the "
            "first cover judges self-collision too; the state test costs 2.5-4.3x less)",
            minimum=0,
            maximum=1024,
            why_maximum="every capsule is one more to check",
        ),
        Key(
            "sim_urdf",
            "path",
            "",
            "",
            "the robot's real geometry for the simulator: a URDF with the same joints and "
            "links (e.g. the mesh original of a spherized urdf), relative to the problem file",
        ),
        *base_pose_keys("root link"),
    ),
    build=build,
)

__all__ = ["TABLE", "build"]

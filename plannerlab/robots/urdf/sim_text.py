"""The URDF text PyBullet loads for a :class:`~plannerlab.robots.urdf.model.UrdfChain`:
the file as it is, real collision meshes included (verdicts are measured on them)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from plannerlab.robots.base import urdf_origin


def _motion(axis: np.ndarray, value: float, prismatic: bool) -> np.ndarray:
    """A joint's motion (4, 4) at ``value`` about/along the unit ``axis``."""
    T = np.eye(4)
    if prismatic:
        T[:3, 3] = value * axis
    else:
        T[:3, :3] = Rotation.from_rotvec(value * axis).as_matrix()
    return T


def simulator_urdf(chain: Any) -> str:
    """The URDF text for the simulator: the file (``sim_urdf`` when given) as it is (its
    collision meshes, the real geometry, included), with every collision mesh path made absolute (as
    resolved for the covers, ``package://`` included), visual meshes resolved the same
    way or left out when they cannot be (they are only looks; PyBullet refuses a file
    naming a missing mesh) and the frozen joints (see the module) made fixed at their
    value."""
    from plannerlab.robots.urdf.meshes import MeshError, resolve_mesh

    source = chain.sim_urdf_path or chain.urdf_path
    mesh_files = chain._sim_mesh_files if chain.sim_urdf_path else chain._mesh_files
    tree = ET.parse(source)
    root = tree.getroot()
    for link in root.iter("link"):
        for col in link.findall("collision"):
            for mesh in col.iter("mesh"):
                fn = mesh.get("filename", "")
                if fn in mesh_files:
                    mesh.set("filename", str(mesh_files[fn]))
        for visual in link.findall("visual"):
            for mesh in visual.iter("mesh"):
                fn = mesh.get("filename", "")
                try:
                    mesh.set(
                        "filename",
                        str(resolve_mesh(fn, source, tuple(chain.mesh_paths), "")),
                    )
                except MeshError:
                    # a visual whose mesh is not there (PyBullet refuses the file)
                    link.remove(visual)
                    break
    for joint in root.iter("joint"):
        name = joint.get("name", "")
        if name not in chain.frozen_joints:
            continue
        value = chain.frozen_joints[name]
        if value != 0.0:
            from plannerlab.robots.base import pose_matrix

            o = joint.find("origin")
            xyz = (
                [0.0, 0.0, 0.0] if o is None else [float(v) for v in o.get("xyz", "0 0 0").split()]
            )
            rpy = (
                [0.0, 0.0, 0.0] if o is None else [float(v) for v in o.get("rpy", "0 0 0").split()]
            )
            ax = joint.find("axis")
            axis = np.array(
                [1.0, 0.0, 0.0]
                if ax is None
                else [float(v) for v in ax.get("xyz", "1 0 0").split()]
            )
            motion = _motion(
                axis / np.linalg.norm(axis), float(value), joint.get("type") == "prismatic"
            )
            T = np.asarray(pose_matrix(xyz, rpy)) @ motion
            if o is not None:
                joint.remove(o)
            joint.append(ET.fromstring(urdf_origin(T)))
        joint.set("type", "fixed")
        for tag in ("mimic", "limit"):
            for e in joint.findall(tag):
                joint.remove(e)
    return ET.tostring(root, encoding="unicode")


__all__ = ["simulator_urdf"]

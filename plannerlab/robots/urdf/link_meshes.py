"""A URDF chain's links as their real collision geometry: per URDF link one triangle mesh
in its body's frame (its ``<collision>`` meshes, scaled, or their convex hulls; boxes,
cylinders and spheres as trimesh makes them), for tests that judge the links themselves
rather than their covers (the self-collision pairs of :mod:`plannerlab.run.srdf`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.robots.base import Array


@dataclass(frozen=True)
class LinkMesh:
    """A URDF link's collision geometry: its body (the chain's, 0 = root), and its
    triangles (vertices (n, 3) [m] in the body's frame, faces (m, 3))."""

    link: str
    body: int
    vertices_m: Array
    faces: np.ndarray


def link_meshes(robot: Any, hulls: bool = True) -> list[LinkMesh]:
    """Every URDF link of ``robot`` (a :class:`~plannerlab.robots.urdf.model.UrdfChain`)
    that has collision geometry, as one mesh in its body's frame; with ``hulls`` each
    collision mesh as its convex hull (what PyBullet checks, and so the simulator's and
    the referee's verdicts), else its triangles as the file gives them."""
    import trimesh

    from plannerlab.robots.urdf.meshes import load_mesh, resolve_mesh
    from plannerlab.robots.urdf.tree import _chain, _load_urdf, _place_links

    path = robot.urdf_path
    tree = _chain(_load_urdf(path), robot.tip_link, path)
    placed = _place_links(tree)
    out = []
    for lname, link in tree.links.items():
        b, T_link = placed[lname]
        parts = []
        for col in link.collisions:
            T = T_link @ (np.eye(4) if col.origin is None else np.asarray(col.origin, float))
            g = col.geometry
            if g.mesh is not None:
                where = f"link {lname} of {path.name}"
                file = resolve_mesh(str(g.mesh.filename), path, tuple(robot.mesh_paths), where)
                scale = np.ones(3) if g.mesh.scale is None else np.asarray(g.mesh.scale, float)
                V, F = load_mesh(file, np.broadcast_to(scale, (3,)), where)
                m = trimesh.Trimesh(V, F, process=False)
                if hulls:
                    m = m.convex_hull
            elif g.box is not None:
                m = trimesh.creation.box(np.asarray(g.box.size, dtype=float))
            elif g.cylinder is not None:
                m = trimesh.creation.cylinder(float(g.cylinder.radius), float(g.cylinder.length))
            elif g.sphere is not None:
                m = trimesh.creation.icosphere(3, float(g.sphere.radius))
            else:
                continue
            m.apply_transform(T)
            parts.append(m)
        if parts:
            whole: Any = trimesh.util.concatenate(parts) if len(parts) > 1 else parts[0]
            out.append(
                LinkMesh(lname, int(b), np.asarray(whole.vertices, float), np.asarray(whole.faces))
            )
    return out


__all__ = ["LinkMesh", "link_meshes"]

"""What the 3-D viewer (:mod:`plannerlab.plot.view`) draws, as plain data: each leg's
timeline of frames from the records (:func:`leg_motions`), the robot's capsules as
instances of a unit cylinder and sphere, obstacles and goal cones as triangles, the
clearance colours, a URDF's visual meshes (yourdfpy, trimesh) and the camera. No viser
here: everything is numpy arrays a test can check.
"""

from __future__ import annotations

import math
import socket
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.problem.load import Problem
from plannerlab.problem.scene import Box, Cylinder, Sphere
from plannerlab.record.cells import rough as rough_cell
from plannerlab.robots.base import Array
from plannerlab.robots.paths import densify, path_length, roughness

PLANNED_RGB = (31, 119, 180)
EXECUTED_RGB = (255, 127, 14)
SCENE_RGB = (165, 165, 170)
GOAL_RGB = (44, 160, 44)
CONTACT_RGB = (214, 39, 40)
#: opacity of the planned robot (the executed one is opaque: both stay visible)
PLANNED_OPACITY = 0.45
#: clearance at which the nearest link is drawn green [m]; red at 0
CLEAR_AT_M = 0.05
#: a goal ball or contact marker is drawn at least this big, to be seen [m]
MIN_MARK_M = 0.006
#: a link is drawn at least this thick (radius), as a fraction of the motion's size
MIN_LINK_SPAN = 0.006

#: ``clearance(q)``: per link, the smallest signed distance to the scene [m] (inf for a
#: link that is never checked) and the obstacle it is measured to
ClearanceFn = Callable[[Array], tuple[Array, Sequence[str]]]


# ----------------------------------------------------------------------- the frames
@dataclass(frozen=True, eq=False)
class LegMotion:
    """One leg's frames, as the viewer's timeline shows them.

    Attributes:
        leg, goal, status, verdict: the leg, its goal's name, the plan's status and (when
            executed) what the execution did, in words.
        t_s: (n,) time of each frame from the leg's start [s] (the execution's simulated
            time; the fraction of the path for a plan that was not executed).
        q_planned: (n, dof) the planned (commanded) state of each frame.
        q_executed: (n, dof) PyBullet's state at the same instant, or None.
        tips_planned, tips_executed: (m, 3) tip traces in the world [m] (None: not
            executed).
        contacts: the execution's contact records (empty when none or not executed).
        quality: the planned path's quality in words (:func:`path_quality`).
    """

    leg: int
    goal: str
    status: str
    verdict: str
    t_s: Array
    q_planned: Array
    q_executed: Array | None
    tips_planned: Array
    tips_executed: Array | None
    contacts: tuple[Any, ...] = ()
    quality: str = ""

    @property
    def frames(self) -> int:
        return len(self.t_s)


def _subsample(n: int, max_frames: int) -> np.ndarray:
    """At most ``max_frames`` indices spread over range(n), first and last included."""
    if n <= max_frames:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, max_frames).round().astype(int))


def _verdict(e: Any) -> str:
    ok = "executed cleanly" if e.success else "execution failed"
    parts = [ok]
    if np.isfinite(e.final_pos_err_m):
        parts.append(f"final tip error {e.final_pos_err_m * 1000:.1f} mm")
    if e.contacts:
        parts.append(f"{len(e.contacts)} contact pair(s)")
    if not e.success and e.reason:
        parts.append(e.reason)
    return ", ".join(parts)


def path_quality(problem: Problem, r: Any) -> str:
    """A leg's planned path in words, from its record: its joint-space length, its
    smoothness (roughness, :func:`~plannerlab.robots.paths.roughness`: lower is smoother;
    computed from the path when the record has none) and the smallest clearance along the
    whole path (``path_clearance_m``, measured when it was planned; "not measured" for a
    leg that did not solve, a contact plan, or a plan file written before it was)."""
    path = np.atleast_2d(np.asarray(r.path, dtype=float))
    cont = problem.robot.continuous
    rough = getattr(r, "roughness_rad2", math.nan)
    if not math.isfinite(rough):
        rough = roughness(path, cont)
    clear = getattr(r, "path_clearance_m", math.nan)
    clear_text = f"{clear * 1000:.1f} mm" if math.isfinite(clear) else "not measured"
    return (
        f"path: length {path_length(path, cont):.3g} rad, smoothness {rough_cell(rough)} rad² "
        f"(roughness, lower is smoother), clearance along the whole path {clear_text}"
    )


def leg_motions(
    problem: Problem, legs: Sequence[Any], executions: Sequence[Any] = (), max_frames: int = 300
) -> list[LegMotion]:
    """The timeline of every leg (see :class:`LegMotion`), at most ``max_frames`` + 1
    frames a leg (the tip traces keep every state)."""
    robot = problem.robot
    by_leg = {e.leg: e for e in executions}
    out = []
    for r in legs:
        path = np.atleast_2d(np.asarray(r.path, dtype=float))
        dense, _ = (
            densify(path, problem.joint_step, robot.continuous) if len(path) > 1 else (path, None)
        )
        e = by_leg.get(r.leg)
        if e is not None and len(e.q_cmd_rad):
            cmd = np.asarray(e.q_cmd_rad, dtype=float)
            act = np.asarray(e.q_actual_rad, dtype=float)
            t = np.asarray(e.t_s, dtype=float)
            idx = _subsample(len(cmd), max_frames)
            q_p = np.vstack([cmd[idx], dense[-1:]])
            q_e = np.vstack([act[idx], np.asarray(e.q_final_rad, dtype=float)[None]])
            t_end = float(e.sim_time_s) if np.isfinite(e.sim_time_s) else float(t[-1])
            t_s = np.append(t[idx], max(t_end, float(t[-1])))
            tips_e = np.vstack([np.atleast_2d(robot.tip(act)[0]), robot.tip(q_e[-1])[0][None]])
            out.append(
                LegMotion(
                    r.leg,
                    r.goal,
                    str(r.status),
                    _verdict(e),
                    t_s,
                    q_p,
                    q_e,
                    np.atleast_2d(robot.tip(dense)[0]),
                    tips_e,
                    tuple(e.contacts),
                    path_quality(problem, r),
                )
            )
        else:
            idx = _subsample(len(dense), max_frames)
            out.append(
                LegMotion(
                    r.leg,
                    r.goal,
                    str(r.status),
                    "not executed",
                    idx / max(len(dense) - 1, 1),
                    dense[idx],
                    None,
                    np.atleast_2d(robot.tip(dense)[0]),
                    None,
                    quality=path_quality(problem, r),
                )
            )
    return out


# -------------------------------------------------------------------- the geometry
def z_to_wxyz(d: Array) -> Array:
    """Unit quaternions (w, x, y, z) (n, 4) turning +z onto the directions d (n, 3)
    (a zero direction: identity)."""
    d = np.asarray(d, dtype=float).reshape(-1, 3)
    n = np.linalg.norm(d, axis=1, keepdims=True)
    u = np.where(n > 1e-12, d / np.where(n > 1e-12, n, 1.0), [[0.0, 0.0, 1.0]])
    q = np.stack([1.0 + u[:, 2], -u[:, 1], u[:, 0], np.zeros(len(u))], axis=1)
    flip = q[:, 0] < 1e-9  # d = -z: half a turn about x
    q[flip] = [0.0, 1.0, 0.0, 0.0]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def matrix_to_wxyz(R: Array) -> Array:
    """A rotation matrix (3, 3) as a unit quaternion (w, x, y, z)."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(np.asarray(R, dtype=float)).as_quat()
    return np.array([w, x, y, z])


@dataclass(frozen=True)
class CapsuleBatch:
    """A robot's capsules as instances of a unit cylinder (radius 1, height 1, axis z)
    and a unit sphere (two caps per link)."""

    cyl_positions: Array  # (L, 3) centres [m]
    cyl_wxyzs: Array  # (L, 4)
    cyl_scales: Array  # (L, 3) (r, r, length) [m]
    cap_positions: Array  # (2L, 3) [m]
    cap_scales: Array  # (2L,) radii [m]


def capsule_batch(segments: Array, radii_m: Array) -> CapsuleBatch:
    """Instances drawing the capsules with axes ``segments`` (L, 2, 3) and radii (L,)."""
    seg = np.asarray(segments, dtype=float)
    r = np.asarray(radii_m, dtype=float)
    a, b = seg[:, 0], seg[:, 1]
    length = np.linalg.norm(b - a, axis=1)
    return CapsuleBatch(
        cyl_positions=(a + b) / 2.0,
        cyl_wxyzs=z_to_wxyz(b - a),
        cyl_scales=np.stack([r, r, np.maximum(length, 1e-6)], axis=1),
        cap_positions=np.concatenate([a, b]),
        cap_scales=np.concatenate([r, r]),
    )


def obstacle_mesh(o: Any) -> tuple[Array, np.ndarray]:
    """An obstacle's surface as triangles in the world: vertices (V, 3) [m], faces (F, 3).

    Boxes, cylinders and spheres are made exactly (cylinders and spheres finely
    faceted); a mesh obstacle gives its own triangles (``vertices_m`` or ``vertices``
    and ``faces``, in its frame); any other shape is drawn as its world bounding box.
    """
    import trimesh

    T = np.asarray(o.T_world_obstacle, dtype=float)
    if isinstance(o, Box):
        m = trimesh.creation.box(extents=np.asarray(o.size_m, dtype=float))
    elif isinstance(o, Cylinder):
        m = trimesh.creation.cylinder(
            radius=float(o.radius_m), height=float(o.length_m), sections=48
        )
    elif isinstance(o, Sphere):
        m = trimesh.creation.icosphere(subdivisions=3, radius=float(o.radius_m))
    else:
        verts = getattr(o, "vertices_m", None)
        if verts is None:
            verts = getattr(o, "vertices", None)
        faces = getattr(o, "faces", None)
        if verts is not None and faces is not None:
            v = np.asarray(verts, dtype=float).reshape(-1, 3)
            return v @ T[:3, :3].T + T[:3, 3], np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        h = np.asarray(o.half_extents_world(), dtype=float)
        m = trimesh.creation.box(extents=2.0 * h)
        T = np.eye(4)
        T[:3, 3] = np.asarray(o.T_world_obstacle, dtype=float)[:3, 3]
    m.apply_transform(T)
    return np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64)


def cone_mesh(
    apex: Array, axis: Array, half_angle_deg: float, length_m: float
) -> tuple[Array, np.ndarray]:
    """An open cone (the tip normals a goal accepts): apex, unit axis, half angle, slant
    height. Vertices (V, 3) [m] and faces (F, 3)."""
    import trimesh

    a = math.radians(min(max(half_angle_deg, 0.5), 89.0))
    h = length_m * math.cos(a)
    m = trimesh.creation.cone(radius=length_m * math.sin(a), height=h, sections=32)
    # trimesh's cone: base at z = 0, apex at z = h; turn it so the apex is at 0 and the
    # base at +h along the axis
    v = np.asarray(m.vertices, dtype=float)
    v[:, 2] = h - v[:, 2]
    w, x, y, z = z_to_wxyz(np.asarray(axis, dtype=float)[None])[0]
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    faces = np.asarray(m.faces, dtype=np.int64)[:, ::-1]
    return v @ R.T + np.asarray(apex, dtype=float), faces


def clearance_rgb(d_m: float) -> tuple[int, int, int]:
    """Red (touching or penetrating) through yellow to green (``CLEAR_AT_M`` or more)."""
    from matplotlib import colormaps

    if not np.isfinite(d_m):
        return (120, 120, 120)
    c = colormaps["RdYlGn"](float(np.clip(d_m / CLEAR_AT_M, 0.0, 1.0)))
    return (int(255 * c[0]), int(255 * c[1]), int(255 * c[2]))


def hex_colour(rgb: Sequence[int]) -> str:
    return "#" + "".join(f"{int(c):02x}" for c in rgb)


def port_free(host: str, port: int) -> bool:
    """True when ``host:port`` can be bound now."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        # as asyncio's server binds (SO_REUSEADDR): a port in TIME_WAIT is free
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError:
            return False
    return True


# ------------------------------------------------------------------ URDF meshes
def urdf_with_meshes(robot: Any, mesh_dirs: Sequence[Path]) -> tuple[Any | None, str]:
    """A URDF robot's model with its visual meshes loaded (yourdfpy), or None and why
    not (no URDF, no visual meshes, or a mesh file not found beside the URDF nor in
    ``mesh_dirs``)."""
    path = getattr(robot, "urdf_path", None)
    if path is None:
        return None, ""
    import xml.etree.ElementTree as ET

    import yourdfpy

    path = Path(path)
    names = [
        m.get("filename", "")
        for v in ET.parse(path).getroot().iter("visual")
        for m in v.iter("mesh")
    ]
    if not names:
        return None, ""
    roots = [path.parent, *map(Path, mesh_dirs)]

    def find(fname: str) -> Path | None:
        rel = fname.split("://", 1)[-1]
        parts = Path(rel).parts
        for root in roots:
            for k in range(len(parts)):  # package://pkg/meshes/x.obj: try shorter tails too
                p = root.joinpath(*parts[k:])
                if p.is_file():
                    return p
        return None

    missing = [n for n in names if find(n) is None]
    if missing:
        where = ", ".join(str(r) for r in roots)
        return None, (
            f"{len(missing)} of {len(names)} visual meshes not found in {where} "
            f"(e.g. {missing[0]}): drawn as the collision geometry"
        )

    def handler(fname: str, dir: str = "") -> str:  # noqa: A002 - yourdfpy's keyword
        p = find(fname)
        return str(p) if p is not None else fname

    import logging

    log = logging.getLogger("yourdfpy")
    level = log.level
    log.setLevel(logging.ERROR)  # not a warning per mimic joint off the chain
    try:
        model = yourdfpy.URDF.load(
            str(path),
            build_scene_graph=True,
            load_meshes=True,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
            filename_handler=handler,
        )
    finally:
        log.setLevel(level)
    return model, ""


def urdf_cfg(robot: Any, model: Any, q: Array) -> Array:
    """yourdfpy's configuration (its actuated joints) for the robot's state q."""
    index = {n: i for i, n in enumerate(robot.joint_names)}
    frozen = getattr(robot, "frozen_joints", {})
    return np.array(
        [
            float(q[index[n]]) if n in index else float(frozen.get(n, 0.0))
            for n in model.actuated_joint_names
        ]
    )


# --------------------------------------------------------------------- helpers
def polyline_segments(points: Array) -> Array:
    """Consecutive point pairs (n - 1, 2, 3) of a polyline (n, 3) (one point: a dot)."""
    p = np.atleast_2d(np.asarray(points, dtype=float))
    if len(p) < 2:
        p = np.vstack([p, p])
    return np.stack([p[:-1], p[1:]], axis=1)


def motion_span(problem: Problem, legs: Sequence[LegMotion]) -> float:
    """The size of what is shown [m]: the diagonal of the tip traces and goals."""
    pts = [m.tips_planned for m in legs] + [np.array([g.p_world_m for g in problem.goals])]
    pts += [np.asarray(problem.robot.link_segments(legs[0].q_planned[0])).reshape(-1, 3)]
    p = np.concatenate(pts)
    return max(float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))), 0.1)


def unit_cylinder() -> tuple[Array, Array]:
    import trimesh

    m = trimesh.creation.cylinder(radius=1.0, height=1.0, sections=24)
    return np.asarray(m.vertices, dtype=np.float32), np.asarray(m.faces, dtype=np.uint32)


def unit_sphere() -> tuple[Array, Array]:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    return np.asarray(m.vertices, dtype=np.float32), np.asarray(m.faces, dtype=np.uint32)


def _segment_hits_boxes(p0: Array, p1: Array, lo: Array, hi: Array) -> np.ndarray:
    """Which axis-aligned boxes (n, 3) the segment p0-p1 passes through (slab test)."""
    d = p1 - p0
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (lo - p0) / d
        t1 = (hi - p0) / d
    t_near = np.nanmax(np.where(np.isfinite(t0), np.minimum(t0, t1), -np.inf), axis=1)
    t_far = np.nanmin(np.where(np.isfinite(t1), np.maximum(t0, t1), np.inf), axis=1)
    inside = np.all((p0 >= lo) & (p0 <= hi) | (d != 0), axis=1)  # parallel slabs
    return inside & (t_near <= t_far) & (t_far >= 0.0) & (t_near <= 1.0)


def camera_pose(problem: Problem, legs: Sequence[LegMotion]) -> tuple[Array, Array]:
    """A camera position and look-at point [m] that frame the motion and the goals, from
    the side (of eight, 35 degrees up) whose line of sight crosses the fewest obstacles
    (those around the look-at point left out: every side crosses them)."""
    pts = [m.tips_planned for m in legs] + [np.array([g.p_world_m for g in problem.goals])]
    pts += [np.asarray(problem.robot.link_segments(legs[0].q_planned[0])).reshape(-1, 3)]
    p = np.concatenate(pts)
    lo, hi = p.min(axis=0), p.max(axis=0)
    centre = (lo + hi) / 2.0
    span = max(float(np.linalg.norm(hi - lo)), 0.2)
    olo, ohi = problem.scene.aabbs()
    keep = ~np.all((centre >= olo) & (centre <= ohi), axis=1)
    olo, ohi = olo[keep], ohi[keep]
    best, best_hits = None, None
    for k in range(8):  # from the default side (-51 degrees) round
        az = math.radians(-51.0 + 45.0 * k)
        el = math.radians(35.0)
        direction = np.array(
            [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]
        )
        eye = centre + 1.45 * span * direction
        hits = int(np.sum(_segment_hits_boxes(eye, centre, olo, ohi))) if len(olo) else 0
        if best_hits is None or hits < best_hits:
            best, best_hits = eye, hits
    assert best is not None
    return best, centre


__all__ = [
    "CapsuleBatch",
    "ClearanceFn",
    "LegMotion",
    "camera_pose",
    "capsule_batch",
    "clearance_rgb",
    "path_quality",
    "cone_mesh",
    "leg_motions",
    "matrix_to_wxyz",
    "obstacle_mesh",
    "port_free",
    "urdf_cfg",
    "urdf_with_meshes",
    "z_to_wxyz",
]

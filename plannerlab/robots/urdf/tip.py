"""The default tip of a URDF arm (:func:`default_tip_link`): the tool centre where the
URDF names one, else the hand, never a gripper's jaw.

Three steps, each from the URDF's own structure and geometry (no link names):

1. **The end of the arm.** From the root, down the one child whose subtree holds the most
   movable joints, stopping where two children each hold movable joints (a gripper's
   fingers: the hand is where they branch) or none does.
2. **A single moving jaw is not the arm.** A gripper with one moving jaw closing against a
   jaw fixed on the hand (Unitree's Z1, the SO-100/101, TALOS's gripper) is one movable
   child, so step 1 walks into it. The end link is taken to be such a jaw, and the hand
   (its parent) is the end instead, when its revolute joint is a *pivot* and the hand holds
   a *counterpart*:

   * pivot: the centroid of the link's collision hull lies off the joint's axis by more
     than :data:`PIVOT_OFF_AXIS` of the hull's largest distance from the axis (a wrist's or
     flange's roll joint turns a body centred on its axis: 0.00-0.05 on the UR10, the
     iiwa, the xArm6 and the Jaco; a jaw swings a lever: 0.27-0.33 on the Z1, the
     SO-100/101 and TALOS);
   * counterpart: along the jaw's direction from the axis (the centroid's, perpendicular
     to the axis, with the jaw at the value off-chain joints are frozen at), the hand's
     geometry reaches out at least :data:`COUNTERPART_REACH` of as far as the jaw's. The
     last link of a plain chain (a pendulum, a planar arm) also swings a lever, but the
     link before it ends at the pivot: no counterpart, so it stays the end.

3. **The tool centre.** Among the links hung on the end link by fixed joints only, the
   frames (links without collision or visual geometry: ``tool0``, ``panda_hand_tcp``,
   ``gripper_frame_link``, ...), the one farthest from the end link's origin is the tip;
   none: the end link itself. Where movable joints hang on below the end link (a hand's
   fingers, a jaw, a torso's limbs) only frames on the axis of the chain's last movable
   joint count (off it by at most :data:`TOOL_OFF_AXIS` of their distance along it): a
   tool frame is on the wrist's roll axis, a sensor's (an IMU, a camera) need not be.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array

MOVABLE = ("revolute", "continuous", "prismatic")
#: a revolute leaf is a pivot (a lever, not a roll) when its hull's centroid is off the
#: axis by more than this share of the hull's largest distance from the axis
PIVOT_OFF_AXIS = 0.15
#: the hand holds a counterpart jaw when it reaches along the jaw's direction at least
#: this share of the jaw's own reach from the axis
COUNTERPART_REACH = 0.5
#: a tool frame lies on the last movable joint's axis: off it by at most this share of
#: its distance along it (from the end link's origin)
TOOL_OFF_AXIS = 0.25


def _rpy(r: float, p: float, y: float) -> Array:
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _origin(elem: Any) -> Array:
    """The 4x4 pose of an element's ``<origin>`` (identity when absent or unreadable: a
    xacro expression left in the file)."""
    T = np.eye(4)
    o = None if elem is None else elem.find("origin")
    if o is not None:
        try:
            T[:3, 3] = [float(v) for v in (o.get("xyz") or "0 0 0").split()]
            T[:3, :3] = _rpy(*[float(v) for v in (o.get("rpy") or "0 0 0").split()])
        except ValueError:
            return np.eye(4)
    return T


def _floats(text: str | None, default: str) -> Array:
    return np.array([float(v) for v in (text or default).split()], dtype=float)


def _geometry_points(link: Any, urdf: Path, mesh_paths: tuple[Path, ...]) -> Array | None:
    """Points of a link's collision geometry (its visual geometry when it has none), in
    the link's frame: mesh vertices, box corners, cylinder rims, sphere extremes. None
    when it has no geometry or a mesh cannot be read."""
    from plannerlab.robots.urdf.meshes import load_mesh, resolve_mesh

    for tag in ("collision", "visual"):
        parts = []
        for g in link.findall(tag):
            geo = g.find("geometry")
            if geo is None or len(geo) == 0:
                continue
            shape = geo[0]
            where = f"link {link.get('name')} of {urdf.name}"
            if shape.tag == "mesh":
                try:
                    file = resolve_mesh(shape.get("filename", ""), urdf, mesh_paths, where)
                    V, _ = load_mesh(file, _floats(shape.get("scale"), "1 1 1"), where)
                except PlannerlabError:
                    return None
            elif shape.tag == "box":
                h = _floats(shape.get("size"), "0 0 0") / 2
                V = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
                V = V * h
            elif shape.tag == "cylinder":
                r, half = float(shape.get("radius", 0)), float(shape.get("length", 0)) / 2
                t = np.linspace(0, 2 * np.pi, 16, endpoint=False)
                ring = np.c_[r * np.cos(t), r * np.sin(t)]
                V = np.vstack([np.c_[ring, np.full(16, z)] for z in (-half, half)])
            elif shape.tag == "sphere":
                V = float(shape.get("radius", 0)) * np.vstack([np.eye(3), -np.eye(3)])
            else:
                continue
            T = _origin(g)
            parts.append(V @ T[:3, :3].T + T[:3, 3])
        if parts:
            return np.vstack(parts)
    return None


def _hull_centroid(P: Array) -> Array:
    """The centroid of the points' convex hull (the points' mean when it is flat)."""
    import trimesh

    try:
        hull = trimesh.Trimesh(P, process=False).convex_hull
        if hull.volume > 0:
            return np.asarray(hull.center_mass, dtype=float)
    except Exception:  # a degenerate hull (flat or too few points): scipy's QhullError
        pass
    return np.asarray(P.mean(axis=0), dtype=float)


def _is_jaw(root: Any, jaw: str, joint: Any, urdf: Path, mesh_paths: tuple[Path, ...]) -> bool:
    """Is the movable leaf ``jaw`` a single moving jaw on its parent (module docstring)?"""
    if joint.get("type") not in ("revolute", "continuous"):
        return False
    links = {e.get("name", ""): e for e in root.findall("link")}
    P_jaw = _geometry_points(links[jaw], urdf, mesh_paths)
    if P_jaw is None:
        return False
    axis = _floats(
        joint.find("axis").get("xyz") if joint.find("axis") is not None else None, "1 0 0"
    )
    axis = axis / np.linalg.norm(axis)
    # the jaw at the value an off-chain joint is frozen at (0, clipped into its limits)
    lim = joint.find("limit")
    lo = float(lim.get("lower", 0)) if lim is not None else 0.0
    hi = float(lim.get("upper", 0)) if lim is not None else 0.0
    q = float(np.clip(0.0, lo, hi)) if joint.get("type") == "revolute" else 0.0
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R_q = np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * (K @ K)
    P_jaw = P_jaw @ R_q.T  # in the joint's frame
    c = _hull_centroid(P_jaw)
    u = c - (c @ axis) * axis
    r_max = float(np.max(np.linalg.norm(P_jaw - np.outer(P_jaw @ axis, axis), axis=1)))
    if r_max <= 0 or np.linalg.norm(u) <= PIVOT_OFF_AXIS * r_max:
        return False
    u = u / np.linalg.norm(u)
    # the hand: the parent and what is fixed to it (the jaw excluded), in the joint's frame
    parent = joint.find("parent").get("link")
    T_joint_parent = np.linalg.inv(_origin(joint))
    hand = []
    stack = [(parent, T_joint_parent)]
    fixed_kids: dict[str, list[tuple[str, Any]]] = {}
    for j in root.findall("joint"):
        if j.get("type") == "fixed":
            fixed_kids.setdefault(j.find("parent").get("link"), []).append(
                (j.find("child").get("link"), j)
            )
    while stack:
        name, T = stack.pop()
        P = _geometry_points(links[name], urdf, mesh_paths) if name in links else None
        if P is not None:
            hand.append(P @ T[:3, :3].T + T[:3, 3])
        stack += [(c, T @ _origin(j)) for c, j in fixed_kids.get(name, []) if c != jaw]
    if not hand:
        return False
    reach_jaw = float(np.max(P_jaw @ u))
    reach_hand = float(np.max(np.vstack(hand) @ u))
    return reach_hand >= COUNTERPART_REACH * reach_jaw


def _tool_frame(root: Any, end: str, chain_end: bool) -> str:
    """The farthest geometry-free link hung on ``end`` by fixed joints, else ``end``;
    unless ``chain_end`` (no movable joint below ``end``), only frames on the axis of the
    chain's last movable joint (off it by at most :data:`TOOL_OFF_AXIS` of their distance
    along it): where the chain branches on (a hand's fingers, a torso's limbs), a tool
    frame is on the wrist's axis, a sensor's frame (an IMU's, a camera's) need not be."""
    links = {e.get("name", ""): e for e in root.findall("link")}
    kids: dict[str, list[tuple[str, Any]]] = {}
    joint_of: dict[str, Any] = {}
    for j in root.findall("joint"):
        p, c = j.find("parent"), j.find("child")
        if p is None or c is None:
            continue
        joint_of[c.get("link", "")] = j
        if j.get("type") == "fixed":
            kids.setdefault(p.get("link", ""), []).append((c.get("link", ""), j))
    # the end link in the frame of the chain's last movable joint
    T_joint_end, name = np.eye(4), end
    while name in joint_of and joint_of[name].get("type") not in MOVABLE:
        T_joint_end = _origin(joint_of[name]) @ T_joint_end
        name = joint_of[name].find("parent").get("link", "")
    last = joint_of.get(name)
    if last is None:  # no movable joint above: not an arm's end
        return end
    ax = last.find("axis")
    axis = _floats(ax.get("xyz") if ax is not None else None, "1 0 0")
    axis = axis / np.linalg.norm(axis)
    best, best_d = end, 0.0
    stack = [(end, T_joint_end)]
    while stack:
        name, T = stack.pop(0)
        for child, j in kids.get(name, []):
            T_c = T @ _origin(j)
            link = links.get(child)
            frame = (
                link is not None and link.find("collision") is None and link.find("visual") is None
            )
            p = T_c[:3, 3] - T_joint_end[:3, 3]
            along = abs(float(p @ axis))
            off = float(np.linalg.norm(p - (p @ axis) * axis))
            d = float(np.linalg.norm(p))
            if frame and (chain_end or off <= TOOL_OFF_AXIS * along) and d > best_d + 1e-9:
                best, best_d = child, d
            stack.append((child, T_c))
    return best


def default_tip_link(urdf: Path, mesh_paths: tuple[Path, ...] = ()) -> str:
    """The arm's tip link: the tool centre frame where the URDF has one, else the hand
    (module docstring). ``mesh_paths``: folders searched for ``package://`` meshes (the
    jaw test reads two links' geometry; a mesh not found: the link is not taken for a
    jaw).

    Raises:
        PlannerlabError: the file is not a readable URDF, or has no movable joint.
    """
    urdf = Path(urdf)
    try:
        root = ET.parse(urdf).getroot()
    except (OSError, ET.ParseError) as exc:
        raise PlannerlabError(f"{urdf}: expected a readable URDF (XML): {exc}") from None
    links = [e.get("name", "") for e in root.findall("link")]
    if not links:
        raise PlannerlabError(f"{urdf}: expected a URDF with links; it has none")
    children: dict[str, list[tuple[str, bool]]] = {n: [] for n in links}
    joint_of: dict[str, Any] = {}
    has_parent = set()
    for j in root.findall("joint"):
        p, c = j.find("parent"), j.find("child")
        if p is not None and c is not None and p.get("link") in children:
            children[p.get("link", "")].append((c.get("link", ""), j.get("type") in MOVABLE))
            has_parent.add(c.get("link", ""))
            joint_of[c.get("link", "")] = j
    memo: dict[str, int] = {}

    def movable_below(link: str, seen: frozenset[str] = frozenset()) -> int:
        if link not in memo:
            memo[link] = sum(
                int(m) + movable_below(c, seen | {link})
                for c, m in children.get(link, [])
                if c not in seen
            )
        return memo[link]

    tops = [n for n in links if n not in has_parent]
    link = max(tops, key=movable_below)
    if movable_below(link) == 0:
        raise PlannerlabError(f"{urdf}: expected movable joints; it has none")
    while True:
        held = [(c, int(m) + movable_below(c)) for c, m in children.get(link, [])]
        moving = [h for h in held if h[1] > 0]
        if len(moving) != 1:
            break
        link = moving[0][0]
    end_joint = joint_of.get(link)
    parent = None if end_joint is None else end_joint.find("parent")
    if (
        end_joint is not None
        and parent is not None
        and end_joint.get("type") in MOVABLE
        and not children.get(link)
        and _is_jaw(root, link, end_joint, urdf, tuple(Path(p) for p in mesh_paths))
    ):
        link = parent.get("link", "")
    return _tool_frame(root, link, movable_below(link) == 0)


__all__ = ["COUNTERPART_REACH", "PIVOT_OFF_AXIS", "TOOL_OFF_AXIS", "default_tip_link"]

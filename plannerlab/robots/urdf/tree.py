"""A URDF's kinematic tree from its root link to the tip: parsing (``yourdfpy``), the
movable joints' axes and limits, and where each URDF link sits on the chain's bodies.
The part of :mod:`plannerlab.robots.urdf.model` that knows the URDF's joints, not its
geometry; :mod:`plannerlab.robots.urdf.link_meshes` reads it too."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.robots.base import Array
from plannerlab.robots.urdf.errors import UrdfError, hint

MOVABLE = ("revolute", "continuous", "prismatic")


def axis_motion(axis: Array, q: Array, prismatic: bool) -> Array:
    """Joint motions (..., 4, 4) for values q (...,) about/along a unit axis (3,)."""
    q = np.asarray(q, dtype=float)
    T = np.broadcast_to(np.eye(4), q.shape + (4, 4)).copy()
    if prismatic:
        T[..., :3, 3] = q[..., None] * axis
        return T
    x, y, z = axis
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    s = np.sin(q)[..., None, None]
    c = np.cos(q)[..., None, None]
    T[..., :3, :3] = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    return T


def _joint_axis(j: Any) -> Array:
    """A URDF joint's unit axis (x when none is given)."""
    a = np.array([1.0, 0.0, 0.0] if j.axis is None else j.axis, dtype=float)
    n = float(np.linalg.norm(a))
    if n < 1e-12:
        raise UrdfError("urdf", f"a non-zero axis on joint {j.name}")
    return a / n


def _joint_limits(j: Any) -> tuple[float, float]:
    """A URDF joint's limits (a continuous joint's: one turn)."""
    if j.type == "continuous":
        return (-math.pi, math.pi)
    lim = j.limit
    if lim is None or lim.lower is None or lim.upper is None:
        raise UrdfError("urdf", f"lower and upper limits on joint {j.name} ({j.type})")
    lo, hi = float(lim.lower), float(lim.upper)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
        raise UrdfError("urdf", f"limits lower <= upper on joint {j.name}, got {lo}, {hi}")
    return lo, hi


def _origin(x: Any) -> Array:
    return np.eye(4) if x.origin is None else np.asarray(x.origin, dtype=float)


def _load_urdf(path: Path) -> Any:
    """The parsed URDF (``yourdfpy``'s ``Robot``: links and joints, no meshes)."""
    import yourdfpy

    if not path.is_file():
        raise UrdfError("urdf", f"an existing URDF file; {path} does not exist")
    try:  # yourdfpy would recover from broken XML and read part of it
        ET.parse(path)
    except ET.ParseError as exc:
        raise UrdfError("urdf", f"a well-formed URDF (XML); {path}: {exc}") from None
    try:
        model = yourdfpy.URDF.load(
            str(path),
            build_scene_graph=False,
            build_collision_scene_graph=False,
            load_meshes=False,
            load_collision_meshes=False,
        )
    except Exception as exc:  # yourdfpy raises many kinds for a malformed file
        raise UrdfError("urdf", f"a valid URDF; {path}: {exc}") from None
    return model.robot


@dataclass(frozen=True)
class _Tree:
    """A URDF's links by name, each link's joint to its parent, the root link, the
    movable joints from the root to the tip link in order, and the movable joints off
    that chain with the value each is frozen at."""

    links: dict[str, Any]
    joint_of_child: dict[str, Any]
    root: str
    movable: list[Any]
    frozen: dict[str, float]


def _chain(urdf: Any, tip_link: str, path: Path) -> _Tree:
    """The chain from the URDF's root link to ``tip_link``, its joints checked."""
    links = {link.name: link for link in urdf.links}
    joint_of_child = {j.child: j for j in urdf.joints}
    children = set(joint_of_child)
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise UrdfError("urdf", f"a URDF tree with one root link; {path} has {roots}")
    root = roots[0]
    if tip_link not in links:
        raise UrdfError(
            "tip_link",
            f"a link of {path.name}, got {tip_link!r}{hint(tip_link, list(links))}; "
            f"its links: {', '.join(links)}",
        )
    # the chain: root -> tip
    chain: list[Any] = []
    name = tip_link
    while name != root:
        j = joint_of_child[name]
        chain.append(j)
        name = j.parent
    chain.reverse()
    for j in chain:
        if j.type not in MOVABLE + ("fixed",):
            raise UrdfError(
                "urdf", f"revolute, continuous, prismatic or fixed joints; {j.name} is {j.type}"
            )
        if j.type in MOVABLE and j.mimic is not None:
            raise UrdfError("urdf", f"no mimic joint on the chain; {j.name} mimics one")
    movable = [j for j in chain if j.type in MOVABLE]
    chain_names = {j.name for j in movable}
    frozen: dict[str, float] = {}
    for j in urdf.joints:
        if j.type in MOVABLE and j.name not in chain_names:
            lo, hi = _joint_limits(j)
            frozen[j.name] = float(np.clip(0.0, lo, hi))
        elif j.type not in MOVABLE + ("fixed",):
            raise UrdfError(
                "urdf", f"revolute, continuous, prismatic or fixed joints; {j.name} is {j.type}"
            )
    return _Tree(links, joint_of_child, root, movable, frozen)


def _place_links(tree: _Tree) -> dict[str, tuple[int, Array]]:
    """Every link's body and its pose on that body: (body, T_body_link) by link name."""
    body_of_joint = {j.name: i + 1 for i, j in enumerate(tree.movable)}
    placed: dict[str, tuple[int, Array]] = {tree.root: (0, np.eye(4))}

    def place(link: str) -> tuple[int, Array]:
        if link in placed:
            return placed[link]
        j = tree.joint_of_child[link]
        origin = _origin(j)
        if j.name in body_of_joint:
            out = (body_of_joint[j.name], np.eye(4))
        else:
            b, T = place(j.parent)
            T = T @ origin
            if j.name in tree.frozen:
                T = T @ axis_motion(
                    _joint_axis(j), np.asarray(tree.frozen[j.name]), j.type == "prismatic"
                )
            out = (b, T)
        placed[link] = out
        return out

    for link in tree.links:
        place(link)
    return placed

"""Self-collision pairs a robot never needs checked, computed as MoveIt's set-up assistant
does, and written to an SRDF the user can keep.

:func:`disabled_pairs` samples the robot's joint space (a seeded generator) and checks
link pair by link pair, at the URDF link level, on the links' **real geometry**
(``geometry="hulls"``, the default: each link's collision meshes as their convex hulls,
as PyBullet checks them, and so execution and the referee, and its primitives; python-fcl's
exact test; ``"meshes"``: the meshes' own triangles, as MoveIt does) or on the capsules and
covers plannerlab plans with (``geometry="covers"``: a pair that only the covers' excess
brings together is then kept checked):

* ``Adjacent``: links on one body or on adjacent bodies (parent and child of a movable
  joint, or joined through bodies without collision geometry, as MoveIt counts them:
  :func:`~plannerlab.robots.urdf.pairs.adjacent_bodies`) -- plannerlab never checks
  them anyway;
* ``Default``: in collision at the default state (every joint at 0, clipped into its
  limits);
* ``Always``: in collision in every sampled state;
* ``Never``: in collision in none of the sampled states (MoveIt disables these too: a
  pair that never met in ``n_states`` random states is taken as unable to meet; pass
  ``never=False`` to keep them checked).

:func:`write_srdf` writes ``<disable_collisions link1= link2= reason=>`` elements, the
file ``[robot] srdf`` reads. The URDF's own ``[robot] srdf`` and ``allowed_collisions``
are ignored here: the chain is rebuilt without them.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from plannerlab.collision.fcl_checker import colliding_link_pairs
from plannerlab.robots.urdf.model import UrdfChain
from plannerlab.robots.urdf.pairs import adjacent_bodies


@dataclass(frozen=True)
class DisabledPair:
    """A URDF link pair not to check, and why (``Adjacent``, ``Default``, ``Always``,
    ``Never``)."""

    link1: str
    link2: str
    reason: str


def disabled_pairs(
    robot: UrdfChain,
    rng: np.random.Generator,
    n_states: int = 2000,
    never: bool = True,
    geometry: str = "hulls",
) -> list[DisabledPair]:
    """The link pairs of ``robot``'s URDF that need no self-collision check (module
    docstring), sorted by reason then names.

    Args:
        robot: the chain (its SRDF and allowed pairs are not used).
        rng: the generator drawing the random states.
        n_states: random states sampled (MoveIt's default density is 10 000).
        never: also list the pairs never in collision.
        geometry: ``"hulls"``, ``"meshes"`` (the links' real geometry) or ``"covers"``
            (module docstring).
    """
    if geometry not in ("hulls", "meshes", "covers"):
        raise ValueError(f"geometry: 'hulls', 'meshes' or 'covers', got {geometry!r}")
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene

    bare = replace(robot, srdf_path=None, allowed_collisions=())
    urdf_of = dict(zip(bare.link_names, bare.link_urdf_names, strict=True))
    body = {bare.link_urdf_names[i]: int(bare._cap_body[i]) for i in range(len(bare.link_names))}
    parent = [int(p) for p in bare._parent_body]
    neighbours = adjacent_bodies(parent, body.values())
    links = sorted(set(bare.link_urdf_names))
    out: dict[frozenset[str], str] = {}
    for i, a in enumerate(links):
        for b in links[i + 1 :]:
            if body[a] == body[b] or frozenset((body[a], body[b])) in neighbours:
                out[frozenset((a, b))] = "Adjacent"
    if geometry != "covers":
        colliding = colliding_link_pairs(bare, out, geometry == "hulls")
    else:
        checker = CollisionChecker(bare, Scene(), backend="core")  # type: ignore[arg-type]

        def colliding(q: np.ndarray) -> set[frozenset[str]]:
            found = set()
            for x, y in checker.colliding_pairs(q):
                la, lb = urdf_of[x], urdf_of.get(y)
                if lb is not None and la != lb:
                    found.add(frozenset((la, lb)))
            return found

    q0 = np.clip(np.zeros(bare.dof), bare.lower, bare.upper)
    for p in colliding(q0):
        out.setdefault(p, "Default")
    counts: dict[frozenset[str], int] = {}
    lo, hi = np.asarray(bare.lower), np.asarray(bare.upper)
    for _ in range(int(n_states)):
        for p in colliding(lo + rng.random(bare.dof) * (hi - lo)):
            counts[p] = counts.get(p, 0) + 1
    for p, k in counts.items():
        if k == n_states:
            out.setdefault(p, "Always")
    if never:
        for i, a in enumerate(links):
            for b in links[i + 1 :]:
                p = frozenset((a, b))
                if p not in out and p not in counts:
                    out[p] = "Never"
    order = {"Adjacent": 0, "Default": 1, "Always": 2, "Never": 3}
    pairs = [DisabledPair(*sorted(p), reason) for p, reason in out.items()]  # type: ignore[call-arg]
    return sorted(pairs, key=lambda d: (order[d.reason], d.link1, d.link2))


def write_srdf(pairs: list[DisabledPair], path: Path, robot_name: str) -> None:
    """An SRDF holding the pairs as ``<disable_collisions>`` elements."""
    root = ET.Element("robot", name=robot_name)
    root.append(ET.Comment(" written by plannerlab.run.srdf.disabled_pairs (seeded sampling) "))
    for d in pairs:
        ET.SubElement(root, "disable_collisions", link1=d.link1, link2=d.link2, reason=d.reason)
    ET.indent(root)
    Path(path).write_text(ET.tostring(root, encoding="unicode") + "\n", encoding="utf-8")


def srdf_for(
    urdf_path: Path,
    tip_link: str,
    out_path: Path,
    *,
    seed: int = 0,
    n_states: int = 2000,
    never: bool = True,
    **chain_args: object,
) -> list[DisabledPair]:
    """Compute the disabled pairs of a URDF's chain to ``tip_link`` and write the SRDF
    (the function a CLI command calls). ``chain_args`` go to :class:`UrdfChain`
    (``mesh_paths``, ``cover_excess_m``, ...)."""
    robot = UrdfChain(Path(urdf_path), tip_link, **chain_args)  # type: ignore[arg-type]
    pairs = disabled_pairs(robot, np.random.default_rng(seed), n_states, never)
    name = ET.parse(urdf_path).getroot().get("name", "robot")
    write_srdf(pairs, Path(out_path), name)
    return pairs


__all__ = ["DisabledPair", "disabled_pairs", "srdf_for", "write_srdf"]

"""Self-collision pairs a URDF chain never checks: an SRDF's ``<disable_collisions>``,
the problem's allowed pairs, capsules on one body or on neighbouring bodies."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from plannerlab.robots.urdf.errors import UrdfError, hint


def read_srdf_disabled(path: Path) -> list[tuple[str, str]]:
    """The ``<disable_collisions link1= link2=>`` pairs of an SRDF file."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise UrdfError("srdf", f"a readable SRDF (XML) file; {path}: {exc}") from None
    return [(str(e.get("link1")), str(e.get("link2"))) for e in root.iter("disable_collisions")]


def adjacent_bodies(
    parent_body: Sequence[int], with_geometry: Iterable[int]
) -> set[frozenset[int]]:
    """Body pairs that are adjacent as MoveIt's set-up assistant counts them: parent and
    child of a movable joint (body ``i + 1`` hangs from ``parent_body[i]``), or joined
    through bodies without collision geometry (its "adjacent with no geometry links
    between them"). A body with no geometry of its own (a Unitree Z1's ``link01``: a
    bare joint housing) would otherwise leave its two neighbours, built to overlap at
    the joint, checked against each other, and in collision in every state.
    """
    n = len(parent_body) + 1
    links: dict[int, set[int]] = {b: set() for b in range(n)}
    for i, p in enumerate(parent_body):
        links[int(p)].add(i + 1)
        links[i + 1].add(int(p))
    solid = set(int(b) for b in with_geometry)
    out: set[frozenset[int]] = set()
    for b in range(n):
        seen, stack = {b}, [b]
        while stack:  # b's neighbours, and on through the bare ones
            for c in links[stack.pop()]:
                if c not in seen:
                    seen.add(c)
                    out.add(frozenset((b, c)))
                    if c not in solid:
                        stack.append(c)
    return out


def excluded_pairs(
    caps: Any,
    parent_body: list[int],
    links: dict[str, Any],
    srdf_path: Path | None,
    allowed_collisions: tuple[tuple[str, str], ...],
    path: Path,
) -> set[tuple[int, int]]:
    """Capsule pairs never checked (``caps``: the chain's capsules, their URDF links and
    bodies): on one body, on adjacent bodies (:func:`adjacent_bodies`), or of links the
    SRDF or the problem's allowed-collision pairs name."""
    disabled: set[frozenset[str]] = set()
    if srdf_path is not None:
        for l1, l2 in read_srdf_disabled(Path(srdf_path)):
            disabled.add(frozenset((l1, l2)))
    for l1, l2 in allowed_collisions:
        for n in (l1, l2):
            if n not in links:
                raise UrdfError(
                    "allowed_collisions",
                    f"pairs of links of {path.name}; {n!r} is not one{hint(n, list(links))}",
                )
        disabled.add(frozenset((l1, l2)))
    neighbours = adjacent_bodies(parent_body, caps.body)
    excluded = set()
    L = len(caps.names)
    for i in range(L):
        for j2 in range(i + 1, L):
            bi, bj = caps.body[i], caps.body[j2]
            if (
                bi == bj
                or frozenset((bi, bj)) in neighbours
                or frozenset((caps.link[i], caps.link[j2])) in disabled
            ):
                excluded.add((i, j2))
    return excluded


__all__ = ["adjacent_bodies", "excluded_pairs", "read_srdf_disabled"]

"""Rooms of more kinds for :mod:`plannerlab.problem.variants` (issue 33, item 2): windows on
other walls (a side wall, the ceiling) and at other heights, rooms with two windows, rooms
8-10 m deep, and visits in reversed and shuffled orders.

The paper's room has one window in its near wall (the wall facing the arm's base); the
kinds of this module keep the paper's room, its goals placed relative to the walls
(``docs/papers.md`` §1) and its arm, and change what the arm must get through:

- ``side``: the near wall is closed; the window is in the side wall that faces the base
  (the room stands beside the base, its right wall 1.55-2.55 m to the left of it before
  mirroring): the arm reaches forward past the room's corner and turns into the room.
  A-E are placed as in the paper with the window's wall as the near wall (the paper's
  frame turned about z): placed in the world's frame, D and E would look back at the
  wall the arm comes in through, a U-turn no witness was found for (3 of 4 draws dropped
  at D).
- ``roof``: the near wall is closed; the window is in the ceiling near the near wall: the
  arm reaches over the near wall and comes down into the room. Not witnessed yet: the
  clearance-aware IK stalls with the body against the window's edge when the tip, hung
  down through the ceiling, is led 5-8 m sideways to A or B (0 of 8 draws kept); no
  committed variant is of this kind.
- ``heights``: the near wall's window sits low (its sill 0.2-0.6 m above the floor) or
  high (its lintel 0.2-0.6 m below the ceiling); A-E visited in reverse.
- ``two_windows``: the near wall's window as in the paper, and a second one in a side
  wall or the ceiling; A-E visited in a shuffled order.
- ``deep``, ``deep_far``: the far wall 8-10 m in from the near wall; A-E in the paper's
  order, or right to left ending at B in the far corner away from the window.
- ``reverse``, ``shuffled``: the paper's kind of room, A-E visited in reverse, or in an
  order drawn from the generator.

A wall with windows is cut into boxes round them (:func:`wall_boxes`). The arm gets the
modules its reach needs (:func:`modules_needed`: from its base to the window's centre,
then to the farthest goal, plus 2 m), at least the paper kinds' count and at most
:data:`MODULES_MAX`. Everything random comes from the generator passed in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

#: the kinds of this module: their room layout and the order of their visits
LAYOUTS: dict[str, tuple[str, str]] = {
    "side": ("side", "paper"),
    "roof": ("roof", "paper"),
    "heights": ("heights", "reverse"),
    "two_windows": ("two_windows", "shuffled"),
    "deep": ("deep", "paper"),
    "deep_far": ("deep", "far_rtl"),
    "reverse": ("paper", "reverse"),
    "shuffled": ("paper", "shuffled"),
}
#: what each kind is, in words (the files' headers)
NOTES: dict[str, str] = {
    "side": "the window in the side wall facing the base (the near wall closed), A-E placed "
    "with the window's wall as the near wall, in the paper's order",
    "roof": "the window in the ceiling by the near wall (the near wall closed), A-E in the "
    "paper's order",
    "heights": "the near wall's window low or high, A-E in reverse (E, D, C, B, A)",
    "two_windows": "a second window in a side wall or the ceiling, A-E in a shuffled order",
    "deep": "the far wall 8-10 m in, A-E in the paper's order",
    "deep_far": "the far wall 8-10 m in, right to left (E, D, C, A, B), ending at B in the "
    "far corner away from the window",
    "reverse": "A-E in reverse (E, D, C, B, A), ending at A by the near wall",
    "shuffled": "A-E in an order drawn from the generator",
}
#: the most modules a variant of these kinds gets (a deep room needs a longer arm)
MODULES_MAX = 40
#: an Arm-Z module's collision radius [m] (the paper's)
MODULE_RADIUS_M = 0.75
#: an Arm-Z module's chord [m] (the paper's: sqrt(δy² + δz²))
CHORD_M = 0.716
#: the walls a window may be cut in; each wall's plane coordinates (u, v)
WALL_AXES: dict[str, tuple[int, int]] = {
    "near": (0, 2),
    "far": (0, 2),
    "left": (1, 2),
    "right": (1, 2),
    "ceiling": (0, 1),
}


@dataclass(frozen=True)
class Window:
    """A window in one wall of a room (before mirroring), metres.

    Attributes:
        wall: "near", "far", "left", "right" or "ceiling" (:data:`WALL_AXES`).
        lo, hi: its corners in the wall's plane coordinates (near/far: x, z; left/right:
            y, z; ceiling: x, y).
    """

    wall: str
    lo: tuple[float, float]
    hi: tuple[float, float]

    def centre(self, room: Any) -> list[float]:
        """The window's centre in the world (before mirroring) [m]."""
        u, v = WALL_AXES[self.wall]
        p = [0.0, 0.0, 0.0]
        p[u] = 0.5 * (self.lo[0] + self.hi[0])
        p[v] = 0.5 * (self.lo[1] + self.hi[1])
        fixed = {"near": room.y0, "far": room.y1, "left": room.x0, "right": room.x1}
        p[3 - u - v] = fixed.get(self.wall, room.z1)
        return p

    def inward(self) -> list[float]:
        """The unit normal from the window into the room."""
        return {
            "near": [0.0, 1.0, 0.0],
            "far": [0.0, -1.0, 0.0],
            "left": [1.0, 0.0, 0.0],
            "right": [-1.0, 0.0, 0.0],
            "ceiling": [0.0, 0.0, -1.0],
        }[self.wall]


def wall_boxes(
    name: str,
    lo: tuple[float, float, float],
    hi: tuple[float, float, float],
    axes: tuple[int, int],
    holes: list[tuple[tuple[float, float], tuple[float, float]]],
) -> list[dict[str, Any]]:
    """A wall (the box ``lo``..``hi``) with rectangular ``holes`` in its plane (coordinates
    ``axes``) as boxes: strips between the holes' edges along the first axis, each cut
    round the holes it meets along the second; neighbouring strips cut alike are merged.
    One box named ``name`` without holes, else ``name_0``, ``name_1``, ..."""
    u, v = axes
    if not holes:
        return [_box(name, lo, hi)]
    cuts = sorted({lo[u], hi[u], *(c for h in holes for c in (h[0][0], h[1][0]))})
    cuts = [c for c in cuts if lo[u] <= c <= hi[u]]
    strips: list[tuple[float, float, list[tuple[float, float]]]] = []
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        if b - a < 1e-9:
            continue
        mid = 0.5 * (a + b)
        blocked = sorted((h[0][1], h[1][1]) for h in holes if h[0][0] < mid < h[1][0])
        solid, at = [], lo[v]
        for c0, c1 in blocked:
            if c0 > at + 1e-9:
                solid.append((at, c0))
            at = max(at, c1)
        if hi[v] > at + 1e-9:
            solid.append((at, hi[v]))
        if strips and strips[-1][2] == solid and abs(strips[-1][1] - a) < 1e-9:
            strips[-1] = (strips[-1][0], b, solid)
        else:
            strips.append((a, b, solid))
    boxes: list[dict[str, Any]] = []
    for a, b, solid in strips:
        for c0, c1 in solid:
            blo, bhi = list(lo), list(hi)
            blo[u], bhi[u], blo[v], bhi[v] = a, b, c0, c1
            boxes.append(_box(f"{name}_{len(boxes)}", blo, bhi))
    return boxes


def _box(name: str, lo: Any, hi: Any) -> dict[str, Any]:
    c = [0.5 * (a + b) for a, b in zip(lo, hi, strict=True)]
    s = [b - a for a, b in zip(lo, hi, strict=True)]
    return {"name": name, "type": "box", "center_m": c, "size_m": s}


def room_boxes(room: Any, windows: tuple[Window, ...], wall_m: float) -> list[dict[str, Any]]:
    """The room's walls (``[[obstacles]]`` tables, before mirroring) with ``windows`` cut
    in them: floor, ceiling, far, left, right and near walls, extents as in the paper's
    file (floor, ceiling and the near and far walls span the side walls' thickness)."""
    r, t = room, wall_m
    X0, X1, Y0, Y1 = r.x0 - t, r.x1 + t, r.y0 - t, r.y1 + t
    walls = {
        "floor": ("room_floor", (X0, Y0, r.z0 - t), (X1, Y1, r.z0), (0, 1)),
        "ceiling": ("room_ceiling", (X0, Y0, r.z1), (X1, Y1, r.z1 + t), (0, 1)),
        "far": ("wall_far", (X0, r.y1, r.z0), (X1, Y1, r.z1), (0, 2)),
        "left": ("wall_left", (X0, r.y0, r.z0), (r.x0, r.y1, r.z1), (1, 2)),
        "right": ("wall_right", (r.x1, r.y0, r.z0), (X1, r.y1, r.z1), (1, 2)),
        "near": ("wall_near", (X0, Y0, r.z0), (X1, r.y0, r.z1), (0, 2)),
    }
    out = []
    for key, (name, lo, hi, axes) in walls.items():
        holes = [(w.lo, w.hi) for w in windows if w.wall == key]
        out += wall_boxes(name, lo, hi, axes, holes)
    return out


def _window_in(
    rng: np.random.Generator,
    wall: str,
    span_u: tuple[float, float],
    span_v: tuple[float, float],
    centre_u: tuple[float, float] | None = None,
    centre_v: tuple[float, float] | None = None,
) -> Window:
    """A window 2.7-3.6 m by 2.7-3.6 m (the arm is 1.5 m thick) in a wall whose plane spans
    ``span_u`` × ``span_v``, at least 0.5 m from its edges, its centre drawn within
    ``centre_u`` / ``centre_v`` where given (clipped to what fits)."""
    w = float(rng.uniform(2.7, 3.6))
    h = float(rng.uniform(2.7, 3.6))
    w = min(w, span_u[1] - span_u[0] - 1.0)
    h = min(h, span_v[1] - span_v[0] - 1.0)
    cu = _draw_centre(rng, span_u, w, centre_u)
    cv = _draw_centre(rng, span_v, h, centre_v)
    return Window(wall, (cu - w / 2, cv - h / 2), (cu + w / 2, cv + h / 2))


def _draw_centre(
    rng: np.random.Generator,
    span: tuple[float, float],
    size: float,
    want: tuple[float, float] | None,
) -> float:
    lo, hi = span[0] + 0.5 + size / 2, span[1] - 0.5 - size / 2
    if want is not None:
        lo, hi = max(lo, want[0]), min(hi, want[1])
    return float(rng.uniform(lo, hi)) if hi > lo else 0.5 * (span[0] + span[1])


def draw_windows(layout: str, room: Any, rng: np.random.Generator) -> tuple[Window, ...]:
    """The windows of a room of ``layout`` (:data:`LAYOUTS`), drawn from ``rng``: the
    ``paper`` and ``deep`` layouts keep the paper's near-wall window (the room's ``wx``,
    ``wz``: none here), the others see the module docstring."""
    r = room
    mid = 0.5 * (r.z0 + r.z1)
    if layout == "side":
        # the right wall faces the base (the room stands to its left)
        return (_window_in(rng, "right", (r.y0, r.y1), (r.z0, r.z1), None, (mid - 0.6, mid + 0.6)),)
    if layout == "roof":
        return (
            _window_in(rng, "ceiling", (r.x0, r.x1), (r.y0, r.y1), (-2.5, 2.5), (r.y0, r.y0 + 3.5)),
        )
    if layout == "heights":
        low = bool(rng.random() < 0.5)
        gap = float(rng.uniform(0.2, 0.6))
        near = _window_in(rng, "near", (r.x0, r.x1), (r.z0, r.z1), (-2.5, 2.5))
        h = near.hi[1] - near.lo[1]
        h = min(h, r.z1 - r.z0 - gap - 0.3)
        v0 = r.z0 + gap if low else r.z1 - gap - h
        return (Window("near", (near.lo[0], v0), (near.hi[0], v0 + h)),)
    if layout == "two_windows":
        near = _window_in(
            rng, "near", (r.x0, r.x1), (r.z0, r.z1), (-2.5, 2.5), (mid - 0.6, mid + 0.6)
        )
        wall = ("left", "right", "ceiling")[int(rng.integers(0, 3))]
        span = {"left": (r.y0, r.y1), "right": (r.y0, r.y1), "ceiling": (r.x0, r.x1)}[wall]
        span_v = (r.y0, r.y1) if wall == "ceiling" else (r.z0, r.z1)
        return (near, _window_in(rng, wall, span, span_v))
    return ()


def draw_room(
    layout: str, scale: float, shift: tuple[float, float, float], rng: np.random.Generator
):
    """The interior box of a room of ``layout`` (x0, x1, y0, y1, z0, z1) [m]: the paper's
    scaled about the base and shifted; ``deep``: its far wall 8-10 m in; ``side``: moved
    to the left of the base, its right wall 1.55-2.55 m from the base's axis."""
    x0, x1 = -7.5 * scale + shift[0], 2.6 * scale + shift[0]
    y0, y1 = 5.0 * scale + shift[1], 10.0 * scale + shift[1]
    z0, z1 = 2.5 * scale + shift[2], 7.5 * scale + shift[2]
    if layout == "deep":
        y1 = y0 + float(rng.uniform(8.0, 10.0))
    if layout == "side":
        width = x1 - x0
        x1 = -(0.75 + 0.3 + float(rng.uniform(0.5, 1.5)))
        x0 = x1 - width
    return x0, x1, y0, y1, z0, z1


def modules_needed(base_m: Any, window_m: Any, goals_m: list[Any]) -> int:
    """Modules whose chords reach from the base to the window's centre, then to the
    farthest goal, with 2 m to spare (the witnesses' IK and the planners need slack)."""
    base, win = np.asarray(base_m, dtype=float), np.asarray(window_m, dtype=float)
    far = max(float(np.linalg.norm(np.asarray(g, dtype=float) - win)) for g in goals_m)
    return int(math.ceil((float(np.linalg.norm(win - base)) + far + 2.0) / CHORD_M)) + 1


def draw_order(order: str, rng: np.random.Generator) -> tuple[str, ...]:
    """The visits A-E of an order (``paper``, ``reverse``, ``far_rtl``, or ``shuffled``:
    a permutation drawn from ``rng``)."""
    if order == "reverse":
        return ("E", "D", "C", "B", "A")
    if order == "far_rtl":
        return ("E", "D", "C", "A", "B")
    if order == "shuffled":
        return tuple(str(x) for x in rng.permutation(np.array(["A", "B", "C", "D", "E"])))
    return ("A", "B", "C", "D", "E")

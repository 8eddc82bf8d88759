"""Variants of the Arm-Z paper's task (``problems/armz_inspection.toml``) on rooms it has
never seen, each with a proven-reachable configuration for every goal.

A variant keeps the paper's layout and changes the room: the room is scaled about the
base (with 20-32 modules, more for bigger rooms), shifted, and mirrored about the base's
y-z plane or not; the window sits elsewhere on the near wall and has another size. The
goals are placed relative to the walls as in the paper (``docs/papers.md`` §1, ρ = 0.8 m
from the walls at the corners): ``enter`` 1.5 m inside the window's centre looking into
the room, A and B in the left corners by the near and the far wall, C in the middle of
the far wall, D in the far right corner, E 1.1 m from the right wall 1 m inside the
near wall, ``leave`` the rest pose's tip.

Every goal gets a *witness*: a collision-free state inside the goal's tolerances with at
least ``min_clearance_m`` of clearance to the scene and between modules (the collision
checker's exact signed distances). Witnesses come from a clearance-aware numeric IK
(damped least squares on the tip error, with every pair closer than the wanted clearance
pushed apart through its point Jacobian), seeded from the previous goal's witness and
from noisy restarts: not from any planner. A variant whose goals are not all witnessed is
dropped before any planner sees it. The witnesses are written as ``[witness]
goal_states_rad`` (one state per goal, in leg order), which the loader validates.

**Kinds** (:data:`ORDERS`): the same rooms and goals, visited in another order. ``paper``
visits A–E in the paper's order and ends at E, 1.7–5 m sideways of the window, near the
near wall. ``far_ltr`` and ``far_rtl`` end on the far wall, far from the window, so that
``leave`` starts deep in the room: left to right (A, B, C, then E and D: the task ends in
the far corner on the window's side) and right to left (E, D, C, A, B: it ends in the far
corner of the other side, 5–7 m sideways of the window). "Left" is the side of A and B
before mirroring.

**Rooms of more kinds** (:mod:`plannerlab.problem.variant_rooms`, :data:`KINDS`): windows
in a side wall or the ceiling, low or high, two windows, the far wall 8-10 m in; visits in
reverse and shuffled orders. Their arms get the modules their reach needs (up to
:data:`~plannerlab.problem.variant_rooms.MODULES_MAX`).

Everything random comes from the ``numpy.random.Generator`` passed in: a fixed seed gives
the same files (the kinds of :data:`ORDERS` draw nothing: the ``paper`` kind's files are
those made before kinds existed, and those of every kind of :data:`ORDERS` are those made
before the rooms of more kinds existed).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.problem import variant_rooms as rooms
from plannerlab.problem.load import Problem, problem_from_dict
from plannerlab.problem.variant_witness import (  # noqa: F401 (re-exported)
    WitnessResult,
    clearance_ik,
    find_witness,
    witness_states,
)
from plannerlab.record.files import write_text_atomic
from plannerlab.robots.base import Array

#: margin ρ of the paper's corner points from the walls [m]
RHO_M = 0.8
#: wall thickness of the paper's room [m]
WALL_M = 0.3
#: fewest and most modules of a variant's arm (the paper's has 24)
MODULES_RANGE = (20, 32)
#: the order of the legs of each kind of variant (goal names, see the module docstring)
ORDERS: dict[str, tuple[str, ...]] = {
    "paper": ("enter", "A", "B", "C", "D", "E", "leave"),
    "far_ltr": ("enter", "A", "B", "C", "E", "D", "leave"),
    "far_rtl": ("enter", "E", "D", "C", "A", "B", "leave"),
}
#: what each kind is, in words (the files' headers)
KIND_NOTES: dict[str, str] = {
    "paper": "A-E in the paper's order, ending at E by the near wall",
    "far_ltr": "left to right (A, B, C, E, D), ending at D in the far corner on the window's side",
    "far_rtl": "right to left (E, D, C, A, B), ending at B in the far corner away from the window",
    **rooms.NOTES,
}
#: every kind: the paper's rooms in three orders, then the rooms of more kinds
KINDS: tuple[str, ...] = (*ORDERS, *rooms.LAYOUTS)


class VariantError(PlannerlabError):
    """A generator input that cannot be used (named, with what was expected)."""


@dataclass(frozen=True)
class Room:
    """A variant's room in the world frame (before mirroring), metres.

    Interior ``x0..x1``, ``y0..y1`` (y0: the near wall, facing the base), ``z0..z1``; the
    window in the near wall spans ``wx0..wx1`` × ``wz0..wz1``.
    """

    x0: float
    x1: float
    y0: float
    y1: float
    z0: float
    z1: float
    wx0: float
    wx1: float
    wz0: float
    wz1: float


@dataclass(frozen=True)
class VariantSpec:
    """What was drawn for one variant (kept in the file's comments and ``[problem]``)."""

    index: int
    scale: float
    shift_m: tuple[float, float, float]
    mirrored: bool
    n_modules: int
    room: Room
    extras: dict[str, Any] = field(default_factory=dict)
    kind: str = "paper"
    #: (rooms of more kinds) windows other than the near wall's one of ``room``
    windows: tuple[rooms.Window, ...] = ()
    #: (rooms of more kinds) the order of the visits A-E
    visits: tuple[str, ...] = ()

    @property
    def legs(self) -> tuple[str, ...]:
        """The goals' names in leg order."""
        if self.kind in ORDERS:
            return ORDERS[self.kind]
        return ("enter", *self.visits, "leave")


# ---------------------------------------------------------------------- drawing
def draw_spec(index: int, rng: np.random.Generator, kind: str = "paper") -> VariantSpec:
    """One variant's room, window and arm, drawn from ``rng``; ``kind`` (:data:`ORDERS`)
    orders its legs and draws nothing.

    The paper's room (interior x ∈ [−7.5, 2.6], y ∈ [5, 10], z ∈ [2.5, 7.5], window
    x ∈ [−2.5, 0.5], z ∈ [3.5, 6.5]) is scaled about the base by s ∈ [0.85, 1.3], shifted
    by up to ±1 m in x, −0.5…+1 m in y (away from the base) and ±0.5 m in z; the arm gets
    round(24 s) − 1 … + 2 modules (within 20–32). The window (2.7–3.6 m wide and tall, the
    arm is 1.5 m thick) is moved along the near wall: its centre x within 2.5 m of the
    base's x (the arm leans into it from the rest pose), its centre z within ±0.6 m of the
    room's mid-height, at least 0.5 m from every edge of the wall.
    """
    if kind not in KINDS:
        raise VariantError(f"--kind: one of {', '.join(KINDS)}, got {kind!r}")
    if kind not in ORDERS:
        return _draw_more(index, rng, kind)
    scale = float(rng.uniform(0.85, 1.3))
    shift = (
        float(rng.uniform(-1.0, 1.0)),
        float(rng.uniform(-0.5, 1.0)),
        float(rng.uniform(-0.5, 0.5)),
    )
    mirrored = bool(rng.random() < 0.5)
    n = int(round(24 * scale)) + int(rng.integers(-1, 3))
    n_modules = int(min(max(n, MODULES_RANGE[0]), MODULES_RANGE[1]))
    x0, x1 = -7.5 * scale + shift[0], 2.6 * scale + shift[0]
    y0, y1 = 5.0 * scale + shift[1], 10.0 * scale + shift[1]
    z0, z1 = 2.5 * scale + shift[2], 7.5 * scale + shift[2]
    w = float(rng.uniform(2.7, 3.6))
    h = float(rng.uniform(2.7, 3.6))
    h = min(h, (z1 - z0) - 1.0)
    lo = max(x0 + 0.5 + w / 2, -2.5)
    hi = min(x1 - 0.5 - w / 2, 2.5)
    cx = float(rng.uniform(lo, hi)) if hi > lo else 0.5 * (x0 + x1)
    zc = 0.5 * (z0 + z1)
    dz = min(0.6, 0.5 * (z1 - z0) - h / 2 - 0.5)
    cz = float(rng.uniform(zc - dz, zc + dz)) if dz > 0 else zc
    room = Room(x0, x1, y0, y1, z0, z1, cx - w / 2, cx + w / 2, cz - h / 2, cz + h / 2)
    return VariantSpec(index, scale, shift, mirrored, n_modules, room, kind=kind)


def _draw_more(index: int, rng: np.random.Generator, kind: str) -> VariantSpec:
    """A room of more kinds (:mod:`plannerlab.problem.variant_rooms`): scaled, shifted and
    mirrored as the paper kinds' are, its windows and the order of its visits drawn for
    the kind; the arm as the paper kinds' or longer, as its reach needs (within 20 to
    :data:`~plannerlab.problem.variant_rooms.MODULES_MAX`)."""
    layout, order = rooms.LAYOUTS[kind]
    scale = float(rng.uniform(0.85, 1.3))
    shift = (
        float(rng.uniform(-1.0, 1.0)),
        float(rng.uniform(-0.5, 1.0)),
        float(rng.uniform(-0.5, 0.5)),
    )
    mirrored = bool(rng.random() < 0.5)
    n = int(round(24 * scale)) + int(rng.integers(-1, 3))
    x0, x1, y0, y1, z0, z1 = rooms.draw_room(layout, scale, shift, rng)
    nan = float("nan")
    room = Room(x0, x1, y0, y1, z0, z1, nan, nan, nan, nan)
    windows = rooms.draw_windows(layout, room, rng) or (_paper_window(room, rng),)
    visits = rooms.draw_order(order, rng)
    first = windows[0].centre(room)
    if len(windows) == 1 and windows[0].wall == "near":
        # one window in the near wall: the paper kinds' room, its walls named as theirs
        (wx0, wz0), (wx1, wz1) = windows[0].lo, windows[0].hi
        room, windows = replace(room, wx0=wx0, wx1=wx1, wz0=wz0, wz1=wz1), ()
    spec = VariantSpec(
        index, scale, shift, mirrored, 20, room, kind=kind, windows=windows, visits=visits
    )
    goals = {g["name"]: g["p_m"] for g in goal_tables(replace(spec, mirrored=False))}
    need = rooms.modules_needed([0.0, 0.0, 0.35], first, [goals[k] for k in "ABCDE"])
    n_modules = int(min(max(n, need, MODULES_RANGE[0]), rooms.MODULES_MAX))
    return replace(spec, n_modules=n_modules)


def _paper_window(room: Room, rng: np.random.Generator) -> rooms.Window:
    """The near wall's window drawn as :func:`draw_spec` draws it."""
    r = room
    w = float(rng.uniform(2.7, 3.6))
    h = min(float(rng.uniform(2.7, 3.6)), (r.z1 - r.z0) - 1.0)
    lo, hi = max(r.x0 + 0.5 + w / 2, -2.5), min(r.x1 - 0.5 - w / 2, 2.5)
    cx = float(rng.uniform(lo, hi)) if hi > lo else 0.5 * (r.x0 + r.x1)
    zc = 0.5 * (r.z0 + r.z1)
    dz = min(0.6, 0.5 * (r.z1 - r.z0) - h / 2 - 0.5)
    cz = float(rng.uniform(zc - dz, zc + dz)) if dz > 0 else zc
    return rooms.Window("near", (cx - w / 2, cz - h / 2), (cx + w / 2, cz + h / 2))


# ---------------------------------------------------------------------- the problem file
def _box(name: str, lo: Sequence[float], hi: Sequence[float]) -> dict[str, Any]:
    c = [0.5 * (a + b) for a, b in zip(lo, hi, strict=True)]
    s = [b - a for a, b in zip(lo, hi, strict=True)]
    return {"name": name, "type": "box", "center_m": c, "size_m": s}


def _mirror_box(box: dict[str, Any]) -> dict[str, Any]:
    out = dict(box)
    out["center_m"] = [-box["center_m"][0], *box["center_m"][1:]]
    return out


_MIRROR_NAMES = {
    "wall_left": "wall_right",
    "wall_right": "wall_left",
    "wall_near_left": "wall_near_right",
    "wall_near_right": "wall_near_left",
}


def _mirror_name(name: str) -> str:
    """A box's name after mirroring: left and right swapped (``wall_left_2`` too)."""
    if name in _MIRROR_NAMES:
        return _MIRROR_NAMES[name]
    for a, b in (("wall_left_", "wall_right_"), ("wall_right_", "wall_left_")):
        if name.startswith(a):
            return b + name[len(a) :]
    return name


def scene_boxes(spec: VariantSpec) -> list[dict[str, Any]]:
    """The room's boxes (``[[obstacles]]`` tables), as in the paper's file: ground,
    floor, ceiling, far, left and right walls, and the near wall as four boxes around the
    window (rooms of more kinds: every wall cut round its windows,
    :func:`~plannerlab.problem.variant_rooms.room_boxes`). Mirrored: x → −x, and
    "left"/"right" keep meaning −x/+x."""
    ground = {
        "name": "ground",
        "type": "box",
        "center_m": [0.0, 0.0, -0.95],
        "size_m": [60.0, 60.0, 1.0],
    }
    if spec.windows:
        boxes = [ground, *rooms.room_boxes(spec.room, spec.windows, WALL_M)]
        if spec.mirrored:
            boxes = [ground] + [
                {**_mirror_box(b), "name": _mirror_name(b["name"])} for b in boxes[1:]
            ]
        return boxes
    r, t = spec.room, WALL_M
    X0, X1 = r.x0 - t, r.x1 + t
    Y0, Y1 = r.y0 - t, r.y1 + t
    boxes = [
        {
            "name": "ground",
            "type": "box",
            "center_m": [0.0, 0.0, -0.95],
            "size_m": [60.0, 60.0, 1.0],
        },
        _box("room_floor", (X0, Y0, r.z0 - t), (X1, Y1, r.z0)),
        _box("room_ceiling", (X0, Y0, r.z1), (X1, Y1, r.z1 + t)),
        _box("wall_far", (X0, r.y1, r.z0), (X1, Y1, r.z1)),
        _box("wall_left", (X0, r.y0, r.z0), (r.x0, r.y1, r.z1)),
        _box("wall_right", (r.x1, r.y0, r.z0), (X1, r.y1, r.z1)),
        _box("wall_near_left", (X0, Y0, r.z0), (r.wx0, r.y0, r.z1)),
        _box("wall_near_right", (r.wx1, Y0, r.z0), (X1, r.y0, r.z1)),
        _box("wall_near_below", (r.wx0, Y0, r.z0), (r.wx1, r.y0, r.wz0)),
        _box("wall_near_above", (r.wx0, Y0, r.wz1), (r.wx1, r.y0, r.z1)),
    ]
    if spec.mirrored:
        boxes = [boxes[0]] + [
            {**_mirror_box(b), "name": _MIRROR_NAMES.get(b["name"], b["name"])} for b in boxes[1:]
        ]
    return boxes


def rest_tip(n_modules: int) -> tuple[list[float], list[float]]:
    """Tip position [m] and normal of the straight column (every θ = π) of the paper's
    module with ``n_modules`` modules, base at the origin."""
    from plannerlab.robots.armz.model import ArmZ

    arm = ArmZ(n_modules=n_modules)
    p, n = arm.tip(np.full(arm.dof, np.pi))
    return [float(v) for v in p], [float(v) for v in n]


def _goal_frame(spec: VariantSpec) -> tuple[Array, Array]:
    """The horizontal axes (across, inward) of the frame the goals A-E are placed in: the
    world's x and y, or, for a window in a side wall (kind ``side``), turned about z so
    that the window's wall is the near wall (its inward normal the frame's y)."""
    wall = spec.windows[0].wall if spec.windows else "near"
    if wall not in ("left", "right"):
        return np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    ey = np.array(spec.windows[0].inward(), dtype=float)
    return np.cross(ey, [0.0, 0.0, 1.0]), ey


def goal_tables(spec: VariantSpec) -> list[dict[str, Any]]:
    """The seven ``[[goals]]`` tables, placed relative to the walls as in the paper, in
    the order of the spec's kind (:data:`ORDERS`; rooms of more kinds: ``enter`` inside
    the first of their windows, and their visits' order)."""
    r = spec.room
    zc = 0.5 * (r.z0 + r.z1)
    s2 = math.sqrt(0.5)
    if spec.windows:
        w = spec.windows[0]
        inward = w.inward()
        p_enter = [c + 1.5 * d for c, d in zip(w.centre(r), inward, strict=True)]
    else:
        inward = [0.0, 1.0, 0.0]
        p_enter = [0.5 * (r.wx0 + r.wx1), r.y0 + 1.5, 0.5 * (r.wz0 + r.wz1)]
    goals: list[dict[str, Any]] = [
        {
            "name": "enter",
            "note": "tip 1.5 m inside the window's centre, looking into the room",
            "p_m": p_enter,
            "n": inward,
            "pos_tol_m": 0.3,
            "angle_tol_deg": 30.0,
        },
    ]
    # A-E in the frame whose near wall is the window's wall (the paper's own frame unless
    # the window is in a side wall): u across, w inward, then back to the world
    ex, ey = _goal_frame(spec)
    u0, u1 = sorted(float(np.dot(ex[:2], c)) for c in ((r.x0, r.y0), (r.x1, r.y1)))
    w0, w1 = sorted(float(np.dot(ey[:2], c)) for c in ((r.x0, r.y0), (r.x1, r.y1)))

    def world(u: float, w: float, z: float) -> list[float]:
        return [float(v) for v in u * ex + w * ey + np.array([0.0, 0.0, z])]

    for name, (gu, gw), (nu, nw) in (
        ("A", (u0 + RHO_M, w0 + RHO_M), (-1.0, 0.0)),
        ("B", (u0 + RHO_M, w1 - RHO_M), (-s2, s2)),
        ("C", (0.5 * (u0 + u1), w1 - RHO_M), (0.0, 1.0)),
        ("D", (u1 - RHO_M, w1 - RHO_M), (s2, s2)),
        ("E", (u1 - 1.1, w0 + 1.0), (1.0, 0.0)),
    ):
        goals.append({"name": name, "p_m": world(gu, gw, zc), "n": world(nu, nw, 0.0)})
    for g in goals[1:]:
        g["pos_tol_m"] = 0.1
        g["angle_tol_deg"] = 10.0
    p, n = rest_tip(spec.n_modules)
    goals.append(
        {
            "name": "leave",
            "note": "back to the rest pose's tip: the straight column beside the room",
            "p_m": p,
            "n": n,
            "pos_tol_m": 0.5,
            "angle_tol_deg": 20.0,
        }
    )
    if spec.mirrored:
        for g in goals:
            g["p_m"] = [-g["p_m"][0], *g["p_m"][1:]]
            g["n"] = [-g["n"][0], *g["n"][1:]]
    by_name = {g["name"]: g for g in goals}
    return [by_name[name] for name in spec.legs]


def _kind_words(spec: VariantSpec) -> str:
    """The end of a variant's description: how it differs from the paper's kind."""
    if spec.kind == "paper":
        return ""
    if spec.kind in ORDERS:
        return f", visited {KIND_NOTES[spec.kind]}"
    return f", {spec.kind}: {KIND_NOTES[spec.kind]} ({''.join(spec.visits)})"


def problem_document(spec: VariantSpec, name: str) -> dict[str, Any]:
    """The variant as a parsed-TOML document (without witnesses)."""
    return {
        "problem": {
            "name": name,
            "description": (
                f"armz_inspection variant {spec.index}: room x{spec.scale:.3f}, shifted "
                f"{', '.join(f'{v:+.2f}' for v in spec.shift_m)} m"
                + (", mirrored" if spec.mirrored else "")
                + f", {spec.n_modules} modules"
                + _kind_words(spec)
            ),
        },
        "robot": {
            "type": "armz",
            "n_modules": spec.n_modules,
            "zeta_deg": 22.5,
            "delta_y_m": -0.1397,
            "delta_z_m": 0.7023,
            "collision_radius_m": 0.75,
            "self_exclude_within": 5,
            "base_xyz_m": [0.0, 0.0, 0.0],
            "base_rpy_deg": [0.0, 0.0, 0.0],
        },
        "start": {"fill_deg": 180.0},
        "obstacles": scene_boxes(spec),
        "goals": goal_tables(spec),
        "budget": {"max_iterations": 3000, "time_limit_s": 300.0},
        "simulation": {"gravity_mps2": [0.0, 0.0, 0.0]},
        "checking": {"joint_step": 0.02},
    }


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        text = repr(round(v, 6))
        return "0.0" if text == "-0.0" else text
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"no TOML form for {type(v).__name__}")


def to_toml(doc: dict[str, Any], header: str = "") -> str:
    """TOML text of a problem document (tables, arrays of tables, numbers, strings and
    lists of them: what a problem file holds)."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    for key, value in doc.items():
        if isinstance(value, list) and value and isinstance(value[0], dict):
            for item in value:
                lines += ["", f"[[{key}]]"]
                lines += [f"{k} = {_toml_value(v)}" for k, v in item.items()]
        else:
            lines += ["", f"[{key}]"]
            for k, v in value.items():
                if isinstance(v, list) and v and isinstance(v[0], list):
                    lines.append(f"{k} = [")
                    lines += [f"    {_toml_value(row)}," for row in v]
                    lines.append("]")
                else:
                    lines.append(f"{k} = {_toml_value(v)}")
    return "\n".join(lines).lstrip("\n") + "\n"


@dataclass(frozen=True)
class Variant:
    """A kept variant: what was drawn, the problem, its witnesses and its file text."""

    spec: VariantSpec
    name: str
    problem: Problem
    witnesses: tuple[Array, ...]
    clearances_m: tuple[float, ...]
    text: str


def _windows_words(spec: VariantSpec) -> str:
    """The header's words on the windows (the paper kinds': as their files say)."""
    r = spec.room
    if not spec.windows:
        words = (
            f"window in the\nnear wall x in [{r.wx0:.3f}, {r.wx1:.3f}], z in "
            f"[{r.wz0:.3f}, {r.wz1:.3f}].\n"
        )
    else:
        axes = {"near": "x, z", "far": "x, z", "left": "y, z", "right": "y, z", "ceiling": "x, y"}
        words = "windows (before mirroring):\n" + "".join(
            f"  in the {w.wall} wall, ({axes[w.wall]}) from ({w.lo[0]:.3f}, {w.lo[1]:.3f}) to "
            f"({w.hi[0]:.3f}, {w.hi[1]:.3f});\n"
            for w in spec.windows
        )
    if spec.kind in rooms.LAYOUTS:
        words += f"Kind {spec.kind}: {KIND_NOTES[spec.kind]}; visits {', '.join(spec.visits)}.\n"
    return words


def _header(spec: VariantSpec, name: str, command: str, min_clearance_m: float) -> str:
    r = spec.room
    return (
        f"{name}: a variant of the Arm-Z paper's task (problems/armz_inspection.toml) in a room\n"
        f"it was not developed on, made by plannerlab.problem.variants:\n"
        f"    {command}\n"
        f"Drawn: room scaled x{spec.scale:.4f} about the base, shifted "
        f"[{', '.join(f'{v:.3f}' for v in spec.shift_m)}] m, "
        + ("mirrored x -> -x" if spec.mirrored else "not mirrored")
        + f", {spec.n_modules} modules.\n"
        f"Room interior (before mirroring) x in [{r.x0:.3f}, {r.x1:.3f}], y in [{r.y0:.3f}, "
        f"{r.y1:.3f}], z in [{r.z0:.3f}, {r.z1:.3f}]; walls {WALL_M} m thick; "
        + _windows_words(spec)
        + "Goals as in the paper"
        + ("" if spec.kind != "side" else " (the window's wall taken as the near wall)")
        + f": enter 1.5 m inside the window's centre; A, B, D at rho = "
        f"{RHO_M} m from two walls;\nC mid far wall; E 1.1 m from the right wall, 1 m "
        "inside "
        f"the near wall; leave at the rest pose's tip.\n"
        "[witness] goal_states_rad: one state per goal from a clearance-aware IK "
        "(not a planner),\n"
        f"collision-free with at least {min_clearance_m} m of clearance (collision checker's "
        f"signed distances)."
    )


def _interior(spec: VariantSpec) -> tuple[Array, Array] | None:
    """Rooms of more kinds: the room's inside less the module radius (world frame, after
    mirroring), where the witness search leads the tip along straight segments
    (:func:`~plannerlab.problem.variant_witness.find_witness`); None for the kinds of
    :data:`ORDERS`, whose witnesses are searched as before they existed."""
    if spec.kind in ORDERS:
        return None
    r, m = spec.room, rooms.MODULE_RADIUS_M
    xs = sorted((-r.x0, -r.x1) if spec.mirrored else (r.x0, r.x1))
    lo = np.array([xs[0] + m, r.y0 + m, r.z0 + m])
    hi = np.array([xs[1] - m, r.y1 - m, r.z1 - m])
    return lo, hi


def make_variant(
    index: int,
    rng: np.random.Generator,
    min_clearance_m: float = 0.04,
    command: str = "",
    kind: str = "paper",
) -> Variant | str:
    """Draw variant ``index`` of ``kind`` and find its witnesses: the kept
    :class:`Variant`, or why it was dropped (a string)."""
    spec = draw_spec(index, rng, kind)
    name = f"armz_inspection_v{index:02d}"
    doc = problem_document(spec, name)
    problem = problem_from_dict(doc, f"<variant {name}>")
    found = witness_states(problem, rng, min_clearance_m, interior=_interior(spec))
    if isinstance(found, str):
        return found
    states, clear = found
    doc["witness"] = {
        "note": "one collision-free state per goal, in leg order (plannerlab.problem.variants)",
        "clearance_floor_m": min_clearance_m,
        "goal_states_rad": [[round(float(v), 6) for v in q] for q in states],
    }
    text = to_toml(doc, _header(spec, name, command, min_clearance_m))
    # what is written is what a user loads: parse the text, re-check the rounded states
    import tomllib

    problem = problem_from_dict(tomllib.loads(text), f"<variant {name}>")
    rounded = tuple(np.array(q, dtype=float) for q in doc["witness"]["goal_states_rad"])
    checker = CollisionChecker(problem.robot, problem.scene)
    clear_rounded = tuple(float(checker.clearance(q)) for q in rounded)
    if min(clear_rounded) < min_clearance_m - 1e-4:
        return "a witness lost its clearance when rounded to 6 digits"
    return Variant(spec, name, problem, rounded, clear_rounded, text)


def generate(
    count: int,
    rng: np.random.Generator | int,
    *,
    min_clearance_m: float = 0.04,
    max_draws: int | None = None,
    command: str = "",
    progress: Callable[[str], None] | None = None,
    kinds: Sequence[str] = ("paper",),
    first_index: int = 0,
) -> list[Variant]:
    """``count`` kept variants, drawn in order from ``rng`` (a generator, or a seed for
    ``numpy.random.default_rng``; a dropped draw is reported through ``progress`` and
    replaced by the next draw), numbered from ``first_index``; the k-th kept one is of
    kind ``kinds[k % len(kinds)]`` (:data:`KINDS`).

    Raises:
        VariantError: bad arguments, or fewer than ``count`` kept in ``max_draws`` draws
            (default 3 × count).
    """
    if count < 1:
        raise VariantError(f"--count: a number of variants >= 1, got {count}")
    if not kinds or any(k not in KINDS for k in kinds):
        raise VariantError(f"--kind: each one of {', '.join(KINDS)}, got {list(kinds)}")
    if first_index < 0:
        raise VariantError(f"--first-index: a number >= 0, got {first_index}")
    if not (0.0 <= min_clearance_m < 0.75):
        raise VariantError(
            "--min-clearance: a clearance in [0, 0.75) m (the module radius), "
            f"got {min_clearance_m}"
        )
    rng = np.random.default_rng(rng)  # a Generator passes through unchanged
    max_draws = max_draws or 3 * count
    kept: list[Variant] = []
    draw = 0
    while len(kept) < count:
        if draw >= max_draws:
            raise VariantError(
                f"only {len(kept)} of {count} variants kept in {max_draws} draws "
                "(each needs a witness for every goal)"
            )
        v = make_variant(
            first_index + len(kept), rng, min_clearance_m, command, kinds[len(kept) % len(kinds)]
        )
        draw += 1
        if isinstance(v, str):
            if progress:
                progress(
                    f"draw {draw}: variant {len(kept)} "
                    f"({kinds[len(kept) % len(kinds)]}) dropped: {v}"
                )
            continue
        kept.append(v)
        if progress:
            progress(
                f"draw {draw}: kept {v.name} ({len(kept)}/{count}, {v.spec.kind}): "
                f"{v.spec.n_modules} modules, "
                f"smallest witness clearance {min(v.clearances_m) * 100:.1f} cm"
            )
    return kept


def write_variants(variants: Sequence[Variant], out_dir: str | Path) -> list[Path]:
    """Write each variant to ``out_dir/<name>.toml`` atomically; the paths written."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise VariantError(f"--out {out}: a folder, but a file is in the way")
    return [write_text_atomic(out / f"{v.name}.toml", v.text) for v in variants]

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

Everything random comes from the ``numpy.random.Generator`` passed in: a fixed seed gives
the same files (the kind draws nothing: the ``paper`` kind's files are those made before
kinds existed).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Problem, problem_from_dict
from plannerlab.record.files import write_text_atomic
from plannerlab.robots.base import Array, wrap_to_pi

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
}


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
    if kind not in ORDERS:
        raise VariantError(f"--kind: one of {', '.join(ORDERS)}, got {kind!r}")
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


def scene_boxes(spec: VariantSpec) -> list[dict[str, Any]]:
    """The room's boxes (``[[obstacles]]`` tables), as in the paper's file: ground,
    floor, ceiling, far, left and right walls, and the near wall as four boxes around the
    window. Mirrored: x → −x, and "left"/"right" keep meaning −x/+x."""
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


def goal_tables(spec: VariantSpec) -> list[dict[str, Any]]:
    """The seven ``[[goals]]`` tables, placed relative to the walls as in the paper, in
    the order of the spec's kind (:data:`ORDERS`)."""
    r = spec.room
    zc = 0.5 * (r.z0 + r.z1)
    s2 = math.sqrt(0.5)
    goals: list[dict[str, Any]] = [
        {
            "name": "enter",
            "note": "tip 1.5 m inside the window's centre, looking into the room",
            "p_m": [0.5 * (r.wx0 + r.wx1), r.y0 + 1.5, 0.5 * (r.wz0 + r.wz1)],
            "n": [0.0, 1.0, 0.0],
            "pos_tol_m": 0.3,
            "angle_tol_deg": 30.0,
        },
        {"name": "A", "p_m": [r.x0 + RHO_M, r.y0 + RHO_M, zc], "n": [-1.0, 0.0, 0.0]},
        {"name": "B", "p_m": [r.x0 + RHO_M, r.y1 - RHO_M, zc], "n": [-s2, s2, 0.0]},
        {"name": "C", "p_m": [0.5 * (r.x0 + r.x1), r.y1 - RHO_M, zc], "n": [0.0, 1.0, 0.0]},
        {"name": "D", "p_m": [r.x1 - RHO_M, r.y1 - RHO_M, zc], "n": [s2, s2, 0.0]},
        {"name": "E", "p_m": [r.x1 - 1.1, r.y0 + 1.0, zc], "n": [1.0, 0.0, 0.0]},
    ]
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
    return [by_name[name] for name in ORDERS[spec.kind]]


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
                + ("" if spec.kind == "paper" else f", visited {KIND_NOTES[spec.kind]}")
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


# ---------------------------------------------------------------------- witnesses
@dataclass(frozen=True)
class WitnessResult:
    """One clearance-aware IK descent: the state reached and whether it is a witness."""

    q: Array
    success: bool
    clearance_m: float
    pos_err_m: float
    angle_err_deg: float
    iterations: int


def _point_jacobians(frames: Array, link: Array, t: Array) -> tuple[Array, Array]:
    """Points ``a + t (b − a)`` on Arm-Z links (m, 3) and their Jacobians (m, 3, dof).

    Link i runs from face frame i to i + 1; joint k (1-based) turns about frame k's z
    axis, and a point on link i moves with joints 1..i."""
    o = frames[:, :3, 3]
    p = o[link] + t[:, None] * (o[link + 1] - o[link])
    z = frames[1:-1, :3, 2]
    oj = frames[1:-1, :3, 3]
    dof = z.shape[0]
    J = np.cross(z[None, :, :], p[:, None, :] - oj[None, :, :])  # (m, dof, 3)
    mask = np.arange(1, dof + 1)[None, :] <= link[:, None]
    return p, np.transpose(J * mask[:, :, None], (0, 2, 1))


def clearance_ik(
    robot: Any,
    checker: CollisionChecker,
    goal: GoalRegion,
    q_seed: Array,
    min_clearance_m: float,
    *,
    target_fraction: float = 0.5,
    max_iterations: int = 400,
    max_step_rad: float = 0.08,
    damping: float = 0.1,
    push_weight: float = 3.0,
    max_tip_units: float = 4.0,
) -> WitnessResult:
    """A damped-least-squares IK descent that keeps clearance (Arm-Z).

    Each step solves one weighted least-squares problem: the tip's position and normal
    errors scaled by the goal's tolerances (clipped to ``max_tip_units`` so far targets
    are approached a little at a time) and, for every checked pair closer than
    ``min_clearance_m`` + 2 cm, the pair's closest points pushed apart along the
    checker's separating direction (``pair_distances``: link points' Jacobians, the
    deficit in units of 2 cm, times ``push_weight``). It stops once the tip is within
    ``target_fraction`` of both tolerances and every pair is at least
    ``min_clearance_m`` apart.
    """
    q = wrap_to_pi(np.asarray(q_seed, dtype=float).copy(), robot.continuous)
    pos_scale = 1.0 / goal.pos_tol_m
    ang_scale = 1.0 / math.radians(goal.angle_tol_deg)
    want = min_clearance_m + 0.02
    d_min = pos_e = ang_e = math.inf
    for it in range(max_iterations + 1):
        F = robot.fk(q)
        p, n = F[-1, :3, 3], F[-1, :3, 2]
        pos_e, ang_e = (float(v) for v in goal.errors_from_tip(p, n))
        pd = checker.pair_distances(q, want + 0.2)
        d_min = float(pd.d_m.min()) if len(pd.d_m) else math.inf
        inside = pos_e <= target_fraction * goal.pos_tol_m and ang_e <= (
            target_fraction * goal.angle_tol_deg
        )
        if inside and d_min >= min_clearance_m:
            return WitnessResult(q, True, d_min, pos_e, ang_e, it)
        if it == max_iterations:
            break
        e = np.concatenate([(goal.p_world_m - p) * pos_scale, (goal.n_world - n) * ang_scale])
        size = float(np.linalg.norm(e))
        if size > max_tip_units:
            e *= max_tip_units / size
        z = F[1:-1, :3, 2]
        oj = F[1:-1, :3, 3]
        J_tip = np.vstack([np.cross(z, p - oj).T * pos_scale, np.cross(z, n).T * ang_scale])
        rows, rhs = [J_tip], [e]
        close = pd.d_m < want
        if np.any(close):
            link = pd.link[close]
            _, Ja = _point_jacobians(F, link, pd.t_link[close])
            nrm = pd.n_world[close]
            G = np.einsum("mk,mkd->md", nrm, Ja)
            other_link = pd.other_is_link[close]
            if np.any(other_link):
                _, Jb = _point_jacobians(
                    F, pd.other[close][other_link], pd.t_other[close][other_link]
                )
                G[other_link] -= np.einsum("mk,mkd->md", nrm[other_link], Jb)
            deficit = (want - pd.d_m[close]) / 0.02
            rows.append(push_weight * G / 0.02)
            rhs.append(push_weight * deficit)
        A = np.vstack(rows)
        b = np.concatenate(rhs)
        dq = np.linalg.solve(A.T @ A + damping**2 * np.eye(robot.dof), A.T @ b)
        biggest = float(np.max(np.abs(dq)))
        if biggest > max_step_rad:
            dq *= max_step_rad / biggest
        q = wrap_to_pi(q + dq, robot.continuous)
    return WitnessResult(q, False, d_min, pos_e, ang_e, max_iterations)


def _approach(goal: GoalRegion, distance_m: float) -> GoalRegion:
    """A loose goal ``distance_m`` back from ``goal`` along its normal (the tip then comes
    in along the normal it must show)."""
    return GoalRegion(
        f"{goal.name}-approach",
        goal.p_world_m - distance_m * goal.n_world,
        goal.n_world,
        0.5,
        30.0,
    )


def find_witness(
    robot: Any,
    checker: CollisionChecker,
    goal: GoalRegion,
    seeds: Sequence[Array],
    rng: np.random.Generator,
    min_clearance_m: float,
    attempts: int = 12,
) -> WitnessResult | None:
    """A witness state for ``goal``: collision-free, inside both tolerances, at least
    ``min_clearance_m`` from the scene and between modules; or None.

    Attempt k starts from seed ``k mod len(seeds)`` (plus Gaussian noise of 0.05 · 1.5^k
    rad, at most 1 rad, from the second round of seeds on), descends by
    :func:`clearance_ik` first to the approach point 2.5 m back along the goal's normal,
    then to the goal. A seed already inside the goal with the clearance is taken as is.
    """
    for q0 in seeds:
        pos_e, ang_e = (float(v) for v in goal.errors(robot, q0))
        if pos_e <= goal.pos_tol_m and ang_e <= goal.angle_tol_deg:
            if checker.clearance(q0) >= min_clearance_m:
                return WitnessResult(
                    np.array(q0, dtype=float), True, checker.clearance(q0), pos_e, ang_e, 0
                )
    for k in range(attempts):
        q0 = np.array(seeds[k % len(seeds)], dtype=float)
        if k >= len(seeds):
            q0 = q0 + rng.normal(0.0, min(0.05 * 1.5**k, 1.0), robot.dof)
        first = clearance_ik(robot, checker, _approach(goal, 2.5), q0, min_clearance_m)
        result = clearance_ik(robot, checker, goal, first.q, min_clearance_m)
        if result.success:
            # the final word is the checker's: collision-free and the clearance kept
            if checker.is_valid(result.q) and checker.clearance(result.q) >= min_clearance_m:
                return result
    return None


@dataclass(frozen=True)
class Variant:
    """A kept variant: what was drawn, the problem, its witnesses and its file text."""

    spec: VariantSpec
    name: str
    problem: Problem
    witnesses: tuple[Array, ...]
    clearances_m: tuple[float, ...]
    text: str


def witness_states(
    problem: Problem,
    rng: np.random.Generator,
    min_clearance_m: float,
    checker: CollisionChecker | None = None,
) -> tuple[list[Array], list[float]] | str:
    """One witness per goal (in leg order) and its clearance [m], or the reason there is
    none (a string naming the goal)."""
    robot = problem.robot
    checker = checker or CollisionChecker(robot, problem.scene)
    if checker.clearance(problem.q_start) < min_clearance_m:
        return f"the start state is closer than {min_clearance_m:g} m to the scene"
    found: list[Array] = []
    clear: list[float] = []
    for goal in problem.goals:
        previous = found[-1] if found else problem.q_start
        seeds = [previous, *found[:-1][::-1], problem.q_start]
        w = find_witness(robot, checker, goal, seeds, rng, min_clearance_m)
        if w is None:
            return f"no witness for goal {goal.name}"
        found.append(w.q)
        clear.append(float(checker.clearance(w.q)))
    return found, clear


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
        f"{r.y1:.3f}], z in [{r.z0:.3f}, {r.z1:.3f}]; walls {WALL_M} m thick; window in the\n"
        f"near wall x in [{r.wx0:.3f}, {r.wx1:.3f}], z in [{r.wz0:.3f}, {r.wz1:.3f}].\n"
        f"Goals as in the paper: enter 1.5 m inside the window's centre; A, B, D at rho = "
        f"{RHO_M} m from two walls;\nC mid far wall; E 1.1 m from the right wall, 1 m "
        "inside "
        f"the near wall; leave at the rest pose's tip.\n"
        "[witness] goal_states_rad: one state per goal from a clearance-aware IK "
        "(not a planner),\n"
        f"collision-free with at least {min_clearance_m} m of clearance (collision checker's "
        f"signed distances)."
    )


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
    found = witness_states(problem, rng, min_clearance_m)
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
    kind ``kinds[k % len(kinds)]`` (:data:`ORDERS`).

    Raises:
        VariantError: bad arguments, or fewer than ``count`` kept in ``max_draws`` draws
            (default 3 × count).
    """
    if count < 1:
        raise VariantError(f"--count: a number of variants >= 1, got {count}")
    if not kinds or any(k not in ORDERS for k in kinds):
        raise VariantError(f"--kind: each one of {', '.join(ORDERS)}, got {list(kinds)}")
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
                progress(f"draw {draw}: variant {len(kept)} dropped: {v}")
            continue
        kept.append(v)
        if progress:
            progress(
                f"draw {draw}: kept {v.name} ({len(kept)}/{count}): {v.spec.n_modules} modules, "
                f"smallest witness clearance {min(v.clearances_m) * 100:.1f} cm"
            )
    return kept


def write_variants(variants: Sequence[Variant], out_dir: str | Path) -> list[Path]:
    """Write each variant to ``out_dir/<name>.toml`` atomically; the paths written."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise VariantError(f"--out {out}: a folder, but a file is in the way")
    return [write_text_atomic(out / f"{v.name}.toml", v.text) for v in variants]

"""OMPL's KinematicChain benchmark as plannerlab problems (``plannerlab import
kinematic-chain``).

OMPL's demo (``demos/KinematicChain.h``, ``KinematicChainBenchmark.cpp``; Gipson and
Moll) plans a planar chain of ``N`` links, each ``1/N`` long, every joint a full turn
(angles wrap at ±π), from inside a curved "horn" out into the open. Its validity test
treats links and walls as line segments: no two links may cross and no link may cross a
wall. This module builds the same problem from plannerlab's parts:

* the robot as a URDF (:func:`chain_urdf`): ``N`` continuous joints about z, link ``i``
  a cylinder of radius ``link_radius_m`` from joint ``i`` to joint ``i + 1`` (plannerlab
  covers it by the capsule on the same axis: the demo's segment, thickened), every
  non-adjacent link pair checked (the URDF family excludes neighbours);
* the horn (:func:`horn_segments`: the demo's walls, ``N - 1`` segments each, ``eps =
  ln(N) / N``) as thin boxes (:func:`horn_boxes`: ``wall_thickness_m`` thick, as tall in z
  as :data:`WALL_HEIGHT_M`, each one thickness longer than its segment so that
  neighbouring boxes overlap at the horn's corners);
* the demo's start (first joint 0, every other ``π / N``: the chain curled along the
  horn) and goal (first joint ``π - 0.001``, the others 0: the chain straight out to the
  left), the goal as a goal state.

:func:`problem_toml` gives the problem file's text and :func:`write_problem` writes the
URDF and the problem file. :func:`chain_geometry` gives the same chain and walls as plain
numbers for a program that checks them itself (the C++ side of
``bench/kinematic_chain_bench.py``).
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array

#: links at least / at most (the demo needs two for a wall segment; the cost of a state
#: test grows with the square of the links)
MIN_LINKS, MAX_LINKS = 2, 200
#: the demo's goal: the first joint this far short of π [rad]
GOAL_OFFSET_RAD = 1e-3
#: the walls' height along z [m] (the chain lies in z = 0; any height above the links'
#: diameter gives the same verdicts)
WALL_HEIGHT_M = 0.1
#: defaults: thin links and walls (the demo's are segments), the re-check at 0.0125 rad
DEFAULT_LINK_RADIUS_M = 1e-3
DEFAULT_WALL_THICKNESS_M = 2e-3
DEFAULT_MARGIN_M = 0.0
DEFAULT_JOINT_STEP_RAD = 0.05
DEFAULT_TIME_LIMIT_S = 10.0


def _check_links(n_links: int) -> int:
    if isinstance(n_links, bool) or int(n_links) != n_links:
        raise PlannerlabError(f"kinematic chain: links must be an integer, got {n_links!r}")
    n = int(n_links)
    if not MIN_LINKS <= n <= MAX_LINKS:
        raise PlannerlabError(
            f"kinematic chain: links must be in {MIN_LINKS} … {MAX_LINKS}, got {n}"
        )
    return n


def _positive(name: str, value: float, *, zero: bool = False) -> float:
    v = float(value)
    if not math.isfinite(v) or v < 0.0 or (v == 0.0 and not zero):
        more = ">= 0" if zero else "> 0"
        raise PlannerlabError(
            f"kinematic chain: {name} must be a finite number {more}, got {value!r}"
        )
    return v


def horn_segments(n_links: int) -> Array:
    """The demo's horn (``createHornEnvironment(N, ln(N) / N)``): (2 (N - 1), 4) wall
    segments ``x0, y0, x1, y1`` [m], the outer wall's then the inner wall's, each a
    polyline from ``(1/N, ∓eps)`` turning by ``π / N`` before every segment."""
    n = _check_links(n_links)
    eps = math.log(n) / n
    w = 1.0 / n
    out = []
    for side, scale in ((-1.0, w * (1.0 + math.pi * eps)), (1.0, w * (1.0 - math.pi * eps))):
        x, y, theta = w, side * eps, 0.0
        for _ in range(n - 1):
            theta += math.pi / n
            xn, yn = x + math.cos(theta) * scale, y + math.sin(theta) * scale
            out.append((x, y, xn, yn))
            x, y = xn, yn
    return np.array(out, dtype=float).reshape(-1, 4)


@dataclass(frozen=True)
class Wall:
    """One wall as a box in the plane z = 0: centre [m], yaw [rad], half length and half
    thickness [m] (its full height is :data:`WALL_HEIGHT_M`)."""

    center_m: tuple[float, float]
    yaw_rad: float
    half_length_m: float
    half_thickness_m: float


def horn_boxes(n_links: int, wall_thickness_m: float = DEFAULT_WALL_THICKNESS_M) -> list[Wall]:
    """The horn's segments as boxes ``wall_thickness_m`` thick, centred on their segments
    and one thickness longer (half at each end), so that neighbours overlap."""
    t = _positive("wall_thickness_m", wall_thickness_m)
    walls = []
    for x0, y0, x1, y1 in horn_segments(n_links):
        length = math.hypot(float(x1 - x0), float(y1 - y0))
        walls.append(
            Wall(
                center_m=(float(x0 + x1) / 2.0, float(y0 + y1) / 2.0),
                yaw_rad=math.atan2(float(y1 - y0), float(x1 - x0)),
                half_length_m=(length + t) / 2.0,
                half_thickness_m=t / 2.0,
            )
        )
    return walls


def start_goal(n_links: int) -> tuple[Array, Array]:
    """The demo's start (0, then ``π / N`` for every other joint) and goal
    (``π - 0.001``, then zeros) [rad]."""
    n = _check_links(n_links)
    q_start = np.full(n, math.pi / n)
    q_start[0] = 0.0
    q_goal = np.zeros(n)
    q_goal[0] = math.pi - GOAL_OFFSET_RAD
    return q_start, q_goal


def link_name(i: int) -> str:
    return f"link_{i + 1}"


def chain_urdf(n_links: int, link_radius_m: float = DEFAULT_LINK_RADIUS_M) -> str:
    """The chain as a URDF: ``base`` (no geometry), then per link a continuous joint about
    z at the previous link's end and a cylinder along x from the joint over the link's
    length ``1/N`` (its capsule: the demo's segment with radius ``link_radius_m``)."""
    n = _check_links(n_links)
    r = _positive("link_radius_m", link_radius_m)
    length = 1.0 / n
    lines = [
        '<?xml version="1.0"?>',
        f'<robot name="kinematic_chain_{n}">',
        '  <link name="base"/>',
    ]
    parent = "base"
    for i in range(n):
        x = 0.0 if i == 0 else length
        lines += [
            f'  <joint name="joint_{i + 1}" type="continuous">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{link_name(i)}"/>',
            f'    <origin xyz="{x!r} 0 0" rpy="0 0 0"/>',
            '    <axis xyz="0 0 1"/>',
            "  </joint>",
            f'  <link name="{link_name(i)}">',
            "    <collision>",
            f'      <origin xyz="{length / 2.0!r} 0 0" rpy="0 {math.pi / 2.0!r} 0"/>',
            f'      <geometry><cylinder radius="{r!r}" length="{length!r}"/></geometry>',
            "    </collision>",
            "    <inertial>",
            f'      <origin xyz="{length / 2.0!r} 0 0"/>',
            '      <mass value="0.01"/>',
            '      <inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/>',
            "    </inertial>",
            "  </link>",
        ]
        parent = link_name(i)
    lines += ["</robot>", ""]
    return "\n".join(lines)


def _vec(v: object) -> str:
    return "[" + ", ".join(repr(float(x)) for x in np.asarray(v, dtype=float).reshape(-1)) + "]"


def problem_name(n_links: int) -> str:
    return f"kinematic_chain_{_check_links(n_links)}"


def problem_toml(
    n_links: int,
    *,
    urdf: str,
    wall_thickness_m: float = DEFAULT_WALL_THICKNESS_M,
    safety_margin_m: float = DEFAULT_MARGIN_M,
    joint_step_rad: float = DEFAULT_JOINT_STEP_RAD,
    time_limit_s: float = DEFAULT_TIME_LIMIT_S,
) -> str:
    """The problem file's text for ``N`` links; ``urdf``: the URDF's path relative to the
    problem file (:func:`chain_urdf` written there). Edges are checked every
    ``joint_step_rad`` and re-checked every quarter of it (0.0125 rad by default); with a
    margin, also so that no point moves further than it between two checked states."""
    n = _check_links(n_links)
    margin = _positive("safety_margin_m", safety_margin_m, zero=True)
    step = _positive("joint_step_rad", joint_step_rad)
    limit = _positive("time_limit_s", time_limit_s)
    q_start, q_goal = start_goal(n)
    lines = [
        "# OMPL's KinematicChain benchmark (demos/KinematicChain.h): the horn, N links",
        "# (plannerlab import kinematic-chain)",
        "[problem]",
        f"name = {json.dumps(problem_name(n))}",
        f'description = "OMPL KinematicChain: {n} links of 1/{n} m out of the horn '
        f'(eps = ln {n} / {n})"',
        "",
        "[robot]",
        'type = "urdf"',
        f"urdf = {json.dumps(urdf)}",
        f'tip_link = "{link_name(n - 1)}"',
        "tip_axis = [1.0, 0.0, 0.0]",
        f"tip_offset_m = [{1.0 / n!r}, 0.0, 0.0]",
        "",
        "[start]",
        f"q = {_vec(q_start)}",
        "",
        "[planning]",
        f"safety_margin_m = {margin!r}",
        "",
        "[checking]",
        f"joint_step = {step!r}",
        "",
        "[budget]",
        f"time_limit_s = {limit!r}",
        "",
    ]
    for k, wall in enumerate(horn_boxes(n, wall_thickness_m)):
        side = "outer" if k < n - 1 else "inner"
        lines += [
            "[[obstacles]]",
            f'name = "horn_{side}_{k % (n - 1)}"',
            'type = "box"',
            f"center_m = [{wall.center_m[0]!r}, {wall.center_m[1]!r}, 0.0]",
            f"rpy_deg = [0.0, 0.0, {math.degrees(wall.yaw_rad)!r}]",
            f"size_m = {_vec([2 * wall.half_length_m, 2 * wall.half_thickness_m, WALL_HEIGHT_M])}",
            "",
        ]
    lines += ["[[goals]]", 'name = "out"', f"q = {_vec(q_goal)}", ""]
    return "\n".join(lines)


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_problem(
    n_links: int,
    out_dir: str | Path,
    *,
    link_radius_m: float = DEFAULT_LINK_RADIUS_M,
    wall_thickness_m: float = DEFAULT_WALL_THICKNESS_M,
    safety_margin_m: float = DEFAULT_MARGIN_M,
    joint_step_rad: float = DEFAULT_JOINT_STEP_RAD,
    time_limit_s: float = DEFAULT_TIME_LIMIT_S,
) -> Path:
    """Write ``kinematic_chain_N.urdf`` and ``kinematic_chain_N.toml`` into ``out_dir``
    (each atomically); returns the problem file's path."""
    n = _check_links(n_links)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise PlannerlabError(f"{out}: a folder is needed (the URDF and problem file go in it)")
    name = problem_name(n)
    urdf_text = chain_urdf(n, link_radius_m)
    toml_text = problem_toml(
        n,
        urdf=f"{name}.urdf",
        wall_thickness_m=wall_thickness_m,
        safety_margin_m=safety_margin_m,
        joint_step_rad=joint_step_rad,
        time_limit_s=time_limit_s,
    )
    _write_atomic(out / f"{name}.urdf", urdf_text)
    target = out / f"{name}.toml"
    _write_atomic(target, toml_text)
    return target


__all__ = [
    "DEFAULT_JOINT_STEP_RAD",
    "DEFAULT_LINK_RADIUS_M",
    "DEFAULT_MARGIN_M",
    "DEFAULT_TIME_LIMIT_S",
    "DEFAULT_WALL_THICKNESS_M",
    "Wall",
    "chain_urdf",
    "horn_boxes",
    "horn_segments",
    "problem_name",
    "problem_toml",
    "start_goal",
    "write_problem",
]

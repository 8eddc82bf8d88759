"""Defaults that fit the robot (issue 27, point 4): the clearance family's distances are
derived from the robot's size (clearance.settings.robot_size), so the same defaults solve a
0.7-m six-joint arm and the 16-m Arm-Z, and on every Arm-Z they are exactly today's.

The small arm is built here: six revolute joints, 0.77 m from its base to its tool,
cylinder links of 2-6 cm radius, on a table before a shelf; leg 0 puts its tool into the
shelf (a tip goal), leg 1 takes it out to a goal state beside the shelf. With Arm-Z's
distances (a 0.3-m margin, a 3-cm clearance floor, a 2.5-m approach) the descent stalls
in its first iterations (as the issue measured on a held-back arm); with the derived ones
it solves both legs.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import toy_problem

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.planners import Status, make_planner
from plannerlab.planners.clearance.settings import (
    DERIVED_DISTANCES,
    ClearanceSettings,
    robot_size,
)
from plannerlab.planners.follow_leader.planner import DERIVED_DISTANCES as LEADER_DISTANCES
from plannerlab.planners.follow_leader.planner import FollowLeaderSettings
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget, Problem
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix

#: the arm's links: (name, joint axis, joint limit [rad], cylinder radius [m], length [m]);
#: each link is a cylinder along z, the next joint at its end
ARM6_LINKS = (
    ("link1", "0 0 1", 3.1, 0.05, 0.1),
    ("link2", "0 1 0", 2.0, 0.04, 0.25),
    ("link3", "0 1 0", 2.5, 0.035, 0.2),
    ("link4", "0 0 1", 3.1, 0.03, 0.06),
    ("link5", "0 1 0", 2.0, 0.03, 0.06),
    ("tool", "0 0 1", 3.1, 0.02, 0.05),
)


def _cylinder(name: str, radius_m: float, length_m: float) -> str:
    return (
        f'<link name="{name}"><collision><origin xyz="0 0 {length_m / 2}"/>'
        f'<geometry><cylinder radius="{radius_m}" length="{length_m}"/></geometry>'
        "</collision></link>"
    )


def arm6_urdf() -> str:
    """A six-joint arm, 0.77 m from its base to its tool's end."""
    parts = ['<?xml version="1.0"?>\n<robot name="arm6">', _cylinder("base_link", 0.06, 0.05)]
    parent, z = "base_link", 0.05
    for i, (name, axis, limit, radius, length) in enumerate(ARM6_LINKS, start=1):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{name}"/><origin xyz="0 0 {z}"/><axis xyz="{axis}"/>'
            f'<limit lower="{-limit}" upper="{limit}" effort="10" velocity="2"/></joint>'
        )
        parts.append(_cylinder(name, radius, length))
        parent, z = name, length
    parts.append("</robot>\n")
    return "\n".join(parts)


ARM6_SHELF_TOML = """
[problem]
name = "arm6_shelf"
description = "a 6-joint 0.77-m arm reaching into a shelf on a table, and out again"

[robot]
type = "urdf"
urdf = "arm6.urdf"
tip_link = "tool"
allowed_collisions = [["base_link", "link2"], ["link3", "link5"], ["link4", "tool"]]

[start]
q = [0.0, -0.3, 1.2, 0.0, 0.8, 0.0]

[planning]
safety_margin_m = 0.01

[checking]
joint_step = 0.05

[[obstacles]]
name = "table"
type = "box"
center_m = [0.3, 0.0, -0.05]
size_m = [1.2, 1.2, 0.04]

[[obstacles]]
name = "shelf_bottom"
type = "box"
center_m = [0.55, 0.0, 0.2]
size_m = [0.3, 0.5, 0.02]

[[obstacles]]
name = "shelf_top"
type = "box"
center_m = [0.55, 0.0, 0.45]
size_m = [0.3, 0.5, 0.02]

[[obstacles]]
name = "shelf_back"
type = "box"
center_m = [0.71, 0.0, 0.325]
size_m = [0.02, 0.5, 0.27]

[[goals]]
name = "in_shelf"
p_m = [0.5, 0.0, 0.32]
n = [1.0, 0.0, 0.0]
pos_tol_m = 0.01
angle_tol_deg = 5.0

[[goals]]
name = "beside_shelf"
q = [1.2, 0.4, 1.0, 0.0, 0.6, 0.5]
joint_tol_rad = 0.01
"""

#: Arm-Z's distances, set explicitly (what every robot got before they were derived)
ARMZ_DISTANCES = {k: str(v) for k, v in DERIVED_DISTANCES.items()}
BUDGET = Budget(max_iterations=3000, max_collision_checks=20_000)


@pytest.fixture(scope="module")
def arm6(tmp_path_factory) -> Problem:
    folder: Path = tmp_path_factory.mktemp("arm6")
    (folder / "arm6.urdf").write_text(arm6_urdf(), "utf-8")
    (folder / "arm6_shelf.toml").write_text(ARM6_SHELF_TOML, "utf-8")
    return load_problem(folder / "arm6_shelf.toml")


def test_every_arm_z_gets_exactly_todays_distances():
    """Any number of modules, any radius, any base pose: the ratio is 1.0 and every
    derived value is the one the planners were measured with (bit for bit)."""
    base = pose_matrix([1.0, -2.0, 0.5], [0.1, -0.2, 0.3])
    robots = [ArmZ(n_modules=n) for n in (2, 3, 6, 8, 24)]
    robots += [ArmZ(n_modules=24, T_world_base=base), toy_problem().robot]
    robots += [load_problem("armz_inspection").robot, ArmZ(collision_radius_m=3.0)]
    for robot in robots:
        assert robot_size(robot).ratio == 1.0
        s = ClearanceSettings().for_robot(robot)
        for key, value in DERIVED_DISTANCES.items():
            assert getattr(s, key) == value, (robot, key)
        f = FollowLeaderSettings().for_robot(robot)
        for key, value in LEADER_DISTANCES.items():
            assert getattr(f, key) == value, (robot, key)
    # the values the clearance family was built with
    assert (DERIVED_DISTANCES["influence_m"], DERIVED_DISTANCES["clearance_floor_m"]) == (0.3, 0.03)
    assert DERIVED_DISTANCES["approach_m"] == 2.5 == LEADER_DISTANCES["approach_m"]


def test_a_small_arms_distances_are_scaled_and_a_users_value_wins(arm6):
    size = robot_size(arm6.robot)
    assert size.reach_m == pytest.approx(0.77)
    assert size.pitch_m == pytest.approx(0.06)  # its (upper) median link: the wrist's
    s = ClearanceSettings().for_robot(arm6.robot)
    assert s.influence_m == pytest.approx(0.3 * 0.06 / 0.7160596, rel=1e-5)
    assert s.clearance_floor_m == pytest.approx(s.influence_m / 10)
    assert s.approach_m < 0.3 * size.reach_m
    planner = make_planner("gradient.clearance", {"influence_m": "0.05"})
    assert planner.settings.influence_m == 0.05 and planner.settings.clearance_floor_m is None
    resolved = planner.for_robot(arm6.robot).settings
    assert resolved.influence_m == 0.05  # set: kept
    assert resolved.clearance_floor_m == s.clearance_floor_m  # left: derived
    # the planner's own settings are not changed by deriving them
    assert planner.settings.clearance_floor_m is None


def _legs(problem: Problem, name: str, overrides: dict) -> list:
    """Both legs in turn (leg 1 from where leg 0 ended), seed 0."""
    results, q = [], problem.q_start
    for leg in range(len(problem.goals)):
        planner = make_planner(name, overrides)
        r = planner.solve(problem, leg, BUDGET, np.random.default_rng(0), q_start=q)
        results.append(r)
        q = r.path[-1]
    return results


@pytest.mark.parametrize("name", ["gradient.clearance", "gradient.clearance+rrtconnect"])
def test_the_clearance_descent_solves_a_small_arm_with_its_defaults(arm6, name):
    checker = problem_checker(arm6)
    for leg, r in enumerate(_legs(arm6, name, {})):
        assert r.status is Status.SOLVED, (leg, r.reason)
        assert arm6.goals[leg].contains(arm6.robot, r.path[-1])
        assert r.collision_checks <= BUDGET.max_collision_checks
        check = checker.check_path(r.path, arm6.joint_step / 4)
        assert check.valid, (leg, check.first_invalid_edge, check.pairs)
        # the result records the distances it ran with, derived for this arm
        assert r.settings["influence_m"] == pytest.approx(0.3 * robot_size(arm6.robot).ratio)


def test_with_arm_zs_distances_the_small_arm_stalls(arm6):
    """What the derived defaults fix: Arm-Z's 0.3-m margin and 3-cm floor on this arm."""
    r = _legs(arm6, "gradient.clearance", ARMZ_DISTANCES)[0]
    assert r.status is Status.LOCAL_MINIMUM, r.reason
    assert r.iterations < 60


@pytest.mark.parametrize("cls", [ClearanceSettings, FollowLeaderSettings])
def test_every_setting_is_documented_in_one_attributes_form(cls):
    """``plannerlab planners NAME`` prints the settings from these docstrings: every
    field has its own ``name: text`` entry under ``Attributes:``, each distance its unit
    and how its default is derived."""
    doc = cls.__doc__ or ""
    assert "Attributes:" in doc
    section = doc.split("Attributes:", 1)[1]
    found = re.findall(r"^ {8}(\w+): (.*(?:\n {12}.*)*)", section, flags=re.M)
    entries = {name: " ".join(text.split()) for name, text in found}
    fields = [f.name for f in dataclasses.fields(cls)]
    assert sorted(entries) == sorted(fields)
    derived = DERIVED_DISTANCES if cls is ClearanceSettings else LEADER_DISTANCES
    for name in fields:
        if name.endswith("_m"):
            assert "[m]" in entries[name], name
        if name in derived:
            assert "derived" in entries[name] and f"{derived[name]:g} on Arm-Z" in entries[name]


def _scaled_arm6(folder: Path, s: float) -> Problem:
    """The arm and its shelf problem scaled by s: every length of the URDF, the scene, the
    goal's point and tolerance, the margin (joint values and angles unchanged)."""
    urdf = arm6_urdf()
    urdf = re.sub(r'(radius|length)="([0-9.]+)"', lambda m: f'{m[1]}="{float(m[2]) * s}"', urdf)
    urdf = re.sub(r'xyz="0 0 ([0-9.]+)"', lambda m: f'xyz="0 0 {float(m[1]) * s}"', urdf)
    toml = ARM6_SHELF_TOML

    def vec(m: re.Match[str]) -> str:
        return f"{m[1]} = [{', '.join(str(float(v) * s) for v in m[2].split(','))}]"

    toml = re.sub(r"(center_m|size_m|p_m) = \[([^\]]+)\]", vec, toml)
    toml = re.sub(
        r"(pos_tol_m|safety_margin_m) = ([0-9.]+)", lambda m: f"{m[1]} = {float(m[2]) * s}", toml
    )
    (folder / "arm6.urdf").write_text(urdf, "utf-8")
    (folder / "arm6_shelf.toml").write_text(toml, "utf-8")
    return load_problem(folder / "arm6_shelf.toml")


@pytest.mark.parametrize("name", ["ompl.rrtconnect", "native.rrtconnect"])
def test_sampling_planners_defaults_fit_every_robot_size(tmp_path, name):
    """The same arm and shelf at 0.4x (a 30-cm hobby arm), 1x and 20x (Arm-Z's 16 m): the
    sampling planners' defaults (steps, ranges, tolerances, edge cuts: joint-space or
    derived from the robot's reach and the problem's margin) solve every size with the
    same budget of checks, and the paths, in joint space, keep the same shape."""
    lengths, checks = [], []
    for s in (0.4, 1.0, 20.0):
        folder = tmp_path / f"x{s}"
        folder.mkdir()
        problem = _scaled_arm6(folder, s)
        assert robot_size(problem.robot).reach_m == pytest.approx(0.77 * s)
        checker = problem_checker(problem)
        for leg, r in enumerate(_legs(problem, name, {})):
            assert r.status is Status.SOLVED, (s, leg, r.reason)
            assert checker.check_path(r.path, problem.joint_step / 4).valid
            if leg == 0:
                lengths.append(float(np.sum(np.linalg.norm(np.diff(r.path, axis=0), axis=1))))
                checks.append(r.collision_checks)
    # scale-free: within a factor of two of each other in joint length and checks
    assert max(lengths) < 2 * min(lengths), lengths
    assert max(checks) < 4 * min(checks), checks

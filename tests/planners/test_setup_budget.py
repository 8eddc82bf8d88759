"""Set-up inside the budget, and bounded (issue 26, point 4).

A planar chain of 10 links 10 cm long and 1 mm in radius, built here as a URDF: at the
clearance field's spacing (0.4 r) it would take 2 520 spheres (3.2e6 self pairs), and
follow-the-leader's grid at half the tip's radius some 1e10 voxels. Every planner's
set-up (fields, grids, pools) is built in the leg's time and is capped by the robot and
scene; each planner returns within a 0.5 s limit plus one loop on a clock the test
controls (no wall clock: a loaded machine gives the same verdict).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_planner_contract import CHECK_S, LOOP_CHECKS, LOOP_READS, timed_solve

from plannerlab.errors import PlannerlabError
from plannerlab.planners import REGISTRY, Status, make_planner
from plannerlab.planners.clearance import MAX_SPHERES, ClearanceField, SetupStopped
from plannerlab.planners.follow_leader.grid import grid_voxel_m, grid_voxels
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget, Problem

N_LINKS = 10
LINK_M = 0.1


def chain_urdf(n_links: int, link_m: float, radius_m: float) -> str:
    """A planar chain: ``n_links`` revolute joints about z, each link a cylinder of
    ``radius_m`` along x."""
    parts = [
        '<?xml version="1.0"?>\n<robot name="thin_chain">',
        '<link name="base"><collision><geometry><sphere radius="0.002"/></geometry>'
        "</collision></link>",
    ]
    parent = "base"
    for i in range(n_links):
        x = 0.0 if i == 0 else link_m
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="{parent}"/>'
            f'<child link="l{i}"/><origin xyz="{x} 0 0"/><axis xyz="0 0 1"/>'
            '<limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>'
        )
        parts.append(
            f'<link name="l{i}"><collision>'
            f'<origin xyz="{link_m / 2} 0 0" rpy="0 1.5707963267948966 0"/>'
            f'<geometry><cylinder radius="{radius_m}" length="{link_m}"/></geometry>'
            "</collision></link>"
        )
        parent = f"l{i}"
    parts.append(
        f'<joint name="tip_joint" type="fixed"><parent link="{parent}"/><child link="tip"/>'
        f'<origin xyz="{link_m} 0 0" rpy="0 1.5707963267948966 0"/></joint>'
        '<link name="tip"/>\n</robot>\n'
    )
    return "\n".join(parts)


PROBLEM_TOML = """
[problem]
name = "thin_chain"
description = "a planar chain of thin links behind a wall with a slot"

[robot]
type = "urdf"
urdf = "thin_chain.urdf"
tip_link = "tip"

[start]
q = [{start}]

[checking]
joint_step = 0.02

[[obstacles]]
name = "wall_low"
type = "box"
center_m = [0.6, -0.3, 0.0]
size_m = [0.02, 0.5, 0.2]

[[obstacles]]
name = "wall_high"
type = "box"
center_m = [0.6, 0.35, 0.0]
size_m = [0.02, 0.5, 0.2]

[[goals]]
name = "behind"
p_m = [0.8, 0.3, 0.0]
n = [0.0, 1.0, 0.0]
pos_tol_m = 0.005
angle_tol_deg = 5.0
"""


def thin_chain(folder: Path, radius_m: float = 0.001) -> Problem:
    """The thin chain's problem, written into ``folder``: the chain curled (a quarter
    turn a link... 0.25 rad) before a wall with a 15-cm slot, its goal behind the wall."""
    (folder / "thin_chain.urdf").write_text(chain_urdf(N_LINKS, LINK_M, radius_m), "utf-8")
    start = ", ".join(["0.25"] * N_LINKS)
    path = folder / "thin_chain.toml"
    path.write_text(PROBLEM_TOML.format(start=start), "utf-8")
    return load_problem(path)


@pytest.fixture(scope="module")
def chain(tmp_path_factory) -> Problem:
    return thin_chain(tmp_path_factory.mktemp("thin_chain"))


def _urdf_planners() -> list[str]:
    return [n for n, e in REGISTRY.items() if e.robots is None or "urdf" in e.robots]


#: a larger step than the contract's: the thin chain's descents evaluate a field of
#: 1 000 spheres per state, so fewer looks at the clock keep the test short
READ_S = 0.01
TIME_LIMIT_S = 0.5


@pytest.mark.parametrize("name", _urdf_planners())
def test_every_planner_returns_within_its_time_limit_on_a_thin_chain(chain, name):
    r, t_s, clock = timed_solve(name, chain, TIME_LIMIT_S, read_s=READ_S)
    slack = TIME_LIMIT_S * 0.01 + LOOP_READS * READ_S + LOOP_CHECKS * CHECK_S
    assert t_s <= TIME_LIMIT_S + slack, (t_s, clock.reads, r.status, r.reason)
    assert r.status is not Status.INVALID_START, r.reason
    if r.status is Status.BUDGET_EXHAUSTED:
        assert "time limit" in r.reason, r.reason


def test_the_clearance_field_of_a_thin_chain_is_capped_and_arm_zs_is_not(chain, tmp_path):
    field = ClearanceField(chain.robot, chain.scene, 0.01)
    # 0.4 r spacing would take 251 spheres a link; capped, every link alike
    assert len(field._t) <= MAX_SPHERES
    assert len(field._t) > MAX_SPHERES - 2 * N_LINKS  # the common spacing uses the cap
    counts = np.bincount(field._link)[1:]  # the chain's links (the base is a sphere)
    assert counts.max() - counts.min() <= 1  # one spacing for all (lengths round)
    finer = ClearanceField(thin_chain(tmp_path, radius_m=1e-4).robot, chain.scene, 0.01)
    assert len(finer._t) == len(field._t)  # a tenth of the radius: the same cap
    armz = load_problem("armz_inspection")
    field = ClearanceField(armz.robot, armz.scene, 0.3)
    # Arm-Z: 4 spheres a 0.716-m module of radius 0.75 m (0.3 m apart), 3 on its base
    assert np.array_equal(np.bincount(field._link), [3] + [4] * 23)


@pytest.mark.parametrize(
    "name", ["problems/urdf/panda/bookshelf_small_0001.toml", "irb6_case1", "armz_pocket"]
)
def test_the_fields_spheres_and_pairs_are_the_rule_written_out(name):
    """The field's spheres (evenly spaced on each link, both ends included) and its self
    pairs (built in whole arrays) against the rule written out link by link: every pair
    a < b of spheres on two different links that are checked against each other (not
    both fixed, not an excluded pair), in order of a, then b."""
    problem = load_problem(name)
    robot = problem.robot
    field = ClearanceField(robot, problem.scene, 0.1)
    counts = np.bincount(field._link, minlength=len(robot.link_radii_m))
    for i, k in enumerate(counts):
        np.testing.assert_allclose(field._t[field._link == i], np.linspace(0.0, 1.0, k))
    fixed = set(robot.fixed_links)
    excluded = {frozenset(p) for p in robot.excluded_pairs}
    want = [
        (a, b)
        for a in range(len(field._link))
        for b in range(a + 1, len(field._link))
        if field._link[a] != field._link[b]
        and not (field._link[a] in fixed and field._link[b] in fixed)
        and frozenset((int(field._link[a]), int(field._link[b]))) not in excluded
    ]
    assert len(want) > 0
    assert list(zip(field._self_a.tolist(), field._self_b.tolist(), strict=True)) == want


def test_a_field_whose_time_is_up_stops_and_the_planner_says_why(chain):
    with pytest.raises(SetupStopped, match="time is up"):
        ClearanceField(chain.robot, chain.scene, 0.01, stop=lambda: True)
    reads = iter([0.0])  # the tracker starts at 0; every later look says 1 s

    def clock() -> float:
        return next(reads, 1.0)

    r = make_planner("gradient.clearance").solve(
        chain, 0, Budget(time_limit_s=0.5, clock=clock), np.random.default_rng(0)
    )
    assert r.status is Status.BUDGET_EXHAUSTED
    assert "time limit of 0.5 s reached" in r.reason and "clearance field" in r.reason
    assert r.iterations == 0


def test_a_grid_past_the_cap_is_coarsened_or_refused(chain):
    extent = np.array([2.0, 2.0, 0.2])  # the thin chain's search box, about
    fine = 0.0005  # half the tip's radius
    assert grid_voxels(extent, fine) > 1e9
    voxel = grid_voxel_m(extent, fine, 1_000_000)
    assert grid_voxels(extent, voxel) <= 1_000_000
    assert voxel < 1.1 * grid_voxel_m(extent, voxel * 0.9, 1_000_000)  # about the finest
    with pytest.raises(PlannerlabError, match="max_voxels = 1000000"):
        grid_voxel_m(extent, fine, 1_000_000, voxel_set=True)
    # a grid within the cap is left as asked
    assert grid_voxel_m(extent, 0.05, 1_000_000) == 0.05
    # the planner: its leader's grid on the thin chain is coarsened to the cap, and a
    # voxel set finer than the cap allows is refused with the setting's name
    planner = make_planner("gradient.follow_leader", {"max_voxels": "100000"})
    leader = planner.leader_path(chain, 0, chain.q_start, None)
    assert leader is not None  # through the slot, on a grid of at most 1e5 voxels
    assert 0 < leader.free_voxels <= 100_000
    strict = make_planner("gradient.follow_leader", {"voxel_m": "0.0005"})
    with pytest.raises(PlannerlabError, match="voxel_m = 0.0005 m"):
        strict.leader_path(chain, 0, chain.q_start, None)

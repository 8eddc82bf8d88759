"""OMPL's KinematicChain benchmark as plannerlab problems (plannerlab/problem/
kinematic_chain.py, `plannerlab import kinematic-chain`): the demo's horn, start and goal,
the chain as a URDF, the problem as the checker sees it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import plannerlab as pl
from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.errors import PlannerlabError
from plannerlab.problem import kinematic_chain as kc

DATA = Path(__file__).resolve().parents[1] / "data"


def test_the_horn_is_the_demos():
    """createHornEnvironment(N, ln N / N): two polylines of N - 1 segments from
    (1/N, ∓eps), turning by π/N before each, the outer one scaled by 1 + π eps."""
    n = 10
    seg = kc.horn_segments(n)
    eps = math.log(n) / n
    assert seg.shape == (2 * (n - 1), 4)
    assert seg[0, :2] == pytest.approx([0.1, -eps])
    assert seg[n - 1, :2] == pytest.approx([0.1, eps])
    outer = np.hypot(seg[: n - 1, 2] - seg[: n - 1, 0], seg[: n - 1, 3] - seg[: n - 1, 1])
    inner = np.hypot(seg[n - 1 :, 2] - seg[n - 1 :, 0], seg[n - 1 :, 3] - seg[n - 1 :, 1])
    assert outer == pytest.approx(np.full(n - 1, 0.1 * (1 + math.pi * eps)))
    assert inner == pytest.approx(np.full(n - 1, 0.1 * (1 - math.pi * eps)))
    heading = np.arctan2(seg[: n - 1, 3] - seg[: n - 1, 1], seg[: n - 1, 2] - seg[: n - 1, 0])
    assert np.diff(np.unwrap(heading)) == pytest.approx(np.full(n - 2, math.pi / n))
    # polylines: each segment starts where the last ended
    assert seg[1 : n - 1, :2] == pytest.approx(seg[: n - 2, 2:])


def test_start_and_goal_are_the_demos():
    q_start, q_goal = kc.start_goal(20)
    assert q_start[0] == 0.0 and q_start[1:] == pytest.approx(np.full(19, math.pi / 20))
    assert q_goal[0] == pytest.approx(math.pi - 0.001) and not q_goal[1:].any()


@pytest.fixture(scope="module")
def chain10(tmp_path_factory):
    out = tmp_path_factory.mktemp("kc")
    problem = pl.load_problem(kc.write_problem(10, out))
    return problem, problem_checker(problem)


def test_the_problem_loads_with_its_robot_scene_start_and_goal(chain10):
    problem, checker = chain10
    robot = problem.robot
    assert robot.dof == 10 and bool(np.all(robot.continuous))
    assert len(problem.scene.obstacles) == 18
    q_start, q_goal = kc.start_goal(10)
    assert np.allclose(problem.q_start, q_start)
    goal = problem.goals[0]
    assert np.allclose(goal.q_rad, q_goal)
    # the chain's joints lie on its links' capsules, 1/N apart, the tip at the end
    segs = robot.link_segments(q_goal)
    assert segs.shape[0] == 10
    assert np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1) == pytest.approx(np.full(10, 0.1))
    assert segs[-1, 1] == pytest.approx([math.cos(math.pi - 0.001), math.sin(math.pi - 0.001), 0])
    assert problem.joint_step == pytest.approx(0.05)
    assert checker.margin_m == 0.0


def test_start_and_goal_are_free_and_the_horn_is_in_the_way(chain10):
    problem, checker = chain10
    q_start, q_goal = kc.start_goal(10)
    assert checker.is_valid(q_start) and checker.is_valid(q_goal)
    # the straight motion from start to goal sweeps the chain through the inner wall
    straight = np.array([q_start, q_goal])
    assert not checker.check_path(straight, 0.0125, mode="grid").valid
    # folding the chain onto itself collides (a non-adjacent pair crosses)
    folded = q_start.copy()
    folded[3] = math.pi - 0.05
    folded[4] = math.pi - 0.05
    assert not checker.is_valid(folded)


def test_a_known_free_path_is_free(chain10):
    """A path C++ OMPL's KPIECE1 found with its own 2-D checker (bench/kinematic_chain/
    chain_ompl.cpp, tests/data/kinematic_chain_10_path.json) is free for plannerlab's
    checker on the grid at 0.0125 rad, start to goal; with its middle waypoint's links
    pushed through the walls it is not."""
    problem, checker = chain10
    data = json.loads((DATA / "kinematic_chain_10_path.json").read_text())
    P = np.array(data["path_rad"])
    q_start, q_goal = kc.start_goal(10)
    assert np.allclose(P[0], q_start) and np.allclose(P[-1], q_goal)
    check = checker.check_path(P, 0.0125, mode="grid")
    assert check.complete and check.valid, check.first_invalid_edge
    assert check.states_checked > 200
    bent = P.copy()
    bent[len(P) // 2, 1:] = q_start[1:] * 1.5  # curled tighter than the inner wall
    assert not checker.check_path(bent, 0.0125, mode="grid").valid


def test_the_urdf_and_problem_file_are_written_atomically_and_bad_input_is_refused(tmp_path):
    target = kc.write_problem(12, tmp_path, safety_margin_m=0.01, joint_step_rad=0.02)
    assert target.name == "kinematic_chain_12.toml"
    assert (tmp_path / "kinematic_chain_12.urdf").read_text().count('type="continuous"') == 12
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "kinematic_chain_12.toml",
        "kinematic_chain_12.urdf",
    ]
    problem = pl.load_problem(target)
    assert problem.safety_margin_m == pytest.approx(0.01)
    for bad in (1, 0, 2.5, True, 1000):
        with pytest.raises(PlannerlabError, match="links"):
            kc.write_problem(bad, tmp_path)  # type: ignore[arg-type]
    with pytest.raises(PlannerlabError, match="wall_thickness_m"):
        kc.problem_toml(10, urdf="x.urdf", wall_thickness_m=float("nan"))
    with pytest.raises(PlannerlabError, match="safety_margin_m"):
        kc.problem_toml(10, urdf="x.urdf", safety_margin_m=-1.0)
    (tmp_path / "file").write_text("")
    with pytest.raises(PlannerlabError, match="folder"):
        kc.write_problem(10, tmp_path / "file")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--links", "10", "1"], "--links: each N must be in 2 … 200 links, got 1"),
        (["--links", "201"], "--links: each N must be in 2 … 200 links, got 201"),
        (["--links", "x"], "argument --links: invalid int value: 'x'"),
        (["--links", "10", "--time-limit", "-1"], "time_limit_s must be a finite number > 0"),
        (["--links", "10", "--joint-step", "nan"], "joint_step"),
    ],
)
def test_the_import_command_refuses_bad_input_naming_the_flag_and_writes_nothing(
    tmp_path, capsys, argv, message
):
    """``plannerlab import kinematic-chain``: a bad N, time limit or step is refused with
    exit code 2 and a message naming what was expected; no file is written, not even the
    good N's before a bad one."""
    from plannerlab.cli import main

    out = tmp_path / "out"
    try:
        code = main(["import", "kinematic-chain", *argv, "--out", str(out)])
    except SystemExit as stop:  # argparse's own refusals
        code = stop.code
    err = " ".join(capsys.readouterr().err.split())
    assert code == 2
    assert message in err
    assert not out.exists() or not any(out.iterdir())

"""OMPL's repair of a path that fails plannerlab's re-check (issue 19: MotionBenchMaker's
INVALID_PATH were simplified paths pulled taut against an obstacle, grazing it between the
states checked at ``joint_step``).

A Panda swings its hand past a 3 mm board, with motions checked every 0.2 rad: a motion
can step over the board between two checked states, and the re-check at 0.05 rad refuses
it. The repair makes a sound path of it. Each solve runs in a fresh process (the CLI):
OMPL's seed takes effect only before its first generator exists.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.load import parse_problem

PANDA = ROOT / "problems" / "urdf" / "panda"

BOARD = f"""
[problem]
name = "board"
description = "a 3 mm board in the way of the Panda's hand"

[robot]
type = "urdf"
urdf = "{(PANDA / "panda_spherized.urdf").as_posix()}"
srdf = "{(PANDA / "panda.srdf").as_posix()}"
tip_link = "panda_hand"

[start]
q = [-0.6, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]

[planning]
safety_margin_m = 0.0

[checking]
joint_step = 0.2

[[obstacles]]
name = "board"
type = "box"
center_m = [0.35, 0.0, 0.45]
rpy_deg = [0.0, 0.0, 0.0]
size_m = [0.3, 0.003, 0.3]

[[goals]]
name = "goal"
q = [0.6, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
joint_tol_rad = 0.001
"""


#: seed -> (how the repair went, collision checks of the whole solve). Re-pinned on the
#: certified edges (issue 32): the same repairs; the re-checks count their lanes (1 796 and
#: 3 747 before: a path beside the board proves its stretches in short pieces)
CASES = {
    7: ("the path as planned, simplified again with strict motion checks", 1928),
    3: ("solved again with strict motion checks", 3935),
}


@pytest.mark.parametrize("seed", sorted(CASES))
def test_a_path_that_steps_over_a_board_is_repaired_into_a_sound_one(tmp_path, seed):
    problem_file = tmp_path / "board.toml"
    problem_file.write_text(BOARD, encoding="utf-8")
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "plannerlab",
            "solve",
            str(problem_file),
            "--planner",
            "ompl.rrtconnect",
            "--seed",
            str(seed),
            "--max-checks",
            "50000",
            "--json",
            "--out",
            str(tmp_path / "plan.json"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    leg = json.loads(out.stdout)["legs"][0]
    # the first path went through the board between two checked states: refused ...
    assert "x board" in leg["extra"]["recheck_failed"]
    # ... and repaired
    how, checks = CASES[seed]
    assert (leg["status"], leg["extra"]["repair"], leg["collision_checks"]) == (
        "solved",
        how,
        checks,
    )
    problem = parse_problem(problem_file)
    path = np.array(leg["path"], dtype=float)
    assert path[0] == pytest.approx(problem.q_start)
    assert bool(problem.goals[0].contains(problem.robot, path[-1]))
    # sound: FCL finds nothing on it at half the re-check's step (0.025 rad), nor does the
    # core at an eighth of it
    fcl = CollisionChecker(problem.robot, problem.scene, backend="fcl")
    assert fcl.check_path(path, problem.joint_step / 8).valid
    core = CollisionChecker(problem.robot, problem.scene, backend="core")
    assert core.check_path(path, problem.joint_step / 32).valid
    assert leg["min_clearance_m"] > 0.0

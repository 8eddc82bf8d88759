"""Problem files: the bundled ones load; each kind of bad file gets an error that names
the file, the key and what was expected."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import TINY_PROBLEM_TOML, tiny_problem_text, write_problem

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import ProblemError, UnknownNameError
from plannerlab.problem.catalog import list_problems, load_problem


def test_the_good_file_loads(tmp_path):
    p = load_problem(write_problem(tmp_path, TINY_PROBLEM_TOML))
    assert p.robot.dof == 5 and p.scene.names == ("wall",) and p.goals[0].name == "up"


@pytest.mark.parametrize("path", list_problems(), ids=lambda p: p.stem)
def test_every_bundled_problem_loads_with_a_free_start(path):
    p = load_problem(path)
    assert CollisionChecker(p.robot, p.scene).is_valid(p.q_start)
    assert p.legs >= 1


BAD = {
    "missing_key": (tiny_problem_text('name = "up"\n', ""), "goals[0].name", "missing"),
    "zero_normal": (
        tiny_problem_text("n = [0.0, 0.0, 1.0]", "n = [0.0, 0.0, 0.0]"),
        "goals[0].n",
        "non-zero",
    ),
    "nan": (
        tiny_problem_text("p_m = [0.5, 0.0, 3.0]", "p_m = [0.5, nan, 3.0]"),
        "goals[0].p_m",
        "finite",
    ),
    "wrong_joint_count": (
        tiny_problem_text("fill_deg = 180.0", "q = [0.0, 1.0]"),
        "start.q",
        "5 joint values",
    ),
    "unknown_obstacle_type": (
        tiny_problem_text('type = "box"', 'type = "cone"'),
        "obstacles[0].type",
        "one of box, cylinder, sphere",
    ),
    "unknown_robot_type": (
        tiny_problem_text('type = "armz"', 'type = "armzz"'),
        "robot.type",
        "did you mean 'armz'",
    ),
    "negative_tolerance": (
        tiny_problem_text("pos_tol_m = 0.1", "pos_tol_m = -0.1"),
        "goals[0].pos_tol_m",
        "positive",
    ),
    "string_for_number": (
        tiny_problem_text("angle_tol_deg = 10.0", 'angle_tol_deg = "ten"'),
        "goals[0].angle_tol_deg",
        "a number",
    ),
    "misspelt_key": (
        tiny_problem_text("size_m", "sizes_m"),
        "obstacles[0].sizes_m",
        "not a known key",
    ),
    "no_goals": (TINY_PROBLEM_TOML[: TINY_PROBLEM_TOML.index("[[goals]]")], "goals", "missing"),
    "syntax": (tiny_problem_text("[robot]", "[robot"), "<syntax>", "valid TOML"),
}

START_IN_COLLISION = tiny_problem_text("center_m = [3.0, 0.0, 2.0]", "center_m = [0.5, 0.0, 2.0]")


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_bad_file_names_file_key_and_expectation(tmp_path, case):
    text, key, expected = BAD[case]
    path = write_problem(tmp_path, text)
    with pytest.raises(ProblemError) as err:
        load_problem(path)
    msg = str(err.value)
    assert str(path) in msg
    assert f"[{key}]" in msg
    assert expected in msg
    assert err.value.key == key


def test_a_start_in_collision_is_refused_where_planning_starts(tmp_path):
    """Loading needs no collision checker; planning checks the start once, naming the pairs."""
    from plannerlab.run.pipeline import solve_legs

    problem = load_problem(write_problem(tmp_path, START_IN_COLLISION))
    with pytest.raises(ProblemError) as err:
        solve_legs(problem, "gradient.analytic", 0)
    assert err.value.key == "start" and "module_1 x wall" in str(err.value)
    assert str(problem.source) in str(err.value)


def test_missing_file_and_unknown_problem_name(tmp_path):
    with pytest.raises(ProblemError, match="existing problem file"):
        load_problem(tmp_path / "nope.toml")
    with pytest.raises(UnknownNameError, match="did you mean 'armz_pocket'"):
        load_problem("armz_pockt")


def test_loaded_problem_is_read_only(tmp_path):
    p = load_problem(write_problem(tmp_path, TINY_PROBLEM_TOML))
    with pytest.raises(ValueError):
        p.q_start[0] = 0.0
    assert np.all(p.q_start == np.pi)
    assert re.match(r"^tiny$", p.name)

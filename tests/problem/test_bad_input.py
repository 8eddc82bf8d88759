"""Bad input of every kind gets a clear answer: exit code 2, no traceback, and a message
that names the file and the key (or the flag) that is wrong.

Problem files are a small valid Arm-Z problem with one thing broken; plan files a valid
plan (written here, not planned) with one thing broken; command lines one bad flag each.
Every case runs ``plannerlab`` in-process (an escaped exception would fail the test);
a few run it as a subprocess to see exactly what a user sees.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import PROBLEMS, ROOT, TINY_PROBLEM_TOML, tiny_problem_text, write_problem

from plannerlab.cli.main import main
from plannerlab.planners.base import PlanResult, Status
from plannerlab.problem.load import parse_problem


def run(capsys, *argv: str) -> tuple[int, str, str]:
    """``plannerlab ARGV`` in-process: exit code, stdout, stderr (argparse exits too)."""
    try:
        code = main(list(argv))
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def assert_clean_error(code: int, err: str, *names: str) -> None:
    assert code == 2, err
    assert "Traceback" not in err
    for name in names:
        assert name in err, f"{name!r} not in {err!r}"


def test_the_valid_problem_is_valid(tmp_path):
    problem = parse_problem(write_problem(tmp_path, TINY_PROBLEM_TOML))
    assert problem.name == "tiny" and problem.robot.dof == 5


# --------------------------------------------------------------- problem files
PROBLEM_CASES = {
    # name: (file text, key that must be named)
    "misspelled_table": (
        TINY_PROBLEM_TOML + "\n[simulaton]\ngravity_mps2 = [0, 0, 0]\n",
        "simulaton",
    ),
    "unknown_table": (TINY_PROBLEM_TOML + "\n[extra_stuff]\na = 1\n", "extra_stuff"),
    "touch_links_not_a_link": (
        tiny_problem_text(
            "size_m = [0.4, 4.0, 4.0]", 'size_m = [0.4, 4.0, 4.0]\ntouch_links = ["module_9"]'
        ),
        "obstacles[0].touch_links",
    ),
    "touch_links_not_names": (
        tiny_problem_text(
            "size_m = [0.4, 4.0, 4.0]", 'size_m = [0.4, 4.0, 4.0]\ntouch_links = "module_5"'
        ),
        "obstacles[0].touch_links",
    ),
    "unknown_problem_key": (
        tiny_problem_text('name = "tiny"', 'name = "tiny"\ntitel = "x"'),
        "titel",
    ),
    "missing_problem_name": (tiny_problem_text('name = "tiny"\n', ""), "problem.name"),
    "unknown_robot_type": (tiny_problem_text('type = "armz"', 'type = "armzz"'), "robot.type"),
    "huge_n_modules": (tiny_problem_text("n_modules = 6", "n_modules = 10000"), "robot.n_modules"),
    "n_modules_float": (tiny_problem_text("n_modules = 6", "n_modules = 6.5"), "robot.n_modules"),
    "unknown_robot_key": (
        tiny_problem_text("n_modules = 6", "n_modules = 6\nmodules = 3"),
        "robot.modules",
    ),
    "two_starts": (tiny_problem_text("fill_deg = 180.0", "fill_deg = 180.0\nfill = 3.0"), "start"),
    "start_wrong_length": (tiny_problem_text("fill_deg = 180.0", "q = [1.0, 2.0]"), "start.q"),
    "obstacle_bad_type": (tiny_problem_text('type = "box"', 'type = "cube"'), "obstacles[0].type"),
    "obstacle_negative_size": (
        tiny_problem_text("size_m = [0.4, 4.0, 4.0]", "size_m = [0.4, -4.0, 4.0]"),
        "obstacles[0].size_m",
    ),
    "obstacle_nan_center": (
        tiny_problem_text("center_m = [3.0, 0.0, 2.0]", "center_m = [nan, 0.0, 2.0]"),
        "obstacles[0].center_m",
    ),
    "duplicate_obstacle": (
        TINY_PROBLEM_TOML
        + '\n[[obstacles]]\nname = "wall"\ntype = "sphere"\ncenter_m = [9, 9, 9]\n'
        "radius_m = 0.5\n",
        "obstacles[1].name",
    ),
    "no_goals": (
        TINY_PROBLEM_TOML.split("[[goals]]")[0] + "[budget]\nmax_iterations = 5\n",
        "goals",
    ),
    "duplicate_goal_names": (
        TINY_PROBLEM_TOML
        + '\n[[goals]]\nname = "up"\np_m = [1, 0, 3]\nn = [0, 0, 1]\npos_tol_m = 0.1\n'
        "angle_tol_deg = 10\n",
        "goals[1].name",
    ),
    "numeric_goal_name": (tiny_problem_text('name = "up"', 'name = "3"'), "goals[0].name"),
    "empty_goal_name": (tiny_problem_text('name = "up"', 'name = " "'), "goals[0].name"),
    "angle_tol_270": (
        tiny_problem_text("angle_tol_deg = 10.0", "angle_tol_deg = 270"),
        "angle_tol_deg",
    ),
    "negative_pos_tol": (
        tiny_problem_text("pos_tol_m = 0.1", "pos_tol_m = -0.1"),
        "goals[0].pos_tol_m",
    ),
    "zero_normal": (tiny_problem_text("n = [0.0, 0.0, 1.0]", "n = [0.0, 0.0, 0.0]"), "goals[0].n"),
    "unknown_goal_key": (
        tiny_problem_text("pos_tol_m = 0.1", "pos_tol_m = 0.1\ntol = 1"),
        "goals[0].tol",
    ),
    "zero_check_budget": (
        tiny_problem_text("max_iterations = 50", "max_collision_checks = 0"),
        "budget.max_collision_checks",
    ),
    "unknown_budget_key": (
        tiny_problem_text("max_iterations = 50", "max_checks = 50"),
        "budget.max_checks",
    ),
    "tiny_joint_step": (
        tiny_problem_text("joint_step = 0.05", "joint_step = 1e-9"),
        "checking.joint_step",
    ),
    "huge_joint_step": (
        tiny_problem_text("joint_step = 0.05", "joint_step = 10.0"),
        "checking.joint_step",
    ),
    "negative_safety_margin": (
        TINY_PROBLEM_TOML + "\n[planning]\nsafety_margin_m = -0.01\n",
        "planning.safety_margin_m",
    ),
    "tiny_safety_margin": (
        TINY_PROBLEM_TOML + "\n[planning]\nsafety_margin_m = 1e-6\n",
        "planning.safety_margin_m",
    ),
    "huge_safety_margin": (
        TINY_PROBLEM_TOML + "\n[planning]\nsafety_margin_m = 2.0\n",
        "planning.safety_margin_m",
    ),
    "text_safety_margin": (
        TINY_PROBLEM_TOML + '\n[planning]\nsafety_margin_m = "1 cm"\n',
        "planning.safety_margin_m",
    ),
    "unknown_planning_key": (
        TINY_PROBLEM_TOML + "\n[planning]\nmargin_m = 0.01\n",
        "planning.margin_m",
    ),
    "gravity_two_numbers": (
        TINY_PROBLEM_TOML + "\n[simulation]\ngravity_mps2 = [0, -9.81]\n",
        "simulation.gravity_mps2",
    ),
    "deviation_limit_negative": (
        TINY_PROBLEM_TOML + "\n[simulation]\nmax_deviation_m = -0.01\n",
        "simulation.max_deviation_m",
    ),
    "deviation_limit_zero": (
        TINY_PROBLEM_TOML + "\n[simulation]\nmax_deviation_m = 0\n",
        "simulation.max_deviation_m",
    ),
    "deviation_limit_text": (
        TINY_PROBLEM_TOML + '\n[simulation]\nmax_deviation_m = "1 cm"\n',
        "simulation.max_deviation_m",
    ),
    "witness_wrong_joint_count": (
        TINY_PROBLEM_TOML
        + "\n[witness]\npath_rad = [[3.14, 3.14, 3.14, 3.14, 3.14], [1.0, 2.0]]\n",
        "witness.path_rad[1]",
    ),
    "witness_one_waypoint": (
        TINY_PROBLEM_TOML + "\n[witness]\npath_rad = [[3.14, 3.14, 3.14, 3.14, 3.14]]\n",
        "witness.path_rad",
    ),
    "witness_neither_path_nor_states": (
        TINY_PROBLEM_TOML + '\n[witness]\nnote = "empty"\n',
        "witness.path_rad",
    ),
    "witness_goal_states_wrong_count": (
        TINY_PROBLEM_TOML
        + "\n[witness]\ngoal_states_rad = [[3.14, 3.14, 3.14, 3.14, 3.14],"
        + " [3.14, 3.14, 3.14, 3.14, 3.14]]\n",
        "witness.goal_states_rad",
    ),
    "witness_goal_state_wrong_joint_count": (
        TINY_PROBLEM_TOML + "\n[witness]\ngoal_states_rad = [[3.14, 3.14]]\n",
        "witness.goal_states_rad[0]",
    ),
    "witness_goal_state_outside_its_goal": (
        # the straight column's tip is 3.6 m up, not at the goal (0.5, 0, 3)
        TINY_PROBLEM_TOML
        + "\n[witness]\ngoal_states_rad = [[3.1416, 3.1416, 3.1416, 3.1416, 3.1416]]\n",
        "witness.goal_states_rad[0]",
    ),
    "witness_negative_clearance": (
        TINY_PROBLEM_TOML
        + "\n[witness]\npath_rad = [[3.14, 3.14, 3.14, 3.14, 3.14], [3.1, 3.1, 3.1, 3.1, 3.1]]\n"
        + "clearance_floor_m = -0.1\n",
        "witness.clearance_floor_m",
    ),
    "continuum_nan_point": (
        TINY_PROBLEM_TOML + "\n[continuum]\ncollision_points_m = [[0.1, 0.2], [nan, 0.2]]\n",
        "continuum.collision_points_m[1]",
    ),
    "continuum_unknown_guide": (
        TINY_PROBLEM_TOML + '\n[continuum]\nguide_obstacles = ["sleeve"]\n',
        "continuum.guide_obstacles",
    ),
    "continuum_unknown_key": (
        TINY_PROBLEM_TOML + "\n[continuum]\ncollision_point_m = [[0.1, 0.2]]\n",
        "continuum.collision_point_m",
    ),
    "toml_syntax": (TINY_PROBLEM_TOML + "\n[goals\n", "<syntax>"),
    "latin1_text": (tiny_problem_text("a short", "café, a short").encode("latin-1"), "<encoding>"),
    "binary_file": (bytes(range(256)) * 4, "<encoding>"),
}


@pytest.mark.parametrize("case", sorted(PROBLEM_CASES))
def test_bad_problem_file(capsys, tmp_path, case):
    text, key = PROBLEM_CASES[case]
    path = write_problem(tmp_path, text)
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, str(path), key)


def test_a_touch_link_that_is_no_link_is_named_with_the_links_it_could_be(capsys, tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["touch_links_not_a_link"][0])
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    # the tiny Arm-Z has modules 0 to 5: the message says which name is wrong and lists them
    assert_clean_error(code, err, "'module_9' is not one", "module_0, module_1", "module_5")


def test_touch_links_naming_the_robots_links_load(tmp_path):
    text = tiny_problem_text(
        "size_m = [0.4, 4.0, 4.0]",
        'size_m = [0.4, 4.0, 4.0]\ntouch_links = ["module_5", "module_4"]',
    )
    problem = parse_problem(write_problem(tmp_path, text))
    assert problem.scene.obstacles[0].touch_links == ("module_5", "module_4")


def test_misspelled_table_suggests_the_right_one(capsys, tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["misspelled_table"][0])
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, "did you mean 'simulation'")


def test_tiny_safety_margin_is_refused_with_the_cost(capsys, tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["tiny_safety_margin"][0])
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, "collision checks", "0 (no margin)")


def test_huge_robot_is_refused_with_the_cost(capsys, tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["huge_n_modules"][0])
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, "<= 100", "10000")


def test_tiny_joint_step_is_refused_with_the_cost(capsys, tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["tiny_joint_step"][0])
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, "collision checks")


def test_directory_as_problem_file(capsys, tmp_path):
    code, _, err = run(capsys, "solve", str(tmp_path), "--planner", "gradient")
    assert_clean_error(code, err, str(tmp_path), "directory")


def test_missing_problem_file(capsys, tmp_path):
    path = tmp_path / "nope.toml"
    code, _, err = run(capsys, "solve", str(path), "--planner", "gradient")
    assert_clean_error(code, err, str(path), "<file>")


def test_unknown_problem_name(capsys):
    code, _, err = run(capsys, "solve", "armz_pockt", "--planner", "gradient")
    assert_clean_error(code, err, "armz_pockt", "did you mean 'armz_pocket'")


# --------------------------------------------------------------- command lines
POCKET = str(PROBLEMS / "armz_pocket.toml")

CLI_CASES = {
    "seed_negative": (["--seed", "-1"], "--seed"),
    "seed_not_a_number": (["--seed", "abc"], "--seed"),
    "max_checks_zero": (["--max-checks", "0"], "--max-checks"),
    "max_checks_negative": (["--max-checks", "-5"], "--max-checks"),
    "max_checks_float": (["--max-checks", "2.5"], "--max-checks"),
    "max_iterations_zero": (["--max-iterations", "0"], "--max-iterations"),
    "time_limit_negative": (["--time-limit", "-1"], "--time-limit"),
    "time_limit_nan": (["--time-limit", "nan"], "--time-limit"),
    "time_limit_inf": (["--time-limit", "inf"], "--time-limit"),
    "time_limit_zero": (["--time-limit", "0"], "--time-limit"),
    "legs_empty": (["--legs", ""], "--legs"),
    "legs_empty_item": (["--legs", "0,,1"], "--legs"),
    "legs_out_of_range": (["--legs", "5"], "--legs"),
    "legs_unknown_name": (["--legs", "pockett"], "--legs"),
    "legs_twice": (["--legs", "0,pocket"], "--legs"),
    "unknown_planner": (["--planner", "ompl.rrtconect"], "ompl.rrtconnect"),
    "unknown_setting": (["--set", "no_such_setting=3"], "no_such_setting"),
    "set_without_equals": (["--set", "alpha"], "--set"),
    "goal_selection_unknown": (
        ["--planner", "ompl.rrtconnect", "--set", "goal_selection=far"],
        "goal_selection",
    ),
    "descent_backend_unknown": (
        ["--planner", "gradient.clearance", "--set", "backend=cuda"],
        "backend",
    ),
}


@pytest.mark.parametrize("case", sorted(CLI_CASES))
def test_bad_command_line(capsys, case):
    extra, name = CLI_CASES[case]
    argv = ["solve", POCKET, *(["--planner", "gradient"] if "--planner" not in extra else [])]
    code, _, err = run(capsys, *argv, *extra)
    assert_clean_error(code, err, name)


@pytest.mark.parametrize(
    "extra,name",
    [
        (["--jobs", "0"], "--jobs"),
        (["--max-checks", "0"], "--max-checks"),
        (["--time-limit", "nan"], "--time-limit"),
        (["--legs", "7"], "--legs"),
        (["--seeds", "x"], "--seeds"),
    ],
    ids=["jobs", "max_checks", "time_limit", "legs", "seeds"],
)
def test_bad_compare_command_line(capsys, tmp_path, extra, name):
    code, _, err = run(
        capsys, "compare", POCKET, "--planners", "gradient", "--out", str(tmp_path), *extra
    )
    assert_clean_error(code, err, name)


@pytest.mark.parametrize(
    "extra,name",
    [
        (["--count", "0"], "--count"),
        (["--seed", "-3"], "--seed"),
        (["--clearance-floor", "-0.01"], "--clearance-floor"),
        (["--clearance-floor", "0.8"], "--clearance-floor"),
        (["--max-draws", "0"], "--max-draws"),
    ],
    ids=["count_zero", "seed_negative", "clearance_negative", "clearance_too_big", "draws_zero"],
)
def test_bad_variants_command_line(capsys, tmp_path, extra, name):
    code, _, err = run(capsys, "variants", "armz_inspection", "--out", str(tmp_path), *extra)
    assert_clean_error(code, err, name)


def test_variants_of_an_unknown_task_and_onto_a_file_are_refused(capsys, tmp_path):
    code, _, err = run(capsys, "variants", "armz_pocket", "--out", str(tmp_path))
    assert_clean_error(code, err, "armz_inspection")
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    code, _, err = run(capsys, "variants", "armz_inspection", "--count", "1", "--out", str(blocker))
    assert_clean_error(code, err, "--out", str(blocker))
    assert blocker.read_text() == "x"


def test_variants_that_cannot_all_be_kept_fail_with_the_count(capsys, tmp_path):
    # a clearance no witness of this room keeps: every draw is dropped, and the error says so
    code, _, err = run(
        capsys,
        "variants",
        "armz_inspection",
        "--count",
        "1",
        "--max-draws",
        "1",
        "--clearance-floor",
        "0.7",
        "--out",
        str(tmp_path / "v"),
    )
    assert_clean_error(code, err, "0 of 1 variants kept in 1 draws")
    assert "dropped" in err
    assert not (tmp_path / "v").exists()


def test_out_into_an_impossible_path_fails_before_planning(capsys, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    out = blocker / "sub" / "plan.json"
    code, _, err = run(capsys, "solve", POCKET, "--planner", "gradient", "--out", str(out))
    assert_clean_error(code, err, str(blocker))


@pytest.mark.parametrize("flag", ["--out", "--figures"])
def test_continuum_folder_onto_a_file_fails_before_the_runs(capsys, tmp_path, flag):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    # checked before any case is loaded: the bad case name would be the error otherwise
    code, _, err = run(capsys, "continuum", "no_such_case", "--runs", "1", flag, str(blocker))
    assert_clean_error(code, err, str(blocker))


# --------------------------------------------------------------- plan files
def _valid_plan(tmp_path: Path) -> dict:
    """A plan of armz_pocket (23 joints) with a short straight path, written by hand."""
    problem = parse_problem(PROBLEMS / "armz_pocket.toml")
    q0 = problem.q_start
    path = np.array([q0, q0 + 0.01, q0 + 0.02])
    r = PlanResult("gradient", problem.name, 0, "pocket", Status.FAILED, "hand-made", path)
    return {
        "format": "plannerlab.plan/1",
        "problem": problem.name,
        "problem_file": str(PROBLEMS / "armz_pocket.toml"),
        "planner": "gradient",
        "seed": 0,
        "budget": {},
        "legs": [r.to_dict()],
        "executions": [],
    }


def _plan_file(tmp_path: Path, data: dict | str | bytes) -> Path:
    p = tmp_path / "plan.json"
    if isinstance(data, bytes):
        p.write_bytes(data)
    else:
        p.write_text(data if isinstance(data, str) else json.dumps(data), encoding="utf-8")
    return p


def _broken(tmp_path: Path, how: str) -> dict | str | bytes:
    d = _valid_plan(tmp_path)
    if how == "no_legs":
        d["legs"] = []
    elif how == "legs_not_a_list":
        d["legs"] = 3
    elif how == "wrong_joint_count":
        d["legs"][0]["path"] = [[3.14] * 5, [3.0] * 5]
    elif how == "nan_in_path":
        d["legs"][0]["path"][1][4] = float("nan")
    elif how == "leg_out_of_range":
        d["legs"][0]["leg"] = 4
    elif how == "wrong_format":
        d["format"] = "something/9"
    elif how == "missing_planner":
        del d["planner"]
    elif how == "not_json":
        return "{not json"
    elif how == "binary":
        return bytes(range(256))
    return d


PLAN_CASES = {
    "no_legs": "legs",
    "legs_not_a_list": "legs",
    "wrong_joint_count": "legs[0].path",
    "nan_in_path": "legs[0].path[1]",
    "leg_out_of_range": "legs[0].leg",
    "wrong_format": "format",
    "missing_planner": "planner",
    "not_json": "JSON",
    "binary": "<encoding>",
}


@pytest.mark.parametrize("command", ["plot", "execute"])
@pytest.mark.parametrize("case", sorted(PLAN_CASES))
def test_bad_plan_file(capsys, tmp_path, case, command):
    path = _plan_file(tmp_path, _broken(tmp_path, case))
    code, _, err = run(capsys, command, str(path), "--out", str(tmp_path / "o"))
    assert_clean_error(code, err, str(path), PLAN_CASES[case])


def test_directory_as_plan_file(capsys, tmp_path):
    d = tmp_path / "x.json"
    d.mkdir()
    code, _, err = run(capsys, "plot", str(d))
    assert_clean_error(code, err, str(d), "directory")


# --------------------------------------------------------------- as a user sees it
def test_subprocess_shows_one_error_line_and_no_traceback(tmp_path):
    path = write_problem(tmp_path, PROBLEM_CASES["latin1_text"][0])
    proc = subprocess.run(
        [sys.executable, "-m", "plannerlab", "solve", str(path), "--planner", "gradient"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert proc.stderr.startswith("error:") and "<encoding>" in proc.stderr
    assert proc.stdout == ""


# --------------------------------------------------------------- right diagnoses
def test_goal_beyond_the_arm_is_unreachable_before_planning(capsys, tmp_path):
    far = tiny_problem_text("p_m = [0.5, 0.0, 3.0]", "p_m = [100.0, 0.0, 3.0]")
    path = write_problem(tmp_path, far)
    code, out, _ = run(
        capsys,
        "solve",
        str(path),
        "--planner",
        "ompl.rrtconnect",
        "--json",
        "--out",
        str(tmp_path / "plan.json"),
    )
    assert code == 0
    leg = json.loads(out)["legs"][0]
    assert leg["status"] == "unreachable"
    assert leg["collision_checks"] == 0 and "reaches at most" in leg["reason"]


@pytest.mark.parametrize("planner", ["gradient", "ompl.rrtconnect"])
@pytest.mark.parametrize("goal", ["p_m = [0.5, 0.0, 3.0]", "p_m = [100.0, 0.0, 3.0]"])
def test_a_colliding_start_is_refused_with_the_file_and_the_key(capsys, tmp_path, planner, goal):
    """The wall through the column: the problem's start collides without the margin, so
    the problem is bad input, whether the first leg is planned or out of reach."""
    text = tiny_problem_text("center_m = [3.0, 0.0, 2.0]", "center_m = [0.0, 0.0, 2.0]")
    path = write_problem(tmp_path, text.replace("p_m = [0.5, 0.0, 3.0]", goal))
    code, _, err = run(capsys, "solve", str(path), "--planner", planner)
    assert_clean_error(code, err, str(path), "start", "wall")


def test_a_start_within_the_margin_is_the_planners_invalid_start(capsys, tmp_path):
    """The wall 5 mm from the column: free, but inside the 1-cm clearance margin. Not bad
    input: the leg's one start check (with the margin) says why it cannot start."""
    text = tiny_problem_text("center_m = [3.0, 0.0, 2.0]", "center_m = [0.955, 0.0, 2.0]")
    path = write_problem(tmp_path, text)
    code, out, err = run(capsys, "solve", str(path), "--planner", "gradient", "--json")
    assert code == 0, err
    leg = json.loads(out)["legs"][0]
    assert leg["status"] == "invalid_start" and "wall" in leg["reason"]
    assert leg["collision_checks"] == 2  # the start checked once, and its pairs named


def test_irb6_goal_off_the_track_is_unreachable(tmp_path):
    from plannerlab.problem.goals import unreachable_reason

    problem = parse_problem(PROBLEMS / "irb6_case1.toml")
    goal = problem.goals[0]
    assert unreachable_reason(problem.robot, goal) is None
    T = problem.robot.T_world_base
    far = type(goal)(
        "far", T[:3, :3] @ [0.3, 0.9, 25.0] + T[:3, 3], goal.n_world, goal.pos_tol_m, 10.0
    )
    why = unreachable_reason(problem.robot, far)
    assert why is not None and "track" in why


def test_every_bundled_goal_passes_the_reach_check():
    from plannerlab.problem.catalog import list_problems
    from plannerlab.problem.goals import unreachable_reason

    for f in list_problems():
        p = parse_problem(f)
        for g in p.goals:
            assert unreachable_reason(p.robot, g) is None, (f, g.name)


def test_reach_bound_holds_for_random_armz_states():
    """The bound is a bound: no random state's tip lies beyond it."""
    from plannerlab.problem.goals import GoalRegion, unreachable_reason

    problem = parse_problem(PROBLEMS / "armz_pocket.toml")
    rng = np.random.default_rng(0)
    for q in rng.uniform(-np.pi, np.pi, (200, problem.robot.dof)):
        p, n = problem.robot.tip(q)
        assert unreachable_reason(problem.robot, GoalRegion("g", p, n, 1e-6, 1.0)) is None


def test_armz_without_simulation_table_runs_gravity_free_and_says_so(tmp_path):
    problem = parse_problem(write_problem(tmp_path, TINY_PROBLEM_TOML))
    assert problem.simulation.gravity_mps2 == (0.0, 0.0, 0.0)
    assert "gravity off" in problem.simulation.origin


def test_base_rpy_without_base_xyz_is_honoured(tmp_path):
    text = tiny_problem_text("n_modules = 6", "n_modules = 6\nbase_rpy_deg = [0.0, 0.0, 90.0]")
    problem = parse_problem(write_problem(tmp_path, text))
    assert np.allclose(problem.robot.T_world_base[:3, 3], 0.0)
    assert np.allclose(problem.robot.T_world_base[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)


def test_problem_names_resolve_from_the_working_directory_first(tmp_path, monkeypatch):
    from plannerlab.problem.catalog import resolve_problem_path

    (tmp_path / "problems").mkdir()
    mine = write_problem(tmp_path / "problems", TINY_PROBLEM_TOML, "armz_pocket.toml")
    monkeypatch.chdir(tmp_path)
    assert resolve_problem_path("armz_pocket").resolve() == mine.resolve()


SUBCOMMANDS = (
    "problems",
    "planners",
    "solve",
    "execute",
    "plot",
    "ik",
    "compare",
    "continuum",
    "variants",
)


def test_help_lists_every_subcommand_and_has_no_markup(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0
    for name in SUBCOMMANDS:
        assert f"    {name} " in out, name
    for name in SUBCOMMANDS:
        code, out, _ = run(capsys, name, "--help")
        assert code == 0 and "``" not in out and ":func:" not in out, name
        assert "usage: plannerlab " + name in out


def test_help_shows_defaults(capsys):
    _, out, _ = run(capsys, "solve", "--help")
    text = " ".join(out.split())
    assert "(default: 0)" in text  # --seed
    assert "[budget]" in text  # budget flags: the problem file's budget
    _, out, _ = run(capsys, "compare", "--help")
    assert "(default 1)" in " ".join(out.split())  # --jobs


def test_too_small_a_budget_is_reported_as_the_budget():
    """Not as an invalid goal: the budget ran out before IK could find a goal state."""
    from conftest import small_armz_problem

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget

    problem = small_armz_problem()
    r = make_planner("ompl.rrtconnect").solve(
        problem, 0, Budget(max_collision_checks=2), np.random.default_rng(0)
    )
    assert r.status is Status.BUDGET_EXHAUSTED, r.reason
    assert "collision-check budget of 2" in r.reason and r.collision_checks <= 2


# --------------------------------------------------------------- URDF robots
_PANDA = ROOT / "problems" / "urdf" / "panda"
URDF_PROBLEM_TOML = f"""\
[problem]
name = "panda"
[robot]
type = "urdf"
urdf = "{(_PANDA / "panda_spherized.urdf").as_posix()}"
srdf = "{(_PANDA / "panda.srdf").as_posix()}"
tip_link = "panda_hand"
[start]
q = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
[[goals]]
name = "g"
q = [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]
"""

URDF_CASES = {
    # name: (replace this, with that, what the error must name)
    "missing_urdf_file": ("panda_spherized.urdf", "no_such.urdf", ("robot.urdf", "no_such.urdf")),
    "unknown_tip_link": (
        'tip_link = "panda_hand"',
        'tip_link = "panda_hnd"',
        ("robot.tip_link", "panda_hnd", "did you mean 'panda_hand'"),
    ),
    "missing_tip_link": ('tip_link = "panda_hand"', "", ("robot.tip_link", "is missing")),
    "missing_srdf_file": ("panda.srdf", "nope.srdf", ("robot.srdf", "nope.srdf")),
    "unknown_allowed_link": (
        'tip_link = "panda_hand"',
        'tip_link = "panda_hand"\nallowed_collisions = [["panda_link1", "panda_lnk3"]]',
        ("robot.allowed_collisions", "panda_lnk3"),
    ),
    "allowed_not_pairs": (
        'tip_link = "panda_hand"',
        'tip_link = "panda_hand"\nallowed_collisions = ["panda_link1"]',
        ("robot.allowed_collisions", "pairs"),
    ),
    "goal_state_too_short": (
        "q = [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]",
        "q = [1.2, -0.3]",
        ("goals[0].q", "7 joint values"),
    ),
    "goal_state_off_limits": (
        "q = [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]",
        "q = [1.2, -0.3, 0.2, 2.0, 0.1, 1.9, 0.9]",
        ("goals[0].q", "panda_joint4"),
    ),
    "goal_state_and_position": (
        "q = [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]",
        "q = [1.2, -0.3, 0.2, -2.0, 0.1, 1.9, 0.9]\np_m = [0, 0, 1]",
        ("goals[0].p_m",),
    ),
}


@pytest.mark.parametrize("case", sorted(URDF_CASES))
def test_bad_urdf_problem_file(capsys, tmp_path, case):
    old, new, names = URDF_CASES[case]
    assert old in URDF_PROBLEM_TOML
    path = write_problem(tmp_path, URDF_PROBLEM_TOML.replace(old, new))
    code, _, err = run(capsys, "solve", str(path), "--planner", "ompl.rrtconnect")
    assert_clean_error(code, err.replace("\n", ""), str(path), *names)


def test_the_valid_urdf_problem_is_valid(tmp_path):
    problem = parse_problem(write_problem(tmp_path, URDF_PROBLEM_TOML))
    assert problem.robot.kind == "urdf" and problem.robot.dof == 7


def test_a_malformed_urdf_names_the_file_and_the_key(capsys, tmp_path):
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'>", encoding="utf-8")
    text = URDF_PROBLEM_TOML.replace((_PANDA / "panda_spherized.urdf").as_posix(), "broken.urdf")
    path = write_problem(tmp_path, text)
    code, _, err = run(capsys, "solve", str(path), "--planner", "ompl.rrtconnect")
    assert_clean_error(code, err.replace("\n", ""), str(path), "robot.urdf", "broken.urdf")


def test_bad_mbm_yaml_names_the_file_and_the_key(capsys, tmp_path):
    scene = tmp_path / "scene0001.yaml"
    request = tmp_path / "request0001.yaml"
    scene.write_text(
        "world:\n  collision_objects:\n    - id: a\n      primitives:\n"
        "        - type: cone\n          dimensions: [1, 2]\n      primitive_poses:\n"
        "        - position: [0, 0, 0]\n          orientation: [0, 0, 0, 1]\n",
        encoding="utf-8",
    )
    request.write_text("start_state: {}\n", encoding="utf-8")
    code, _, err = run(
        capsys,
        "import",
        "mbm",
        str(scene),
        str(request),
        "--urdf",
        str(_PANDA / "panda_spherized.urdf"),
        "--out",
        str(tmp_path / "out"),
    )
    assert_clean_error(
        code, err.replace("\n", ""), str(scene), "world.collision_objects[0].primitives[0]"
    )

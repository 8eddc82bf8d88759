"""The IRb-6 scenes in problems/, the ``plannerlab ik`` command and the goal-sampling hook.

Each scene's file states (in comments and in its ``[ik_expected]`` table) what the
analytic IK gives for the goal's exact pose; these tests hold the file to it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from plannerlab.cli.main import main
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError, ProblemError
from plannerlab.planners import PlanResult, make_planner
from plannerlab.problem.catalog import load_problem, resolve_problem_path
from plannerlab.problem.load import Problem
from plannerlab.problem.scene import Scene
from plannerlab.robots.irb6.goals import sample_goal_state
from plannerlab.robots.irb6.ik import solve_ik
from plannerlab.robots.irb6.model import IRb6

IRB6_PROBLEMS = (
    "irb6_pick_table",
    "irb6_case1",
    "irb6_case2_two_intervals",
    "irb6_track_obstacle",
)


def _station_goal(problem: Problem) -> tuple[np.ndarray, np.ndarray]:
    """The first goal's flange position and approach vector in the station frame."""
    goal = problem.goals[0]
    T_base_world = np.linalg.inv(problem.robot.T_world_base)
    p = T_base_world[:3, :3] @ goal.p_world_m + T_base_world[:3, 3]
    return p, T_base_world[:3, :3] @ goal.n_world


def _goal_states(problem: Problem, n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = sample_goal_state(problem.robot, problem.goals[0], rng)
        assert q is not None
        out.append(q)
    return out


@pytest.fixture(scope="module", params=IRB6_PROBLEMS)
def problem(request: pytest.FixtureRequest) -> Problem:
    return load_problem(request.param)


# ----------------------------------------------------------------------------- scenes
def test_loads_with_a_free_start_and_a_reachable_goal(problem: Problem) -> None:
    robot = problem.robot
    assert isinstance(robot, IRb6)
    checker = CollisionChecker(robot, problem.scene)
    assert checker.is_valid(problem.q_start)
    assert np.all(problem.q_start >= robot.lower) and np.all(problem.q_start <= robot.upper)
    free = [q for q in _goal_states(problem, 40, seed=0) if checker.is_valid(q)]
    assert free, "no collision-free goal state among 40 samples"
    goal = problem.goals[0]
    for q in free:
        assert goal.contains(robot, q)
        assert np.all(q >= robot.lower) and np.all(q <= robot.upper)


def test_the_ik_gives_what_the_file_says(problem: Problem) -> None:
    expected = problem.extras["ik_expected"]
    p, c = _station_goal(problem)
    answer = solve_ik(problem.robot, (p, c, 0.0))
    assert answer.case == expected["case"]
    assert np.allclose(answer.lambda0_intervals_m, expected["lambda0_intervals_m"], atol=2e-6)
    if "R_wew_m" in expected:
        assert math.isclose(answer.inner_radius_m, expected["R_wew_m"], abs_tol=2e-6)
        assert math.isclose(answer.outer_radius_m, expected["R_zew_m"], abs_tol=2e-6)
    # one IK solution per interval, at its midpoint, each exact
    assert len(answer.solutions) == len(answer.lambda0_intervals_m)
    for q, (lo, hi) in zip(answer.solutions, answer.lambda0_intervals_m, strict=True):
        assert math.isclose(q[0], 0.5 * (lo + hi), abs_tol=1e-12)
        tp, tc = problem.robot.tip(q)
        assert np.linalg.norm(tp - problem.goals[0].p_world_m) < 1e-9
        assert np.allclose(tc, problem.goals[0].n_world, atol=1e-9)


def test_case1_is_one_interval_inside_the_track() -> None:
    problem = load_problem("irb6_case1")
    p, c = _station_goal(problem)
    assert abs(c[0]) < 1e-12 and abs(p[0]) < 1e-12 and abs(c[1]) < 0.99  # c_x = d_x = 0
    ((lo, hi),) = solve_ik(problem.robot, (p, c, 0.0)).lambda0_intervals_m
    assert 0.0 < lo < hi < 0.851
    # the start is parked beyond the interval: the track has to move
    assert problem.q_start[0] > hi + 0.1


def test_case2_has_two_separate_intervals_and_the_start_between_them() -> None:
    problem = load_problem("irb6_case2_two_intervals")
    p, c = _station_goal(problem)
    answer = solve_ik(problem.robot, (p, c, 0.0))
    assert answer.case == "ambiguous_2"
    (a_lo, a_hi), (b_lo, b_hi) = answer.lambda0_intervals_m
    assert a_hi + 0.4 < b_lo  # a gap of 0.46 m
    assert a_hi < problem.q_start[0] < b_lo
    # sampled goal states (with tolerances) keep the two pieces apart, and use both
    checker = CollisionChecker(problem.robot, problem.scene)
    lams = np.array([q[0] for q in _goal_states(problem, 60, seed=1) if checker.is_valid(q)])
    assert np.all((lams < a_hi + 0.05) | (lams > b_lo - 0.05))
    assert (lams < a_hi + 0.05).any() and (lams > b_lo - 0.05).any()


def test_the_pillar_forces_the_track_to_move() -> None:
    problem = load_problem("irb6_track_obstacle")
    margin = problem.extras["ik_expected"]["min_track_travel_m"]
    lam_start = problem.q_start[0]
    checker = CollisionChecker(problem.robot, problem.scene)
    states = _goal_states(problem, 150, seed=2)
    free = [q for q in states if checker.is_valid(q)]
    assert len(free) >= 20
    assert all(abs(q[0] - lam_start) > margin for q in free)
    # it is the pillar: without it, goal states right at the start's λ0 are free
    no_pillar = Scene(tuple(o for o in problem.scene.obstacles if o.name != "pillar"))
    assert len(no_pillar.obstacles) == len(problem.scene.obstacles) - 1
    free_without = CollisionChecker(problem.robot, no_pillar)
    near = [q for q in states if free_without.is_valid(q) and abs(q[0] - lam_start) < 0.05]
    assert near
    assert all(not checker.is_valid(q) for q in near)


# ----------------------------------------------------------------------------- sampling hook
def test_sample_goal_state_hook_is_deterministic_and_checks_seeds() -> None:
    problem = load_problem("irb6_case2_two_intervals")
    robot, goal = problem.robot, problem.goals[0]
    a = sample_goal_state(robot, goal, np.random.default_rng(5), seeds=[problem.q_start])
    b = sample_goal_state(robot, goal, np.random.default_rng(5), seeds=[problem.q_start])
    assert a is not None and np.array_equal(a, b)
    with pytest.raises(PlannerlabError, match="seed"):
        sample_goal_state(robot, goal, np.random.default_rng(5), seeds=[np.zeros(3)])


# ----------------------------------------------------------------------------- CLI
def _ik_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict]:
    code = main(["ik", "irb6", *args, "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_cli_ik_case2_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _ik_json(
        capsys, "--position", "0.3", "0.95", "0.4", "--approach", "0", "-1", "0", "--roll", "15"
    )
    assert code == 0 and out["reachable"] and out["case"] == "ambiguous_2"
    assert np.allclose(out["lambda0_intervals_m"], [[0.0, 0.170821], [0.629179, 0.851]], atol=2e-6)
    assert math.isclose(out["R_wew_m"], 0.377522, abs_tol=2e-6)
    assert len(out["solutions"]) == 2
    for sol in out["solutions"]:
        assert sol["pos_err_m"] <= 1e-9 and sol["rot_err_deg"] <= 1e-7
        assert len(sol["q"]) == 6 and len(sol["theta_deg"]) == 5
        assert math.isclose(sol["theta_deg"][3], -90.0, abs_tol=1e-9)  # θ4: straight down


def test_cli_ik_from_a_problem_in_its_world_frame(capsys: pytest.CaptureFixture[str]) -> None:
    problem = load_problem("irb6_case1")
    goal = problem.goals[0]
    code, out = _ik_json(
        capsys,
        "--problem", "irb6_case1", "--frame", "world",
        "--position", *map(str, goal.p_world_m), "--approach", *map(str, goal.n_world),
    )  # fmt: skip
    assert code == 0 and out["problem"] == "irb6_case1" and out["case"] == "ambiguous_1"
    assert np.allclose(out["position_station_m"], [0.0, 0.9, 1.15], atol=1e-12)
    assert np.allclose(out["lambda0_intervals_m"], [[0.112923, 0.697860]], atol=2e-6)
    assert out["solutions"][0]["pos_err_m"] <= 1e-9


def test_cli_ik_previous_theta5_picks_the_branch(capsys: pytest.CaptureFixture[str]) -> None:
    args = ("--position", "0.6", "1.0", "0.3", "--approach", "0.8", "-0.2", "0.3", "--roll", "180")
    code, both = _ik_json(capsys, *args)
    assert code == 0 and len(both["solutions"]) == 2  # θ5 = ±180° give the same pose
    code, one = _ik_json(capsys, *args, "--previous-theta5", "-170")
    assert code == 0 and len(one["solutions"]) == 1
    assert math.isclose(one["solutions"][0]["theta_deg"][4], -180.0, abs_tol=1e-9)


def test_cli_ik_table_output(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["ik", "irb6", "--position", "0.75", "0.65", "0.5",
                 "--approach", "0.469846", "-0.866025", "0.171010"])  # fmt: skip
    text = capsys.readouterr().out
    assert code == 0
    for word in ("unambiguous", "0.2270", "150.000", "pos err m", "λ0 intervals [m]"):
        assert word in text


def test_cli_ik_unreachable_exits_1_with_the_reason(capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _ik_json(capsys, "--position", "2.0", "1.0", "0.4", "--approach", "1", "0", "0")
    assert code == 1 and not out["reachable"] and out["solutions"] == []
    assert out["reason_code"] == "outside_annulus" and "annulus" in out["reason"]
    code = main(["ik", "irb6", "--position", "2.0", "1.0", "0.4", "--approach", "1", "0", "0"])
    assert code == 1 and "outside_annulus" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--approach", "0", "0", "0"), "--approach must be a non-zero direction"),
        (("--approach", "nan", "1", "0"), "--approach expects three finite numbers"),
        (("--approach", "0", "1", "0", "--roll", "inf"), "--roll expects a finite angle"),
        (("--approach", "0", "1", "0", "--frame", "world"), "--frame world needs --problem"),
        (("--approach", "0", "1", "0", "--problem", "armz_pocket"), "needs a problem with"),
        (("--approach", "0", "1", "0", "--problem", "irb6_nope"), "unknown problem"),
    ],
)
def test_cli_ik_bad_input_exits_2(
    capsys: pytest.CaptureFixture[str], args: tuple[str, ...], message: str
) -> None:
    code = main(["ik", "irb6", "--position", "0.3", "0.95", "0.4", *args])
    captured = capsys.readouterr()
    assert code == 2 and captured.out == ""
    assert message in " ".join(captured.err.split())


# ----------------------------------------------------------------------------- bad files
@pytest.mark.parametrize(
    ("old", "new", "key", "expected"),
    [
        ('type = "irb6"', 'type = "irb6"\nlower_arm = 0.5', "robot.lower_arm", "not a known key"),
        ('type = "irb6"', 'type = "irb6"\nupper_arm_m = -0.67', "robot.upper_arm_m", "positive"),
        ('type = "irb6"', 'type = "irb6"\ntheta2_range_deg = [40, -40]', "robot.theta2_range_deg",
         "lower <= upper"),
        ('type = "irb6"', 'type = "irb6"\ntheta1_range_deg = [-200, 200]',
         "robot.theta1_range_deg", "360"),
        ('type = "irb6"', 'type = "irb6"\ndead_wedge_side = "left"', "robot.dead_wedge_side",
         '"-z"'),
        ("base_rpy_deg = [90.0, 0.0, 90.0]", "base_rpy_deg = [90.0, 0.0]", "robot.base_rpy_deg",
         "3 numbers"),
    ],
)  # fmt: skip
def test_bad_robot_table_names_the_key(
    tmp_path: Path, old: str, new: str, key: str, expected: str
) -> None:
    text = resolve_problem_path("irb6_case1").read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(ProblemError) as info:
        load_problem(path)
    assert info.value.key == key and expected in info.value.expected
    assert str(path) in str(info.value)


def test_robot_table_defaults_and_overrides(tmp_path: Path) -> None:
    text = resolve_problem_path("irb6_case1").read_text(encoding="utf-8")
    path = tmp_path / "custom.toml"
    path.write_text(
        text.replace(
            'type = "irb6"',
            'type = "irb6"\nlower_arm_m = 0.45\ntrack_range_m = [0.0, 1.2]\n'
            'theta5_range_deg = [-270, 270]\ndead_wedge_side = "+z"',
            1,
        ),
        encoding="utf-8",
    )
    robot = load_problem(path).robot
    assert robot.lower_arm_m == 0.45 and robot.track_range_m == (0.0, 1.2)
    assert np.isclose(robot.upper[5], math.radians(270)) and robot.dead_wedge_side == "+z"
    assert robot.upper_arm_m == IRb6().upper_arm_m  # untouched: the model's default


# ----------------------------------------------------------------------------- planners
@pytest.mark.parametrize("name", IRB6_PROBLEMS)
def test_gradient_analytic_runs_on_every_irb6_problem(name: str) -> None:
    problem = load_problem(name)
    planner = make_planner("gradient.analytic")
    budget = problem.budget.replace(max_iterations=150)
    result = planner.solve(problem, 0, budget, np.random.default_rng(0))
    assert isinstance(result, PlanResult)
    assert result.path.ndim == 2 and result.path.shape[1] == 6
    assert np.array_equal(result.path[0], problem.q_start)
    assert result.iterations <= 150 and result.reason


def test_rrtconnect_reaches_the_goal_through_the_analytic_ik_and_moves_the_track():
    """OMPL's goal sampling goes through the IRb-6's analytic IK (the robot's hook)."""
    from plannerlab.planners import make_planner
    from plannerlab.planners.base import Status

    problem = load_problem("irb6_track_obstacle")
    r = make_planner("ompl.rrtconnect").solve(
        problem,
        0,
        problem.budget.replace(max_collision_checks=60000, max_iterations=None),
        np.random.default_rng(0),
    )
    assert r.status is Status.SOLVED, r.reason
    assert problem.goal(0).contains(problem.robot, r.path[-1])
    assert r.path[-1][0] >= 0.48  # the pillar forces the carriage along the track


def test_simworld_drives_the_irb6_through_its_urdf_joint_mapping():
    """q holds absolute angles; the simulator converts them for the URDF and back."""
    from plannerlab.sim import SimWorld

    problem = load_problem("irb6_pick_table")
    robot = problem.robot
    rng = np.random.default_rng(5)
    with SimWorld(robot, problem.scene, gravity_mps2=(0.0, 0.0, 0.0)) as world:
        for _ in range(5):
            q = rng.uniform(robot.lower, robot.upper)
            world.reset(q)
            np.testing.assert_allclose(world.state(), q, atol=1e-9)
            np.testing.assert_allclose(world.link_frames(), robot.fk(q), atol=1e-6)
        target = q.copy()
        target[1] += 0.05
        reached = world.move_towards(target, 240)
        np.testing.assert_allclose(reached, target, atol=2e-3)

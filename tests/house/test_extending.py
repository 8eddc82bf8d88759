"""docs/extending.md's examples run as written (issue 36, item 8): the sampling planner and
the compiled planner (registered through their entry points and solved through the road
every command walks), the robot family in code (registered, loaded from a problem file,
checked on the compiled road, planned and executed in PyBullet), the robot from a URDF and
the problem file."""

from __future__ import annotations

import re
import sys
import types
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "extending.md"


def _blocks(lang: str) -> dict[str, str]:
    """The doc's ``lang`` code blocks by the file (or entry) their first line names."""
    out = {}
    for body in re.findall(rf"```{lang}\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S):
        first = body.splitlines()[0]
        name = re.sub(r"^(#|<!--)\s*|\s*-->$", "", first).strip()
        assert name not in out, f"two blocks named {name!r}"
        out[name] = body
    return out


def _write(directory: Path) -> dict[str, Path]:
    files = {**_blocks("toml"), **_blocks("xml")}
    paths = {}
    for name, text in files.items():
        paths[name] = directory / name
        paths[name].write_text(text, encoding="utf-8")
    return paths


def _module(monkeypatch, name: str, code: str, package: bool = False) -> types.ModuleType:
    """``code`` as the module ``name`` (in sys.modules before it runs: dataclasses look
    their module up)."""
    module = types.ModuleType(name)
    if package:
        module.__path__ = []  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, name, module)
    exec(compile(code, name.replace(".", "/") + ".py", "exec"), module.__dict__)
    return module


def _entry(name: str, key: str) -> object:
    """The object ``key`` the entry block of ``name`` defines."""
    (code,) = [c for n, c in _blocks("python").items() if n.startswith(f"the entry of {name} ")]
    scope: dict = {}
    exec(code, scope)
    return scope[key]


@pytest.fixture
def planners(monkeypatch) -> dict[str, types.ModuleType]:
    """The example planners as plannerlab.planners.tiny_rrt and .via, registered through
    the doc's entries (whose entry points import those modules)."""
    import plannerlab.planners as registry

    python = _blocks("python")
    modules = {
        short: _module(monkeypatch, f"plannerlab.planners.{short}", python[path])
        for short, path in (
            ("tiny_rrt", "plannerlab/planners/tiny_rrt.py"),
            ("via", "plannerlab/planners/via.py"),
        )
    }
    entries = {name: _entry(name, "ENTRY") for name in modules}
    monkeypatch.setattr(registry, "REGISTRY", MappingProxyType({**registry.REGISTRY, **entries}))
    return modules


@pytest.fixture
def planar(monkeypatch, planners) -> types.ModuleType:
    """The example robot family as plannerlab.robots.planar, registered in FAMILIES."""
    from plannerlab.robots import registry

    python = _blocks("python")
    _module(monkeypatch, "plannerlab.robots.planar", "", package=True)
    model = _module(
        monkeypatch, "plannerlab.robots.planar.model", python["plannerlab/robots/planar/model.py"]
    )
    _module(
        monkeypatch, "plannerlab.robots.planar.schema", python["plannerlab/robots/planar/schema.py"]
    )
    monkeypatch.setitem(registry.FAMILIES, "planar", _entry("planar", "FAMILY"))
    return model


# ---------------------------------------------------------------------- the planners
def test_the_sampling_planner_solves_the_example_problem(planners, tmp_path):
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import parse_problem
    from plannerlab.record.leg import Status
    from plannerlab.run.pipeline import solve_legs

    problem = parse_problem(_write(tmp_path)["tip_up.toml"])
    assert make_planner("tiny_rrt", {"step_rad": "0.2"}).settings.step_rad == 0.2
    plan = solve_legs(problem, "tiny_rrt", 0)
    (leg,) = plan.legs
    assert leg.status is Status.SOLVED, leg.reason
    assert problem.goal(0).contains(problem.robot, leg.path[-1])
    assert problem_checker(problem).check_path(leg.path, problem.joint_step / 4).valid
    assert leg.collision_checks > 0 and leg.min_clearance_m >= problem.safety_margin_m
    again = solve_legs(problem, "tiny_rrt", 0).legs[0]
    np.testing.assert_array_equal(again.path, leg.path)  # its seed decides the search


def test_the_sampling_planner_reports_a_colliding_start_and_its_budget(planners, tmp_path):
    from plannerlab.problem.load import parse_problem
    from plannerlab.record.leg import Status
    from plannerlab.run.pipeline import leg_rng

    path = _write(tmp_path)["tip_up.toml"]
    problem = parse_problem(path)
    small = problem.budget.replace(max_collision_checks=40)
    r = (
        planners["tiny_rrt"]
        .make("tiny_rrt", {"goal_bias": "0"})
        .solve(problem, 0, small, leg_rng(0, 0))
    )
    assert r.status is Status.BUDGET_EXHAUSTED and "collision" in r.reason
    assert 40 <= r.collision_checks < 40 + 20  # at most one edge's states past the limit
    block = '[[obstacles]]\nname = "block"\ntype = "box"\ncenter_m = [0.0, 0.0, 2.0]\n'
    path.write_text(path.read_text() + block + "size_m = [1.0, 1.0, 1.0]\n")
    problem = parse_problem(path)  # a box round the column: the start collides
    r = planners["tiny_rrt"].make("tiny_rrt", {}).solve(problem, 0, problem.budget, leg_rng(0, 0))
    assert r.status is Status.INVALID_START and "block" in r.reason


def test_the_compiled_planner_finds_a_via_state_and_keeps_its_budget(planar, tmp_path):
    import plannerlab as pl
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.record.leg import Status

    problem = pl.parse_problem(_write(tmp_path)["planar.toml"])
    checker = problem_checker(problem)
    goal_state = problem.goal(0).q_rad
    straight = np.array([problem.q_start, goal_state])
    assert not checker.check_path(straight, problem.joint_step).valid  # the post is in the way
    (leg,) = pl.solve(problem, "via", 0).legs
    assert leg.status is Status.SOLVED, leg.reason
    assert len(leg.path) == 3 and checker.check_path(leg.path, problem.joint_step / 4).valid
    # its compiled checks are charged: more than the goal state's and the re-check's
    assert leg.collision_checks > checker.grid_states(leg.path, problem.joint_step / 4) + 1
    # a budget that cannot find a via state round the post: used to its last check
    (leg,) = pl.solve(
        problem, "via", 0, budget=problem.budget.replace(max_collision_checks=20)
    ).legs
    assert leg.status is Status.BUDGET_EXHAUSTED and leg.collision_checks == 20


# ---------------------------------------------------------------------- the robots
def test_the_robot_family_in_code_plans_and_executes(planar, tmp_path):
    import plannerlab as pl
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.collision.queries import segments
    from plannerlab.record.leg import Status

    problem = pl.parse_problem(_write(tmp_path)["planar.toml"])
    robot = problem.robot
    assert isinstance(robot, planar.PlanarArm) and robot.dof == 3
    # the compiled road, from chain_data() alone: the model's capsules are the robot's
    Q = np.random.default_rng(0).uniform(robot.lower, robot.upper, (20, robot.dof))
    out = np.empty((20, robot.dof, 2, 3))
    segments(problem_checker(problem).packed_model, Q, out)
    np.testing.assert_allclose(out, robot.link_segments(Q), atol=1e-12)
    J_p, _ = robot.tip_jacobian(Q[0])
    eps = 1e-7
    dq = np.eye(robot.dof)[1] * eps
    np.testing.assert_allclose(
        J_p[:, 1], (robot.tip(Q[0] + dq)[0] - robot.tip(Q[0] - dq)[0]) / (2 * eps), atol=1e-6
    )
    for name in ("tiny_rrt", "native.rrtconnect"):
        plan = pl.solve(problem, name, 0)
        assert plan.legs[0].status is Status.SOLVED, (name, plan.legs[0].reason)
    (execution,) = pl.execute(plan, problem)  # PyBullet, from robot.urdf()
    assert execution.success, execution.failures


def test_the_urdf_robot_example_plans_with_rrtconnect(tmp_path):
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.problem.load import parse_problem
    from plannerlab.record.leg import Status
    from plannerlab.run.pipeline import solve_legs

    problem = parse_problem(_write(tmp_path)["two_link.toml"])
    assert problem.robot.kind == "urdf" and problem.robot.dof == 2
    plan = solve_legs(problem, "ompl.rrtconnect", 0)
    (leg,) = plan.legs
    assert leg.status is Status.SOLVED, leg.reason
    np.testing.assert_allclose(leg.path[-1], [2.0, 0.5], atol=1e-3)
    assert problem_checker(problem).check_path(leg.path, problem.joint_step / 4).valid


# ---------------------------------------------------------------------- the optimiser
def test_the_trajectory_optimiser_smooths_its_seed_and_keeps_the_re_check(
    monkeypatch, planar, tmp_path
):
    import plannerlab as pl
    import plannerlab.planners as registry
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.record.leg import Status
    from plannerlab.robots.paths import roughness

    python = _blocks("python")
    _module(monkeypatch, "plannerlab.planners.smooth", python["plannerlab/planners/smooth.py"])
    entry = _entry("smooth", "ENTRY")
    monkeypatch.setattr(
        registry, "REGISTRY", MappingProxyType({**registry.REGISTRY, "smooth": entry})
    )
    problem = pl.parse_problem(_write(tmp_path)["planar.toml"])
    (leg,) = pl.solve(problem, "smooth", 0).legs
    assert leg.status is Status.SOLVED, leg.reason
    checker = problem_checker(problem)
    assert checker.check_path(leg.path, problem.joint_step / 4).valid  # no tunnelling
    seed = np.array(leg.extra["seed_path"])
    assert checker.check_path(seed, problem.joint_step / 4).valid
    cont = problem.robot.continuous
    assert roughness(leg.path, cont) < roughness(seed, cont)  # it bends less than its seed
    np.testing.assert_allclose(leg.path[0], problem.q_start)
    assert problem.goal(0).contains(problem.robot, leg.path[-1])
    # the seed's checks are the leg's, and the smoothing's re-checks come on top
    assert leg.collision_checks > leg.extra["seed_checks"] > 0

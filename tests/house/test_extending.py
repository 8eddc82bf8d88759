"""docs/extending.md's examples run as written: the planner (registered and solved through
the road every command walks), the robot from a URDF, and the problem file."""

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
    """The doc's ``lang`` code blocks by the file their first line names."""
    out = {}
    for body in re.findall(rf"```{lang}\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S):
        first = body.splitlines()[0]
        name = re.sub(r"^(#|<!--)\s*|\s*-->$", "", first).strip()
        out[name] = body
    return out


def _write(directory: Path) -> dict[str, Path]:
    files = {**_blocks("toml"), **_blocks("xml")}
    paths = {}
    for name, text in files.items():
        paths[name] = directory / name
        paths[name].write_text(text, encoding="utf-8")
    return paths


@pytest.fixture
def straight(monkeypatch) -> types.ModuleType:
    """The example planner as the module plannerlab.planners.straight, registered."""
    import plannerlab.planners as registry

    (code,) = [c for name, c in _blocks("python").items() if "straight.py" in name]
    module = types.ModuleType("plannerlab.planners.straight")
    monkeypatch.setitem(sys.modules, module.__name__, module)  # before: dataclasses look it up
    exec(compile(code, "plannerlab/planners/straight.py", "exec"), module.__dict__)
    (entry_code,) = [c for c in _blocks("python").values() if "PlannerEntry(" in c]
    scope: dict = {}
    exec(entry_code, scope)
    monkeypatch.setattr(
        registry, "REGISTRY", MappingProxyType({**registry.REGISTRY, "straight": scope["ENTRY"]})
    )
    return module


def test_the_example_planner_solves_the_example_problem(straight, tmp_path):
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import parse_problem
    from plannerlab.record.leg import Status
    from plannerlab.run.pipeline import solve_legs

    problem = parse_problem(_write(tmp_path)["tip_up.toml"])
    assert make_planner("straight", {"goal_attempts": 10}).settings.goal_attempts == 10
    plan = solve_legs(problem, "straight", 0)
    (leg,) = plan.legs
    assert leg.status is Status.SOLVED, leg.reason
    assert problem.goal(0).contains(problem.robot, leg.path[-1])
    assert problem_checker(problem).check_path(leg.path, problem.joint_step / 4).valid
    assert leg.collision_checks > 0 and leg.min_clearance_m >= problem.safety_margin_m


def test_the_example_planner_reports_a_colliding_start(straight, tmp_path):
    from plannerlab.problem.load import parse_problem
    from plannerlab.record.leg import Status
    from plannerlab.run.pipeline import leg_rng

    path = _write(tmp_path)["tip_up.toml"]
    block = '[[obstacles]]\nname = "block"\ntype = "box"\ncenter_m = [0.0, 0.0, 2.0]\n'
    path.write_text(path.read_text() + block + "size_m = [1.0, 1.0, 1.0]\n")
    problem = parse_problem(path)  # a box round the column: the start collides
    r = straight.make("straight", {}).solve(problem, 0, problem.budget, leg_rng(0, 0))
    assert r.status is Status.INVALID_START and "block" in r.reason


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

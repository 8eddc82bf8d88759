"""The MotionBenchMaker importer declares a grasp goal's contacts (issue 35 item 4): an
object that the hand's links touch at the goal state gets the end effector's links as its
``touch_links`` (with a comment), so the goal is valid; an object the hand does not touch
gets none and still collides."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
from conftest import PROBLEMS

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.mbm import end_effector_links, problem_toml
from plannerlab.robots.urdf.model import UrdfChain

PANDA = PROBLEMS / "urdf" / "panda"
URDF, SRDF = PANDA / "panda_spherized.urdf", PANDA / "panda.srdf"
START = [0.0, -0.785, 0.0, -1.9, 0.0, 1.571, 0.785]
#: the hand points down, the fingers at y = ±0.08 m and ±0.073 m, z = 0.51 m and 0.488 m
GOAL = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]

SCENE = """\
robot_model_name: panda
world:
  collision_objects:
    - id: can
      primitives:
        - type: box
          dimensions: [0.04, 0.15, 0.04]
      primitive_poses:
        - position: [0.307, 0.0, 0.48]
          orientation: [0, 0, 0, 1]
    - id: table
      primitives:
        - type: box
          dimensions: [1.0, 1.0, 0.04]
      primitive_poses:
        - position: [0.8, 0.0, 0.2]
          orientation: [0, 0, 0, 1]
"""


def _request(goal: list[float]) -> str:
    names = [f"panda_joint{i}" for i in range(1, 8)]
    cons = "\n".join(
        f"      - {{joint_name: {n}, position: {v}, tolerance_above: 0.001, "
        f"tolerance_below: 0.001}}"
        for n, v in zip(names, goal, strict=True)
    )
    return (
        "start_state:\n  joint_state:\n"
        f"    name: [{', '.join(names)}]\n    position: {START}\n"
        f"goal_constraints:\n  - joint_constraints:\n{cons}\n"
    )


def _import(tmp_path: Path, goal: list[float]) -> Path:
    (tmp_path / "scene.yaml").write_text(SCENE, encoding="utf-8")
    (tmp_path / "request.yaml").write_text(_request(goal), encoding="utf-8")
    out = tmp_path / "grasp.toml"
    text = problem_toml(
        tmp_path / "scene.yaml",
        tmp_path / "request.yaml",
        out_path=out,
        urdf=URDF,
        srdf=SRDF,
        tip_link="panda_hand",
    )
    out.write_text(text, encoding="utf-8")
    return out


def test_the_end_effector_is_the_hand_and_its_fingers() -> None:
    robot = UrdfChain(URDF, "panda_hand", srdf_path=SRDF)
    # panda_link7 is the last joint's own link; panda_link8 has no collision geometry
    assert end_effector_links(robot) == ["panda_hand", "panda_leftfinger", "panda_rightfinger"]


def test_a_grasp_goals_object_is_declared_and_the_goal_is_valid(tmp_path: Path) -> None:
    path = _import(tmp_path, GOAL)
    text = path.read_text(encoding="utf-8")
    assert "# grasped at the goal: panda_leftfinger, panda_rightfinger touch it" in text
    data = tomllib.loads(text)
    by_name = {o["name"]: o for o in data["obstacles"]}
    assert by_name["can"]["touch_links"] == ["panda_hand", "panda_leftfinger", "panda_rightfinger"]
    assert "touch_links" not in by_name["table"]
    problem = load_problem(path)
    q_goal = np.asarray(GOAL)
    assert problem_checker(problem).is_valid(q_goal)
    assert CollisionChecker(problem.robot, problem.scene, "fcl").is_valid(q_goal)
    # without the declaration the fingers collide with the can at the goal
    bare = CollisionChecker(problem.robot, type(problem.scene)(tuple(
        type(o)(o.name, o.T_world_obstacle, o.size_m) for o in problem.scene.obstacles
    )))  # fmt: skip
    assert {b for _, b in bare.colliding_pairs(q_goal)} == {"can"}


def test_a_goal_clear_of_every_object_declares_nothing(tmp_path: Path) -> None:
    goal = list(GOAL)
    goal[3] += 0.3  # the hand 13 cm higher, clear of the can
    text = _import(tmp_path, goal).read_text(encoding="utf-8")
    assert "touch_links" not in text and "grasped" not in text

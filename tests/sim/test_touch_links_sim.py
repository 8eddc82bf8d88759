"""Declared contacts in the PyBullet judge (issue 35 item 4): a box held between the
spherized Panda's fingers (``tests/collision/test_touch_links.py``'s grasp) makes contacts
and negative clearance with the fingers without ``touch_links``, none with them; another
obstacle at the same place still touches the fingers."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "collision"))
from test_touch_links import FINGERS, Q0, _box, _problem  # noqa: E402

from plannerlab.sim import SimWorld  # noqa: E402


def _judge(problem) -> tuple[set[tuple[str, str]], dict[str, float]]:
    """PyBullet's contacts at the grasp (URDF link, obstacle) and, per URDF link, its smallest
    distance to the scene [m]."""
    robot = problem.robot
    with SimWorld(robot, problem.scene) as world:
        world.reset(np.asarray(Q0))
        contacts = {
            (c.link_name.split("#")[0], c.other_name)
            for c in world.contacts()
            if not c.other_is_link
        }
        scene, _, _ = world.link_distances(0.05)
    dist: dict[str, float] = {}
    for name, d in zip(robot.link_urdf_names, scene, strict=True):
        dist[name] = min(dist.get(name, np.inf), float(d))
    return contacts, dist


def test_pybullet_counts_no_contact_between_the_declared_links_and_the_object() -> None:
    contacts, dist = _judge(_problem([_box("cup", None)]))
    assert {c[0] for c in contacts} == set(FINGERS) and {c[1] for c in contacts} == {"cup"}
    assert all(dist[f] < 0.0 for f in FINGERS)
    contacts, dist = _judge(_problem([_box("cup", FINGERS)]))
    assert contacts == set()
    assert min(dist.values()) > 0.0  # the hand clear of the box; the fingers not measured
    contacts, dist = _judge(_problem([_box("cup", FINGERS), _box("other", None, z_m=0.47)]))
    assert {c[1] for c in contacts} == {"other"} and {c[0] for c in contacts} == set(FINGERS)
    assert all(dist[f] < 0.0 for f in FINGERS)


@pytest.mark.slow
def test_a_grasp_leg_is_planned_into_the_object_and_executes_cleanly() -> None:
    """The leg into the grasp (fingers through the declared box) is solved within a check
    budget and executes cleanly: no contact, clearance kept by every other pair; without
    the declaration the goal is refused, naming the fingers and the box."""
    from plannerlab.planners.base import Status
    from plannerlab.problem.settings import Budget
    from plannerlab.run.pipeline import execute_results, solve_legs

    budget = Budget(max_collision_checks=200_000)
    problem = _problem([_box("cup", FINGERS)])
    (leg,) = solve_legs(problem, "native.rrtconnect", 0, legs=[0], budget=budget).legs
    assert leg.status is Status.SOLVED, leg.reason
    (ex,) = execute_results(problem, [leg])
    assert ex.success, ex.reason
    assert ex.min_clearance_m > 0.0
    bare = _problem([_box("cup", None)])
    (leg,) = solve_legs(bare, "native.rrtconnect", 0, legs=[0], budget=budget).legs
    assert leg.status is Status.INVALID_GOAL
    assert "panda_leftfinger x cup" in leg.reason and "panda_rightfinger x cup" in leg.reason

"""The records and their one codec: non-finite numbers, plan and execution files."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from plannerlab.errors import PlanFileError
from plannerlab.record.codec import dumps, loads, read_float, to_data
from plannerlab.record.leg import PlanResult, Status
from plannerlab.record.plan import Plan
from plannerlab.robots.paths import densify, waypoints


def _result(path: np.ndarray, **kw) -> PlanResult:
    return PlanResult("p", "toy", 0, "goal", Status.APPROXIMATE, "why", path, **kw)


def test_non_finite_numbers_are_null_and_read_back_as_nan():
    text = dumps({"a": math.inf, "b": [np.float64(-math.inf), math.nan], "c": np.arange(2)})
    assert json.loads(text) == {"a": None, "b": [None, None], "c": [0, 1]}
    assert math.isnan(read_float(loads(text)["a"])) and read_float("inf") == math.inf
    r = _result(np.zeros((2, 3)), pos_err_m=math.inf, trace=[1.0, math.inf, math.nan])
    back = PlanResult.from_dict(loads(dumps(r.to_dict())))
    assert math.isnan(back.pos_err_m) and back.trace[0] == 1.0 and np.isnan(back.trace[1:]).all()
    assert to_data(Status.SOLVED) == "solved"


def test_a_leg_without_its_path_names_the_path_by_digest():
    path = np.arange(12.0).reshape(4, 3)
    d = _result(path).to_dict(include_path=False)
    assert "path" not in d and "trace" not in d and d["path_points"] == 4
    assert d["path_sha256"] == _result(path.copy()).path_sha256() != _result(path + 1).path_sha256()


def test_waypoints_undo_interpolation_and_keep_curves():
    rng = np.random.default_rng(0)
    corners = np.cumsum(rng.normal(size=(30, 5)), axis=0)
    dense, _ = densify(corners, 0.01, np.zeros(5, dtype=bool))
    assert len(dense) > 1000
    np.testing.assert_array_equal(waypoints(dense), corners)
    # a slow arc: each state is nearly on its neighbours' chord, but not on the long one
    th = np.linspace(0.0, 1e-3, 2000)
    arc = np.stack([np.cos(th), np.sin(th)], axis=1)
    assert len(waypoints(arc)) == 2000


def test_a_plan_file_holds_waypoints_and_reads_back(tmp_path):
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])
    dense, _ = densify(corners, 0.001, np.zeros(2, dtype=bool))
    plan = Plan("toy", "", "p", 1, {}, (_result(dense),))
    path = plan.save(tmp_path / "plan.json")
    assert path.stat().st_size < 2_000
    back = Plan.load(path)
    np.testing.assert_array_equal(back.legs[0].path, corners)
    assert back.legs[0].status is Status.APPROXIMATE


def test_a_plan_file_without_legs_is_refused(tmp_path):
    bad = tmp_path / "plan.json"
    plan = Plan("toy", "", "p", 1, {}, (_result(np.zeros((1, 2))),)).to_dict()
    bad.write_text(json.dumps({**plan, "legs": []}))
    with pytest.raises(PlanFileError, match=r"\[legs\] expected a non-empty list"):
        Plan.load(bad)


@pytest.mark.parametrize(
    ("contact_plan", "expected"),
    [
        ({"chosen": 0}, "not a contact plan: KeyError: 'base_xy_m'"),
        ([1, 2], "not a contact plan: list"),
    ],
)
def test_a_plan_file_with_a_broken_contact_plan_is_refused(tmp_path, contact_plan, expected):
    """A chord_arc leg's contact plan is read back as a typed record: a broken one is
    refused with the file named, not carried on as an untyped dict."""
    bad = tmp_path / "plan.json"
    plan = Plan("toy", "", "p", 1, {}, (_result(np.zeros((1, 2))),)).to_dict()
    plan["legs"][0]["contact_plan"] = contact_plan
    bad.write_text(json.dumps(plan))
    with pytest.raises(PlanFileError, match=str(bad)) as err:
        Plan.load(bad)
    assert expected in str(err.value)


def test_a_contact_plan_choosing_a_missing_solution_is_refused():
    from plannerlab.record.contact_plan import ContactPlan

    good = {
        "base_xy_m": [0, 0],
        "base_tangent": [0, 1],
        "target_xy_m": [0, 1],
        "obstacles": [],
        "planning_obstacles": [],
        "collision_points_m": [],
        "link_radius_m": 0.002,
        "inflated_by_m": 0.002,
        "contact_tolerance_m": 0.014,
    }
    assert ContactPlan.from_dict(good).chosen_solution is None
    with pytest.raises(PlanFileError, match="chosen = 2 but there are 0 solutions"):
        ContactPlan.from_dict({**good, "chosen": 2})

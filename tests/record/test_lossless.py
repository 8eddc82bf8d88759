"""One plan, one verdict: a saved plan executes exactly as the plan in memory and as the
trial of ``compare --execute`` did.

The problem is ``armz_pocket`` with ``gradient.clearance+detour``, seed 0 and a budget of
5 000 collision checks (one leg, solved in about a second): its descent takes a straight
run of steps of shrinking length, so the planner's own path (323 states) is not its
canonical form (314 waypoints), which is what made a plan file and ``compare`` execute
different paths before. Every road is compared field by field on the same machine (the
wall clock excepted), so exact equality is asked: the same numbers, not close ones.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest
from conftest import plannerlab

import plannerlab as pl
from plannerlab.record.codec import dumps, loads
from plannerlab.record.plan import ExecutionFile, Plan, execution_path
from plannerlab.record.trial import ExecutionRecord, LegRecord, TrialRecord
from plannerlab.robots.paths import waypoints
from plannerlab.run.pipeline import canonical_result, execute_results, leg_rng

PROBLEM = "armz_pocket"
PLANNER = "gradient.clearance+detour"
SEED = 0
MAX_CHECKS = 5000

#: fields of an execution record that are clocks, not verdicts
CLOCKS = ("wall_time_s",)


def _verdict(e: Any, *, include_log: bool = False) -> dict[str, Any]:
    """An execution's record without its clocks (a record read from a file, or not)."""
    d = e if isinstance(e, dict) else e.to_dict(include_log=include_log)
    return {k: v for k, v in d.items() if k not in CLOCKS}


@pytest.fixture(scope="module")
def api() -> dict[str, Any]:
    """The API road: ``pl.solve`` then ``pl.execute``."""
    problem = pl.load_problem(PROBLEM)
    budget = problem.budget.replace(max_collision_checks=MAX_CHECKS)
    plan = pl.solve(problem, PLANNER, seed=SEED, budget=budget)
    assert plan.solved, [r.reason for r in plan.legs]
    return {"problem": problem, "budget": budget, "plan": plan, "executions": pl.execute(plan)}


def test_the_case_is_one_whose_path_collapses(api: dict[str, Any]) -> None:
    # the planner's own path has states inside straight segments: what the fix is about
    problem = api["problem"]
    raw = pl.make_planner(PLANNER).solve(problem, 0, api["budget"], leg_rng(SEED, 0))
    assert len(waypoints(raw.path)) < len(raw.path)
    # solve_legs returns the canonical form, and executing the raw result runs it too
    (leg,) = api["plan"].legs
    assert np.array_equal(leg.path, waypoints(raw.path))
    (e_raw,) = execute_results(problem, [raw])
    assert _verdict(e_raw, include_log=True) == _verdict(api["executions"][0], include_log=True)


def test_a_plan_file_holds_the_plan_bit_for_bit(api: dict[str, Any], tmp_path: Path) -> None:
    plan = api["plan"]
    loaded = Plan.load(plan.save(tmp_path / "p.json"))
    for a, b in zip(plan.legs, loaded.legs, strict=True):
        assert a.path.tobytes() == b.path.tobytes()
        assert a.path_sha256() == b.path_sha256()
    # and executing the file is executing the plan, log and all
    again = pl.execute(loaded)
    assert [_verdict(e, include_log=True) for e in again] == [
        _verdict(e, include_log=True) for e in api["executions"]
    ]


def test_execute_of_the_cli_plan_file_and_compare_execute_agree_with_the_api(
    api: dict[str, Any], tmp_path: Path
) -> None:
    plan_file = tmp_path / "p.json"
    budget = ("--max-checks", str(MAX_CHECKS))
    solved = plannerlab(
        "solve", PROBLEM, "--planner", PLANNER, "--seed", str(SEED), *budget,
        "--out", str(plan_file), "--json",
    )  # fmt: skip
    assert solved.returncode == 0, solved.stderr[-2000:]
    executed = plannerlab("execute", str(plan_file), "--json")
    assert executed.returncode == 0, executed.stderr[-2000:]
    compared = plannerlab(
        "compare", PROBLEM, "--planners", PLANNER, "--seeds", str(SEED), *budget,
        "--execute", "--jobs", "1", "--out", str(tmp_path / "runs"), "--name", "c", "--json",
    )  # fmt: skip
    assert compared.returncode == 0, compared.stderr[-2000:]

    file_plan = Plan.load(plan_file)
    exec_file = ExecutionFile.load(execution_path(plan_file))
    assert json.loads(executed.stdout) == exec_file.to_dict()
    (trial,) = pl.TrialStore(tmp_path / "runs" / "c" / "trials.jsonl").load().values()
    assert isinstance(trial, TrialRecord)
    api_plan, api_exec = api["plan"], api["executions"]

    # the same verdict, field by field: the execution file (its log too) and the trial
    assert [_verdict(e, include_log=True) for e in exec_file.executions] == [
        _verdict(e, include_log=True) for e in api_exec
    ]
    assert trial.executions is not None
    untimed = [msgspec.structs.replace(x, wall_time_s=None) for x in trial.executions]
    assert untimed == [
        msgspec.structs.replace(ExecutionRecord.of(e), wall_time_s=None) for e in api_exec
    ]
    # the same legs (clocks aside), the same path on every road: the file's, the trial's
    # (its hash) and the API's
    continuous = api["problem"].robot.continuous
    assert [msgspec.structs.replace(x, time_s=0.0, progress=()) for x in trial.legs_run] == [
        msgspec.structs.replace(LegRecord.of(r, continuous), time_s=0.0, progress=())
        for r in api_plan.legs
    ]
    assert [r.path.tobytes() for r in file_plan.legs] == [r.path.tobytes() for r in api_plan.legs]
    assert [x.path_sha256 for x in trial.legs_run] == [r.path_sha256() for r in api_plan.legs]
    assert [x.path_points for x in trial.legs_run] == [len(r.path) for r in api_plan.legs]
    # the path's quality is the plan file's too
    assert [x.path_clearance_m for x in trial.legs_run] == [
        r.path_clearance_m for r in file_plan.legs
    ]
    assert trial.exec_success == all(e.success for e in api_exec)


def test_waypoints_are_a_fixed_point_and_survive_json() -> None:
    rng = np.random.default_rng(3)
    corners = rng.uniform(-3, 3, size=(6, 5))
    # straight runs of uneven steps between the corners, plus a slow curve
    parts = [corners[0][None]]
    for a, b in zip(corners[:-1], corners[1:], strict=True):
        t = np.sort(rng.uniform(0, 1, size=7))
        parts.append(a + np.append(t, 1.0)[:, None] * (b - a))
    s = np.linspace(0, 1, 9)[1:, None]
    parts.append(corners[-1] + np.hstack([np.sin(s), np.cos(s), s, s**2, -s]))
    path = np.vstack(parts)
    w = waypoints(path)
    assert len(w) < len(path)
    assert waypoints(w).tobytes() == w.tobytes()
    assert np.asarray(loads(dumps(w)), dtype=float).tobytes() == w.tobytes()


def test_canonical_result_leaves_a_canonical_result_alone(api: dict[str, Any]) -> None:
    (leg,) = api["plan"].legs
    assert canonical_result(leg) is leg

"""``plannerlab continuum`` speaks the house's records (issue 12, item 1).

* ``--json`` is one JSON document whose per-case entries embed the plan record (as the
  plan file holds it) and the execution record, written through the one codec.
* ``--out DIR`` writes ``<case>.plan.json`` and ``<case>.plan.exec.json``, which
  ``plannerlab execute`` and ``plannerlab plot`` read like any other plan: ``execute``
  runs a contact plan in the continuum's executor (expected contacts are no failure).
* The records: a contact the plan asked for is no failure, any other contact is; an
  execution without an FCL re-check (``path_valid`` None) is not an invalid one; files
  written before these fields read back.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import plannerlab

from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.record.plan import ExecutionFile, Plan

CASE = "continuum_case3"


@pytest.fixture(scope="module")
def continuum_run(tmp_path_factory) -> tuple[dict, Path]:
    """``plannerlab continuum 3 --runs 2 --execute --out DIR --json`` (no figures)."""
    out = tmp_path_factory.mktemp("continuum")
    proc = plannerlab(
        "continuum", "3", "--runs", "2", "--execute", "--no-figures", "--out", str(out), "--json"
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout), out  # one document: raises on anything around it


def test_json_embeds_the_plan_and_execution_records(continuum_run) -> None:
    doc, out = continuum_run
    assert doc["planner"] == "chord_arc" and doc["runs"] == 2
    (case,) = doc["cases"]
    assert case["problem"] == CASE
    assert case["runs"] == 2 and case["same_every_run"] is True
    assert case["paper"] == {"time_s": 0.04, "collision_points": 5, "solutions": 1}
    assert case["search_median_s"] > 0 and case["solve_median_s"] > 0
    # the plan entry is the plan file's content, which adds where the problem file is
    # from the plan's own folder
    plan_file = out / f"{CASE}.plan.json"
    assert case["files"]["plan_file"] == str(plan_file)
    saved = json.loads(plan_file.read_text())
    from_plan = saved.pop("problem_file_from_plan")
    assert case["plan"] == saved
    assert (plan_file.parent / from_plan).resolve() == Path(saved["problem_file"]).resolve()
    plan = Plan.load(plan_file)
    (leg,) = plan.legs
    assert plan.planner == "chord_arc" and plan.seed == 0 and plan.problem == CASE
    assert leg.solved and leg.contact_plan.chosen == 0
    assert leg.contact_plan.solutions[0].contact_indices == (1,)
    # the execution entry is the execution file's record
    ex = ExecutionFile.load(out / f"{CASE}.plan.exec.json")
    assert ex.plan_file == str(plan_file) and ex.planner == "chord_arc"
    (e,) = ex.executions
    assert case["execution"] == e.to_dict()
    assert e.extra["executor"] == "chord_arc" and e.extra["collision_points_used"] == [1]
    assert e.success and not e.unexpected_contacts and e.path_valid is None
    assert e.final_pos_err_m < 1e-3
    # the chain follows its path (measured 0.79 mm at the waypoints' window ends, against
    # the 1 cm limit); its clearance is not judged: it touches its collision point
    assert e.max_deviation_m < 2e-3 and e.max_deviation_limit_m == 0.01 and e.followed
    assert math.isnan(e.min_clearance_m) and e.solver == "dantzig"


def test_plannerlab_execute_runs_a_continuum_plan(continuum_run, tmp_path) -> None:
    """The plan file holds the path's waypoints, the canonical form every road executes;
    execute cuts them to the planner's steps again and runs them in the continuum's
    executor: the very execution ``continuum --execute`` made (the wall clock aside)."""
    doc, out = continuum_run
    exec_file = tmp_path / "again.exec.json"
    proc = plannerlab("execute", str(out / f"{CASE}.plan.json"), "--out", str(exec_file), "--json")
    assert proc.returncode == 0, proc.stderr
    (e,) = ExecutionFile.load(exec_file).executions
    assert json.loads(proc.stdout)["executions"] == [e.to_dict()]
    assert e.extra["executor"] == "chord_arc" and e.success, e.reason
    first = Execution.from_dict(doc["cases"][0]["execution"])
    assert {**e.to_dict(), "wall_time_s": 0} == {**first.to_dict(), "wall_time_s": 0}
    steps = np.abs(np.diff(e.q_cmd_rad, axis=0))
    assert np.max(steps[:, 0]) <= 0.002 * (1 + 1e-6)  # insertion [m]
    assert np.max(steps[:, 1:]) <= 0.02 * (1 + 1e-6)  # bend joints [rad]


def test_plannerlab_plot_reads_a_continuum_plan(continuum_run, tmp_path) -> None:
    _, out = continuum_run
    proc = plannerlab("plot", str(out / f"{CASE}.plan.json"), "--out", str(tmp_path), "--json")
    assert proc.returncode == 0, proc.stderr
    files = json.loads(proc.stdout)
    assert any(Path(f).name == "leg0_target_end.png" for f in files)
    assert all(Path(f).stat().st_size > 0 for f in files)


def test_densify_restores_the_planner_steps_and_keeps_a_sampled_path() -> None:
    from plannerlab.planners import make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.robots.paths import waypoints
    from plannerlab.run.pipeline import leg_rng, solve_legs
    from plannerlab.sim.continuum import densify_chord_arc_path

    problem = load_problem("continuum_case2")
    r = make_planner("chord_arc").solve(problem, 0, problem.budget, leg_rng(0, 0))
    assert densify_chord_arc_path(r.path, r.settings) is r.path  # already at its steps
    # a plan holds the path's canonical form, its waypoints
    (canonical,) = solve_legs(problem, "chord_arc", 0).legs
    np.testing.assert_array_equal(canonical.path, waypoints(r.path))
    corners = waypoints(r.path)
    assert len(corners) < len(r.path) / 2
    again = densify_chord_arc_path(corners, r.settings)
    # case 2's straight stretches were sampled evenly: the same states come back
    assert again.shape == r.path.shape
    np.testing.assert_allclose(again, r.path, atol=1e-12)
    np.testing.assert_array_equal(densify_chord_arc_path(corners, {}), corners)


def _contact(expected: bool) -> ContactRecord:
    return ContactRecord("link_3", "slab", False, 1e-4, 0.5, (0.1, 0.2, 0.0), expected, 1, 2e-3)


def _execution(contacts: tuple[ContactRecord, ...], path_valid: bool | None) -> Execution:
    q = np.zeros((2, 3))
    return Execution(
        problem="p",
        leg=0,
        goal="g",
        path_valid=path_valid,
        recheck_joint_step=math.nan,
        recheck_states=0,
        recheck_first_invalid_edge=None,
        recheck_pairs=(),
        waypoint_step=0.01,
        steps_per_waypoint=12,
        settle_steps=240,
        dt_s=1 / 240,
        contact_tol_m=0.0,
        gravity_mps2=(0.0, 0.0, -9.81),
        t_s=[0.05, 0.1],
        q_cmd_rad=q,
        q_actual_rad=q,
        track_err_rad=[0.0, 0.0],
        tip_track_err_m=[0.0, 0.0],
        contacts=contacts,
        q_start_rad=q[0],
        carried_over=False,
        start_offset_rad=0.0,
        q_final_rad=q[-1],
        final_track_err_rad=0.0,
        final_tip_track_err_m=0.0,
        final_pos_err_m=1e-4,
        final_angle_err_deg=math.nan,
        goal_reached=True,
        sim_time_s=1.1,
        wall_time_s=0.3,
        reason="r",
        extra={"approaches": [{"obstacle": "slab", "distance_m": -math.inf}]},
    )


def test_expected_contacts_are_no_failure_and_others_are() -> None:
    assert _execution((_contact(True),), None).success
    assert not _execution((_contact(True), _contact(False)), None).success
    assert not _execution((_contact(True),), False).success
    e = _execution((_contact(True), _contact(False)), None)
    assert e.expected_contacts == (_contact(True),)
    assert e.unexpected_contacts == (_contact(False),)


def test_execution_extra_and_contact_fields_round_trip_through_the_codec() -> None:
    from plannerlab.record.codec import dumps, loads

    e = _execution((_contact(True), _contact(False)), None)
    data = loads(dumps(e.to_dict()))
    assert data["extra"]["approaches"][0]["distance_m"] is None  # non-finite: the codec's
    assert data["recheck_joint_step"] is None and data["path_valid"] is None
    back = Execution.from_dict(data)
    assert back.contacts == e.contacts and back.path_valid is None
    assert math.isnan(back.recheck_joint_step)
    # a contact written before ``expected`` existed reads back as unexpected
    old = dict(_contact(True).to_dict())
    for k in ("expected", "collision_point", "distance_m"):
        del old[k]
    assert ContactRecord.from_dict(old) == ContactRecord(
        "link_3", "slab", False, 1e-4, 0.5, (0.1, 0.2, 0.0)
    )


def test_sim_world_names_its_links_publicly() -> None:
    from plannerlab.problem.catalog import load_problem
    from plannerlab.sim import SimWorld

    problem = load_problem(CASE)
    robot = problem.robot
    with SimWorld(robot, problem.scene) as world:
        named = {j: world.link_name(j) for j in world.urdf_link_names}
    robot_links = {name: i for name, i in named.values() if i is not None}
    assert robot_links == {n: i for i, n in enumerate(robot.link_names)}
    assert all(name == world.urdf_link_names[j] for j, (name, i) in named.items() if i is None)

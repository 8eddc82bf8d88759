"""The continuum paper's table, one case (comparison/continuum.py, behind ``plannerlab
continuum``): the row's plan planned by the one road, the timed runs, the zero-thickness
solve the figures and table need (no figure plans), the paper's row."""

from __future__ import annotations

import pytest

from plannerlab.comparison.continuum import case_name, run_case
from plannerlab.errors import PlannerlabError
from plannerlab.planners.chord_arc.planner import PAPER_TABLE


def test_a_case_gives_its_records_and_timing():
    row = run_case("2", runs=2)
    assert case_name("2") == row.problem.name == "continuum_case2"
    assert (row.plan.planner, row.plan.seed, len(row.plan.legs)) == ("chord_arc", 0, 1)
    assert row.result.solved and row.execution is None
    # the robot's radius (the default): the row's own leg is the thick record
    assert row.thick is row.result
    assert row.thin.settings["inflate_by_radius"] is False
    # case 2 loses one solution to the robot's 2 mm radius (test_continuum_planning)
    paper = PAPER_TABLE["continuum_case2"]
    assert len(row.thin.contact_plan.solutions) == paper.solutions
    assert len(row.thick.contact_plan.solutions) == paper.solutions - 1
    t = row.timing
    assert (t["runs"], t["same_every_run"], t["solutions_zero_thickness"]) == (
        2,
        True,
        paper.solutions,
    )
    assert t["paper"]["solutions"] == paper.solutions and t["search_median_s"] > 0
    doc = row.to_dict({"figure": "f.png"})
    assert doc["problem"] == "continuum_case2" and doc["files"] == {"figure": "f.png"}
    assert doc["plan"] == row.plan.to_dict() and doc["execution"] is None


def test_with_the_radius_dropped_the_thick_record_is_solved_for_the_figure():
    row = run_case("2", 1, {"inflate_by_radius": False})
    assert row.result.settings["inflate_by_radius"] is False
    assert row.thick is not row.result and row.thick.settings["inflate_by_radius"] is True
    assert len(row.thick.contact_plan.solutions) == PAPER_TABLE["continuum_case2"].solutions - 1


def test_runs_must_be_positive():
    with pytest.raises(PlannerlabError, match="--runs"):
        run_case("1", runs=0)

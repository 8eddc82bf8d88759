"""The screen's choice of each family's best member (comparison/screen.py), on records
made by hand: most problems executed cleanly, then fewest checks, then name."""

from __future__ import annotations

import pytest

from plannerlab.comparison.screen import best_members, screen_table
from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import ExecutionRecord, LegRecord, TrialRecord


def _rec(planner: str, problem: str, seed: int, clean: bool, checks: int) -> TrialRecord:
    leg = LegRecord(
        planner=planner,
        problem=problem,
        leg=0,
        goal="g",
        status="solved" if clean else "local_minimum",
        collision_checks=checks,
    )
    execs = (
        (ExecutionRecord(problem=problem, leg=0, goal="g", success=True, path_valid=True),)
        if clean
        else None
    )
    return TrialRecord(
        key=f"{problem}/{planner}/s{seed}",
        problem=problem,
        problem_file=f"{problem}.toml",
        planner=planner,
        seed=seed,
        status=leg.status,
        success=clean,
        legs_run=(leg,),
        executions=execs,
    )


FAMILIES = {"a": ("a1", "a2", "a3"), "b": ("b1",), "empty": ()}
PROBLEMS = ("p", "q")


def _screen() -> list[TrialRecord]:
    return [
        _rec("a1", "p", 0, True, 900),
        _rec("a1", "q", 0, False, 50),
        _rec("a2", "p", 0, True, 500),
        _rec("a2", "q", 0, False, 400),  # a1, a2: one clean each; a2 fewer checks (900)
        _rec("a3", "p", 0, False, 10),
        _rec("a3", "q", 0, False, 10),
        _rec("b1", "p", 0, False, 1),
        _rec("b1", "q", 0, False, 1),
        # another seed's trials do not count: a3 clean on both at seed 1
        _rec("a3", "p", 1, True, 1),
        _rec("a3", "q", 1, True, 1),
    ]


def test_the_best_member_has_most_clean_problems_then_fewest_checks():
    recs = _screen()
    table = screen_table(recs, 0)
    assert (table["a1"].clean, table["a1"].checks) == (1, 950)
    assert (table["a2"].clean, table["a2"].checks) == (1, 900)
    assert best_members(recs, FAMILIES, 0, PROBLEMS) == {"a": "a2", "b": "b1"}
    # on seed 1 only a3 ran: the screen is incomplete for the others
    with pytest.raises(PlannerlabError, match="incomplete for 'a': a1, a2 have not run"):
        best_members(recs, FAMILIES, 1, PROBLEMS)


def test_a_member_missing_a_problem_is_refused_not_ranked():
    recs = [r for r in _screen() if not (r.planner == "a1" and r.problem == "q")]
    with pytest.raises(PlannerlabError, match="a1 has not run every problem of p, q"):
        best_members(recs, FAMILIES, 0, PROBLEMS)

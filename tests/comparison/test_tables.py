"""Terminal tables fit the terminal and never split a number.

Each table is rendered at 80 and 120 columns: no line is longer than the width, and every
number (every cell of a numeric column) appears whole on one line. The ``compare`` rows are
made up with the worst cases seen (tiny and huge numbers, long planner names, a 100 %
interval, errors); the other commands run for real through ``plannerlab.cli.main``.
"""

from __future__ import annotations

import io
import json
import math
import os
import re

import numpy as np
import pytest
from rich.console import Console

from plannerlab.cli.main import main
from plannerlab.cli.solve import leg_table
from plannerlab.cli.tables import (
    COMPACT_COLUMNS,
    PIPE_WIDTH,
    SUMMARY_COLUMNS,
    WIDE_COLUMNS,
    output_width,
    pick_columns,
    print_summary_tables,
)
from plannerlab.comparison.statistics import SUMMARY_COLUMNS as ROW_KEYS
from plannerlab.comparison.statistics import SummaryRow
from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult

WIDTHS = (80, 120)


def _row(planner: str, **changes: float) -> SummaryRow:
    row: dict = {k: math.nan for k in ROW_KEYS}
    row.update(
        problem="armz_pocket",
        planner=planner,
        n=100,
        successes=97,
        errors=3,
        success_rate=0.97,
        ci95_low=0.915,
        ci95_high=0.994,
        time_median_s=0.000208,
        time_p75_s=123.456,
        time_p95_s=98765.4,
        path_length_median=12.3456,
        pos_err_median_m=11.8,
        angle_err_median_deg=179.99,
        checks_median=1234567.0,
        iterations_median=50000.0,
        local_minima=649,
        escapes=378,
        executed=97,
        exec_successes=80,
        exec_success_rate=80 / 97,
        exec_track_err_median_rad=0.00123,
        exec_contacts=17,
        deterministic=False,
        distinct_trials=100,
        smoothness_median_rad2=0.987,
        path_clearance_min_m=0.0126,
        pos_tol_m=0.1,
        angle_tol_deg=10.0,
    )
    row.update(changes)
    return SummaryRow(**row)


ROWS = [
    _row("gradient+rrtconnect", successes=100, errors=0, success_rate=1.0, ci95_high=1.0),
    _row("gradient.multistart", successes=0, success_rate=0.0, ci95_low=0.0),
    _row("ompl.informedrrtstar"),
    # every seed the same trial: "deterministic" where the interval would be
    _row(
        "gradient",
        n=100,
        successes=100,
        errors=0,
        success_rate=1.0,
        deterministic=True,
        distinct_trials=1,
    ),
]


def _render(width: int, draw) -> list[str]:
    buf = io.StringIO()
    console = Console(file=buf, width=width, color_system=None, legacy_windows=False)
    draw(console)
    return buf.getvalue().splitlines()


def _fits(lines: list[str], width: int) -> None:
    assert lines
    too_long = [line for line in lines if len(line) > width]
    assert not too_long, too_long


def _whole(cells: list[str], lines: list[str]) -> None:
    """Every cell appears unbroken on some line (and is not cut with an ellipsis)."""
    for cell in cells:
        assert any(cell in line for line in lines), (cell, lines)


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("which", ["compact", "wide"])
def test_compare_table_fits_and_keeps_every_number_whole(width: int, which: str) -> None:
    keys = pick_columns(None, wide=(which == "wide"), executed=True)
    lines = _render(width, lambda c: print_summary_tables(c, "armz_pocket", ROWS, keys))
    _fits(lines, width)
    _whole([SUMMARY_COLUMNS[k].cell(r) for r in ROWS for k in keys], lines)
    if which == "compact":
        # one table at 80 columns: the header line names every compact column once
        assert sum("planner" in line for line in lines) == 1
    elif width == 80:
        assert sum("planner" in line for line in lines) >= 2  # split rather than cut


def test_compact_columns_are_the_issue_s_and_exec_columns_need_execution() -> None:
    assert COMPACT_COLUMNS == ("planner", "solved", "time", "checks", "minima", "exec_ok")
    assert "exec_ok" not in pick_columns(None, wide=False, executed=False)
    assert "track_err" not in pick_columns(None, wide=True, executed=False)
    assert set(WIDE_COLUMNS) <= set(SUMMARY_COLUMNS)
    assert pick_columns("planner,checks,time", wide=True, executed=False) == [
        "planner",
        "checks",
        "time",
    ]
    with pytest.raises(PlannerlabError, match="chekcs"):
        pick_columns("planner,chekcs", wide=False, executed=False)
    cell = SUMMARY_COLUMNS["solved"].cell(ROWS[0])
    assert cell == "100/100 [92-100%]"
    assert SUMMARY_COLUMNS["solved"].cell(ROWS[-1]) == "100/100 [one trial]"
    assert SUMMARY_COLUMNS["success"].cell(ROWS[-1]) == "100% [deterministic]"


@pytest.mark.parametrize("width", WIDTHS)
def test_leg_table_fits(width: int) -> None:
    legs = [
        PlanResult(
            planner="gradient+rrtconnect",
            problem="armz_inspection",
            leg=i,
            goal=goal,
            status=status,
            reason="descent stalled; " * 8,
            path=np.zeros((2, 23)),
            time_s=0.000208 * (i + 1),
            iterations=123456,
            collision_checks=1234567,
            pos_err_m=11.8,
            angle_err_deg=0.000173,
        )
        for i, (goal, status) in enumerate(
            [("enter", "solved"), ("A", "local_minimum"), ("leave", "budget_exhausted")]
        )
    ]

    class _Plan:
        pass

    plan = _Plan()
    plan.legs = legs
    lines = _render(width, lambda c: c.print(leg_table(plan, "gradient+rrtconnect, seed 0")))
    _fits(lines, width)
    _whole(["0.000208", "0.000416", "1234567", "123456", "11.8", "0.000173"], lines)
    _whole(["local_minimum", "budget_exhausted"], lines)


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("command", ["problems", "planners"])
def test_listing_commands_fit(width: int, command: str, monkeypatch, capsys) -> None:
    assert main([command, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    monkeypatch.setenv("COLUMNS", str(width))
    assert main([command]) == 0
    lines = capsys.readouterr().out.splitlines()
    _fits(lines, width)
    _whole([r["name"] for r in rows], lines)
    if command == "problems":  # each row whole on its line: name, from, robot, dof, obstacles
        for r in rows:
            pattern = (
                rf"^{r['name']}\s+{re.escape(r['from'])}\s+{r['robot']}\s+{r['dof']}\s+"
                rf"{r['obstacles']}\s"
            )
            assert any(re.search(pattern, line) for line in lines), r["name"]


def test_piped_output_width(monkeypatch) -> None:
    monkeypatch.setenv("COLUMNS", "93")
    assert output_width(io.StringIO()) == 93
    monkeypatch.delenv("COLUMNS")

    def no_terminal(fd: int = 0) -> os.terminal_size:
        raise OSError("not a terminal")

    monkeypatch.setattr(os, "get_terminal_size", no_terminal)
    assert output_width(io.StringIO()) == PIPE_WIDTH == 100


@pytest.mark.parametrize("width", WIDTHS)
def test_execution_table_keeps_obstacle_names_whole(width: int) -> None:
    from types import SimpleNamespace as NS

    from plannerlab.cli.execute import execution_table

    contact = NS(link_name="module_17", other_name="boulder")
    legs = [NS(leg=0, goal="pocket"), NS(leg=1, goal="leave")]
    executions = [
        NS(
            path_valid=False,
            recheck_first_invalid_edge=12,
            recheck_pairs=(("module_16", "boulder"),),
            final_pos_err_m=11.8,
            final_angle_err_deg=0.000173,
            max_deviation_m=0.217,
            min_clearance_m=-0.0031,
            max_track_err_rad=0.0512,
            contacts=(contact,) * 3,
            unexpected_contacts=(contact,) * 3,
            expected_contacts=(),
            duration_s=162.125,
            wall_time_s=41.9,
            success=False,
            failures=(
                "re-check: module_16 x boulder collide",
                "contact module_17 x boulder (+2 more)",
                "clearance -3.1 mm (module_17 x boulder)",
            ),
        ),
        NS(
            path_valid=True,
            recheck_first_invalid_edge=None,
            recheck_pairs=(),
            final_pos_err_m=0.000208,
            final_angle_err_deg=1.5,
            max_deviation_m=1.2e-6,
            min_clearance_m=0.0384,
            max_track_err_rad=0.00123,
            contacts=(),
            unexpected_contacts=(),
            expected_contacts=(),
            duration_s=3.5,
            wall_time_s=0.9,
            success=True,
            failures=(),
        ),
    ]
    lines = _render(width, lambda c: c.print(execution_table(legs, executions)))
    _fits(lines, width)
    _whole(["11.8", "0.000173", "41.9", "0.000208"], lines)
    _whole(["217", "-3.1", "0.0012", "38.4"], lines)  # deviation and clearance [mm]
    _whole(["module_17 x boulder", "module_16 x boulder", "pocket", "collides"], lines)


def test_leg_table_puts_tolerances_beside_errors_and_no_number_on_a_leg_without_result() -> None:
    """A leg solved at 0.0976 m / 9.54° against 0.1 m / 10° says so; a leg that gave up at
    its start prints "—" (its reason is in the caption), not 1.23 m / 180°."""

    def leg(i: int, status: str, points: int, pos: float, ang: float, **kw) -> PlanResult:
        return PlanResult(
            "ompl.rrtconnect", "p", i, f"g{i}", status, f"reason {i}", np.zeros((points, 3)),
            pos_err_m=pos, angle_err_deg=ang, pos_tol_m=0.1, angle_tol_deg=10.0, **kw,
        )  # fmt: skip

    class _Plan:
        legs = [
            leg(0, "solved", 5, 0.0976, 9.54, roughness_rad2=0.25, path_clearance_m=0.0126),
            leg(1, "budget_exhausted", 1, 1.23, 180.0),
            leg(2, "local_minimum", 7, 0.4, 30.0),
        ]

    lines = _render(120, lambda c: c.print(leg_table(_Plan(), "t")))
    text = "\n".join(lines)
    _whole(["0.0976 / 0.1", "9.54 / 10", "0.4 / 0.1", "30 / 10"], lines)
    assert "1.23" not in text and "180" not in text
    row = next(line for line in lines if "budget_exhausted" in line)
    assert row.count("—") == 2
    assert "reason 1" in text and "smoothness 0.25 rad²" in text
    assert "clearance along the path 12.6 mm" in text


def test_a_straight_paths_float_noise_is_no_roughness() -> None:
    from plannerlab.record.cells import rough

    assert rough(2.63e-14) == "0" and rough(0.25) == "0.25" and rough(None) == "-"
    cell = SUMMARY_COLUMNS["smoothness"].cell(_row("x", smoothness_median_rad2=2.63e-14))
    assert cell == "0"

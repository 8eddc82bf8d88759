"""The escape study's progress figure: a seed's best goal distance at given moments, and
the median over seeds (plot/study.py), on hand-made curves."""

from __future__ import annotations

import numpy as np
import pytest

from plannerlab.plot.study import best_so_far, median_curve, progress_panels


def test_best_so_far_is_the_running_minimum_held_after_the_last_row():
    curve = [(0.1, 5.0), (0.2, 7.0), (0.5, 2.0), (1.0, 0.0)]
    t = np.array([0.05, 0.1, 0.3, 0.6, 5.0])
    got = best_so_far(curve, t)
    assert np.isnan(got[0])  # before the seed's first row
    assert got[1:].tolist() == [5.0, 5.0, 2.0, 0.0]  # 7.0 is no improvement; held after 1 s


def test_median_curve_over_seeds_ignores_seeds_not_started():
    seeds = [[(0.0, 4.0), (1.0, 0.0)], [(0.0, 6.0)], [(2.0, 1.0)]]
    got = median_curve(seeds, np.array([0.5, 1.5, 3.0]))
    assert got.tolist() == pytest.approx([5.0, 3.0, 1.0])  # median of (4,6), (0,6), (0,6,1)
    assert np.isnan(median_curve([], np.array([1.0]))).all()


def test_progress_panels_draws_one_panel_per_problem_and_a_line_per_planner():
    curves = {
        "trap_a": {"p1": [[(0.0, 3.0), (0.4, 0.0)]], "p2": [[(0.0, 3.0)]]},
        "trap_b": {"p1": [[(0.0, 2.0)]]},
    }
    fig = progress_panels(curves, "t", t_max_s=30.0)
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in axes] == ["trap_a", "trap_b"]
    assert [len(ax.get_lines()) for ax in axes] == [2, 1]
    solved = axes[0].get_lines()[0].get_ydata()
    assert solved[-1] == 0.0 and solved[0] == 3.0


def test_escape_matrix_colours_each_cell_by_its_share_and_greys_what_did_not_run():
    """plot/escapes.py: rows × columns of cells; the colour is the share executed cleanly
    (green at 1, red at 0, grey for a cell not run), the text the count and its note."""
    from plannerlab.plot.escapes import Cell, escape_matrix

    cells = [[Cell(20, 20, "leader"), Cell(0, 20)], [Cell(1, 1, "1 run"), Cell(0, 0)]]
    fig = escape_matrix(["native", "clearance"], ["armz_deep_a", "armz_pocket"], cells, "t", [0])
    ax = fig.axes[0]
    texts = sorted(t.get_text() for t in ax.texts)
    assert texts == sorted(["20/20\nleader", "0/20", "1/1\n1 run", "–"])
    assert [t.get_text() for t in ax.get_xticklabels()] == ["deep_a", "pocket"]
    image = ax.get_images()[0]
    rgba = image.to_rgba(image.get_array())
    assert rgba[0, 0, 1] > rgba[0, 0, 0]  # all clean: green over red
    assert rgba[0, 1, 0] > rgba[0, 1, 1]  # none clean: red over green
    assert np.ma.is_masked(image.get_array()[1, 1])  # not run: masked, drawn grey
    assert len(ax.get_lines()) == 1  # the line between the two families

"""The continuum paper's cases as planning problems (``docs/papers.md`` §3, issue 4).

* ``chord_arc`` through the registry: solved, the paper's solution counts (2, 2, 1),
  every solution and every dropped one reported, same result every run.
* "Unsolvable without contact": a single constant-curvature section (the paper's claim)
  reaches no target, and RRT-Connect on the 40-link chain with contact forbidden solves
  none of the three cases within a generous budget. The scenes model the insertion
  channel behind the port (a sleeve): without it, the not-yet-inserted links were free
  to swing round the scene and RRT-Connect solved case 3 in a few hundred checks.
* Thickness: the planner plans for the robot's 2 mm radius by default and finds 2, 1, 1
  solutions; the paper's zero-thickness model finds the paper's 2, 2, 1. The solution
  case 2 loses is exactly the one whose thin curve comes closer than the radius to an
  obstacle away from its collision points.
* PyBullet execution of the chosen solution of all three cases (in two worker
  processes): the tip ends inside the 5 mm goal region and the chain touches obstacles
  only at the planned collision point (and the sleeve).
"""

from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from plannerlab.planners import make_planner
from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.chord_arc.planner import PAPER_TABLE
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget
from plannerlab.run.pipeline import leg_rng

CASES = (1, 2, 3)
#: zero-thickness solution counts: the paper's Table I
PAPER_SOLUTIONS = {c: PAPER_TABLE[f"continuum_case{c}"].solutions for c in CASES}
#: with the robot's 2 mm radius: case 2 loses its two-contact solution (points 1, 4),
#: whose thin curve meets the wall's lower right corner and the post's lower left corner
#: at shallow angles (see test_the_solutions_lost_to_thickness_are_those_that_cut)
THICK_SOLUTIONS = {1: 2, 2: 1, 3: 1}
#: the chosen ("shortest") solution's collision points, from the geometry: cases 2 and 3
#: have one solution for the robot's radius (case 2: round the wall's lower left corner,
#: case 3: the slab's corner 1); case 1's two are mirror images about the port's axis
#: (equal length, bends ±0.836 / ∓2.600 rad), and the tie goes to the first in
#: breadth-first order, point 0
CHOSEN_POINTS = {1: (0,), 2: (0,), 3: (1,)}
RRT_CHECKS = 30_000  # collision-check budget of RRT-Connect (generous: without the sleeve
#                      it solved case 3 in a few hundred)


def _solve(case: int, overrides: dict | None = None, seed: int = 0) -> PlanResult:
    problem = load_problem(f"continuum_case{case}")
    planner = make_planner("chord_arc", overrides)
    return planner.solve(problem, 0, problem.budget, leg_rng(seed, 0))


def _execute(case: int) -> dict:
    """Worker: plan (default settings) and execute in PyBullet; the records as plain data
    back (through the codec, as a plan file and an execution file hold them)."""
    from plannerlab.sim.continuum import execute_chord_arc

    problem = load_problem(f"continuum_case{case}")
    r = _solve(case)
    return {"plan": r.to_dict(), "execution": execute_chord_arc(problem, r).to_dict()}


_RRT = """
import json, sys
from plannerlab.problem.catalog import load_problem
from plannerlab.planners import make_planner
from plannerlab.run.pipeline import leg_rng
p = load_problem(sys.argv[1])
r = make_planner("ompl.rrtconnect").solve(
    p, 0, p.budget.replace(max_collision_checks=int(sys.argv[2])), leg_rng(0, 0))
print(json.dumps({"status": r.status.value, "reason": r.reason,
                  "checks": r.collision_checks}))
"""


@pytest.fixture(scope="module")
def rrt_runs():
    """RRT-Connect on each case, one fresh process per case (OMPL's seed is process-global),
    all started at once."""
    procs = {
        c: subprocess.Popen(
            [sys.executable, "-c", _RRT, f"continuum_case{c}", str(RRT_CHECKS)],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        for c in CASES
    }
    yield procs
    for proc in procs.values():
        if proc.poll() is None:
            proc.kill()


@pytest.fixture(scope="module")
def executions():
    """The three PyBullet executions, in two worker processes."""
    with ProcessPoolExecutor(max_workers=2) as pool:
        yield {c: pool.submit(_execute, c) for c in CASES}


def _rrt(rrt_runs, case: int) -> dict:
    proc = rrt_runs[case]
    out, _ = proc.communicate(timeout=300)
    assert proc.returncode == 0, f"RRT-Connect process for case {case} failed"
    return json.loads(out.strip().splitlines()[-1])


# --------------------------------------------------------------------------- chord_arc


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("thick", [True, False], ids=["radius", "zero_thickness"])
def test_chord_arc_solution_counts(case: int, thick: bool) -> None:
    r = _solve(case, {"inflate_by_radius": thick})
    assert r.status is Status.SOLVED, r.reason
    cp = r.contact_plan
    assert cp is not None
    sols = cp.solutions
    assert len(sols) == (THICK_SOLUTIONS if thick else PAPER_SOLUTIONS)[case]
    if thick:
        assert cp.chosen_solution.contact_indices == CHOSEN_POINTS[case]
        assert not any(d.unexpected_contacts for d in cp.dropped)
    for s in sols:
        n = len(s.contact_indices)
        assert n >= 1  # unsolvable without contact
        assert len(s.bend_angles_rad) == len(s.arc_lengths_m) == len(s.arcs) == n + 1
        assert len(s.contact_points_m) == len(s.contact_types) == n
        assert set(s.contact_types) <= {"forward", "backward"}
        assert s.total_length_m <= load_problem(f"continuum_case{case}").robot.length_m
        assert s.path_waypoints > 0 and not s.reason
    assert cp.dropped and all(d.reason and d.stage for d in cp.dropped)
    assert cp.chosen is not None and 0 <= cp.chosen < len(sols)
    # the path: retracted start, tip at the target, contact only at collision points
    assert np.all(r.path[0] == 0.0)
    assert r.pos_err_m < 1e-3
    assert cp.expected_contacts
    assert {e.collision_point for e in cp.expected_contacts} <= set(
        cp.chosen_solution.contact_indices
    )
    # the record goes through the codec and back unchanged
    assert json.loads(json.dumps(r.to_dict())) == r.to_dict()
    assert PlanResult.from_dict(json.loads(json.dumps(r.to_dict()))).contact_plan == cp


@pytest.mark.parametrize("case", CASES)
def test_chord_arc_is_the_same_every_run(case: int) -> None:
    a, b = _solve(case, seed=0), _solve(case, seed=7)
    np.testing.assert_array_equal(a.path, b.path)
    da, db = a.to_dict(), b.to_dict()
    for d in (da, db):
        d["contact_plan"]["search"].pop("time_s")  # the search's wall time
        d.pop("time_s")
        d.pop("seed")
        d["progress"] = [row[1:] for row in d["progress"]]  # without the clock
    assert da == db


def test_chord_arc_declares_contact_and_rejects_a_moved_start() -> None:
    planner = make_planner("chord_arc")
    assert planner.allows_contact is True
    problem = load_problem("continuum_case3")
    q = problem.q_start.copy()
    q[0] = 0.1
    r = planner.solve(problem, 0, problem.budget, leg_rng(0, 0), q_start=q)
    assert r.status is Status.INVALID_START


@pytest.mark.parametrize("case", CASES)
def test_a_single_section_without_contact_reaches_no_target(case: int) -> None:
    """The paper: "all three cases are unsolvable for a single section without contact"."""
    r = _solve(case, {"max_depth": 1})
    assert r.status is Status.FAILED
    assert r.contact_plan.search["geometric_solutions"] == 0


# --------------------------------------------------------------------------- RRT-Connect


@pytest.mark.parametrize("case", CASES)
def test_rrtconnect_without_contact_does_not_solve(case: int, rrt_runs) -> None:
    """Seed 0, 30 000 collision checks. Measured: cases 1 and 2 end INVALID_GOAL (its IK
    finds no contact-free goal state in 200 attempts), case 3 uses its whole budget
    without reaching the target (also with 100 000 checks, seeds 0 and 1)."""
    out = _rrt(rrt_runs, case)
    assert out["status"] in ("invalid_goal", "budget_exhausted"), out


def test_without_the_sleeve_the_chain_is_no_single_section(tmp_path) -> None:
    """Why the scenes have a sleeve: remove it and RRT-Connect swings the un-inserted
    links round the slab and solves case 3 without any contact."""
    text = open(load_problem("continuum_case3").source, encoding="utf-8").read()
    start = text.index("# The insertion channel behind the port")
    path = tmp_path / "no_sleeve.toml"
    text = text.replace('guide_obstacles = ["sleeve_left", "sleeve_right"]', "")  # gone too
    path.write_text(text[:start] + text[text.index("[[goals]]", start) :])
    assert 'name = "sleeve' not in path.read_text()
    done = subprocess.run(
        [sys.executable, "-c", _RRT, str(path), str(RRT_CHECKS)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["status"] == "solved", out


# --------------------------------------------------------------------------- PyBullet


@pytest.mark.parametrize("case", CASES)
def test_the_solutions_lost_to_thickness_are_those_that_cut(case: int) -> None:
    """A zero-thickness solution survives the robot's radius exactly when a 2 mm robot
    along its curve would not cut an obstacle away from its collision points."""
    from plannerlab.planners.chord_arc.scene import thickness_cuts

    problem = load_problem(f"continuum_case{case}")
    thin_planner = make_planner("chord_arc", {"inflate_by_radius": False})
    query, thin = thin_planner.search(problem, 0)
    _, thick = make_planner("chord_arc").search(problem, 0)
    kept = {p.solution.contact_indices for p in thick.plans}
    r = problem.robot.link_radius_m
    for p in thin.plans:
        cuts = thickness_cuts(query, p.solution, r)
        assert (len(cuts) == 0) == (p.solution.contact_indices in kept), p.solution
    if case == 2:  # the two-contact solution cuts the wall's lower edge and the post
        (lost,) = [p for p in thin.plans if p.solution.contact_indices not in kept]
        assert lost.solution.contact_indices == (1, 4)
        cuts = thickness_cuts(query, lost.solution, r)
        assert np.any(np.linalg.norm(cuts - [0.14, 0.18], axis=1) < 0.01)
        assert np.any(np.linalg.norm(cuts - [0.18, 0.25], axis=1) < 0.01)


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES)
def test_execution_reaches_the_target_touching_only_the_planned_points(
    executions, case: int
) -> None:
    """Golden values from the problem, not from a run: the tip ends inside the goal
    region (5 mm), every contact is at the planned collision point (on the obstacle that
    owns it) or with the sleeve, and the motion is the paper's follow / push / re-bend /
    follow for one contact."""
    from plannerlab.record.execution import Execution

    problem = load_problem(f"continuum_case{case}")
    data = executions[case].result(timeout=900)
    plan = PlanResult.from_dict(data["plan"])
    e = Execution.from_dict(data["execution"])
    sol = plan.contact_plan.solutions[e.extra["chosen"]]
    assert sol.contact_indices == CHOSEN_POINTS[case]
    assert tuple(e.extra["collision_points_used"]) == CHOSEN_POINTS[case]
    assert [kind for kind, _ in sol.motion] == ["follow", "push", "rebend", "follow"]
    assert e.final_pos_err_m < problem.goal(0).pos_tol_m, e.reason
    assert e.goal_reached and e.leg == 0 and e.goal == problem.goal(0).name
    assert not e.unexpected_contacts, e.reason
    assert e.success, e.reason
    assert e.path_valid is None  # no FCL re-check: the path touches by design
    guides = set(plan.contact_plan.guide_obstacles)
    owners = set(sol.contact_obstacles)
    touched = {c.other_name for c in e.contacts}
    assert touched <= owners | guides, touched
    # the log: one row per commanded waypoint, the chain on the path to 1 cm
    assert e.q_cmd_rad.shape == e.q_actual_rad.shape == (len(e.t_s), problem.robot.dof)
    np.testing.assert_array_equal(e.q_cmd_rad, plan.path)
    assert e.max_tip_track_err_m < 1e-3 and e.max_track_err_rad < 1e-2
    # the chain grazes the planned corner (within 1 mm: planned for its radius, the
    # axis passes r from the corner) and comes that close to nothing else
    near = {a["obstacle"]: a for a in e.extra["approaches"]}
    assert set(near) == owners, e.extra["approaches"]
    for a in near.values():
        assert a["at_collision_point"] and a["collision_point"] in CHOSEN_POINTS[case], a
        assert a["distance_m"] < 1e-3


SMALL = Budget(max_iterations=100)


def test_bad_guide_obstacles_and_missing_collision_points_name_the_key(tmp_path) -> None:
    from plannerlab.errors import ProblemError

    text = open(load_problem("continuum_case3").source, encoding="utf-8").read()
    bad = tmp_path / "bad_guide.toml"
    bad.write_text(
        text.replace(
            'guide_obstacles = ["sleeve_left", "sleeve_right"]',
            'guide_obstacles = ["sleeve_left", "slieve"]',
        )
    )
    with pytest.raises(ProblemError, match=r"\[continuum.guide_obstacles\].*unknown: slieve"):
        make_planner("chord_arc").solve(load_problem(bad), 0, SMALL, leg_rng(0, 0))
    start = text.index("[continuum]")
    none = tmp_path / "no_points.toml"
    none.write_text(text[:start])
    with pytest.raises(ProblemError, match=r"\[continuum.collision_points_m\] is missing"):
        make_planner("chord_arc").solve(load_problem(none), 0, SMALL, leg_rng(0, 0))


def test_continuum_cli_rejects_an_unknown_case_and_zero_runs(capsys) -> None:
    from plannerlab.cli.main import main

    assert main(["continuum", "9"]) == 2
    assert "unknown problem" in " ".join(capsys.readouterr().err.split())
    assert main(["continuum", "1", "--runs", "0"]) == 2
    assert "--runs must be >= 1" in capsys.readouterr().err

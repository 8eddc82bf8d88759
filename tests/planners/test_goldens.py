"""Golden values of every planner family on fixed seeds and check budgets: the OMPL
adapter, the hybrids' escapes (RRT-Connect from the stall, random restarts) and
follow-the-leader (the clearance descent's own goldens are in test_descent_core and
test_gradient_clearance, the paper's gradient's in test_gradient and test_traps, the
chord-arc search's in test_continuum_planning).

Each solve runs in a fresh spawned process: OMPL's seed takes effect only before its first
generator exists. Pinned: status, collision checks, iterations, local minima met and
escaped, and the path's digest (rounded to 1e-6 rad, conftest.path_digest). A change that
moves one of them changes what the planner does: re-pin only with the reason in the commit.

The hybrids' checks were 14 378 and 24 694 before each leg got one planning context: their
sub-solves (each descent after the first, each RRT-Connect escape) checked their start,
a state of the path checked already, again; 3 and 10 checks fewer, the paths the same.
"""

from __future__ import annotations

import multiprocessing as mp

import pytest

#: (planner, problem, check budget, seed) -> (status, checks, iterations, minima,
#: escapes, path digest)
GOLDEN = {
    ("ompl.rrtconnect", "toy", 20_000, 5): ("solved", 933, 1, 0, 0, "329421407dad09f6"),
    ("ompl.kpiece1", "toy", 20_000, 5): ("solved", 1168, 18, 0, 0, "b39b50323c865506"),
    ("gradient.follow_leader", "toy", 20_000, 5): ("solved", 564, 587, 0, 0, "61d72f1330090571"),
    ("gradient+rrtconnect", "armz_pocket", 30_000, 3): (
        "solved",
        14414,  # the descent's steps confirmed in metres (+39 checks, same path)
        131,
        2,
        2,
        "dea25a25e2abb420",
    ),
    ("gradient.multistart", "armz_pocket", 30_000, 3): (
        # restarts checked in metres: fewer of them are clear, the budget runs out first
        "budget_exhausted",
        30013,
        1074,
        7,
        7,
        "1d8fdcf342e3f1cd",
    ),
}


def _solve(case: tuple[str, str, int, int]) -> tuple:
    """Spawned worker: one leg-0 solve, OMPL seeded by it (a fresh process)."""
    from conftest import path_digest, toy_problem

    from plannerlab.planners import make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget
    from plannerlab.run.pipeline import leg_rng

    name, problem_name, checks, seed = case
    problem = toy_problem() if problem_name == "toy" else load_problem(problem_name)
    r = make_planner(name).solve(problem, 0, Budget(max_collision_checks=checks), leg_rng(seed, 0))
    return (
        r.status.value,
        r.collision_checks,
        r.iterations,
        r.local_minima,
        r.escapes,
        path_digest(r.path),
    )


@pytest.fixture(scope="module")
def solved() -> dict:
    ctx = mp.get_context("spawn")
    cases = sorted(GOLDEN)
    with ctx.Pool(2, maxtasksperchild=1) as pool:
        return dict(zip(cases, pool.map(_solve, cases), strict=True))


@pytest.mark.parametrize("case", sorted(GOLDEN), ids=lambda c: f"{c[0]}-{c[1]}")
def test_golden_values(solved, case):
    assert solved[case] == GOLDEN[case]

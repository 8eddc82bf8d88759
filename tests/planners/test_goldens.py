"""Golden values of every planner family on fixed seeds and check budgets: the OMPL
adapter (a tree planner, KPIECE, the roadmap planners PRM and PRM* of ompl/roadmap.py),
the hybrids' escapes (RRT-Connect from the stall, random restarts), the clearance family
(the plain descent, its detour, random detour and RRT-Connect escapes),
follow-the-leader (and its seeded variant), the chord-arc search, and a goal state
(JointGoal) for OMPL and the clearance descent. The paper's gradient's are in
test_gradient and test_traps; test_descent_core holds the compiled descent to the numpy
one's path, test_joint_goal_descent the Panda's goal-state checks.

Each solve runs in a fresh spawned process: OMPL's seed takes effect only before its first
generator exists. Pinned: status, collision checks, iterations, local minima met and
escaped, and the path (its shape and 33 of its states within 1e-6 rad:
``conftest.assert_golden_path``, pinned in ``tests/data/golden_paths.json``). A change that
moves one of them changes what the planner does: re-pin only with the reason in the commit.
The paths were pinned as SHA-256 digests of the path rounded to 1e-6 rad until a digest
flipped with a float's last bit on another CPU (a joint value on the rounding edge): a
golden must not depend on the last bits of a float.

The hybrids' checks were 14 378 and 24 694 before each leg got one planning context: their
sub-solves (each descent after the first, each RRT-Connect escape) checked their start,
a state of the path checked already, again; 3 and 10 checks fewer, the paths the same.

Re-pinned at the stop after 73e31a2 (six cases: the OMPL toy, PRM, PRM*, both hybrids'
RRT-Connect escapes, multistart): on this machine (AMD EPYC) 73e31a2 itself gave other
checks (and four other paths) than the values pinned on an earlier machine. Two causes:
goal states drawn by the IK descent differed in their last bits (its linear algebra runs
CPU-specific BLAS kernels; IK results are now rounded to 1e-9 rad,
``problem/ik._ROUND_DECIMALS``), and compiled code runs on the host CPU's instructions
(numba compiles for it), which moves a few step sizes by a float's last bit.

Re-pinned when the descent's kinematics came from the compiled robot–scene model
(``collision/spheres.py`` on ``collision/model.py``; its frames, centres and Jacobians
differ from the descent's former own in the last bits, ~1e-14): two cases, floating point
and not behaviour. ``gradient.clearance+random_detour``: the same checks and iterations,
the path within 1.3e-11 rad of the former one, but one of its 12 650 joint values sits
on the digest's rounding edge (2.38927849999787 then, 2.38927850000198 now).
``gradient.clearance+rrtconnect``: the descent to the stall agrees to 2e-13 rad, and the
RRT-Connect escape from there takes another tree (3071 checks before, 3126 now; the numpy
backend, which differs from the compiled one by rounding alone, takes a third, 3221).
``tests/planners/test_descent_reference.py`` holds the descent's paths to 1e-9 rad.

Re-pinned on the certified edges (issue 32: the checker's edges are the re-check's grid
proved by certified stretches; conservative advancement is gone). The paths of the
planners that never check an edge through the checker are unchanged. OMPL's motion
validator asks the checker for every edge: the same searches (iterations) with other
check counts: RRT-Connect 945 -> 1 152 (toy) and 600 -> 946 (toy_joint), KPIECE1
1 168 -> 1 567, PRM 17 925 -> 12 397 and PRM* 20 000 -> 12 880 (their roadmaps' edges,
longer, are certified in fewer tests than advancement took). The RRT-Connect escapes from
Arm-Z stalls pay most: near a wall a stretch is rarely proved whole and is split down to
its states, where advancement stepped by the distance it measured (3 126 -> 10 248 checks
behind the plate; the grid itself takes 49 476). ``gradient+rrtconnect`` on
``armz_pocket`` no longer escapes its second minimum within 30 000 checks (it did in
11 919); ``gradient.multistart``'s restarts, checked in metres, make 386 iterations
within the budget (1 076 before). A stretch cut by the clearance its middle state
measured (advancement inside the rakes) is the next step (issue 32's closing note).

Re-pinned when the sphere field's frames came from the one kinematics (issue 32:
``kinematics.chain_frames`` in float64 instead of chain_valid's own, the same products in
another order, frames equal to rounding): every descent path above stays within 1e-6 rad
and iterations, minima and escapes are unchanged; the chaotic RRT-Connect escape behind
the plate takes 10 477 checks (10 248 before, 2.2 %: just outside its 2 % band).

Problems: ``toy`` (conftest.toy_problem), ``toy_joint`` (the toy with the goal state whose
tip pose its goal region is), ``armz_behind_plate`` (test_escape_goals: the clearance
descent stalls at a plate and escapes with RRT-Connect), the rest bundled.
"""

from __future__ import annotations

import multiprocessing as mp

import pytest

#: (planner, problem, check budget, seed) -> (status, checks, iterations, minima,
#: escapes); the paths in tests/data/golden_paths.json (``goldens/<planner>/<problem>``)
GOLDEN = {
    ("ompl.rrtconnect", "toy", 20_000, 5): ("solved", 1067, 1, 0, 0),
    ("ompl.kpiece1", "toy", 20_000, 5): ("solved", 1274, 18, 0, 0),
    ("gradient.follow_leader", "toy", 20_000, 5): ("solved", 564, 587, 0, 0),
    # solved in 11 919 checks with conservative advancement: see "Re-pinned on the
    # certified edges" above
    ("gradient+rrtconnect", "armz_pocket", 30_000, 3): ("budget_exhausted", 30000, 131, 2, 1),
    ("ompl.prm", "toy", 20_000, 5): ("solved", 9047, 72, 0, 0),
    ("ompl.prmstar", "toy", 20_000, 5): ("solved", 9366, 76, 0, 0),
    ("ompl.rrtconnect", "toy_joint", 20_000, 5): ("solved", 851, 1, 0, 0),
    ("gradient.clearance", "armz_pocket", 20_000, 0): ("solved", 323, 341, 0, 0),
    ("gradient.clearance", "toy_joint", 20_000, 5): ("solved", 39, 39, 0, 0),
    ("gradient.clearance+detour", "armz_thin_wall", 20_000, 0): ("solved", 487, 574, 1, 1),
    ("gradient.clearance+random_detour", "armz_thin_wall", 20_000, 0): (
        # was e490ba083476c424: see "Re-pinned when the descent's kinematics" above
        "solved",
        550,
        607,
        1,
        1,
    ),
    ("gradient.follow_leader+random", "armz_thin_wall", 20_000, 0): ("solved", 409, 427, 0, 0),
    ("chord_arc", "continuum_case1", 20_000, 0): ("solved", 576, 18, 0, 0),
}

#: cases that amplify a float's last bit into another search (a finite-difference gradient
#: into restarts that end at the budget; a descent's stall into an RRT-Connect escape whose
#: goal is found by another descent): the same machine gives the same values, another CPU
#: moves checks and iterations by a fraction of a percent (measured: 30 003 / 1 076 on one
#: machine, 30 013 / 1 074 on an AVX-512 EPYC; 3 126 and 3 130 checks). Pinned: status,
#: minima and escapes exactly, checks and iterations within CHAOTIC_REL of the value.
CHAOTIC = {
    ("gradient.multistart", "armz_pocket", 30_000, 3): (
        # restarts checked in metres: fewer of them are clear, the budget runs out first
        "budget_exhausted",
        30407,
        386,
        4,
        4,
    ),
    ("gradient.clearance+rrtconnect", "armz_behind_plate", 60_000, 0): (
        # was 3071, 3126, then 10248 checks: see "Re-pinned when the descent's
        # kinematics", "Re-pinned on the certified edges" and "... from the one kinematics"
        "solved",
        9786,
        244,
        1,
        1,
    ),
}
CHAOTIC_REL = 0.02


def _problem(name: str):
    """A golden case's problem (see the module docstring)."""
    import dataclasses
    import tempfile
    from pathlib import Path

    import numpy as np
    from conftest import toy_problem

    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.goals import JointGoal

    if name == "toy":
        return toy_problem()
    if name == "toy_joint":
        toy = toy_problem()
        q_goal = np.array([np.pi, 2.2, np.pi, 2.5, np.pi])  # the toy goal region's state
        return dataclasses.replace(toy, goals=(JointGoal.at(toy.robot, "state", q_goal, 0.05),))
    if name == "armz_behind_plate":
        from test_escape_goals import BEHIND_PLATE_TOML

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "armz_behind_plate.toml"
            path.write_text(BEHIND_PLATE_TOML, encoding="utf-8")
            return load_problem(path)
    return load_problem(name)


def _solve(case: tuple[str, str, int, int]) -> tuple:
    """Spawned worker: one leg-0 solve, OMPL seeded by it (a fresh process)."""
    from conftest import path_fingerprint

    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget
    from plannerlab.run.pipeline import leg_rng

    name, problem_name, checks, seed = case
    problem = _problem(problem_name)
    r = make_planner(name).solve(problem, 0, Budget(max_collision_checks=checks), leg_rng(seed, 0))
    return (
        r.status.value,
        r.collision_checks,
        r.iterations,
        r.local_minima,
        r.escapes,
        path_fingerprint(r.path),
    )


@pytest.fixture(scope="module")
def solved() -> dict:
    ctx = mp.get_context("spawn")
    cases = sorted(GOLDEN) + sorted(CHAOTIC)
    with ctx.Pool(2, maxtasksperchild=1) as pool:
        return dict(zip(cases, pool.map(_solve, cases), strict=True))


@pytest.mark.parametrize("case", sorted(GOLDEN), ids=lambda c: f"{c[0]}-{c[1]}")
def test_golden_values(solved, case):
    from conftest import assert_golden_path

    assert solved[case][:5] == GOLDEN[case]
    assert_golden_path(f"goldens/{case[0]}/{case[1]}/{case[2]}/{case[3]}", solved[case][5])


@pytest.mark.parametrize("case", sorted(CHAOTIC), ids=lambda c: f"{c[0]}-{c[1]}")
def test_chaotic_golden_values(solved, case):
    status, checks, iterations, minima, escapes = solved[case][:5]
    want = CHAOTIC[case]
    assert (status, minima, escapes) == (want[0], want[3], want[4])
    assert abs(checks - want[1]) <= CHAOTIC_REL * want[1], (checks, want[1])
    assert abs(iterations - want[2]) <= CHAOTIC_REL * want[2], (iterations, want[2])

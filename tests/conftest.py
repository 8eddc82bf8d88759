"""Shared fixtures: small problems built in code, the tiny problem file (TOML text) the
problem-file tests break one key at a time, and paths to the bundled problems."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.load import Budget, Problem
from plannerlab.problem.scene import Box, Scene, Sphere
from plannerlab.robots.armz.model import ArmZ
from plannerlab.robots.base import pose_matrix, trans

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


@pytest.fixture(autouse=True)
def _fixed_terminal_width(monkeypatch: pytest.MonkeyPatch) -> None:
    """The CLI sizes its tables by ``COLUMNS`` (else the terminal's width, else 100).
    pytest-xdist's workers set ``COLUMNS=80`` and a terminal may set anything, so every
    test sees the width of a pipe: what a test reads from a table does not depend on the
    terminal that runs the suite."""
    from plannerlab.cli.tables import PIPE_WIDTH

    monkeypatch.setenv("COLUMNS", str(PIPE_WIDTH))


#: the one small valid problem file of the tests: a 6-module Arm-Z (5 joints) at the
#: straight column, a wall beside it, one goal ("up") above it; every table a test may edit
#: is present (use :func:`tiny_problem_text` to change one thing, ``+`` to add a table)
TINY_PROBLEM_TOML = """\
[problem]
name = "tiny"
description = "a short Arm-Z and one box"

[robot]
type = "armz"
n_modules = 6

[start]
fill_deg = 180.0

[[obstacles]]
name = "wall"
type = "box"
center_m = [3.0, 0.0, 2.0]
size_m = [0.4, 4.0, 4.0]

[[goals]]
name = "up"
p_m = [0.5, 0.0, 3.0]
n = [0.0, 0.0, 1.0]
pos_tol_m = 0.1
angle_tol_deg = 10.0

[budget]
max_iterations = 50

[checking]
joint_step = 0.05
"""


def plannerlab(*argv: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    """The ``plannerlab`` command in a fresh interpreter (for what a user's shell sees:
    stdout, stderr and exit code, C-level output included)."""
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, "-m", "plannerlab", *argv],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=600,
    )


def assert_witness_solves(problem: Problem) -> None:
    """The problem file's witness path (``[witness] path_rad``) starts at the start, is
    collision-free at joint_step/4 and ends in leg 0's goal region: a path exists."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.robots.base import joint_difference

    witness = np.array(problem.extras["witness"]["path_rad"], dtype=float)
    assert witness.ndim == 2 and witness.shape[1] == problem.robot.dof and len(witness) >= 2
    np.testing.assert_allclose(
        joint_difference(witness[0], problem.q_start, problem.robot.continuous), 0.0, atol=1e-6
    )
    check = CollisionChecker(problem.robot, problem.scene).check_path(
        witness, problem.joint_step / 4
    )
    assert check.valid, f"witness collides on edge {check.first_invalid_edge}: {check.pairs}"
    assert problem.goal(0).contains(problem.robot, witness[-1])


def tiny_problem_text(old: str, new: str) -> str:
    """:data:`TINY_PROBLEM_TOML` with the one occurrence of ``old`` replaced by ``new``."""
    count = TINY_PROBLEM_TOML.count(old)
    assert count == 1, f"{old!r} occurs {count} times in the tiny problem file, not once"
    return TINY_PROBLEM_TOML.replace(old, new)


def write_problem(directory: Path, text: str | bytes, name: str = "p.toml") -> Path:
    """Write a problem file (text as UTF-8, or bytes as they are) and return its path."""
    path = directory / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


def path_digest(path: np.ndarray) -> str:
    """First 16 hex digits of the SHA-256 of a path rounded to 1e-6 rad: for comparing two
    runs *on this machine* (the same seed must give the same path). Never a golden value:
    a value on the rounding edge flips the digest with a float's last bit, and compiled code
    runs the host CPU's instructions; goldens use :func:`assert_golden_path`."""
    rounded = np.round(np.asarray(path, dtype=np.float64), 6) + 0.0  # + 0.0: no -0.0
    return hashlib.sha256(np.ascontiguousarray(rounded).tobytes()).hexdigest()[:16]


#: golden paths of the fixed-seed regressions: per case, the path's shape and up to
#: GOLDEN_SAMPLES of its states (evenly spaced, the first and the last included)
GOLDEN_PATHS = ROOT / "tests" / "data" / "golden_paths.json"
GOLDEN_SAMPLES = 33
#: how far [rad] a golden path's sampled states may move: far above a float's last bits
#: (1e-16 .. 1e-11 rad between CPUs and compilers), far below any change of behaviour
GOLDEN_ATOL_RAD = 1e-6


def path_fingerprint(path: np.ndarray) -> dict:
    """A path's golden form: its shape and a few of its states (JSON-ready)."""
    P = np.atleast_2d(np.asarray(path, dtype=np.float64))
    n = len(P)
    idx = np.unique(np.linspace(0, n - 1, min(n, GOLDEN_SAMPLES)).round().astype(int)) if n else []
    states = np.round(P[idx], 9) + 0.0  # 1e-9 rad: far below the tolerance; no -0.0
    return {"shape": [int(n), int(P.shape[1]) if P.ndim == 2 else 0], "states": states.tolist()}


def _golden_paths() -> dict:
    import json

    if GOLDEN_PATHS.exists():
        return json.loads(GOLDEN_PATHS.read_text(encoding="utf-8"))
    return {}


def _golden_text(table: dict) -> str:
    """The golden paths as JSON, one sampled state a line (readable diffs)."""
    import json

    rows = []
    for key in sorted(table):
        fp = table[key]
        states = ",\n    ".join(json.dumps(s) for s in fp["states"])
        shape = json.dumps(fp["shape"])
        rows.append(f'  {json.dumps(key)}: {{"shape": {shape}, "states": [\n    {states}\n  ]}}')
    return "{\n" + ",\n".join(rows) + "\n}\n"


def assert_golden_path(key: str, fingerprint: dict) -> None:
    """The path (its :func:`path_fingerprint`) is the one pinned under ``key``: the same
    number of states and every sampled state within ``GOLDEN_ATOL_RAD``. With
    ``PLANNERLAB_REPIN_PATHS=1`` the fingerprint is written instead (re-pin only with the
    reason in the commit)."""

    if os.environ.get("PLANNERLAB_REPIN_PATHS") == "1":
        table = _golden_paths()
        table[key] = fingerprint
        GOLDEN_PATHS.parent.mkdir(parents=True, exist_ok=True)
        GOLDEN_PATHS.write_text(_golden_text(table), encoding="utf-8")
        return
    table = _golden_paths()
    assert key in table, f"no golden path {key!r}: run with PLANNERLAB_REPIN_PATHS=1 once"
    want = table[key]
    assert fingerprint["shape"] == want["shape"], (key, fingerprint["shape"], want["shape"])
    got_s, want_s = np.asarray(fingerprint["states"]), np.asarray(want["states"])
    assert got_s.shape == want_s.shape, key
    if got_s.size:
        worst = float(np.max(np.abs(got_s - want_s)))
        assert worst <= GOLDEN_ATOL_RAD, f"{key}: a sampled state moved {worst:.3g} rad"


@pytest.fixture
def armz() -> ArmZ:
    return ArmZ()


def small_armz_problem(n_modules: int = 6, with_wall: bool = True) -> Problem:
    """A short Arm-Z beside a wall, with a reachable goal: quick to solve."""
    robot = ArmZ(n_modules=n_modules)
    q_start = np.full(robot.dof, np.pi)
    q_goal = q_start.copy()
    q_goal[1] -= 1.0
    q_goal[3] += 0.8
    p, n = robot.tip(q_goal)
    obstacles = (
        (Box("wall", pose_matrix([2.0, 0.0, 2.0], [0, 0, 0]), [0.4, 4.0, 4.0]),)
        if with_wall
        else ()
    )
    return Problem(
        name=f"small_armz_{n_modules}",
        robot=robot,
        scene=Scene(obstacles),
        q_start=q_start,
        goals=(GoalRegion("goal", p, n, 0.1, 10.0),),
        budget=Budget(max_iterations=500),
        joint_step=0.02,
    )


#: clearance margin of the toy problem [m]: a 4-m arm of 0.3-m capsules; edges are checked
#: so that no point moves more than the margin, so the margin sets the check counts (the
#: default 1 cm of the 16-m arm's files is held by test_margin and the bench)
TOY_MARGIN_M = 0.05


def toy_problem(
    radius_m: float = 0.3,
    max_collision_checks: int = 20_000,
    safety_margin_m: float = TOY_MARGIN_M,
) -> Problem:
    """The toy problem of the planner tests: a 6-module Arm-Z (5 joints) at the straight
    column beside one sphere, goal a short way from the start."""
    robot = ArmZ(n_modules=6, collision_radius_m=radius_m)
    q0 = np.full(robot.dof, np.pi)
    p, n = robot.tip(np.array([np.pi, 2.2, np.pi, 2.5, np.pi]))
    scene = Scene((Sphere("ball", trans(1.2, 0.0, 2.0), 0.4),))
    return Problem(
        "toy",
        robot,
        scene,
        q0,
        (GoalRegion("near", p, n, 0.15, 15.0),),
        Budget(max_collision_checks=max_collision_checks),
        joint_step=0.05,
        safety_margin_m=safety_margin_m,
    )


def colliding_state(problem: Problem, seed: int = 0) -> np.ndarray:
    """The first of a fixed random sequence of states that collides in ``problem``."""
    from plannerlab.collision.fcl_checker import CollisionChecker

    checker = CollisionChecker(problem.robot, problem.scene)
    Q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (200, problem.robot.dof))
    return Q[int(np.flatnonzero(~checker.valid_batch(Q))[0])]


@pytest.fixture
def small_problem() -> Problem:
    return small_armz_problem()

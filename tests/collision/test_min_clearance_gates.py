"""The path clearance measure's body gates (``kernels.min_clearance_kernel``, issue 35): a
body pair, or a body and an obstacle, whose boxes are further apart than the smallest
distance found so far opens no capsule pair. It returns the previous kernel's values (the
kernel before the gates, kept verbatim as the reference in ``bench/mesh_clearance_cost.py``,
which times the two: a box gap per capsule pair)
to 1e-12 m, never looser, on random states of every family and of a mesh robot with its
finer covers, in and out of collision, with and without the link pairs."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import PROBLEMS, ROOT

from plannerlab.collision.core import Core
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import parse_problem
from plannerlab.problem.scene import Box, Scene, Sphere
from plannerlab.robots.base import pose_matrix
from plannerlab.robots.urdf.model import UrdfChain

sys.path.insert(0, str(ROOT / "bench"))
from mesh_clearance_cost import previous_min_clearance  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"
PANDA = PROBLEMS / "urdf" / "panda" / "bookshelf_small_0001.toml"


def _scene(robot, rng: np.random.Generator, n: int) -> Scene:
    """n boxes and spheres scattered about the robot's reach (some states collide)."""
    seg = robot.link_segments(np.clip(np.zeros(robot.dof), robot.lower, robot.upper))
    c = seg.reshape(-1, 3).mean(axis=0)
    size = float(np.ptp(seg.reshape(-1, 3), axis=0).max()) + 0.2
    obs = []
    for k in range(n):
        p = c + rng.uniform(-size, size, 3)
        if k % 2:
            obs.append(Sphere(f"s{k}", pose_matrix(p, [0, 0, 0]), 0.05 * size))
        else:
            rpy = rng.uniform(-np.pi, np.pi, 3)
            obs.append(Box(f"b{k}", pose_matrix(p, rpy), rng.uniform(0.02, 0.3, 3) * size))
    return Scene(tuple(obs))


@pytest.fixture(scope="module")
def covers(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("clearance_covers")


ROBOTS = {
    "armz": lambda tmp: load_problem("armz_inspection").robot,
    "irb6": lambda tmp: load_problem("irb6_case1").robot,
    "continuum_chain": lambda tmp: load_problem("continuum_case1").robot,
    "panda_spheres": lambda tmp: parse_problem(PANDA).robot,
    "mesh_arm_finer_covers": lambda tmp: UrdfChain(
        DATA / "mesh_arm.urdf",
        "tool",
        mesh_paths=(DATA / "pkgroot",),
        cover_excess_m=0.02,
        cover_cache_dir=tmp,
        self_cover_max_primitives=16,
    ),
}


@pytest.mark.parametrize("which", sorted(ROBOTS))
def test_the_gated_clearance_is_the_previous_one(which: str, covers: Path) -> None:
    robot = ROBOTS[which](covers)
    rng = np.random.default_rng(11)
    cont = np.asarray(robot.continuous, dtype=bool)
    lo, hi = np.where(cont, -np.pi, robot.lower), np.where(cont, np.pi, robot.upper)
    seen_neg = seen_pos = 0
    for margin, n_obs in ((0.0, 0), (0.02, 6), (0.0, 12)):
        core = Core(robot, _scene(robot, rng, n_obs), margin_m=margin)
        Q = rng.uniform(lo, hi, (40, robot.dof))
        segs = core.segments(Q)
        for include_self in (True, False):
            # whole batches, single states and a walk (nearby states: the gates bite)
            walk = np.cumsum(rng.normal(0, 0.02, (30, robot.dof)), axis=0) + Q[0]
            walk = np.clip(walk, lo, hi)
            for part in (segs, segs[:1], segs[7:9], core.segments(walk)):
                got = _gated(core, part, include_self)
                ref = previous_min_clearance(part, core._geo, include_self)
                if math.isinf(ref):
                    assert got == ref
                    continue
                assert abs(got - ref) <= 1e-12 and got <= ref + 1e-15
                seen_neg += ref < 0
                seen_pos += ref > 0
    assert seen_neg and seen_pos  # in and out of collision


def _gated(core: Core, segs: np.ndarray, include_self: bool) -> float:
    from plannerlab.collision.kernels import min_clearance_kernel

    return float(min_clearance_kernel(np.ascontiguousarray(segs), core._geo, include_self))


def test_the_body_pairs_hold_every_checked_pair_once() -> None:
    """``body_pairs``: every checked capsule pair lies in exactly one listed body pair,
    each body's capsules listed once, and only capsules of a checked pair marked."""
    from plannerlab.collision.kernels import body_pairs

    core = Core(parse_problem(PANDA).robot, Scene())
    order, start, bpairs, checked = core._geo.bodies
    L = core.n_links
    assert sorted(order.tolist()) == list(range(L))
    body = np.empty(L, dtype=np.int64)
    for b in range(len(start) - 1):
        body[order[start[b] : start[b + 1]]] = b
    ii, jj = np.nonzero(core.allowed)
    keys = {(min(body[i], body[j]), max(body[i], body[j])) for i, j in zip(ii, jj, strict=True)}
    assert keys == {tuple(p) for p in bpairs.tolist()}
    assert np.array_equal(checked, core.allowed.any(axis=0) | core.allowed.any(axis=1))
    again = body_pairs(body, core.allowed)
    assert all(np.array_equal(a, b) for a, b in zip(again, core._geo.bodies, strict=True))

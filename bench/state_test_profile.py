"""Where a batch state test spends its time (issue 32): the batch road of
``bench/state_test_bench.py`` cut into its stages, each timed as a prefix of the whole.

    PYTHONPATH=. .venv/bin/python bench/state_test_profile.py [--states 200000] [--repeats 5]

Rows (ns of CPU time per state, the least of ``--repeats``; eight states a call, as
``queries.states`` runs them; every stage after the first includes the ones above it):

* ``load``: the states into the lanes (``load_state``, ``fill_lanes``);
* ``+ kinematics``: every body's frame in float32 lanes (``frames32``);
* ``+ scene pairs``: every capsule against every obstacle behind the gates (``_scene_pass``);
* ``+ self pairs``: the checked link pairs behind the gates (``_self_pass``);
* ``whole test``: ``test_lanes``, the float64 confirmation of unsure lanes included;
* ``checker.valid(Q)``: the public call (``pl.checker(problem).valid(Q)``), Python's
  overhead included.

Also printed: the share of lanes the float64 confirmation decided, and of states free.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from numba import njit

import plannerlab as pl
from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.queries import open_packed
from plannerlab.collision.state_test import (
    EVERY_LANE,
    W,
    _scene_pass,
    _self_pass,
    fill_lanes,
    frames32,
    load_state,
    set_plain,
    test_lanes,
)
from plannerlab.problem.catalog import load_problem

PROBLEMS = ("problems/urdf/panda/bookshelf_small_0001.toml", "armz_inspection")


@njit(cache=True, nogil=True, _nrt=False)
def _stages(P, Q, stage):
    """Run the batch road up to ``stage`` (0 load, 1 kinematics, 2 scene, 3 self, 4 whole);
    returns a checksum (so nothing is optimised away) and the confirmed count."""
    m, Z = open_packed(P)
    set_plain(Z)
    acc = 0
    confirmed = 0
    for s0 in range(0, Q.shape[0], W):
        nn = min(W, Q.shape[0] - s0)
        for j in range(nn):
            load_state(Z, j, Q[s0 + j], m.continuous)
        fill_lanes(Z, nn)
        if stage == 0:
            acc += int(Z.Q[0] > 0.0)
            continue
        if stage == 4:
            free, _, c = test_lanes(m, Z, EVERY_LANE)
            acc += free
            confirmed += c
            continue
        for c in range(Z.placed.shape[0]):
            Z.placed[c] = 0
        frames32(m, Z)
        if stage == 1:
            acc += int(Z.F[12 * W * (Z.F.shape[0] // (12 * W) - 1) + 3] > 0.0)
            continue
        hu, _ = _scene_pass(m, Z, EVERY_LANE, (0, 0, 0))
        if stage == 3:
            hu, _ = _self_pass(m, Z, EVERY_LANE, hu)
        acc += hu[0] + hu[1] + hu[2]
    return acc, confirmed


def _cpu(fn: Callable[[], Any]) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def profile(name: str, n: int, repeats: int) -> None:
    problem = load_problem(name)
    checker = problem_checker(problem)
    public = pl.checker(problem)
    robot = problem.robot
    P = checker.packed_model
    Q = np.random.default_rng(0).uniform(robot.lower, robot.upper, (n, robot.dof))
    labels = ["load", "+ kinematics", "+ scene pairs", "+ self pairs", "whole test"]
    roads: list[Callable[[], Any]] = [partial(_stages, P, Q, s) for s in range(5)]
    roads.append(partial(public.valid, Q))
    labels.append("checker.valid(Q)")
    for fn in roads:
        fn()  # compile or load
    best = [np.inf] * len(roads)
    for _ in range(repeats):
        for i, fn in enumerate(roads):
            best[i] = min(best[i], _cpu(fn))
    _, confirmed = _stages(P, Q, 4)
    free = public.valid(Q)
    print(
        f"\n## {problem.name} ({robot.dof} joints, {checker.model.cap_body.shape[0]} capsules, "
        f"{checker.model.obs_kind.shape[0]} obstacles, {checker.model.cpairs.shape[0]} "
        f"checked capsule pairs): {free.mean():.1%} of {n} states free, float64 confirmed "
        f"{confirmed} ({confirmed / n:.2%})\n"
    )
    print("| stage | ns/state (cumulative) | this stage |\n|---|---:|---:|")
    prev = 0.0
    for i, lab in enumerate(labels):
        ns = best[i] / n * 1e9
        step = ns - prev if i < 5 else ns - best[4] / n * 1e9
        print(f"| {lab} | {ns:,.0f} | {step:+,.0f} |")
        if i < 5:
            prev = ns


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--problems", default=",".join(PROBLEMS))
    a = ap.parse_args()
    print(f"# state test profile: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    for name in a.problems.split(","):
        profile(name, a.states, a.repeats)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()

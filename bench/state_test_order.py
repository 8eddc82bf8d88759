"""Coherent lanes (issue 32): what the batch's order saves, in one run.

    PYTHONPATH=. .venv/bin/python bench/state_test_order.py [--states 200000] [--repeats 7]

Rows (ns of CPU time per state, the least and the median of ``--repeats``, the roads
interleaved; uniform random states, seed 0):

* ``as given``: eight states a call in the batch's own order (the batch road before
  ``coherent_order``: ``load_state``, ``fill_lanes``, ``test_lanes``);
* ``coherent``: ``state_test.valid_coherent`` (the batch road of ``queries.states``
  now): the order computed chunk by chunk, states gathered in it, verdicts written back;
* ``order alone``: ``coherent_order`` over the batch's chunks;
* ``as given, on states already in that order``: what the tests cost when the lanes
  are alike and the gather is free (the bound of what the order can save).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from numba import njit

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.queries import open_packed
from plannerlab.collision.state_test import (
    CO_CHUNK,
    EVERY_LANE,
    W,
    coherent_order,
    fill_lanes,
    load_state,
    set_plain,
    test_lanes,
    valid_coherent,
)
from plannerlab.problem.catalog import load_problem

PROBLEMS = ("problems/urdf/panda/bookshelf_small_0001.toml", "armz_inspection")


@njit(cache=True, nogil=True, _nrt=False)
def _as_given(P, Q, out):
    m, Z = open_packed(P)
    set_plain(Z)
    for s0 in range(0, Q.shape[0], W):
        nn = min(W, Q.shape[0] - s0)
        for j in range(nn):
            load_state(Z, j, Q[s0 + j], m.continuous)
        fill_lanes(Z, nn)
        free, _, _ = test_lanes(m, Z, EVERY_LANE)
        for j in range(nn):
            out[s0 + j] = (free >> j) & 1
    return 0


@njit(cache=True, nogil=True, _nrt=False)
def _coherent(P, Q, out):
    m, Z = open_packed(P)
    set_plain(Z)
    return valid_coherent(m, Z, Q, out)


@njit(cache=True, nogil=True, _nrt=False)
def _order(P, Q, order):
    m, Z = open_packed(P)
    for c0 in range(0, Q.shape[0], CO_CHUNK):
        c1 = min(c0 + CO_CHUNK, Q.shape[0])
        coherent_order(Z, Q, c0, c1, m.lower, m.upper)
        for s in range(c1 - c0):
            order[c0 + s] = Z.co_order[s]
    return 0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=200_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--problems", default=",".join(PROBLEMS))
    a = ap.parse_args()
    print(f"# coherent lanes: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    n = a.states
    for name in a.problems.split(","):
        problem = load_problem(name)
        P = problem_checker(problem).packed_model
        lo, hi = problem.robot.lower, problem.robot.upper
        Q = np.random.default_rng(0).uniform(lo, hi, (n, len(lo)))
        out, ref = np.empty(n, np.bool_), np.empty(n, np.bool_)
        order = np.empty(n, np.int64)
        _order(P, Q, order)
        Qs = np.ascontiguousarray(Q[order])
        _as_given(P, Q, ref)
        _coherent(P, Q, out)
        assert np.array_equal(out, ref), "the order changed a verdict"
        roads = {
            "as given": lambda: _as_given(P, Q, out),  # noqa: B023
            "coherent": lambda: _coherent(P, Q, out),  # noqa: B023
            "order alone": lambda: _order(P, Q, order),  # noqa: B023
            "as given, on states already in that order": lambda: _as_given(P, Qs, out),  # noqa: B023
        }
        times: dict[str, list[float]] = {k: [] for k in roads}
        for _ in range(a.repeats):
            for k, fn in roads.items():
                t0 = time.process_time()
                fn()
                times[k].append(time.process_time() - t0)
        print(f"\n## {problem.name} ({len(lo)} joints), {n} states\n")
        print("| road | ns/state, least | median |\n|---|---:|---:|")
        for k, v in times.items():
            print(f"| {k} | {min(v) / n * 1e9:,.0f} | {np.median(v) / n * 1e9:,.0f} |")
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()

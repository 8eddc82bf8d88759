"""Coherent lanes (issue 32): a batch is tested in an order where the eight states of a
call resemble each other (``state_test.coherent_order``: a counting sort by a grid cell
over the joint box). The order may only change the time: every verdict comes back in the
caller's order and equals the float64 test's alone, on random, near-contact and
out-of-bounds states, across chunks, and the order is a permutation that groups each
cell's states."""

from __future__ import annotations

import numpy as np
from numba import njit
from test_model import _exact_valid, _model_valid, _near_contact

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.queries import open_packed
from plannerlab.collision.state_test import (
    CO_CHUNK,
    COHERENT_FROM,
    W,
    coherent_order,
    valid_batch,
)
from plannerlab.problem.catalog import load_problem

PANDA = "problems/urdf/panda/bookshelf_small_0001.toml"


@njit(cache=True)
def _order(P, Q):
    """coherent_order of Q (one chunk) and the cells' key of each state in that order."""
    m, Z = open_packed(P)
    coherent_order(Z, Q, 0, Q.shape[0], m.lower, m.upper)
    order = Z.co_order[: Q.shape[0]].copy()
    keys = np.empty(Q.shape[0], dtype=np.int64)
    for s in range(Q.shape[0]):
        keys[s] = Z.co_key[order[s]]
    return order, keys


def _panda():
    problem = load_problem(PANDA)
    return problem, problem_checker(problem)


def test_order_is_a_permutation_grouping_cells():
    problem, checker = _panda()
    lo, hi = problem.robot.lower, problem.robot.upper
    rng = np.random.default_rng(3)
    Q = rng.uniform(lo, hi, (4096, len(lo)))
    order, keys = _order(checker.packed_model, Q)
    assert np.array_equal(np.sort(order), np.arange(len(Q)))
    assert np.all(np.diff(keys) >= 0)  # sorted by cell, stable
    assert len(np.unique(keys)) > len(Q) // (4 * W)  # about a cell per eight states
    assert not np.array_equal(order, np.arange(len(Q)))
    # the cells split the first joint: its spread within a call of eight is far below
    # the whole range's (random order: about half of it)
    spread = np.ptp(Q[order][: len(Q) // W * W, 0].reshape(-1, W), axis=1)
    assert np.median(spread) < 0.3 * (hi[0] - lo[0])
    # a short batch keeps its own order
    order, _ = _order(checker.packed_model, Q[: COHERENT_FROM - 1])
    assert np.array_equal(order, np.arange(COHERENT_FROM - 1))


def test_long_chain_keeps_its_order():
    """Fewer key bits than joints (Arm-Z's 23): cells would not split every joint, and
    the order is the batch's own."""
    problem = load_problem("armz_inspection")
    checker = problem_checker(problem)
    lo, hi = problem.robot.lower, problem.robot.upper
    Q = np.random.default_rng(0).uniform(lo, hi, (4096, len(lo)))
    order, _ = _order(checker.packed_model, Q)
    assert np.array_equal(order, np.arange(len(Q)))


def test_verdicts_in_the_callers_order():
    """Random, near-contact (either side of the boundary by 2e-4 rad), out-of-bounds
    states and a batch longer than a chunk: the batch's verdicts equal the float64
    test's state by state, and do not depend on how the batch is ordered."""
    problem, checker = _panda()
    core = checker._core
    lo, hi = problem.robot.lower, problem.robot.upper
    rng = np.random.default_rng(7)
    A = rng.uniform(lo, hi, (4000, len(lo)))
    inside, outside = _near_contact(core, lo, hi, A, 300, rng)
    edge, _ = _near_contact(core, lo, hi, A, 100, rng, offset=0.0)  # right at the boundary
    out = lo - 0.5 + rng.uniform(0.0, 1.0, (200, len(lo))) * (hi - lo + 1.0)
    Q = np.concatenate([A, inside, outside, edge, out])
    truth = _exact_valid(core, Q)
    got = _model_valid(core, Q)
    assert np.array_equal(got, truth)
    assert 0 < truth.sum() < len(Q)
    assert len(inside) == 300 and truth[4000:4300].all() and not truth[4300:4600].any()
    perm = rng.permutation(len(Q))
    assert np.array_equal(_model_valid(core, Q[perm]), truth[perm])
    # the compiled batch entry (a fresh scratch) gives the same verdicts
    vb = np.empty(len(Q), dtype=np.bool_)
    valid_batch(core.model, Q, vb)
    assert np.array_equal(vb, truth)
    # longer than a chunk: the chunks ordered one by one, verdicts still the caller's
    L = np.concatenate([Q] * (CO_CHUNK // len(Q) + 1))[: CO_CHUNK + 77]
    assert np.array_equal(_model_valid(core, L), _exact_valid(core, L))

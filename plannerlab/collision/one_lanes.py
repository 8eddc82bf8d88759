"""The tables of the one-state road (:mod:`plannerlab.collision.one_state`): one state's
geometry laid out so that eight of its capsules fill the lanes of a vector.

Built once per compiled model (:func:`one_tables`, numpy; a checker keeps them:
:func:`checker_tables`) and packed into three flat arrays (float32, int64, float64) that
a compiled kernel opens as views (:func:`open_one`), so a call from Python unboxes three
arrays, not twenty.

**Slots.** Every body's capsules (the model's packed order, contiguous per body) get a
run of *slots* that starts at a multiple of eight and is padded to one: slot
``slot0[b] + k`` holds capsule ``body_caps[b] + k``. A *block* is eight slots, so a body's
capsules are a few whole blocks and a vector load of a block never mixes two bodies.
Per slot: the capsule's ends in its body's (folded) frame, float32 (``LX``: a x, y, z,
then b x, y, z, each ``S8`` long), their world places for the state at hand (``WX``, the
scratch), its radius against the scene and between links (``RS``, ``RL``). Per block, bit
masks over its eight slots: the capsules that are there, those that move (``bmove``: the
scene pass tests only them) and whether every capsule there is a sphere (``bsph``).

**Bodies** in blocks of eight as well: each body's gate ball (the model's ``gate_c``,
placed per state into ``GW`` float32 and ``G64`` float64), its radius against the scene
and between links (``GRS``, ``GRL``, float32; -1 for a body with no moving capsule),
the bits of the gated bodies of each block (``bgated``), and per block a world box around
its gates (``BB``, float64, per state).

**Body pairs by block** (``brows``, the self pass's gates): per body u and block k of
bodies v it is paired with, the bits of those v and each one's body pair p (-1: none), so
one vector test meets u's gate with eight others.

**Runs** (the self pass): the model's checked capsule pairs ``(i, j)`` of each body pair
``p`` (``run_start[p]`` to ``run_start[p + 1]``) as runs ``(slot of i, first slot j0,
bits of j - j0 in the run, every capsule of the run a sphere, i a sphere)``: capsule i
against up to eight capsules of the other body at once (``j0 ≤ j < j0 + 8``).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import njit

from plannerlab.collision.simd import LANES

W = LANES
#: the int64 header's length (its fields: see :func:`pack_tables`)
_HEAD = 8
#: columns of a run row
RUN_COLS = 5


class One(NamedTuple):
    """The one-state road's tables and scratch, as views (see the module)."""

    LX: np.ndarray  # (6 * S8,) float32: capsule ends in the body frame, by slot
    WX: np.ndarray  # (6 * S8,) float32: their world places (scratch)
    RS: np.ndarray  # (S8,) float32: radius against the scene
    RL: np.ndarray  # (S8,) float32: radius between links
    GW: np.ndarray  # (3 * NB8,) float32: gate centres in the world (scratch)
    GRS: np.ndarray  # (NB8,) float32: gate radius against the scene (-1: none)
    GRL: np.ndarray  # (NB8,) float32: gate radius between links
    slot0: np.ndarray  # (nb + 1,) int64: each body's first slot
    placed: np.ndarray  # (nb,) int64: the body's capsules placed (scratch)
    bvalid: np.ndarray  # (S8 / 8,) int64: bits of the block's capsules
    bmove: np.ndarray  # (S8 / 8,) int64: bits of its moving capsules
    bsph: np.ndarray  # (S8 / 8,) int64: 1 when every capsule there is a sphere
    bgated: np.ndarray  # (NB8 / 8,) int64: bits of the gated bodies of a body block
    run_start: np.ndarray  # (P + 1,) int64
    runs: np.ndarray  # (R, RUN_COLS) int64
    brows: np.ndarray  # (BR, 3 + 8) int64: body u, block k of bodies v, bits, pairs p
    X32: np.ndarray  # (M8,) float32: the joints' values wrapped (scratch)
    S32: np.ndarray  # (M8,) float32: their sines (scratch)
    C32: np.ndarray  # (M8,) float32: their cosines (scratch)
    G64: np.ndarray  # (3 * nb,) float64: gate centres (scratch)
    BB: np.ndarray  # (6 * NB8 / 8,) float64: a body block's world box (scratch)
    VT: np.ndarray  # (m, 3) float64: each joint's value, sine, cosine (scratch)


def _runs(m: Any, slot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The checked pairs of each body pair as runs (see the module)."""
    sphere = np.asarray(m.cap_sphere, dtype=bool)
    start, rows = [0], []
    for p in range(len(m.bpairs)):
        q0 = int(m.clpair_start[m.bpair_start[p]])
        q1 = int(m.clpair_start[m.bpair_start[p + 1]])
        pairs = sorted((int(slot[i]), int(slot[j]), int(i), int(j)) for i, j in m.cpairs[q0:q1])
        k = 0
        while k < len(pairs):
            si, j0, i, _ = pairs[k]
            bits, allsph = 0, bool(sphere[i])
            while k < len(pairs) and pairs[k][0] == si and pairs[k][1] < j0 + W:
                bits |= 1 << (pairs[k][1] - j0)
                allsph = allsph and bool(sphere[pairs[k][3]])
                k += 1
            rows.append((si, j0, bits, int(allsph), int(sphere[i])))
        start.append(len(rows))
    runs = np.array(rows, dtype=np.int64).reshape(-1, RUN_COLS)
    return np.array(start, dtype=np.int64), runs


def _body_rows(m: Any) -> np.ndarray:
    """The checked body pairs by body u and block of bodies v (see the module)."""
    rows: dict[tuple[int, int], list[int]] = {}
    for p, (u, v) in enumerate(np.asarray(m.bpairs, dtype=np.int64).tolist()):
        row = rows.setdefault((u, v // W), [u, v // W, 0] + [-1] * W)
        row[2] |= 1 << (v % W)
        row[3 + v % W] = p
    out = [rows[k] for k in sorted(rows)]
    return np.array(out, dtype=np.int64).reshape(-1, 3 + W)


def one_tables(m: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The one-state road's tables of the compiled model m, packed (float32, int64,
    float64): see the module and :func:`open_one`."""
    nb = len(m.gate_c)
    ncap = np.diff(np.asarray(m.body_caps, dtype=np.int64))
    nsl = (ncap + W - 1) // W * W
    slot0 = np.concatenate([[0], np.cumsum(nsl)]).astype(np.int64)
    S8 = int(slot0[-1]) + W
    slot = np.concatenate(
        [slot0[b] + np.arange(ncap[b], dtype=np.int64) for b in range(nb)] + [np.zeros(0, int)]
    ).astype(np.int64)
    LX = np.zeros((6, S8), dtype=np.float32)
    LX[0:3, slot] = np.asarray(m.cap_a, dtype=float).T
    LX[3:6, slot] = np.asarray(m.cap_b, dtype=float).T
    RS = np.zeros(S8, dtype=np.float32)
    RL = np.zeros(S8, dtype=np.float32)
    RS[slot] = m.r_scene
    RL[slot] = m.r_self
    nblk = S8 // W
    bvalid = np.zeros(nblk, dtype=np.int64)
    bmove = np.zeros(nblk, dtype=np.int64)
    bsph = np.ones(nblk, dtype=np.int64)
    for l, s in enumerate(slot.tolist()):
        bvalid[s // W] |= 1 << (s % W)
        if m.cap_moving[l]:
            bmove[s // W] |= 1 << (s % W)
        if not m.cap_sphere[l]:
            bsph[s // W] = 0
    NB8 = (nb + W - 1) // W * W
    GRS = np.full(NB8, -1.0, dtype=np.float32)
    GRL = np.full(NB8, -1.0, dtype=np.float32)
    GRS[:nb] = m.gate_r_scene
    GRL[:nb] = m.gate_r_self
    bgated = np.zeros(NB8 // W, dtype=np.int64)
    for b in range(nb):
        if m.gate_r_scene[b] >= 0.0:
            bgated[b // W] |= 1 << (b % W)
    run_start, runs = _runs(m, slot)
    brows = _body_rows(m)
    nj = len(m.parent)
    M8 = (nj + W - 1) // W * W + W
    head = np.array(
        [nb, S8, NB8, len(run_start) - 1, len(runs), len(brows), nj, M8], dtype=np.int64
    )
    f32 = np.concatenate(
        [LX.ravel(), np.zeros(6 * S8, np.float32), RS, RL, np.zeros(3 * NB8, np.float32), GRS, GRL,
         np.zeros(3 * M8, np.float32)]
    )  # fmt: skip
    i64 = np.concatenate(
        [
            head,
            slot0,
            np.zeros(nb, np.int64),
            bvalid,
            bmove,
            bsph,
            bgated,
            run_start,
            runs.ravel(),
            brows.ravel(),
        ]
    )
    f64 = np.zeros(3 * nb + 6 * (NB8 // W) + 3 * nj)
    return (
        np.ascontiguousarray(f32, dtype=np.float32),
        np.ascontiguousarray(i64, dtype=np.int64),
        np.ascontiguousarray(f64, dtype=np.float64),
    )


def checker_tables(checker: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The one-state road's tables of a checker's compiled model, built once and kept by
    the checker (``checker.derived``)."""
    return checker.derived("one_state.tables", lambda: one_tables(checker.model))


@njit(cache=True, nogil=True, inline="always")
def open_one(T):
    """The packed tables (:func:`one_tables`) as views: a :class:`One`."""
    f32, i64, f64 = T
    nb, S8, NB8, P, R = i64[0], i64[1], i64[2], i64[3], i64[4]
    BR, nj, M8 = i64[5], i64[6], i64[7]
    nblk, nbb = S8 // W, NB8 // W
    a = 0
    LX = f32[a : a + 6 * S8]
    a += 6 * S8
    WX = f32[a : a + 6 * S8]
    a += 6 * S8
    RS = f32[a : a + S8]
    a += S8
    RL = f32[a : a + S8]
    a += S8
    GW = f32[a : a + 3 * NB8]
    a += 3 * NB8
    GRS = f32[a : a + NB8]
    a += NB8
    GRL = f32[a : a + NB8]
    a += NB8
    X32 = f32[a : a + M8]
    S32 = f32[a + M8 : a + 2 * M8]
    C32 = f32[a + 2 * M8 : a + 3 * M8]
    k = _HEAD
    slot0 = i64[k : k + nb + 1]
    k += nb + 1
    placed = i64[k : k + nb]
    k += nb
    bvalid = i64[k : k + nblk]
    k += nblk
    bmove = i64[k : k + nblk]
    k += nblk
    bsph = i64[k : k + nblk]
    k += nblk
    bgated = i64[k : k + nbb]
    k += nbb
    run_start = i64[k : k + P + 1]
    k += P + 1
    runs = i64[k : k + R * RUN_COLS].reshape((R, RUN_COLS))
    k += R * RUN_COLS
    brows = i64[k : k + BR * (3 + W)].reshape((BR, 3 + W))
    e = 3 * nb + 6 * nbb
    return One(
        LX, WX, RS, RL, GW, GRS, GRL, slot0, placed, bvalid, bmove, bsph, bgated, run_start,
        runs, brows, X32, S32, C32, f64[: 3 * nb], f64[3 * nb : e],
        f64[e : e + 3 * nj].reshape((nj, 3)),
    )  # fmt: skip


__all__ = ["One", "RUN_COLS", "checker_tables", "one_tables", "open_one"]

"""The one-state road's assembly (issue 32): ``one_state.valid_each`` compiled for the
MotionBenchMaker Panda, read with numba's ``inspect_asm``, its vector instructions counted
by mnemonic; the whole listing written to ``--out``.

    NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=. .venv/bin/python bench/one_state_asm.py \\
        [--out /tmp/valid_each.s]

(An empty cache folder makes numba compile afresh: a kernel loaded from its cache has no
assembly to show.)
"""

from __future__ import annotations

import argparse
import collections
import re

import numpy as np

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.one_lanes import checker_tables
from plannerlab.collision.one_state import valid_each
from plannerlab.problem.load import parse_problem

PROBLEM = "problems/urdf/panda/bookshelf_small_0001.toml"
#: packed-single vector operations, AVX-512 mask operations, broadcasts
VECTOR = re.compile(r"^(v\w*ps|k(or|and|mov)[bw]|vbroadcast\w+|vperm\w+|vshuf\w+)$")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/valid_each.s")
    a = ap.parse_args()
    problem = parse_problem(PROBLEM)
    checker = problem_checker(problem)
    Q = np.random.default_rng(0).uniform(problem.robot.lower, problem.robot.upper, (8, 7))
    valid_each(checker.packed_model, checker_tables(checker), Q, np.empty(8, dtype=np.bool_))
    asm = valid_each.inspect_asm(valid_each.signatures[0])
    with open(a.out, "w", encoding="utf-8") as f:
        f.write(asm)
    ops = [
        line.split()[0]
        for line in asm.splitlines()
        if line.startswith("\t") and not line.strip().startswith(".")
    ]
    count = collections.Counter(ops)
    vec = {k: v for k, v in count.items() if VECTOR.match(k)}
    print(f"{len(ops)} instructions, {sum(vec.values())} vector (packed single, masks)")
    for k, v in sorted(vec.items(), key=lambda kv: -kv[1])[:20]:
        print(f"  {k:14s} {v}")
    lines = asm.splitlines()
    print(f"lines on ymm registers: {sum('ymm' in x for x in lines)}, zmm: "
          f"{sum('zmm' in x for x in lines)}; the listing: {a.out}")  # fmt: skip


if __name__ == "__main__":
    main()

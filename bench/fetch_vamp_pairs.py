"""The Fetch's self-collision link pairs: plannerlab's (the compiled model's capsule pairs,
by link) against VAMP's generated ``fetch.hh`` (its ``// a vs. b`` blocks), issue 35.

    PYTHONPATH=. python bench/fetch_vamp_pairs.py PROBLEM.toml VAMP_TARBALL
"""

from __future__ import annotations

import re
import sys
import tarfile

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.problem.catalog import load_problem


def main() -> None:
    problem = load_problem(sys.argv[1])
    m = problem_checker(problem)._core.model  # type: ignore[union-attr]
    names = [problem.robot.link_names[i].split("#")[0] for i in m.perm]
    ours = {tuple(sorted((names[i], names[j]))) for i, j in m.cpairs.tolist()}
    with tarfile.open(sys.argv[2]) as tar:
        member = next(n for n in tar.getnames() if n.endswith("robots/fetch.hh"))
        text = tar.extractfile(member).read().decode()  # type: ignore[union-attr]
    theirs = {
        tuple(sorted((a, b)))
        for a, b in re.findall(r"// (\w+) vs\. (\w+)", text)
        if not {a.lower(), b.lower()} & {"environment", "attachment", "robot"}
    }
    print(f"plannerlab: {len(ours)} link pairs, VAMP: {len(theirs)}")
    print("only plannerlab:", sorted(ours - theirs))
    print("only VAMP:", sorted(theirs - ours))


if __name__ == "__main__":
    main()

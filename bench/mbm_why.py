"""Why MotionBenchMaker problems fail: the facts of each problem's start and goal, and the
failure classes of a solve log (issue 35, item 3; ``results/mesh_robots.md``, "Fetch").

Per problem of an imported set (``plannerlab import mbm --fetch --robot fetch --out DIR``),
one JSON line (resumable)::

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/mbm_why.py /tmp/mbm/fetch \\
        --log /tmp/why_fetch.jsonl

- the start's and the goal's validity in the spherized model, and the colliding pairs by
  link name (self-collision: link × link; the scene: link × obstacle);
- their clearance [mm] (the checker's, self-collision included);
- the *free-motion fraction*: of 48 straight joint-space motions from the state in seeded
  random directions (clipped to the joint limits), the fraction that is free when checked
  in full on the planner's grid (``joint_step / 4``), at lengths of the native planners'
  default range (OMPL's: 20 % of the joint box's diagonal) and of its halves down to 1/16.
  RRT-Connect grows a tree from a state only by such motions (of at most its range), so
  this fraction is how often an extension from the goal state can succeed;
- the joints at their limits.

Then the report, optionally joined with solve logs of ``bench/mbm_robots_bench.py``::

    PYTHONPATH=. .venv/bin/python bench/mbm_why.py --report /tmp/why_fetch.jsonl \\
        [--solves /tmp/fetch_native.jsonl ...]

prints the invalid problems by pair class, the free-motion fractions per scenario, and per
solve log each failure's class: start or goal invalid (and by which pair), a found path
refused by the final re-check, or the search out of budget (split by whether the goal
tree ever grew beyond its roots).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

#: directions per state and length (seeded)
DIRECTIONS = 48
#: lengths, as fractions of the native planners' default range
FRACTIONS = (1.0, 0.5, 0.25, 0.125, 0.0625)


def link_of(name: str) -> str:
    """A checker's body name without its sphere number (``wrist_flex_link#5``)."""
    return name.split("#", 1)[0]


def pair_classes(pairs: list[list[str]], obstacles: set[str]) -> list[str]:
    """Colliding pairs by class: ``scene LINK x OBSTACLE`` or ``self LINK x LINK``."""
    out = set()
    for a, b in pairs:
        if b in obstacles:
            out.add(f"scene {link_of(a)} x {b}")
        else:
            x, y = sorted((link_of(a), link_of(b)))
            out.add(f"self {x} x {y}")
    return sorted(out)


def free_fractions(problem: Any, checker: Any, q: Any, range0: float) -> dict[str, float]:
    import numpy as np

    robot = problem.robot
    rng = np.random.default_rng(0)
    D = rng.normal(size=(DIRECTIONS, robot.dof))
    D /= np.linalg.norm(D, axis=1)[:, None]
    out = {}
    for f in FRACTIONS:
        ok = 0
        for d in D:
            qb = np.clip(q + f * range0 * d, robot.lower, robot.upper)
            _, bad = checker.check_edge(q, qb, problem.joint_step / 4.0)
            ok += bad is None
        out[f"{f:g}"] = ok / DIRECTIONS
    return out


def examine(path: Path) -> dict[str, Any]:
    import numpy as np

    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.problem.load import parse_problem

    p = parse_problem(path)
    robot, checker = p.robot, problem_checker(p)
    span = np.where(robot.continuous, np.pi, np.asarray(robot.upper) - np.asarray(robot.lower))
    range0 = 0.2 * float(np.sqrt(np.sum(span**2)))
    obstacles = {o.name for o in p.scene.obstacles}
    rec: dict[str, Any] = {"name": p.name, "range0_rad": range0}
    for label, q in (
        ("start", np.asarray(p.q_start, float)),
        ("goal", np.asarray(p.goal(0).q_rad, float)),
    ):
        pairs = [list(x) for x in checker.colliding_pairs(q)]
        rec[label] = q.tolist()
        rec[f"{label}_pairs"] = pair_classes(pairs, obstacles)
        at = np.isclose(q, robot.lower, atol=1e-9) | np.isclose(q, robot.upper, atol=1e-9)
        rec[f"{label}_at_limit"] = [robot.joint_names[i] for i in np.flatnonzero(at)]
        if not pairs:
            rec[f"{label}_clear_mm"] = 1e3 * float(checker.clearance(q))
            rec[f"{label}_free"] = free_fractions(p, checker, q, range0)
    return rec


def run(args: argparse.Namespace) -> None:
    files = sorted(args.folder.glob("*_[0-9]*.toml"))
    if args.per_scenario:
        by: dict[str, list[Path]] = defaultdict(list)
        for f in files:
            by[scenario(f.stem)].append(f)
        files = [f for group in by.values() for f in group[: args.per_scenario]]
    if not files:
        sys.exit(f"no imported problem files in {args.folder}")
    done = set()
    if args.log.is_file():
        done = {json.loads(s)["name"] for s in args.log.read_text().splitlines() if s}
    with args.log.open("a") as log:
        for i, f in enumerate(files):
            if f.stem in done:
                continue
            log.write(json.dumps(examine(f)) + "\n")
            log.flush()
            if (i + 1) % 50 == 0:
                print(f"  {i + 1}/{len(files)}", flush=True)


def scenario(name: str) -> str:
    return name.rsplit("_", 1)[0]


def report(args: argparse.Namespace) -> None:
    recs = {}
    for path in args.report:
        for s in path.read_text().splitlines():
            if s:
                r = json.loads(s)
                recs[r["name"]] = r
    print(f"## {len(recs)} problems\n")
    invalid = Counter()
    for r in recs.values():
        for label in ("start", "goal"):
            if r[f"{label}_pairs"]:
                invalid[(scenario(r["name"]), label, "; ".join(r[f"{label}_pairs"]))] += 1
    print("### Invalid starts and goals in the spherized model\n")
    print("| scenario | state | colliding pairs | problems |\n|---|---|---|---|")
    for (sc, label, pairs), n in sorted(invalid.items()):
        print(f"| {sc} | {label} | {pairs} | {n} |")
    bad = {n for n, r in recs.items() if r["start_pairs"] or r["goal_pairs"]}
    print(f"\n{len(bad)} problems invalid, {len(recs) - len(bad)} valid\n")
    print("### Free-motion fraction from the goal (median over the valid problems)\n")
    any_rec = next(iter(recs.values()))
    head = " | ".join(f"{float(f) * any_rec['range0_rad']:.2f} rad" for f in map(str, FRACTIONS))
    print(f"| scenario | problems | {head} | goals with none free at the default range |")
    print("|---|---|" + "---|" * (len(FRACTIONS) + 1))
    by_sc: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in recs.values():
        if r["name"] not in bad:
            by_sc[scenario(r["name"])].append(r)
    for label in ("goal", "start"):
        if label == "start":
            print("\nThe same from the start:\n")
        for sc, rs in sorted(by_sc.items()):
            cells = [
                f"{statistics.median(r[f'{label}_free'][f'{f:g}'] for r in rs):.3f}"
                for f in FRACTIONS
            ]
            none = sum(1 for r in rs if r[f"{label}_free"]["1"] == 0)
            print(f"| {sc} | {len(rs)} | " + " | ".join(cells) + f" | {none} |")
    limits = Counter(j for r in recs.values() for j in r["goal_at_limit"])
    print(f"\ngoal joints at a limit: {dict(limits)}")
    for path in args.solves or []:
        classify(path, recs)


def classify(path: Path, recs: dict[str, Any]) -> None:
    rows = [json.loads(s) for s in path.read_text().splitlines() if s.startswith("{")]
    classes: Counter[str] = Counter()
    for r in rows:
        why = recs.get(r["name"], {})
        if r.get("solved"):
            classes["solved"] += 1
        elif why.get("start_pairs"):
            classes["start invalid: " + "; ".join(why["start_pairs"])] += 1
        elif why.get("goal_pairs"):
            classes["goal invalid: " + "; ".join(why["goal_pairs"])] += 1
        elif r["status"] == "SOLVED":
            classes["path refused by the final re-check"] += 1
        elif r.get("nodes") and r["nodes"][1] <= (r.get("goal_pool") or 1):
            classes[f"{r['status']}: the goal tree never grew"] += 1
        else:
            classes[f"{r['status']}: both trees grew"] += 1
    print(f"\n### {path.name}: {rows[0]['planner']}, {len(rows)} problems\n")
    print("| class | problems |\n|---|---|")
    for k, n in classes.most_common():
        print(f"| {k} | {n} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path, nargs="?", help="imported problem files")
    ap.add_argument("--log", type=Path, help="JSON lines, appended (resumable)")
    ap.add_argument("--per-scenario", type=int, default=0, help="the first N of each (0: all)")
    ap.add_argument("--report", type=Path, nargs="*", help="summarise these logs")
    ap.add_argument("--solves", type=Path, nargs="*", help="solve logs (mbm_robots_bench.py)")
    args = ap.parse_args()
    if args.report:
        report(args)
        return
    if args.folder is None or args.log is None:
        ap.error("a folder of imported problem files and --log are needed")
    run(args)


if __name__ == "__main__":
    main()

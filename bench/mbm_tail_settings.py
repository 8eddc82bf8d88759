"""Is MotionBenchMaker's tail the state test or the search? ``native.rrtconnect``'s search
settings on the problems an all-700 run found slowest, counted in collision checks (which
do not depend on the machine's load), against a random sample of the others.

    PYTHONPATH=. .venv/bin/python bench/peers_bench.py /tmp/mbm --all \\
        --planners native.rrtconnect,vamp --log /tmp/mbm700.jsonl        # the all-700 run
    PYTHONPATH=. .venv/bin/python bench/mbm_tail_settings.py /tmp/mbm /tmp/mbm700.jsonl \\
        [--tail 40] [--rest 40] [--seeds 3] [--out rows.jsonl]

The tail: the ``--tail`` problems with the longest ``native.rrtconnect`` planning time in
the log (a problem whose goal is invalid is skipped); the rest: ``--rest`` others drawn
with a fixed generator. Each is solved again on fresh seeds with every setting below
(3 000 000 checks, 30 s as a guard); the table gives, per group and setting, the solved
count and the median, 90th percentile and mean of the checks, and the mean CPU time of a
solve (``time.process_time``: a shared machine's load stretches wall time, much less
this). ``--configs`` picks the settings (default: the first four).
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

CONFIGS: dict[str, dict[str, object]] = {
    "default": {},
    "dynamic_domain": {"dynamic_domain": True},
    "range 1.0": {"range_rad": 1.0},
    "range 1.0 + dynamic_domain": {"range_rad": 1.0, "dynamic_domain": True},
    "balance": {"balance": True},
    "dynamic_domain + balance": {"dynamic_domain": True, "balance": True},
}


def main() -> None:
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget, parse_problem

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path, help="imported MotionBenchMaker problems")
    ap.add_argument(
        "log", type=Path, help="an all-700 run's --log of bench/peers_bench.py (.gz too)"
    )
    ap.add_argument("--tail", type=int, default=40)
    ap.add_argument("--rest", type=int, default=40)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--out", type=Path, default=None, help="one JSON line a solve")
    ap.add_argument(
        "--configs",
        default="default,dynamic_domain,range 1.0,range 1.0 + dynamic_domain",
        help=f"comma-separated, of: {', '.join(CONFIGS)}",
    )
    args = ap.parse_args()
    chosen = [c.strip() for c in args.configs.split(",")]
    unknown = [c for c in chosen if c not in CONFIGS]
    if unknown:
        ap.error(f"--configs: unknown {unknown}; known: {', '.join(CONFIGS)}")
    opener = gzip.open if args.log.suffix == ".gz" else open
    with opener(args.log, "rt") as f:
        rows = [json.loads(line) for line in f if line.strip()]
    native = {r["name"]: r for r in rows if r["planner"] == "native.rrtconnect" and r["solved"]}
    names = sorted(native, key=lambda n: -native[n]["plan_s"])
    tail = names[: args.tail]
    rng = np.random.default_rng(7)
    rest = [str(n) for n in rng.choice(names[args.tail :], args.rest, replace=False)]
    problems = {n: parse_problem(args.folder / f"{n}.toml") for n in tail + rest}
    planners = {c: make_planner("native.rrtconnect", CONFIGS[c]) for c in chosen}
    for p in planners.values():  # warm-up, uncounted
        p.solve(problems[tail[0]], 0, Budget(time_limit_s=5), np.random.default_rng(99))
    budget = Budget(time_limit_s=30.0, max_collision_checks=3_000_000)
    out = args.out.open("a") if args.out else None
    got: dict[tuple[str, str], list[tuple[bool, int, float]]] = defaultdict(list)
    load = [os.getloadavg()[0]]
    print(f"load average at the start: {load[0]:.1f}", flush=True)
    for seed in range(args.seeds):
        for group, group_names in (("tail", tail), ("rest", rest)):
            for n in group_names:
                for c, planner in planners.items():
                    t0 = time.process_time()
                    r = planner.solve(problems[n], 0, budget, np.random.default_rng(1000 + seed))
                    cpu_s = time.process_time() - t0
                    solved = r.status.value == "solved"
                    got[(group, c)].append((solved, r.collision_checks, cpu_s))
                    if out:
                        out.write(
                            json.dumps(
                                {
                                    "name": n,
                                    "group": group,
                                    "cfg": c,
                                    "seed": seed,
                                    "solved": solved,
                                    "checks": r.collision_checks,
                                    "cpu_s": round(cpu_s, 4),
                                }
                            )
                            + "\n"
                        )
                        out.flush()
        print(f"  seed {seed} done", flush=True)
    load.append(os.getloadavg()[0])
    print("| group | setting | solved | median checks | p90 | mean | mean CPU s |")
    print("|---|---|---|---:|---:|---:|---:|")
    for (group, c), v in got.items():
        checks = np.array([k for _, k, _ in v])
        print(
            f"| {group} ({len(v) // args.seeds} problems x {args.seeds} seeds) | {c} | "
            f"{sum(s for s, _, _ in v)}/{len(v)} | {np.median(checks):.0f} | "
            f"{np.percentile(checks, 90):.0f} | {checks.mean():.0f} | "
            f"{np.mean([t for _, _, t in v]):.3f} |"
        )
    print(f"load average at the start and the end: {load[0]:.1f}, {load[1]:.1f}")


if __name__ == "__main__":
    main()

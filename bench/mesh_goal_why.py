"""Why a tip-goal leg fails: the goal region's facts measured on a problem file (issue 35,
the UR10 shelf's ``reach``; ``results/mesh_robots.md``).

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/mesh_goal_why.py PROBLEM.toml \\
        [--leg 0] [--ik 200] [--planners native.rrtconnect,ompl.rrtconnect,native.kpiece] \\
        [--max-checks 300000] [--time-limit 30]

Prints, one JSON object per part:

- ``target``: the tip target, its tolerance, and which obstacle boxes hold it;
- ``ik``: ``--ik`` IK descents (the goal pool's: from the leg's start plus growing noise
  and uniformly random states, :func:`~plannerlab.problem.ik.sample_goal_state`'s schedule,
  one descent each): how many reach the region, how many of those are collision-free (the
  margin of the problem) and how many are free with no margin, the colliding pairs of the
  rest by class (self LINK x LINK, scene LINK x OBSTACLE), and how many distinct valid
  states (0.5 rad apart) they found;
- ``pool``: the goal pool a native planner fills with its defaults (seed 0) and, per pool
  state and for the leg's start, the free-motion fraction (``bench/mbm_why.py``: 48
  seeded straight motions at the default range and its halves, checked on the planner's
  grid);
- ``valid_share`` (``--valid-share N``): of N seeded uniform states, the share valid, and
  of (at most 400 of) the invalid ones the share whose colliding pairs touch the scene;
- ``solve``: per ``--planners``, the leg solved with a check budget and a time limit:
  status, checks, tree sizes (``nodes``), the pool size.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def box_distances(problem: Any, p: Any) -> dict[str, float]:
    """The distance [mm] from ``p`` to each box of the scene (mesh covers left out), and
    whether ``p`` lies in the world box around them all (``in_hull``: inside a shelf)."""
    out: dict[str, Any] = {}
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for ob in problem.scene.obstacles:
        if ob.kind != "box" or ob.cover_of:
            continue
        T = ob.T_world_obstacle
        local = np.abs(T[:3, :3].T @ (p - T[:3, 3])) - ob.size_m / 2
        out[ob.name] = round(1e3 * float(np.linalg.norm(np.maximum(local, 0.0))), 1)
        h = ob.half_extents_world()
        lo, hi = np.minimum(lo, T[:3, 3] - h), np.maximum(hi, T[:3, 3] + h)
    out["in_hull"] = bool(np.all((p >= lo) & (p <= hi)))
    return out


def ik_facts(
    problem: Any, checker: Any, leg: int, n: int, seed: int, free_of: int, range0: float
) -> dict[str, Any]:
    from mbm_why import free_fractions, pair_classes

    from plannerlab.collision.chain_ik import descent_for_robot
    from plannerlab.problem.ik import solve_ik

    robot, goal = problem.robot, problem.goal(leg)
    q0 = np.asarray(problem.q_start)
    rng = np.random.default_rng(seed)
    descent = descent_for_robot(robot)
    obstacles = {o.name for o in problem.scene.obstacles}
    reached, valid, classes = 0, [], Counter()
    for k in range(n):
        if k == 0 or rng.random() >= 0.5:
            sigma = min(0.02 * 1.35**k, np.pi)
            q_seed = q0 + rng.normal(0.0, sigma, robot.dof)
        else:
            q_seed = rng.uniform(robot.lower, robot.upper)
        r = solve_ik(robot, goal, q_seed, descent=descent)
        if not r.success:
            continue
        reached += 1
        if checker.is_valid(r.q):
            valid.append(r.q)
        else:
            for c in pair_classes(checker.colliding_pairs(r.q), obstacles):
                classes[c] += 1
    distinct: list[Any] = []
    for q in valid:
        if all(np.max(np.abs(q - d)) > 0.5 for d in distinct):
            distinct.append(q)
    free = [
        {
            "q": np.round(q, 2).tolist(),
            "clearance_mm": round(1e3 * float(checker.clearance(q)), 1),
            "free": free_fractions(problem, checker, q, range0),
        }
        for q in distinct[:free_of]
    ]
    return {
        "free_of_distinct": free,
        "descents": n,
        "reach_region": reached,
        "valid": len(valid),
        "distinct_valid": len(distinct),
        "colliding_classes": dict(classes.most_common(8)),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("problem", type=Path)
    ap.add_argument("--leg", type=int, default=0)
    ap.add_argument("--ik", type=int, default=200)
    ap.add_argument("--ik-free", type=int, default=0, help="free-motion fractions of so many")
    ap.add_argument("--planners", default="native.rrtconnect")
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--pool-uniform", action="store_true", help="diagnostic: see the code")
    ap.add_argument("--max-checks", type=int, default=300000)
    ap.add_argument("--time-limit", type=float, default=30.0)
    ap.add_argument("--set", action="append", default=[], help="planner setting key=value")
    ap.add_argument("--valid-share", type=int, default=0, help="uniform states to judge")
    ap.add_argument("--skip", default="", help="parts to skip: ik,pool")
    args = ap.parse_args()
    from mbm_why import free_fractions

    import plannerlab as pl
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners.native.solve import space_extent

    print(json.dumps({"load_start": os.getloadavg()}), flush=True)
    problem = pl.load_problem(args.problem)
    checker = problem_checker(problem)
    goal = problem.goal(args.leg)
    p = np.asarray(goal.p_world_m)
    print(
        json.dumps(
            {
                "target": p.round(4).tolist(),
                "n": np.asarray(goal.n_world).round(3).tolist(),
                "pos_tol_m": goal.pos_tol_m,
                "angle_tol_deg": goal.angle_tol_deg,
                "box_distance_mm": box_distances(problem, p),
                "margin_m": problem.safety_margin_m,
            }
        ),
        flush=True,
    )
    skip = set(args.skip.split(","))
    if args.valid_share:
        rng = np.random.default_rng(0)
        Q = rng.uniform(
            problem.robot.lower, problem.robot.upper, (args.valid_share, problem.robot.dof)
        )
        valid = np.array([checker.is_valid(q) for q in Q])
        scene = {o.name.split("#")[0] for o in problem.scene.obstacles}
        scene |= {m.name for m in problem.scene.meshes}
        bad = Q[~valid][:400]
        touching = sum(
            any(
                a.split("#")[0] in scene or b.split("#")[0] in scene
                for a, b in checker.colliding_pairs(q)
            )
            for q in bad
        )
        share = {
            "states": args.valid_share,
            "valid": round(float(valid.mean()), 4),
            "invalid_touching_scene": round(touching / max(len(bad), 1), 3),
            "of_invalid": len(bad),
        }
        print(json.dumps({"valid_share": share}), flush=True)
    range0 = 0.2 * space_extent(checker.model)
    if "ik" not in skip:
        facts = ik_facts(problem, checker, args.leg, args.ik, 0, args.ik_free, range0)
        print(json.dumps({"ik": facts}), flush=True)
    q0 = np.asarray(problem.q_start)
    if "pool" not in skip:
        from plannerlab.planners.goal_pool import fill_goal_pool
        from plannerlab.planners.native.settings import RRTConnectSettings

        class Guard:
            def __init__(self) -> None:
                self.checker = checker

            def exhausted(self) -> None:
                return None

            def out_of_time(self) -> bool:
                return False

            def is_valid(self, q: Any) -> bool:
                return bool(checker.is_valid(q))

        from plannerlab.planners.context import PlanningContext

        ctx = PlanningContext.for_planner(
            pl.make_planner("native.rrtconnect"),
            problem,
            args.leg,
            pl.Budget(max_collision_checks=10**7),
            checker=checker,
        )
        extra: dict[str, Any] = {}
        pool, _ = fill_goal_pool(
            ctx, RRTConnectSettings(), Guard(), np.random.default_rng(0), q0, extra
        )
        rows = [
            {
                "state": "start",
                "clearance_mm": round(1e3 * float(checker.clearance(q0)), 1),
                "free": free_fractions(problem, checker, q0, range0),
            }
        ]
        for i, q in enumerate(pool):
            rows.append(
                {
                    "state": f"pool{i}",
                    "q": np.round(q, 3).tolist(),
                    "clearance_mm": round(1e3 * float(checker.clearance(q)), 1),
                    "free": free_fractions(problem, checker, q, range0),
                }
            )
        print(
            json.dumps({"pool": extra, "range_rad": round(range0, 3), "states": rows}), flush=True
        )
    if args.pool_uniform:
        # diagnostic: the pool's slots after the first seeded from uniform states only
        import plannerlab.planners.goal_pool as gp
        from plannerlab.problem.ik import sample_goal_state

        calls = [0]

        def uniform_after_first(*a: Any, **k: Any) -> Any:
            calls[0] += 1
            if k.get("seeds") is not None and calls[0] % 4 != 1:
                k["seeds"] = []
            return sample_goal_state(*a, **k)

        gp.fill_goal_pool.__defaults__ = (uniform_after_first,)
    overrides = {}
    for kv in args.set:
        k, v = kv.split("=", 1)
        overrides[k] = json.loads(v)
    for name, seed in [
        (n, int(k)) for n in filter(None, args.planners.split(",")) for k in args.seeds.split(",")
    ]:
        budget = pl.Budget(max_collision_checks=args.max_checks, time_limit_s=args.time_limit)
        plan = pl.solve(
            problem,
            name,
            seed,
            budget=budget,
            legs=[args.leg],
            overrides=overrides if name.startswith("native") else None,
        )
        leg = plan.legs[0]
        extra = leg.extra or {}
        keep = ("nodes", "goal_pool", "goal_pool_checks", "restarts", "planning_checks")
        print(
            json.dumps(
                {
                    "planner": name,
                    "seed": seed,
                    "set": overrides,
                    "status": leg.status.value,
                    "checks": int(leg.collision_checks),
                    "time_s": round(float(leg.time_s), 2),
                    "iterations": int(leg.iterations),
                    **{k: extra[k] for k in keep if k in extra},
                }
            ),
            flush=True,
        )
    print(json.dumps({"load_end": os.getloadavg()}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

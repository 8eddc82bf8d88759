"""The variants table of results/variants.md from a compare store (trials.jsonl).
Usage: python results/variants/table_ref.py STORE/trials.jsonl"""
import json
import sys

rows = {}
for line in open(sys.argv[1]):
    d = json.loads(line)
    rows[d["problem"]] = d
print(
    "| problem | legs planned | all seven executed cleanly | largest deviation from the plan [mm] "
    "| of which the reference [mm] | smallest simulated clearance [mm] | smallest planned "
    "clearance [mm] | execution wall / simulated [s] | failure |"
)
print("|---|---|---|---|---|---|---|---|---|")
for name in sorted(rows):
    d = rows[name]
    legs = d["legs_run"]
    solved = sum(leg["status"] == "solved" for leg in legs)
    ex = (d.get("execution") or {}).get("legs", [])
    planned = f"{solved}/7" if solved == 7 else f"{solved} of {len(legs)} tried"
    clean = "yes" if d["success"] and solved == 7 and all(e["success"] for e in ex) else "no"
    dev = max((e["max_deviation_m"] for e in ex), default=float("nan")) * 1e3
    ref = max((e.get("reference_deviation_m", float("nan")) for e in ex), default=float("nan")) * 1e3
    sim_clear = min((e["min_clearance_m"] for e in ex), default=float("nan")) * 1e3
    plan_clear = min(leg["min_clearance_m"] for leg in legs) * 1e3
    wall = sum(e["wall_time_s"] for e in ex)
    sim = sum(e["sim_time_s"] for e in ex)
    fail = "—"
    bad = [leg for leg in legs if leg["status"] != "solved"]
    if bad:
        fail = f"{bad[0]['goal']}: {bad[0]['status']} ({bad[0]['reason'][:110]})"
    else:
        bad_ex = [e for e in ex if not e["success"]]
        if bad_ex:
            fail = f"{bad_ex[0]['goal']}: {bad_ex[0]['reason'][:160]}"
    print(
        f"| {name} | {planned} | {clean} | {dev:.2f} | {ref:.2f} | {sim_clear:.1f} | "
        f"{plan_clear:.1f} | {wall:.1f} / {sim:.0f} | {fail} |"
    )

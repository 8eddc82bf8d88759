"""Planned paths of gradient.clearance+detour on the 80 variants at one commit, against the
executed stores of the earlier commits: leg by leg path_sha256."""
import glob
import json

new = {json.loads(l)["problem"]: json.loads(l) for l in open("results/variants/all80/gradient_plan_edb1258/trials.jsonl")}
old = {}
for f in glob.glob("results/variants/all80/gradient_v*/trials.jsonl"):
    for l in open(f):
        r = json.loads(l)
        old[r["problem"]] = r
same = sum(
    [x["path_sha256"] for x in new[p]["legs_run"]] == [x["path_sha256"] for x in old[p]["legs_run"]]
    for p in new
)
clean = sum(
    bool(o["success"]) and o["executed_legs"] == len(o["legs_run"]) and all(e["success"] for e in o["executions"] or [])
    for o in old.values()
)
print(f"{len(new)} variants; planned all legs at edb1258: {sum(bool(r['success']) for r in new.values())}; "
      f"paths identical leg by leg to the executed stores: {same}; executed cleanly there: {clean}")

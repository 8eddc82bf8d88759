"""One line per trial of a plannerlab compare store (issue 33, branch leave3): legs solved,
executed cleanly, the longest leg and the leave leg [s], whether the leave was routed by the
body's opening. Usage: python summary_lines.py STORE/trials.jsonl ..."""
import json, sys
for f in sys.argv[1:]:
    for line in open(f):
        d = json.loads(line)
        legs = d["legs_run"]
        st = [l["status"] for l in legs]
        ex = d.get("executions") or []
        exok = all(e.get("success") for e in ex) if ex else None
        leave = legs[-1]
        lead = leave.get("extra", {}).get("leader", {})
        print(d["problem"][-3:], d["status"], f"{sum(s=='solved' for s in st)}/{len(st)}", "exec", exok, f"max_leg_s {max(l['time_s'] for l in legs):.2f}", f"leave_s {leave['time_s']:.2f}", "opening" if "opening_m" in lead else "-", "retract_first" if lead.get("retract_first") else "", f"wall {d['wall_s']:.0f}", d["finished_at"][11:19])

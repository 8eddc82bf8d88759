"""Issue 33 diagnosis: where gradient.clearance+detour stalled on v42 (E) and v49 (C) at
02da654: the stall state's faces (every 2nd), from the stored trials.

Run from the repo root::

    PYTHONPATH=$PWD python results/variants/all80/leave2_diag/stall.py
"""

import json

import numpy as np

from plannerlab.problem.catalog import load_problem

for line in open("results/variants/all80/gradient_v40_v49/trials.jsonl"):
    r = json.loads(line)
    if r["problem"] not in ("armz_inspection_v42", "armz_inspection_v49"):
        continue
    problem = load_problem(f"problems/variants/{r['problem']}.toml")
    print(r["problem"], [problem.goal(i).name for i in range(problem.legs)])
    for o in problem.scene.obstacles:
        if "ceiling" in o.name or "wall" in o.name:
            print(
                "  ",
                o.name,
                np.round(o.T_world_obstacle[:3, 3], 2).tolist(),
                np.round(o.size_m, 2).tolist(),
            )
    for l in r["legs_run"]:
        if l["status"] == "solved":
            continue
        q = np.array(l["extra"]["q_stall"])
        leg = l["leg"]
        F = problem.robot.fk(q)[:, :3, 3]
        g = problem.goal(leg)
        print(
            " leg",
            l["goal"],
            "goal p",
            np.round(g.p_world_m, 2).tolist(),
            "n",
            np.round(g.n_world, 2).tolist(),
        )
        print(
            " stall tip",
            np.round(F[-1], 2).tolist(),
            "dist to goal",
            round(float(np.linalg.norm(F[-1] - g.p_world_m)), 2),
        )
        print(" faces", np.round(F[::2], 2).tolist())

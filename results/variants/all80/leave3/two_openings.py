"""Issue 33 (branch leave3): the constructed two-opening room of
tests/planners/test_leader.py (armz_inspection_v21's room with a 2.6 m square hole cut in
the ceiling above B's corner), leaving from B's witness with native.rrtconnect+leader,
seed 0, 1 000 000 checks, no clock. Runs on any commit (main's has no body_opening).

Run from the repo root::

    PYTHONPATH=$PWD python results/variants/all80/leave3/two_openings.py
"""

import dataclasses

import numpy as np

from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget
from plannerlab.problem.scene import Box, Scene

base = load_problem("problems/variants/armz_inspection_v21.toml")
c = next(o for o in base.scene.obstacles if o.name == "room_ceiling")
cx, cy, cz = c.T_world_obstacle[:3, 3]
sx, sy, sz = c.size_m
x0, x1, y0, y1 = cx - sx / 2, cx + sx / 2, cy - sy / 2, cy + sy / 2
hx, hy = (-7.8, -5.2), (7.6, 10.2)


def box(name, lo, hi):
    T = np.eye(4)
    T[:3, 3] = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, cz]
    return Box(name, T, np.array([hi[0] - lo[0], hi[1] - lo[1], sz]))


cut = (
    box("ceiling_left", (x0, y0), (hx[0], y1)),
    box("ceiling_right", (hx[1], y0), (x1, y1)),
    box("ceiling_near", (hx[0], y0), (hx[1], hy[0])),
    box("ceiling_far", (hx[0], hy[1]), (hx[1], y1)),
)
kept = tuple(o for o in base.scene.obstacles if o.name != "room_ceiling")
problem = dataclasses.replace(base, scene=Scene(kept + cut, base.scene.meshes), name="two_openings")
q_b = np.array(problem.extras["witness"]["goal_states_rad"][-2])
leave = problem.legs - 1
planner = make_planner("native.rrtconnect+leader")
fl = planner.leader.for_robot(problem.robot)
plain = fl.leader_path(problem, leave, q_b, None)
print("leader from B's tip (plain):", np.round(plain.points_m, 2).tolist())
budget = Budget(max_iterations=None, max_collision_checks=1_000_000, time_limit_s=None)
r = planner.solve(problem, leave, budget, np.random.default_rng(0), q_start=q_b)
print("leave:", r.status.value, "|", r.reason, "| checks", r.collision_checks, "| iterations",
      r.iterations)
print("leader log:", r.extra.get("leader"))

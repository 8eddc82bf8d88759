"""Issue 33 diagnosis (v49 leave): from C's witness state, the leader's route, the retract
(follow_leader.moves.retract: the slide) of native.rrtconnect+leader's leader, where it
stops and the leader's route from there.

Run from the repo root (the budgets are in iterations and checks; no clock)::

    PYTHONPATH=$PWD python -u results/variants/all80/leave2_diag/retract49.py \
        problems/variants/armz_inspection_v49.toml
"""

import sys

import numpy as np

from plannerlab.planners import make_planner
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.follow_leader import moves
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget

name = sys.argv[1] if len(sys.argv) > 1 else "problems/variants/armz_inspection_v49.toml"
problem = load_problem(name)
W = problem.extras["witness"]["goal_states_rad"]
print(
    "witness states",
    len(W),
    "legs",
    problem.legs,
    [problem.goal(i).name for i in range(problem.legs)],
)
q_c = np.array(W[-2])
leave = problem.legs - 1
pl = make_planner("native.rrtconnect+leader")
fl = pl.leader.for_robot(problem.robot)
B = Budget(max_iterations=200000, max_collision_checks=2000000, time_limit_s=None)
ctx = PlanningContext.for_planner(pl, problem, leave, B, q_start=q_c)
goal = problem.goal(leave)
print("leave goal p", goal.p_world_m, "n", goal.n_world)
F = problem.robot.fk(q_c)
faces = F[:, :3, 3]
print("tip", faces[-1], "base", faces[0])
print("faces y,z:", np.round(faces[:, 1:], 2).tolist())
for o in problem.scene.obstacles:
    print(o.name, np.round(o.T_world_obstacle[:3, 3], 2), np.round(o.size_m, 2))
rng = np.random.default_rng(0)
lead = fl.leader_path(problem, leave, q_c, rng)
print("leader pts:\n", np.round(lead.points_m, 2))
print(
    "crosses_body", moves.crosses_body(problem.robot, q_c, lead), "sees", fl.sees_approach(ctx, q_c)
)
print("leaves_from_inside", moves.leaves_from_inside(fl, ctx, q_c, lead))
r = moves.retract(fl, ctx, q_c, 0)
print("retract", r.status, r.reason, len(r.states))
qr = r.states[-1]
Fr = problem.robot.fk(qr)
print("after retract tip", Fr[-1, :3, 3], "sees", fl.sees_approach(ctx, qr))
appr = goal.p_world_m - fl.settings.approach_m * goal.n_world
print("approach point", appr)
lead2 = fl.leader_path(problem, leave, qr, np.random.default_rng(1))
print("leader after retract:\n", np.round(lead2.points_m, 2))

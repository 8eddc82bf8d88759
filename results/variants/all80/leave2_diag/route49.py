"""Issue 33 diagnosis (v49 leave): the leader's tip paths out of the room from C's witness
state, forward and backward, and which body points see the leave goal's approach point.

Run from the repo root::

    PYTHONPATH=$PWD python results/variants/all80/leave2_diag/route49.py \
        problems/variants/armz_inspection_v49.toml
"""

import sys

import numpy as np

from plannerlab.planners.clearance.descent import ClearanceSettings
from plannerlab.planners.clearance.slide import pivot_face, sees
from plannerlab.planners.follow_leader import moves
from plannerlab.planners.follow_leader.planner import FollowLeader, FollowLeaderSettings
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.goals import GoalRegion

problem = load_problem(sys.argv[1])
W = problem.extras["witness"]["goal_states_rad"]
q_c = np.array(W[-2])
leave = problem.legs - 1
fl = FollowLeader(
    "x", FollowLeaderSettings(random_grid=True, retract=False), ClearanceSettings()
).for_robot(problem.robot)
goal = problem.goal(leave)
faces = problem.robot.fk(q_c)[:, :3, 3]
print("goal", np.round(goal.p_world_m, 2), np.round(goal.n_world, 2))
print("faces xyz (every 3rd):", np.round(faces[::3], 2).tolist(), flush=True)
r_tip = float(np.asarray(problem.robot.link_radii_m)[-1])
clr = r_tip + problem.safety_margin_m + fl.settings.extra_clearance_m
appr = goal.p_world_m - fl.settings.approach_m * goal.n_world
print(
    "approach",
    np.round(appr, 2),
    "clearance",
    clr,
    "tip sees approach",
    sees(problem.scene, faces[-1], appr, clr),
)
print("pivot face", pivot_face(problem.scene, faces, appr, clr), "of", len(faces) - 1)
for k in range(len(faces) - 1, -1, -1):
    if sees(problem.scene, faces[k], appr, clr):
        print("last face seeing approach:", k, np.round(faces[k], 2))
        break
for seed in range(3):
    lead = fl.leader_path(problem, leave, q_c, np.random.default_rng(seed))
    print(
        "seed",
        seed,
        "leader pts:",
        np.round(lead.points_m, 2).tolist(),
        "crosses_body",
        moves.crosses_body(problem.robot, q_c, lead),
        flush=True,
    )

q_r = np.asarray(problem.q_start, dtype=float)
p_r, n_r = problem.robot.tip(q_r)
p_c, n_c = problem.robot.tip(q_c)
print("rest tip", np.round(p_r, 2), "C tip", np.round(p_c, 2), np.round(n_c, 2))
g = GoalRegion(
    "start tip", p_c, n_c, fl.settings.subgoal_pos_tol_m, fl.settings.subgoal_angle_tol_deg
)
for seed in range(2):
    lb = fl.leader_path(problem, leave, q_r, np.random.default_rng(seed), goal=g)
    print("backward seed", seed, np.round(lb.points_m, 2).tolist(), flush=True)
arc = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(faces, axis=0), axis=1))])
for back in (0.2, 0.35, 0.5, 1.0, 2.0):
    s = arc[-1] - back
    p = np.array([np.interp(s, arc, faces[:, k]) for k in range(3)])
    print(
        "body point",
        back,
        "m back",
        np.round(p, 2),
        "sees approach",
        sees(problem.scene, p, appr, clr),
    )

"""Issue 33 diagnosis (v49 leave): the leader's tip path from C's witness to the pivot face
(the last face of the body that sees the leave goal's approach point).

Run from the repo root::

    PYTHONPATH=$PWD python results/variants/all80/leave2_diag/via_pivot.py \
        problems/variants/armz_inspection_v49.toml
"""

import sys

import numpy as np

from plannerlab.planners.clearance.descent import ClearanceSettings
from plannerlab.planners.clearance.slide import pivot_face
from plannerlab.planners.follow_leader.planner import FollowLeader, FollowLeaderSettings
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.goals import GoalRegion

problem = load_problem(sys.argv[1])
q_c = np.array(problem.extras["witness"]["goal_states_rad"][-2])
leave = problem.legs - 1
fl = FollowLeader(
    "x", FollowLeaderSettings(random_grid=True, retract=False), ClearanceSettings()
).for_robot(problem.robot)
goal = problem.goal(leave)
F = problem.robot.fk(q_c)
faces = F[:, :3, 3]
clr = (
    float(np.asarray(problem.robot.link_radii_m)[-1])
    + problem.safety_margin_m
    + fl.settings.extra_clearance_m
)
appr = goal.p_world_m - fl.settings.approach_m * goal.n_world
k = pivot_face(problem.scene, faces, appr, clr)
sub = GoalRegion(
    "pivot", faces[k], -F[k, :3, 2], 0.3, 30.0
)  # the pivot face, looking back along the body
lead = fl.leader_path(problem, leave, q_c, np.random.default_rng(0), goal=sub)
print("tip -> pivot face", k, np.round(lead.points_m, 2).tolist())

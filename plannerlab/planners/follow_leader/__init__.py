"""Follow-the-leader, one sub-package (``gradient.follow_leader*``; its moves are reused by
``native.rrtconnect+leader``):

* :mod:`.grid`: the leader's tip path: a voxel grid of the scene's signed distance and the
  shortest path on it (scipy's Dijkstra), corners cut where the straight line keeps the
  clearance;
* :mod:`.moves`: the moves other planners reuse: tracking a tip path into any tip goal,
  and the retract along the body for leaving from deep inside;
* :mod:`.planner`: the planner (:class:`~.planner.FollowLeader`, its settings, ``make``).

The planner's names are importable from here (``from plannerlab.planners.follow_leader
import FollowLeader``); the registry names ``plannerlab.planners.follow_leader.planner:make``.
"""

from plannerlab.planners.follow_leader.planner import (
    DERIVED_DISTANCES,
    FollowLeader,
    FollowLeaderSettings,
    make,
)

__all__ = ["DERIVED_DISTANCES", "FollowLeader", "FollowLeaderSettings", "make"]

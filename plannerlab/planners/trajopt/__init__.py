"""Trajectory optimisation over whole paths (``trajopt.*``), one sub-package.

The Arm-Z paper moves one configuration down a gradient and stalls in local minima; the
field's other answer is to optimise the whole path at once (CHOMP, TrajOpt, GPMP2,
cuRobo). A path of K waypoints is optimised for smoothness (its squared joint
accelerations) under a collision hinge on the sphere field's signed distances, the joint
limits and the goal (a goal state, or the tip's position and normal within their
tolerances), from seeds: the straight line, the paper's gradient descent,
``native.rrtconnect``'s path, the leader's path; restarts are drawn from the trial's
generator. Every returned path passes the re-check every planner's passes (no tunnelling:
an edge it refuses is split and the path optimised again).

* :mod:`.geometry`: the one module that asks the collision core (the sphere field's
  hinge with its gradient, the tip);
* :mod:`.path`: the path problem (merit, gradient, the banded Gauss-Newton matrix);
* :mod:`.solvers`: the penalty loop and its solvers (Gauss-Newton on the band,
  L-BFGS-B, the augmented Lagrangian), chosen by ``bench/trajopt_bench.py``;
* :mod:`.seeds`: the seeds and their restarts;
* :mod:`.settings`: the settings;
* :mod:`.planner`: the planner and the registry's factory (``make``).
"""

from __future__ import annotations

from plannerlab.planners.trajopt.planner import TrajOptPlanner, make
from plannerlab.planners.trajopt.settings import TrajOptSettings

__all__ = ["TrajOptPlanner", "TrajOptSettings", "make"]

"""The clearance descent, one sub-package: the paper's objective with a smooth clearance
term, descended from a state into a goal region (``gradient.clearance*``; tracked by
``gradient.follow_leader*``).

* :mod:`.field`: the clearance field in numpy (spheres on the links, their pairs, cost
  and gradient), the reference;
* :mod:`.settings`: the descent's settings (:class:`ClearanceSettings`, distances
  derived from the robot's size);
* :mod:`.step`: the step in numpy (steepest descent, damped Gauss-Newton, the hold off
  the clearance floor);
* :mod:`.compiled`: the same field and step compiled (numba), on the geometry of the
  compiled robot–scene model (:mod:`plannerlab.collision.spheres`: no geometry of its
  own);
* :mod:`.models`: the field and step at one state on either engine (``backend``);
* :mod:`.descent`: the descent, its escapes and :class:`~.descent.LegPath`, the
  family's planner (``make``).

The field's names are re-exported here (``from plannerlab.planners.clearance import
ClearanceField``).
"""

from plannerlab.planners.clearance.field import (
    MAX_SPHERES,
    Clearance,
    ClearanceField,
    SetupStopped,
    sphere_counts,
)

__all__ = ["MAX_SPHERES", "Clearance", "ClearanceField", "SetupStopped", "sphere_counts"]

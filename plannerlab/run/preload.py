"""What a trial's process imports, all at once: a comparison's fork server imports this
module before it forks one process per trial (``plannerlab.comparison.local``), so that
each trial starts with plannerlab's planners, checker, simulator and records loaded
(numpy, python-fcl, PyBullet and OMPL's Python modules with them; no OMPL object is
created). A module of ``run/`` because ``run/`` may import every room a trial walks
through; the comparison names only this module."""

from __future__ import annotations

import plannerlab.collision.fcl_checker
import plannerlab.planners
import plannerlab.planners.gradient
import plannerlab.planners.hybrid
import plannerlab.planners.ompl
import plannerlab.problem.catalog
import plannerlab.record.files
import plannerlab.run.pipeline
import plannerlab.sim.execute

#: the modules loaded (for a reader; importing this module is the point)
MODULES = (
    plannerlab.collision.fcl_checker,
    plannerlab.problem.catalog,
    plannerlab.planners,
    plannerlab.planners.ompl,
    plannerlab.planners.gradient,
    plannerlab.planners.hybrid,
    plannerlab.run.pipeline,
    plannerlab.sim.execute,
    plannerlab.record.files,
)

__all__ = ["MODULES"]

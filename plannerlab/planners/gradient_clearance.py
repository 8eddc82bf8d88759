"""The clearance descent's former module: its names, now in the sub-package
:mod:`plannerlab.planners.clearance` (:mod:`~plannerlab.planners.clearance.descent`),
re-exported for the code that still imports them from here
(``planners/native/leader.py``)."""

from plannerlab.planners.clearance.descent import (
    VARIANTS,
    ClearanceDescent,
    ClearanceSettings,
    LegPath,
    make,
)

__all__ = ["VARIANTS", "ClearanceDescent", "ClearanceSettings", "LegPath", "make"]

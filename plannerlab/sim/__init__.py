"""Simulation: the only plannerlab package that imports ``pybullet``.

:class:`SimWorld` is one PyBullet world (its own client) holding a robot and a scene; it
is the :class:`~plannerlab.planners.base.Stepper` closed-loop planners drive.
:func:`execute` runs a planned path in a fresh world and reports an :class:`Execution`;
:func:`execute_legs` runs consecutive legs in one world.
"""

from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.sim.execute import execute, execute_legs
from plannerlab.sim.world import DT_S, GRAVITY_MPS2, Contact, SimWorld

__all__ = [
    "DT_S",
    "GRAVITY_MPS2",
    "Contact",
    "ContactRecord",
    "Execution",
    "SimWorld",
    "execute",
    "execute_legs",
]

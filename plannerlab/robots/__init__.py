"""Robot families: one package per family (kinematics, collision capsules, URDF, IK,
goal sampling), each with a ``from_table(reader)`` that builds the model from a problem
file's ``[robot]`` table. The table of robot types lives with the problem loader
(:data:`plannerlab.problem.load.ROBOT_TYPES`), which imports a family only when a problem
asks for it.
"""

from __future__ import annotations

from plannerlab.robots.base import Robot

__all__ = ["Robot"]

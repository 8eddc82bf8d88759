"""Robot families: one package per family (kinematics, collision capsules, URDF, IK,
goal sampling), each declaring its problem-file ``[robot]`` table in ``schema.py``
(:class:`plannerlab.robots.schema.RobotTable`: the keys, and a constructor from their
validated values). The table of robot types lives with the problem loader
(:data:`plannerlab.problem.load.ROBOT_TYPES`), which parses every family's table in one
place and imports a family only when a problem asks for it.
"""

from __future__ import annotations

from plannerlab.robots.base import Robot

__all__ = ["Robot"]

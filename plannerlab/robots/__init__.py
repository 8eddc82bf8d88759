"""Robot families: one package per family (kinematics, collision capsules, URDF, IK,
goal sampling), each declaring its problem-file ``[robot]`` table in ``schema.py``
(:class:`plannerlab.robots.schema.RobotTable`: the keys, and a constructor from their
validated values). Families are registered in :mod:`plannerlab.robots.registry`
(:data:`~plannerlab.robots.registry.FAMILIES`); the problem loader parses every family's
table in one place and imports a family only when a problem asks for it.
"""

from __future__ import annotations

from plannerlab.robots.base import Robot

__all__ = ["Robot"]

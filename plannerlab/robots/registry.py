"""The robot families, registered by the ``[robot] type`` a problem file names.

A family is one package under ``plannerlab/robots/`` (kinematics, collision geometry, its
``[robot]`` table in ``schema.py``). The rest of plannerlab reaches a family only through
its :class:`RobotFamily` entry here, the way planners are reached through
:mod:`plannerlab.planners`: the problem loader reads the entry's table, goal sampling its
analytic IK (if it has one), the reachability pre-check its reach bound, and a new family
plugs in with one entry, without touching ``problem/``, ``planners/`` or ``sim/``. Every
target is a ``"module:attribute"`` string imported on first use, so loading a problem
imports only its own family.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from plannerlab.errors import UnknownNameError
from plannerlab.robots.schema import RobotTable

#: the generic serial-chain builder of the compiled model (from ``robot.chain_data()``)
DEFAULT_MODEL = "plannerlab.collision.model_old:model_of_core"


@dataclass(frozen=True)
class RobotFamily:
    """One registered robot family.

    Attributes:
        kind: the ``[robot] type`` of a problem file (and ``Robot.kind``).
        table: ``"module:attribute"`` of its ``[robot]`` table declaration
            (:class:`~plannerlab.robots.schema.RobotTable`).
        goal_sampler: ``"module:function"`` sampling a goal region through an analytic IK,
            called as ``function(robot, goal, rng, seeds=...)`` and returning a state inside
            the region (collision ignored) or None; None: the numeric IK of
            :mod:`plannerlab.problem.ik` samples its goals.
        reach: ``"module:function"`` bounding where the tip can be, called as
            ``function(robot, p_world_m)`` and returning ``(distance_m, reach_m, where)``:
            the point's distance from the reference ``where`` names and the most the tip
            reaches from it; None: a fixed-base chain's bound (the base to the first link,
            every link's length, the last link to the tip).
        gravity_off: why the family's problems default to no gravity when their file has
            no ``[simulation]`` table, or None for the usual -9.81 m/s² along -z.
        model: ``"module:function"`` building the family's compiled robot–scene model
            (:class:`~plannerlab.collision.model.CompiledModel`) from a built collision core,
            called as ``function(core)``; the default is the generic serial-chain builder,
            which reads the robot's ``chain_data()`` (so a new family with a chain is on the
            compiled road with no entry of its own).
        ik_descent: ``"module:function"`` giving a robot's compiled IK descent
            (``function(robot)`` -> ``descent(goal, q_seed, max_iterations, damping,
            max_step_rad, target_fraction) -> (q, steps)``) that the numeric goal sampling
            of :mod:`plannerlab.problem.ik` restarts instead of its numpy descent; None:
            the numpy descent (on the robot's ``tip_jacobian``).
        summary: one line for the documentation.
    """

    kind: str
    table: str
    goal_sampler: str | None = None
    reach: str | None = None
    gravity_off: str | None = None
    model: str = DEFAULT_MODEL
    ik_descent: str | None = None
    summary: str = ""


#: robot type in a problem file -> its family (one entry per package under robots/)
FAMILIES: dict[str, RobotFamily] = {
    "armz": RobotFamily(
        "armz",
        "plannerlab.robots.armz.schema:TABLE",
        gravity_off=(
            "gravity off: the Arm-Z default when [simulation] is absent (as in every "
            "bundled Arm-Z problem); set gravity_mps2 to change it"
        ),
        summary="the Arm-Z modular hyper-redundant arm (one-DOF modules)",
    ),
    "irb6": RobotFamily(
        "irb6",
        "plannerlab.robots.irb6.schema:TABLE",
        goal_sampler="plannerlab.robots.irb6.goals:sample_goal_state",
        reach="plannerlab.robots.irb6.goals:reach_from_track",
        summary="the IRb-6 industrial arm on the LP-1 track (analytic IK)",
    ),
    "continuum_chain": RobotFamily(
        "continuum_chain",
        "plannerlab.robots.continuum.schema:TABLE",
        summary="a planar continuum robot as a chain of rigid links behind a port",
    ),
    "urdf": RobotFamily(
        "urdf",
        "plannerlab.robots.urdf.schema:TABLE",
        ik_descent="plannerlab.collision.chain_ik:descent_for",
        summary="any serial chain read from a URDF (yourdfpy), with its collision spheres",
    ),
}


def family(kind: str) -> RobotFamily:
    """The family of robot type ``kind``.

    Raises:
        UnknownNameError: a type that is not registered (with "did you mean").
    """
    if kind not in FAMILIES:
        raise UnknownNameError("robot type", kind, FAMILIES)
    return FAMILIES[kind]


def _target(spec: str) -> Any:
    module_name, attribute = spec.split(":")
    return getattr(importlib.import_module(module_name), attribute)


def robot_table(kind: str) -> RobotTable:
    """The ``[robot]`` table declaration of robot type ``kind`` (imports its family).

    Raises:
        UnknownNameError: for a type that is not in :data:`FAMILIES`.
    """
    table: RobotTable = _target(family(kind).table)
    return table


def goal_sampler(kind: str) -> Any:
    """The family's analytic goal sampler (see :attr:`RobotFamily.goal_sampler`), or None
    (also for a kind that is not registered: a robot built in code)."""
    entry = FAMILIES.get(kind)
    return None if entry is None or entry.goal_sampler is None else _target(entry.goal_sampler)


def reach_function(kind: str) -> Any:
    """The family's reach bound (see :attr:`RobotFamily.reach`), or None for the chain's."""
    entry = FAMILIES.get(kind)
    return None if entry is None or entry.reach is None else _target(entry.reach)


def model_builder(kind: str) -> Any:
    """The family's builder of its compiled model (see :attr:`RobotFamily.model`); the
    generic serial-chain builder for a kind that is not registered (a robot built in code)."""
    entry = FAMILIES.get(kind)
    return _target(DEFAULT_MODEL if entry is None else entry.model)


def ik_descent(kind: str) -> Any:
    """The family's compiled IK descent factory (see :attr:`RobotFamily.ik_descent`), or
    None (also for a kind that is not registered)."""
    entry = FAMILIES.get(kind)
    return None if entry is None or entry.ik_descent is None else _target(entry.ik_descent)


def gravity_off_reason(kind: str) -> str | None:
    """Why the family's problems default to no gravity (None: they do not)."""
    entry = FAMILIES.get(kind)
    return None if entry is None else entry.gravity_off


__all__ = [
    "DEFAULT_MODEL",
    "FAMILIES",
    "RobotFamily",
    "family",
    "goal_sampler",
    "gravity_off_reason",
    "ik_descent",
    "model_builder",
    "reach_function",
    "robot_table",
]

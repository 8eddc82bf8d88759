"""The robot families, registered by the ``[robot] type`` a problem file names.

A family is one package under ``plannerlab/robots/`` (kinematics, collision geometry, its
``[robot]`` table in ``schema.py``). The rest of plannerlab reaches a family only through
its :class:`RobotFamily` entry here, the way planners are reached through
:mod:`plannerlab.planners`: the problem loader reads the entry's table, goal sampling its
analytic IK (if it has one), the reachability pre-check its reach bound, and a new family
plugs in with one entry, without touching ``problem/``, ``planners/`` or ``sim/``.

Every target is an *entry point*: a function of this module that imports its family's
module inside its body, so loading a problem imports only its own family, and the
architecture test (``tests/house/test_architecture.py``) sees every import the registry
makes (no ``"module:function"`` strings). The entries point only into ``robots/``: what
another room builds from a robot (the compiled model and IK descent of ``collision/``)
it builds from the robot's own data (``chain_data()``, ``tip_data()``), and a family
opts in to a compiled IK descent with a flag (:attr:`RobotFamily.compiled_ik`), so no
family entry names a module of another room.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from plannerlab.errors import UnknownNameError
from plannerlab.robots.schema import RobotTable


@dataclass(frozen=True)
class RobotFamily:
    """One registered robot family.

    Attributes:
        kind: the ``[robot] type`` of a problem file (and ``Robot.kind``).
        table: entry point returning its ``[robot]`` table declaration
            (:class:`~plannerlab.robots.schema.RobotTable`).
        goal_sampler: entry point sampling a goal region through an analytic IK, called as
            ``function(robot, goal, rng, seeds=...)`` and returning a state inside the
            region (collision ignored) or None; None: the numeric IK of
            :mod:`plannerlab.problem.ik` samples its goals.
        reach: entry point bounding where the tip can be, called as
            ``function(robot, p_world_m)`` and returning ``(distance_m, reach_m, where)``:
            the point's distance from the reference ``where`` names and the most the tip
            reaches from it; None: a fixed-base chain's bound (the base to the first link,
            every link's length, the last link to the tip).
        gravity_off: why the family's problems default to no gravity when their file has
            no ``[simulation]`` table, or None for the usual -9.81 m/s² along -z.
        compiled_ik: the numeric goal sampling restarts the compiled IK descent of the
            robot's chain (:func:`plannerlab.collision.chain_ik.descent_for_robot`, from its
            ``tip_data()``) instead of the numpy descent on ``tip_jacobian``.
        summary: one line for the documentation.
    """

    kind: str
    table: Callable[[], RobotTable]
    goal_sampler: Callable[..., Any] | None = None
    reach: Callable[..., tuple[float, float, str]] | None = None
    gravity_off: str | None = None
    compiled_ik: bool = False
    summary: str = ""

    def __post_init__(self) -> None:
        for name in ("table", "goal_sampler", "reach"):
            value = getattr(self, name)
            if value is not None and not callable(value):
                raise TypeError(
                    f"robot family {self.kind!r}: {name} must be a function that imports its "
                    f"module when called (an entry point), got {value!r}"
                )


# ---------------------------------------------------------------- entry points
def _armz_table() -> RobotTable:
    from plannerlab.robots.armz.schema import TABLE

    return TABLE


def _irb6_table() -> RobotTable:
    from plannerlab.robots.irb6.schema import TABLE

    return TABLE


def _irb6_goal_state(robot: Any, goal: Any, rng: Any, seeds: Any = None) -> Any:
    from plannerlab.robots.irb6.goals import sample_goal_state

    return sample_goal_state(robot, goal, rng, seeds=seeds)


def _irb6_reach(robot: Any, p_world_m: Any) -> tuple[float, float, str]:
    from plannerlab.robots.irb6.goals import reach_from_track

    return reach_from_track(robot, p_world_m)


def _continuum_table() -> RobotTable:
    from plannerlab.robots.continuum.schema import TABLE

    return TABLE


def _urdf_table() -> RobotTable:
    from plannerlab.robots.urdf.schema import TABLE

    return TABLE


#: robot type in a problem file -> its family (one entry per package under robots/)
FAMILIES: dict[str, RobotFamily] = {
    "armz": RobotFamily(
        "armz",
        _armz_table,
        gravity_off=(
            "gravity off: the Arm-Z default when [simulation] is absent (as in every "
            "bundled Arm-Z problem); set gravity_mps2 to change it"
        ),
        summary="the Arm-Z modular hyper-redundant arm (one-DOF modules)",
    ),
    "irb6": RobotFamily(
        "irb6",
        _irb6_table,
        goal_sampler=_irb6_goal_state,
        reach=_irb6_reach,
        summary="the IRb-6 industrial arm on the LP-1 track (analytic IK)",
    ),
    "continuum_chain": RobotFamily(
        "continuum_chain",
        _continuum_table,
        summary="a planar continuum robot as a chain of rigid links behind a port",
    ),
    "urdf": RobotFamily(
        "urdf",
        _urdf_table,
        compiled_ik=True,
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


def robot_table(kind: str) -> RobotTable:
    """The ``[robot]`` table declaration of robot type ``kind`` (imports its family).

    Raises:
        UnknownNameError: for a type that is not in :data:`FAMILIES`.
    """
    return family(kind).table()


def goal_sampler(kind: str) -> Any:
    """The family's analytic goal sampler (see :attr:`RobotFamily.goal_sampler`), or None
    (also for a kind that is not registered: a robot built in code)."""
    entry = FAMILIES.get(kind)
    return None if entry is None else entry.goal_sampler


def reach_function(kind: str) -> Any:
    """The family's reach bound (see :attr:`RobotFamily.reach`), or None for the chain's."""
    entry = FAMILIES.get(kind)
    return None if entry is None else entry.reach


def compiled_ik(kind: str) -> bool:
    """Whether the family's goal sampling runs the compiled IK descent (see
    :attr:`RobotFamily.compiled_ik`; False for a kind that is not registered)."""
    entry = FAMILIES.get(kind)
    return entry is not None and entry.compiled_ik


def gravity_off_reason(kind: str) -> str | None:
    """Why the family's problems default to no gravity (None: they do not)."""
    entry = FAMILIES.get(kind)
    return None if entry is None else entry.gravity_off


__all__ = [
    "FAMILIES",
    "RobotFamily",
    "compiled_ik",
    "family",
    "goal_sampler",
    "gravity_off_reason",
    "reach_function",
    "robot_table",
]

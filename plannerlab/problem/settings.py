"""How a problem is planned and simulated: the ``[budget]``, ``[checking]``, ``[planning]``
and ``[simulation]`` tables, their types (:class:`Budget`, :class:`SimSettings`) and limits."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.problem.reader import TableReader
from plannerlab.robots.base import Robot
from plannerlab.robots.registry import gravity_off_reason

#: smallest ``[checking] joint_step`` [rad]: edges are checked every joint_step and
#: re-checked every joint_step / 4, so the cost grows as 1 / joint_step
MIN_JOINT_STEP_RAD = 1e-3
#: default ``[planning] safety_margin_m`` [m]: at least the execution's deviation limit
#: (``[simulation] max_deviation_m``, 0.01 m), so a plan leaves the executor its centimetre
DEFAULT_SAFETY_MARGIN_M = 0.01
#: smallest positive ``[planning] safety_margin_m`` [m]: edges are checked so that no point
#: moves more than the margin between two checked states, so the cost grows as 1 / margin
MIN_SAFETY_MARGIN_M = 1e-3
#: largest ``[planning] safety_margin_m`` [m]
MAX_SAFETY_MARGIN_M = 0.5


@dataclass(frozen=True, eq=False)
class Budget:
    """Limits of one planning call. ``None`` means no limit of that kind.

    Regression tests use iterations or collision checks; time limits are for benchmarks,
    or for tests on a clock the test controls.

    Attributes:
        max_iterations: the planner's iterations.
        max_collision_checks: collision checks.
        time_limit_s: seconds on ``clock``, set-up included.
        clock: the clock ``time_limit_s`` is read on: a callable giving seconds (None:
            ``time.perf_counter``). A test gives its own (for example
            :class:`~plannerlab.planners.base.StepClock`) so that a time limit is checked
            without the wall clock; it is not part of the budget's record (``to_dict``).
    """

    max_iterations: int | None = None
    max_collision_checks: int | None = None
    time_limit_s: float | None = None
    clock: Callable[[], float] | None = field(default=None, repr=False, compare=False)

    def replace(self, **changes: Any) -> Budget:
        values = {
            "max_iterations": self.max_iterations,
            "max_collision_checks": self.max_collision_checks,
            "time_limit_s": self.time_limit_s,
            "clock": self.clock,
        }
        values.update({k: v for k, v in changes.items() if v is not None})
        return Budget(**values)  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, Any]:
        return {
            "max_iterations": self.max_iterations,
            "max_collision_checks": self.max_collision_checks,
            "time_limit_s": self.time_limit_s,
        }


@dataclass(frozen=True)
class SimSettings:
    """How the problem is simulated when paths are executed (PyBullet).

    Attributes:
        gravity_mps2: gravity in the world frame [m/s²].
        max_track_err_rad: the joint tracking limit of execution records made before
            ``max_deviation_m`` [rad]; kept for old problem files, it no longer decides
            the verdict (the joint error is reported for information).
        max_deviation_m: largest deviation [m] of any point of the robot's collision
            geometry between the commanded and the simulated state, over the whole
            execution, that an execution may show and still count as executed cleanly.
    """

    gravity_mps2: tuple[float, float, float] = (0.0, 0.0, -9.81)
    max_track_err_rad: float = 0.05
    max_deviation_m: float = 0.01
    #: where the setting came from, in words (shown by ``execute``)
    origin: str = "default"


def read_budget(top: TableReader) -> Budget:
    """``[budget]``: limits of one leg's solve (none when absent)."""
    b = TableReader(top.source, "budget", top.raw("budget", {}))
    b.unknown_keys(("max_iterations", "max_collision_checks", "time_limit_s", "note"))
    return Budget(
        max_iterations=b.optional_integer("max_iterations", minimum=1),
        max_collision_checks=b.optional_integer("max_collision_checks", minimum=1),
        time_limit_s=b.optional_number("time_limit_s", positive=True),
    )


def read_joint_step(top: TableReader) -> float:
    """``[checking] joint_step`` [rad]: the largest joint step between checked states."""
    c = TableReader(top.source, "checking", top.raw("checking", {}))
    c.unknown_keys(("joint_step", "note"))
    joint_step = c.number("joint_step", 0.05, positive=True)
    if joint_step < MIN_JOINT_STEP_RAD:
        raise c.fail(
            "joint_step",
            f"a step >= {MIN_JOINT_STEP_RAD:g} rad, got {joint_step:g}: every edge is checked "
            f"every joint_step and re-checked every joint_step/4, so one radian of motion "
            f"would cost {4.0 / joint_step:.3g} collision checks",
        )
    if joint_step > math.pi:
        raise c.fail(
            "joint_step", f"a step <= pi rad, got {joint_step:g} (edges would go unchecked)"
        )
    return joint_step


def read_safety_margin(top: TableReader) -> float:
    """``[planning] safety_margin_m`` [m]: the clearance every plan keeps."""
    pl = TableReader(top.source, "planning", top.raw("planning", {}))
    pl.unknown_keys(("safety_margin_m", "note"))
    safety_margin_m = pl.number(
        "safety_margin_m",
        DEFAULT_SAFETY_MARGIN_M,
        nonnegative=True,
        maximum=MAX_SAFETY_MARGIN_M,
        why_maximum="a margin that wide closes every passage",
    )
    if 0.0 < safety_margin_m < MIN_SAFETY_MARGIN_M:
        raise pl.fail(
            "safety_margin_m",
            f"0 (no margin) or a margin >= {MIN_SAFETY_MARGIN_M:g} m, got {safety_margin_m:g}: "
            "edges are checked so that no point moves more than the margin between two "
            "checked states, so a finer margin multiplies the collision checks",
        )
    return safety_margin_m


def read_simulation(top: TableReader, robot: Robot) -> SimSettings:
    """``[simulation]``: gravity (a family's default when absent) and the execution's limits."""
    if not top.has("simulation"):
        # a family may default to no gravity: under gravity a 16-m Arm-Z bent sideways
        # needs far more torque than its joints have and collapses in PyBullet, and every
        # bundled Arm-Z problem turns gravity off (see problems/armz_pocket.toml)
        off = gravity_off_reason(robot.kind)
        if off is not None:
            return SimSettings((0.0, 0.0, 0.0), origin=off)
        return SimSettings(origin="gravity -9.81 m/s² along -z: the default")
    sim = TableReader(top.source, "simulation", top.raw("simulation"))
    sim.unknown_keys(("gravity_mps2", "max_track_err_rad", "max_deviation_m", "note"))
    if not sim.has("gravity_mps2"):
        default = read_simulation(TableReader(top.source, "", {}), robot)
        g = np.array(default.gravity_mps2)
        origin = default.origin
    else:
        g = sim.vector("gravity_mps2", 3)
        origin = f"gravity {g.tolist()} m/s² from [simulation]"
    return SimSettings(
        gravity_mps2=(float(g[0]), float(g[1]), float(g[2])),
        max_track_err_rad=sim.number("max_track_err_rad", 0.05, positive=True),
        max_deviation_m=sim.number("max_deviation_m", 0.01, positive=True),
        origin=origin,
    )

"""Settings of the clearance descent (``gradient.clearance*``; follow-the-leader's
descents take them as ``descent.<key>``), checked when made, and the robot's size that
their distances are derived from.

**Distances fit the robot.** A distance setting left at ``None`` (its default) is derived
from the robot when a leg is solved (:func:`robot_size`, :meth:`ClearanceSettings.
for_robot`): Arm-Z's value (the value these planners were built and measured with, on
Arm-Z's 0.716-m modules), scaled by the robot's typical link length over Arm-Z's
(:class:`RobotSize`: the median distance between successive frames of its chain). On
every Arm-Z (any radius, any number of modules) the ratio is exactly 1.0, so every
derived value is today's and the paths are bit-identical; a 0.7-m six-joint arm with
links of about 12 cm gets about a sixth of them (``influence_m`` about 5 cm). A value the
user sets (``--set influence_m=0.05``) wins.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar, cast

import numpy as np

from plannerlab.errors import PlannerlabError

#: the escapes from a stall (``escape`` setting)
ESCAPES = ("none", "detour", "random_detour", "rrtconnect")
#: how the field and the step are computed (``backend`` setting)
BACKENDS = ("compiled", "numpy")
#: the default of a distance setting derived from the robot: None until
#: :meth:`ClearanceSettings.for_robot` sets it (typed as the float it then is)
DERIVED: float = cast(float, None)
#: significant digits of the size ratio (a ratio computed in another base frame rounds
#: to the same value: Arm-Z's is exactly 1.0 wherever its base stands)
RATIO_DIGITS = 6


@dataclass(frozen=True)
class RobotSize:
    """How big a robot is, for the distance defaults of the clearance family.

    Attributes:
        pitch_m: the (upper) median distance between successive frames of its chain at the
            reference state (zero clipped to its limits), zero distances left out: the
            length of a typical link [m]. Arm-Z's module is 0.716 m long at any radius
            and any number of modules.
        reach_m: the sum of those distances: the chain's length [m].
        radius_m: the median of its links' radii [m].
        ratio: ``pitch_m`` over Arm-Z's, to 6 significant digits: the factor on Arm-Z's
            values (1.0 on every Arm-Z).
    """

    pitch_m: float
    reach_m: float
    radius_m: float
    ratio: float

    def scaled(self, armz_value: float) -> float:
        """A distance default: ``armz_value`` (Arm-Z's) times :attr:`ratio` [m]."""
        return float(armz_value) * self.ratio


def _pitch_and_reach(robot: Any) -> tuple[float, float]:
    q_ref = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
    F = np.asarray(robot.fk(q_ref), dtype=float)
    # in the base frame: the same numbers wherever the base stands
    T_base_world = np.linalg.inv(np.asarray(robot.T_world_base, dtype=float))
    origins = (T_base_world[None] @ F)[:, :3, 3]
    steps = np.linalg.norm(np.diff(origins, axis=0), axis=1)
    seg = np.asarray(robot.link_segments(q_ref), dtype=float)
    axes = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)
    lengths = steps if steps.sum() >= axes.sum() else axes
    lengths = lengths[lengths > 1e-9 * max(float(lengths.max(initial=0.0)), 1e-300)]
    if not len(lengths):
        return 0.0, 0.0
    # the upper median: a two-module Arm-Z's is its module, not the mean with its base
    return float(np.sort(lengths)[len(lengths) // 2]), float(np.sum(lengths))


def robot_size(robot: Any) -> RobotSize:
    """The robot's :class:`RobotSize` (see its attributes)."""
    pitch, reach = _pitch_and_reach(robot)
    if not pitch > 0:
        raise PlannerlabError(
            f"robot {getattr(robot, 'kind', '?')}: no size to derive the clearance "
            "settings from (its chain has no length at the reference state); set "
            "influence_m, clearance_floor_m, approach_m, subgoal_pos_tol_m, retract_jitter_m "
            "and hold_band_m explicitly"
        )
    radii = np.asarray(robot.link_radii_m, dtype=float)
    radius = float(np.median(radii)) if len(radii) else 0.0
    ratio = float(f"{pitch / _armz_pitch_m():.{RATIO_DIGITS}g}")
    return RobotSize(pitch, reach, radius, ratio)


def _armz_pitch_m() -> float:
    """Arm-Z's module length [m]: the reference of :attr:`RobotSize.ratio`."""
    from plannerlab.robots.armz.model import ArmZ

    return _pitch_and_reach(ArmZ(n_modules=4))[0]


def resolve_distances(settings: Any, defaults: dict[str, float], robot: Any) -> Any:
    """``settings`` (a frozen dataclass) with each field in ``defaults`` that is None set
    to its Arm-Z value scaled to ``robot`` (:func:`robot_size`); itself when none is."""
    missing = [k for k in defaults if getattr(settings, k) is None]
    if not missing:
        return settings
    size = robot_size(robot)
    return dataclasses.replace(settings, **{k: size.scaled(defaults[k]) for k in missing})


#: the distance settings of :class:`ClearanceSettings` derived from the robot: their
#: values on Arm-Z [m]
DERIVED_DISTANCES: dict[str, float] = {
    "influence_m": 0.3,
    "clearance_floor_m": 0.03,
    "hold_band_m": 0.01,
    "approach_m": 2.5,
    "subgoal_pos_tol_m": 0.5,
    "retract_jitter_m": 0.5,
}


@dataclass(frozen=True)
class ClearanceSettings:
    """Settings of the clearance descent.

    Distances marked *derived* default to None: Arm-Z's value scaled to the robot's size
    (see the module docstring; Arm-Z's value is given); a value set wins.

    Attributes:
        r1: weight of the tip position term (paper: 1) [1/m].
        r2: weight of the tip normal term (paper: 1) [1].
        clearance_weight: w, weight of the clearance term [1].
        influence_m: m, the clearance term's distance of influence: a pair of links (or a
            link and an obstacle) closer than m costs ``(m − d)² / m`` [m]; derived, 0.3 on
            Arm-Z. (Named ``margin_m`` before issue 36: not the problem's safety margin.)
        direction: the step rule: "gradient" (steepest descent) or "gauss_newton" (damped
            Gauss-Newton on the residuals; see the module docstring).
        damping: Gauss-Newton damping λ [tolerance units].
        max_step_rad: largest joint change per step [rad]; 0: half the problem's
            joint_step (the executor commands every waypoint for the same time, so this
            halves the arm's speed: measured on armz_inspection, tracking error <= 0.03
            rad instead of up to 0.53 rad with steps of a whole joint_step).
        min_step_rad: the trust radius below which the descent has stalled [rad].
        stall_window: iterations without improvement of the best f that make a stall [1].
        stall_min_decrease: improvement of the best f that resets the stall window
            [f's units: m for a tip goal, rad for a goal state].
        goal_depth: the descent aims at this fraction of the goal tolerances (of
            ``tol_rad`` for a goal state) [1].
        deepen_iterations: iterations the descent goes on inside the goal region towards
            ``goal_depth`` while it makes progress [1].
        clearance_floor_m: the clearance the descent keeps: a step that takes a pair below
            it (and closer than it was) is refused [m]; derived, 0.03 on Arm-Z. (Named
            ``min_clearance_m`` before issue 36: a record's ``min_clearance_m`` is the
            smallest clearance measured along a path.)
        hold_band_m: pairs within this of ``clearance_floor_m`` are held by
            ``hold_clearance`` (they may not come closer) [m]; derived, 0.01 on Arm-Z.
        settle_iterations: in the goal region, iterations of the clearance term alone,
            so the arm does not end close to a wall when the region leaves room [1].
        settle_fraction: the settling stays within this fraction of the tolerances [1].
        escape: what to do at a stall: "none", "detour", "random_detour" or
            "rrtconnect" (see the module docstring).
        max_escapes: stalls escaped at most (``random_detour``: also the most draws from
            one stall) [1].
        escape_checks: collision checks the ``rrtconnect`` escape may use at most [1].
        route_escape: the detours' last resort, when the body's own retracts lead
            nowhere: the tip's route through free workspace from the stall into the goal
            (follow-the-leader's leader path), followed as follow-the-leader does (a
            sub-solve in the leg's context; only when the registry hands the planner
            one, as it does ``gradient.clearance+detour`` and ``+random_detour``).
        approach_m: the tip first descends to the goal's approach point, this far back
            along the goal's normal, then in along it (0: no approach point; a goal state
            has none) [m]; derived, 2.5 on Arm-Z.
        retract_step: modules between the detour's retract sub-goals (``random_detour``:
            its mean step is ``retract_step + 0.5``) [links].
        subgoal_pos_tol_m: position tolerance of the sub-goals (the approach point, the
            retracts) [m]; derived, 0.5 on Arm-Z.
        subgoal_angle_tol_deg: angle tolerance of the sub-goals [deg].
        retract_jitter_m: radius of the ball round the body's face in which
            ``random_detour`` draws each retract sub-goal's point [m]; derived, 0.5 on
            Arm-Z.
        escape_goal_samples: goal states the ``rrtconnect`` escape draws by IK (seeded
            from the stall) when the descent near the stall finds no collision-free goal
            [1].
        hold_clearance: when a step would take a pair below ``clearance_floor_m``, try
            once the same step with the part that closes such pairs taken out before
            shrinking the step; without
            it the descent stalls against the clearance floor (measured on room
            variants: the leave leg stalled at iteration 7 and no retract got out).
        backend: "compiled" (the field and the step compiled with numba; Arm-Z only,
            other robots use numpy) or "numpy" (the reference: the same iterates to
            rounding, 30-50 times slower; ``bench/descent_bench.py``).
    """

    r1: float = 1.0
    r2: float = 1.0
    clearance_weight: float = 0.2
    influence_m: float = DERIVED
    direction: str = "gauss_newton"
    damping: float = 0.1
    max_step_rad: float = 0.0
    min_step_rad: float = 1e-4
    stall_window: int = 60
    stall_min_decrease: float = 1e-3
    goal_depth: float = 0.3
    deepen_iterations: int = 100
    clearance_floor_m: float = DERIVED
    hold_band_m: float = DERIVED
    settle_iterations: int = 100
    settle_fraction: float = 0.7
    escape: str = "none"
    max_escapes: int = 3
    escape_checks: int = 50000
    route_escape: bool = True
    approach_m: float = DERIVED
    retract_step: int = 2
    subgoal_pos_tol_m: float = DERIVED
    subgoal_angle_tol_deg: float = 30.0
    retract_jitter_m: float = DERIVED
    escape_goal_samples: int = 4
    hold_clearance: bool = True
    backend: str = "compiled"

    #: settings renamed (old key -> new): ``--set`` and overrides still take the old key
    #: for one release, with a warning naming the new one (``with_overrides``)
    RENAMED_KEYS: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"margin_m": "influence_m", "min_clearance_m": "clearance_floor_m"}
    )

    def __post_init__(self) -> None:
        if self.direction not in ("gradient", "gauss_newton"):
            raise PlannerlabError(
                f"direction setting: 'gradient' or 'gauss_newton', got {self.direction!r}"
            )
        for key in ("influence_m", "subgoal_pos_tol_m"):
            value = getattr(self, key)
            if value is not None and not value > 0:
                raise PlannerlabError(f"{key} must be > 0, got {value}")
        for key in ("clearance_floor_m", "hold_band_m", "approach_m", "retract_jitter_m"):
            value = getattr(self, key)
            if value is not None and not value >= 0:
                raise PlannerlabError(f"{key} must be >= 0, got {value}")
        if self.backend not in BACKENDS:
            raise PlannerlabError(
                f"backend setting: one of {', '.join(map(repr, BACKENDS))}, got {self.backend!r}"
            )
        if self.escape not in ESCAPES:
            raise PlannerlabError(
                f"escape setting: one of {', '.join(map(repr, ESCAPES))}, got {self.escape!r}"
            )
        if self.escape_goal_samples < 1:
            raise PlannerlabError(
                f"escape_goal_samples must be >= 1, got {self.escape_goal_samples}"
            )
        if self.retract_step < 1:
            raise PlannerlabError(f"retract_step must be >= 1, got {self.retract_step}")
        if self.stall_window < 2:
            raise PlannerlabError(f"stall_window must be >= 2, got {self.stall_window}")

    @property
    def resolved(self) -> bool:
        """Whether every derived distance has a value."""
        return all(getattr(self, k) is not None for k in DERIVED_DISTANCES)

    def for_robot(self, robot: Any) -> ClearanceSettings:
        """These settings with every derived distance that is None set for ``robot``
        (see the module docstring); the values set are kept."""
        out: ClearanceSettings = resolve_distances(self, DERIVED_DISTANCES, robot)
        return out


__all__ = [
    "BACKENDS",
    "DERIVED",
    "DERIVED_DISTANCES",
    "ESCAPES",
    "ClearanceSettings",
    "RobotSize",
    "resolve_distances",
    "robot_size",
]

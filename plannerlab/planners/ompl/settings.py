"""The OMPL planners' settings, one dataclass per family (overridden by name, see
:func:`plannerlab.planners.base.with_overrides`), the OMPL setter of each, and the
adapter's constants. No ``ompl`` import: the settings are read without the engine."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

#: how the goal pool is filled (``goal_selection`` setting)
GOAL_SELECTIONS = ("ik", "near", "near_or_ik")


# ---------------------------------------------------------------------------- settings
@dataclass(frozen=True)
class OMPLSettings:
    """Settings every OMPL planner shares.

    Attributes:
        simplify: run OMPL's PathSimplifier on the solution (within the remaining budget).
        interpolate: densify the returned path so no joint moves more than
            ``problem.joint_step`` between consecutive states.
        goal_samples: size of the IK goal-state pool handed out by ``sampleGoal``.
        max_goal_attempts: IK descents at most to fill the pool.
        motion_check: ``"batched"`` (plannerlab edge check, Linf steps of joint_step) or
            ``"ompl"`` (OMPL's discrete motion validator).
        goal_selection: ``"ik"`` (numeric IK restarts seeded from the leg start,
            the same sampling every planner's goal pool uses) or ``"near"`` (the goal state
            ``gradient.clearance`` selects, with the caller's settings when OMPL is its
            escape: its descent from the leg start with the path unchecked, so the goal
            stays near the start; one state, one check) or
            ``"near_or_ik"`` (that near state; when its descent ends in no collision-free
            goal state, ``goal_samples`` IK states as with ``"ik"``: the escape of
            ``gradient.clearance+rrtconnect``, which gave up with ``invalid_goal`` before).
    """

    simplify: bool = True
    interpolate: bool = True
    goal_samples: int = 4
    max_goal_attempts: int = 200
    motion_check: str = "batched"
    goal_selection: str = "ik"


@dataclass(frozen=True)
class RangeSettings(OMPLSettings):
    """Planners with a step size. ``range``: longest motion added at once, in the state
    space's metric [rad, summed over joints]; 0 = OMPL's default (20 % of the extent)."""

    range: float = 0.0


@dataclass(frozen=True)
class GoalBiasSettings(RangeSettings):
    """Planners with a goal bias: probability of sampling a goal state instead of a
    random one."""

    goal_bias: float = 0.05


@dataclass(frozen=True)
class RRTstarSettings(GoalBiasSettings):
    """RRT* family. ``rewire_factor`` scales the rewiring radius / k."""

    rewire_factor: float = 1.1


@dataclass(frozen=True)
class SORRTstarSettings(RRTstarSettings):
    """SORRT*: ``batch_size`` ordered informed samples per batch. Each sample's ordering
    evaluates the goal heuristic (Python ``distanceGoal``) many times: measured ~1e6 calls
    and ~30 s on a 5-joint toy problem with batch_size 10, and no termination with OMPL's
    default 100 (the sampler does not poll the termination condition)."""

    batch_size: int = 10


@dataclass(frozen=True)
class KPIECESettings(GoalBiasSettings):
    """KPIECE1. ``projection_cell_m``: cell edge of the tip-position projection [m]
    (None: reach / 20)."""

    border_fraction: float = 0.9
    failed_expansion_score_factor: float = 0.5
    min_valid_path_fraction: float = 0.2
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class BKPIECESettings(RangeSettings):
    """BKPIECE1 (bidirectional KPIECE)."""

    border_fraction: float = 0.9
    failed_expansion_score_factor: float = 0.5
    min_valid_path_fraction: float = 0.5
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class LBKPIECESettings(RangeSettings):
    """LBKPIECE1 (lazy bidirectional KPIECE)."""

    border_fraction: float = 0.9
    min_valid_path_fraction: float = 0.5
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class PRMSettings(OMPLSettings):
    """PRM. ``max_nearest_neighbors``: k of the k-nearest connection strategy (also used
    to connect the start and the goal pool); ``roadmap_slice_polls``: termination polls
    per roadmap-growing slice between solution searches."""

    max_nearest_neighbors: int = 10
    roadmap_slice_polls: int = 50


@dataclass(frozen=True)
class PRMstarSettings(OMPLSettings):
    """PRM* (k chosen by OMPL). See :class:`PRMSettings`."""

    roadmap_slice_polls: int = 50


@dataclass(frozen=True)
class BITstarSettings(OMPLSettings):
    """BIT*."""

    samples_per_batch: int = 100
    rewire_factor: float = 1.1
    use_k_nearest: bool = True


@dataclass(frozen=True)
class FMTSettings(OMPLSettings):
    """FMT* / BFMT*: ``num_samples`` states are sampled up front."""

    num_samples: int = 1000
    radius_multiplier: float = 1.1
    nearest_k: bool = True


#: OMPL class -> settings dataclass
SETTINGS_BY_CLASS: Mapping[str, type[OMPLSettings]] = {
    "RRTConnect": RangeSettings,
    "RRT": GoalBiasSettings,
    "RRTstar": RRTstarSettings,
    "InformedRRTstar": RRTstarSettings,
    "SORRTstar": SORRTstarSettings,
    "KPIECE1": KPIECESettings,
    "BKPIECE1": BKPIECESettings,
    "LBKPIECE1": LBKPIECESettings,
    "PRM": PRMSettings,
    "PRMstar": PRMstarSettings,
    "BITstar": BITstarSettings,
    "FMT": FMTSettings,
    "BFMT": FMTSettings,
    "AORRTC": RangeSettings,
}

#: settings field -> OMPL setter (called when the planner has it)
SETTERS: Mapping[str, str] = {
    "range": "setRange",
    "goal_bias": "setGoalBias",
    "rewire_factor": "setRewireFactor",
    "batch_size": "setBatchSize",
    "border_fraction": "setBorderFraction",
    "failed_expansion_score_factor": "setFailedExpansionCellScoreFactor",
    "min_valid_path_fraction": "setMinValidPathFraction",
    "max_nearest_neighbors": "setMaxNearestNeighbors",
    "samples_per_batch": "setSamplesPerBatch",
    "use_k_nearest": "setUseKNearest",
    "num_samples": "setNumSamples",
    "radius_multiplier": "setRadiusMultiplier",
    "nearest_k": "setNearestK",
}

KPIECE = frozenset({"KPIECE1", "BKPIECE1", "LBKPIECE1"})
ROADMAP = frozenset({"PRM", "PRMstar"})
#: optimizing planners that are made to return on their first path, which is then held and
#: the search resumed (BIT*: reading its tree through ``getPlannerData`` leaks its space
#: information in the wheel, and once it has a path, ``stopOnSolnImprovement`` makes every
#: later solve return at once); later improvements are not held: if the final path's
#: re-check does not fit, the first one is re-checked
STOP_ON_FIRST = frozenset({"BITstar"})
#: planners whose informed samplers need a RealVector space (see ``Space``)
#: how often (termination polls) a better path is looked for to hold (its re-check's
#: checks reserved) while an optimizing planner improves it
RESERVE_EVERY_POLLS = 8
#: the *time* reserve is this many times the held path's re-check at the solve's rate:
#: planners poll their termination condition between steps, so they stop a little late
#: (the check reserve needs no factor: the guard refuses to spend it)
RESERVE_FACTOR = 1.25
#: the steps after planning (the fine re-check) may run this fraction past the time limit
TIME_SLACK = 0.01
#: planners whose expansion runs long stretches of C++ without polling the termination
#: condition (FMT*'s and BFMT*'s first expansion computes every sample's neighbourhood):
#: past the time limit a validity callback raises, and the exception unwinds their solve
HARD_STOP = frozenset({"FMT", "BFMT"})
#: states converted / re-checked between two looks at the clock
CHUNK_STATES = 2048
LIFTED = frozenset({"InformedRRTstar", "SORRTstar", "BITstar", "AORRTC"})
MOTION_CHECKS = ("batched", "ompl")
#: OMPL's GoalRegion is satisfied when distanceGoal < threshold (strict)
GOAL_THRESHOLD = 1e-9
#: most states of a path handed to OMPL's PathSimplifier.simplify (its collapseCloseVertices
#: takes time cubic in them, with no termination condition polled)
SIMPLIFY_MAX_STATES = 400


__all__ = [
    "GOAL_SELECTIONS",
    "SETTINGS_BY_CLASS",
    "SETTERS",
    "OMPLSettings",
]

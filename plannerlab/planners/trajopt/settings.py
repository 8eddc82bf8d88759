"""Settings of the trajectory optimisers (``trajopt.*``), frozen, checked when made;
overridden by name (:func:`~plannerlab.planners.base.with_overrides`). No numba here."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from plannerlab.errors import PlannerlabError
from plannerlab.planners.clearance.settings import DERIVED, resolve_distances
from plannerlab.planners.native.settings import GOAL_SELECTIONS
from plannerlab.planners.trajopt.solvers import SOLVERS, PenaltySettings

#: the seeds a ``seeds`` setting names
SEEDS = ("line", "gradient", "rrtconnect", "leader")

#: the distance settings derived from the robot (:func:`~plannerlab.planners.clearance.
#: settings.resolve_distances`): their values on Arm-Z [m], scaled by the robot's link
#: length over Arm-Z's (the Panda's: 0.44 of them)
DERIVED_DISTANCES: dict[str, float] = {"buffer_m": 0.04, "waypoint_m": 2.0}


@dataclass(frozen=True)
class TrajOptSettings:
    """Settings of a ``trajopt.*`` planner (see :mod:`plannerlab.planners.trajopt`).

    Attributes:
        seeds: the seed paths tried in order, comma-separated, each with its restarts:
            ``line`` (the straight joint-space line to each goal state), ``gradient`` (the
            paper's gradient descent, ``gradient.analytic``, then the line from where it
            stops), ``rrtconnect`` (``native.rrtconnect``'s path), ``leader``
            (``native.rrtconnect+leader``'s path).
        restarts: per seed, optimisations from the seed bent by a random smooth bump
            (drawn from the trial's generator) after the first fails.
        restart_sigma_rad: the bump's size: per joint normal with this deviation [rad]
            at the middle of the path, a sine arch to its ends.
        solver: ``gauss_newton``, ``lbfgs`` or ``auglag`` (see :mod:`.solvers`).
        waypoint_m: the seed is resampled at waypoints this far apart, measured as the
            checker measures motion (``Σ |Δq_i| · reach_i``: how far any point of the
            robot can move) [m]; None: derived from the robot (Arm-Z: 2 m).
        coarse_factor: the first pass's waypoints are ``coarse_factor · waypoint_m`` of
            motion apart (K at least ``min_waypoints``): the path is optimised on those,
            and waypoints are added only where the re-check refuses an edge (each refused
            edge split with its neighbours, then re-optimised; ``max_refines`` rounds).
            1: the first pass at ``waypoint_m``. Measured on MotionBenchMaker's Panda
            (results/trajopt.md): the optimiser's time falls with K (every evaluation
            costs the sphere field at ~2 K states) and the coarse path rarely needs a
            refinement (the hinge holds it δ off everything).
        min_waypoints, max_waypoints: K at least / at most.
        substeps: states evaluated inside every edge.
        buffer_m: δ, how far beyond the checker's margin the hinge starts [m]; None:
            derived from the robot (Arm-Z: 4 cm, the Panda 1.8 cm).
        smooth_weight: w_s, the weight of the squared accelerations.
        goal_weight: w_g, the weight of a tip goal region's residuals beside the
            collision hinge's (both grow with the penalty weight).
        goal_depth: ρ, how deep in the region (fraction of each tolerance) the last
            waypoint's tip is drawn.
        penalty_start: μ, the penalty weight of the first inner solve.
        penalty_growth: the factor μ grows by after an inner solve that left the path
            infeasible.
        max_penalty: the largest μ tried before the seed is given up.
        feasible_fraction: a path is feasible when every evaluated state is at least the
            margin plus this fraction of the buffer δ from everything (and the goal is
            reached).
        rel_tol: an inner solve has converged when the merit fell by less than this
            fraction in a step.
        feasible_rel_tol: the early stop (``gauss_newton``): once the path is feasible
            (every evaluated state at least margin + ``feasible_fraction`` · δ clear, the
            goal reached), an inner solve also ends when the merit fell by less than this
            fraction in a step; the penalty loop then ends. 0: ``rel_tol`` only. The
            smoothing goes on only while it still pays: on MotionBenchMaker's Panda the
            optimised path's roughness is two orders below the seed's either way
            (results/trajopt.md).
        max_inner: the most steps of one inner solve.
        max_refines: re-optimisations after the re-check refuses an edge (its
            neighbourhood split into shorter edges each time).
        seed_share: the share of the collision checks and time the leg has left that a
            seed planner (``rrtconnect``, ``leader``, ``gradient``) may use. 1: all of it
            (it returns when it has a path; a path found late is returned un-optimised,
            one not found ends the leg as the seed planner's budget ends it). Measured:
            at 0.8, 3 of 13 ``armz_deep_a`` legs under load 19 failed with the leader
            still searching at 24 of its 30 s.
        goal_samples, max_goal_attempts, goal_selection: the goal pool of a tip goal
            region (as ``native.*``'s: :mod:`plannerlab.planners.goal_pool`).
    """

    seeds: str = "line"
    restarts: int = 2
    restart_sigma_rad: float = 0.5
    solver: str = "gauss_newton"
    waypoint_m: float = DERIVED
    coarse_factor: float = 4.0
    min_waypoints: int = 12
    max_waypoints: int = 200
    substeps: int = 1
    buffer_m: float = DERIVED
    smooth_weight: float = 1.0
    goal_weight: float = 10.0
    goal_depth: float = 0.5
    penalty_start: float = 10.0
    penalty_growth: float = 10.0
    max_penalty: float = 1e6
    feasible_fraction: float = 0.5
    rel_tol: float = 1e-2
    feasible_rel_tol: float = 0.3
    max_inner: int = 60
    max_refines: int = 4
    seed_share: float = 1.0
    goal_samples: int = 4
    max_goal_attempts: int = 200
    goal_selection: str = "ik"

    @property
    def seed_list(self) -> tuple[str, ...]:
        return tuple(s.strip() for s in self.seeds.split(",") if s.strip())

    @property
    def penalty(self) -> PenaltySettings:
        """The penalty loop's settings."""
        return PenaltySettings(
            solver=self.solver,
            penalty_start=self.penalty_start,
            penalty_growth=self.penalty_growth,
            max_penalty=self.max_penalty,
            feasible_fraction=self.feasible_fraction,
            rel_tol=self.rel_tol,
            feasible_rel_tol=self.feasible_rel_tol,
            max_inner=self.max_inner,
        )

    @property
    def resolved(self) -> bool:
        """No distance is left to derive."""
        return all(getattr(self, k) is not None for k in DERIVED_DISTANCES)

    def for_robot(self, robot: object) -> TrajOptSettings:
        """These settings with every derived distance that is None set for ``robot``."""
        out: TrajOptSettings = resolve_distances(self, DERIVED_DISTANCES, robot)
        return out

    def check(self, name: str) -> None:
        """Raise a :class:`PlannerlabError` naming the first setting out of its range."""
        bad = [s for s in self.seed_list if s not in SEEDS]
        if not self.seed_list or bad:
            raise PlannerlabError(
                f"{name}: seeds must name one or more of {', '.join(SEEDS)} "
                f"(comma-separated), got {self.seeds!r}"
            )
        if self.solver not in SOLVERS:
            raise PlannerlabError(
                f"{name}: solver must be one of {', '.join(SOLVERS)}, got {self.solver!r}"
            )
        if self.goal_selection not in GOAL_SELECTIONS:
            raise PlannerlabError(
                f"{name}: goal_selection must be one of {', '.join(GOAL_SELECTIONS)}, "
                f"got {self.goal_selection!r}"
            )
        positive = (
            "restart_sigma_rad",
            "smooth_weight",
            "goal_weight",
            "penalty_start",
            "max_penalty",
            "rel_tol",
        )
        for key in positive:
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise PlannerlabError(f"{name}: {key} must be a finite number > 0, got {v!r}")
        for key in DERIVED_DISTANCES:
            v = getattr(self, key)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise PlannerlabError(f"{name}: {key} must be a finite number > 0, got {v!r}")
        if not (math.isfinite(self.coarse_factor) and self.coarse_factor >= 1):
            raise PlannerlabError(
                f"{name}: coarse_factor must be a finite number >= 1, got {self.coarse_factor!r}"
            )
        if not (self.penalty_growth > 1 and math.isfinite(self.penalty_growth)):
            raise PlannerlabError(f"{name}: penalty_growth must be > 1, got {self.penalty_growth}")
        if not (math.isfinite(self.feasible_rel_tol) and 0 <= self.feasible_rel_tol < 1):
            raise PlannerlabError(
                f"{name}: feasible_rel_tol must be in [0, 1), got {self.feasible_rel_tol!r}"
            )
        for key in ("goal_depth", "feasible_fraction", "seed_share"):
            v = getattr(self, key)
            if not 0 < v <= 1:
                raise PlannerlabError(f"{name}: {key} must be in (0, 1], got {v!r}")
        ints = {
            "restarts": 0,
            "min_waypoints": 3,
            "substeps": 0,
            "max_inner": 1,
            "max_refines": 0,
            "goal_samples": 1,
            "max_goal_attempts": 1,
        }
        for key, least in ints.items():
            if getattr(self, key) < least:
                raise PlannerlabError(f"{name}: {key} must be >= {least}, got {getattr(self, key)}")
        if self.max_waypoints < self.min_waypoints:
            raise PlannerlabError(
                f"{name}: max_waypoints ({self.max_waypoints}) must be >= min_waypoints "
                f"({self.min_waypoints})"
            )


def replace(settings: TrajOptSettings, **changes: object) -> TrajOptSettings:
    """A copy of ``settings`` with some fields changed."""
    return dataclasses.replace(settings, **changes)  # type: ignore[arg-type]

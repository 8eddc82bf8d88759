"""Settings of the clearance descent (``gradient.clearance*``; follow-the-leader's
descents take them as ``descent.<key>``), checked when made."""

from __future__ import annotations

from dataclasses import dataclass

from plannerlab.errors import PlannerlabError

#: the escapes from a stall (``escape`` setting)
ESCAPES = ("none", "detour", "random_detour", "rrtconnect")
#: how the field and the step are computed (``backend`` setting)
BACKENDS = ("compiled", "numpy")


@dataclass(frozen=True)
class ClearanceSettings:
    """Settings of the clearance descent.

    Attributes:
        r1, r2: weights of the tip position and normal terms (paper: 1, 1).
        clearance_weight: w, weight of the clearance term.
        margin_m: m, distance below which a pair costs [m].
        direction: "gradient" or "gauss_newton" (see the module docstring).
        damping: Gauss-Newton damping λ (in tolerance units).
        max_step_rad: largest joint change per step [rad]; 0 = half the problem's joint_step
            (the executor commands every waypoint for the same time, so this halves the
            arm's speed: measured on armz_inspection, tracking error <= 0.03 rad instead
            of up to 0.53 rad with steps of a whole joint_step).
        min_step_rad: trust radius below which the descent has stalled [rad].
        stall_window: iterations without improvement of the best f that make a stall.
        stall_min_decrease: improvement of the best f that resets the stall window.
        goal_depth: aim at this fraction of the goal tolerances (Gauss-Newton residuals;
            of ``tol_rad`` for a goal state).
        escape: what to do at a stall: "none", "detour", "random_detour" or "rrtconnect"
            (see the module docstring); ``max_escapes`` stalls are escaped at most (for
            ``random_detour`` also the most draws from one stall).
        retract_step: modules between the detour's retract sub-goals (``random_detour``:
            its mean step is ``retract_step + 0.5``).
        retract_jitter_m: radius of the ball round the body's face in which
            ``random_detour`` draws each retract sub-goal's point [m].
        escape_goal_samples: goal states the ``rrtconnect`` escape draws by IK (seeded
            from the stall) when the descent near the stall finds no collision-free goal.
        hold_clearance: when a step would take a pair below ``min_clearance_m``, try
            once the same step with the part that closes such pairs taken out
            (:meth:`ClearanceDescent._hold_clearance`) before shrinking the step; without
            it the descent stalls against the clearance floor (measured on room
            variants: the leave leg stalled at iteration 7 and no retract got out).
        backend: "compiled" (the field and the step in numba,
            :mod:`plannerlab.planners._descent_core`; Arm-Z only, other robots use numpy)
            or "numpy" (the reference: the same iterates to rounding, 30-50 times slower;
            `bench/descent_bench.py`).
    """

    r1: float = 1.0
    r2: float = 1.0
    clearance_weight: float = 0.2
    margin_m: float = 0.3
    direction: str = "gauss_newton"
    damping: float = 0.1
    max_step_rad: float = 0.0
    min_step_rad: float = 1e-4
    stall_window: int = 60
    stall_min_decrease: float = 1e-3
    goal_depth: float = 0.3
    deepen_iterations: int = 100
    min_clearance_m: float = 0.03
    settle_iterations: int = 100
    settle_fraction: float = 0.7
    escape: str = "none"
    max_escapes: int = 3
    escape_checks: int = 50000
    approach_m: float = 2.5
    retract_step: int = 2
    subgoal_pos_tol_m: float = 0.5
    subgoal_angle_tol_deg: float = 30.0
    retract_jitter_m: float = 0.5
    escape_goal_samples: int = 4
    hold_clearance: bool = True
    backend: str = "compiled"

    def __post_init__(self) -> None:
        if self.direction not in ("gradient", "gauss_newton"):
            raise PlannerlabError(
                f"direction setting: 'gradient' or 'gauss_newton', got {self.direction!r}"
            )
        if not self.margin_m > 0:
            raise PlannerlabError(f"margin_m must be > 0, got {self.margin_m}")
        if self.backend not in BACKENDS:
            raise PlannerlabError(
                f"backend setting: one of {', '.join(map(repr, BACKENDS))}, got {self.backend!r}"
            )
        if self.escape not in ESCAPES:
            raise PlannerlabError(
                f"escape setting: one of {', '.join(map(repr, ESCAPES))}, got {self.escape!r}"
            )
        if not self.retract_jitter_m >= 0:
            raise PlannerlabError(f"retract_jitter_m must be >= 0, got {self.retract_jitter_m}")
        if self.escape_goal_samples < 1:
            raise PlannerlabError(
                f"escape_goal_samples must be >= 1, got {self.escape_goal_samples}"
            )
        if self.retract_step < 1:
            raise PlannerlabError(f"retract_step must be >= 1, got {self.retract_step}")
        if self.stall_window < 2:
            raise PlannerlabError(f"stall_window must be >= 2, got {self.stall_window}")


__all__ = ["BACKENDS", "ESCAPES", "ClearanceSettings"]

"""The Arm-Z paper's gradient method (``000_a8ed938e94518caf.txt``, §3.1).

    S ← S_0
    while f(S) ≥ ε:
        S_{t+1} ← S_t − γ ∇f(S_t)
        posctrltowards(S_{t+1})        # 100 PyBullet steps of 1/240 s

with γ = 0.05, ε = 0.5, r1 = r2 = 1 and ∇f by finite differences
(``scipy.optimize.approx_fprime``). Three registered variants:

``gradient`` (kinematic, faithful objective and gradient)
    The next state is S − γ∇f. Without a simulator nothing stops the arm from stepping
    into an obstacle, and A(S) is invisible to a finite-difference gradient (every
    perturbed state collides too, so the penalty cancels). The kinematic mode therefore
    does what the simulator's contacts do: the arm moves along the straight joint-space
    segment towards S − γ∇f and stops at the last collision-free state (checked every
    ``problem.joint_step``). Blocked steps make f flat, which the stall detector sees.
``gradient.closed_loop`` (faithful, the paper's loop)
    ``posctrltowards`` is a :class:`~plannerlab.planners.base.Stepper` (PyBullet through
    :mod:`plannerlab.sim`): 100 steps of position control towards S − γ∇f, and the next
    iteration starts from the state the simulator actually reached.
``gradient.analytic`` (faster)
    As ``gradient`` but ∇f from the analytic tip Jacobians: one kinematics call instead of
    dof + 1 objective evaluations (each with a collision check) per iteration. Away from
    obstacle boundaries it is the gradient approx_fprime estimates.

Stopping: the common goal region of the problem (position and angle tolerances) decides
success for every planner, so results compare. With ``stop_at_epsilon = True`` the loop
also stops as in the paper when f < ε (status ``approximate`` if that is outside the
region). A **stall** is declared when the best f has not improved by more than
``stall_min_decrease`` over ``stall_window`` iterations while f ≥ ε: status
``local_minimum`` with the state and iteration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import approx_fprime

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    PlanResult,
    Progress,
    Status,
    with_overrides,
)
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.objective import Objective
from plannerlab.robots.base import Array, wrap_to_pi
from plannerlab.robots.paths import interpolate_edge


@dataclass(frozen=True)
class GradientSettings:
    """Settings of the gradient method (defaults: the paper's).

    Attributes:
        gamma: step factor γ (paper: 0.05).
        epsilon: the paper's goal threshold ε on f (0.5); also the level above which a
            flat f counts as a stall.
        r1, r2: weights of position and normal terms (1, 1).
        penalty: A(S) for a colliding S (1e5).
        gradient: "finite_difference" (approx_fprime) or "analytic".
        fd_step: approx_fprime's epsilon [rad] (scipy's default, sqrt of machine epsilon).
        mode: "kinematic" or "closed_loop" (needs a stepper).
        sim_steps: simulator steps per iteration in closed loop (100 of 1/240 s).
        stall_window: iterations without improvement that make a stall.
        stall_min_decrease: improvement of the best f that resets the stall window.
        stop_at_epsilon: also stop when f < ε, as the paper's loop does.
        max_step_rad: 0 = no limit (faithful); else each joint's step is clipped to it.
    """

    gamma: float = 0.05
    epsilon: float = 0.5
    r1: float = 1.0
    r2: float = 1.0
    penalty: float = 1e5
    gradient: str = "finite_difference"
    fd_step: float = float(np.sqrt(np.finfo(float).eps))
    mode: str = "kinematic"
    sim_steps: int = 100
    stall_window: int = 60
    stall_min_decrease: float = 1e-3
    stop_at_epsilon: bool = False
    max_step_rad: float = 0.0

    def __post_init__(self) -> None:
        if self.gradient not in ("finite_difference", "analytic"):
            raise PlannerlabError(
                f"gradient setting: 'finite_difference' or 'analytic', got {self.gradient!r}"
            )
        if self.mode not in ("kinematic", "closed_loop"):
            raise PlannerlabError(f"mode setting: 'kinematic' or 'closed_loop', got {self.mode!r}")
        if not self.gamma > 0:
            raise PlannerlabError(f"gamma must be > 0, got {self.gamma}")
        if self.stall_window < 2:
            raise PlannerlabError(f"stall_window must be >= 2, got {self.stall_window}")


VARIANTS: dict[str, dict[str, object]] = {
    "gradient": {},
    "gradient.closed_loop": {"mode": "closed_loop"},
    "gradient.analytic": {"gradient": "analytic"},
}


class GradientPlanner(LegPlanner):
    """The gradient method as a plannerlab planner (see the module docstring)."""

    def __init__(self, name: str, settings: GradientSettings) -> None:
        self.name = name
        self.settings = settings

    # ------------------------------------------------------------------ pieces
    def objective(self, problem, leg: int, checker: CollisionChecker | None) -> Objective:
        """The objective f for one leg (build, then solve)."""
        s = self.settings
        return Objective(problem.robot, problem.goal(leg), checker, s.r1, s.r2, s.penalty)

    def gradient(self, f: Objective, q: Array) -> Array:
        if self.settings.gradient == "analytic":
            return f.smooth_gradient(q)
        return approx_fprime(q, f, self.settings.fd_step)

    def _advance_kinematic(
        self, problem, checker: CollisionChecker, q: Array, q_target: Array, max_states: int | None
    ) -> tuple[Array, bool]:
        """Move along q → q_target up to the last collision-free state (blocked by contact).

        The step is cut into states ``joint_step`` apart; the move goes through them up to
        the last one before the first invalid state. With a margin, the checker checks
        edges in metres (certified edges on the re-check's grid: no point of the robot
        moves further than the margin between two checked states): then the stretch kept
        is confirmed
        as one such edge, and, if it is not clear, cut back to the states whose edges from
        their predecessor are (a joint-space grid alone misses an obstacle a long arm's
        tip sweeps through between two states: the paper's 0.02 rad grid moves the
        Arm-Z's tip up to 0.3 m). At most ``max_states`` states are checked (the rest of
        the check budget); an edge longer than that ends where checking had to stop, as
        if blocked.
        """
        states = interpolate_edge(q, q_target, problem.joint_step, problem.robot.continuous)[1:]
        cut = max_states is not None and len(states) > max_states
        if cut:
            states = states[:max_states]
        c0 = checker.checks
        bad = checker.first_invalid(states)
        end = len(states) if bad is None else bad  # states[:end] are valid
        if end and checker.edge_check == "certified":
            left = None if max_states is None else max(max_states - (checker.checks - c0), 0)
            end = self._clear_prefix(checker, q, states[:end], problem.joint_step, left)
        blocked = cut or bad is not None or end < len(states)
        return (states[end - 1] if end > 0 else q), blocked

    @staticmethod
    def _clear_prefix(
        checker: CollisionChecker, q: Array, states: Array, joint_step: float, left: int | None
    ) -> int:
        """How many of ``states`` (valid, in order from q) are reached by edges clear in
        metres: the whole stretch in one check, else edge by edge up to the first that is
        not, within ``left`` checks (None: no limit; an edge the limit cut short is not
        clear)."""
        c0 = checker.checks

        def clear(a: Array, b: Array) -> bool:
            limit = None if left is None else max(left - (checker.checks - c0), 0)
            n, bad = checker.check_edge(a, b, joint_step, limit)
            return bad is None and (limit is None or n <= limit)

        if clear(q, states[-1]):
            return len(states)
        prev = q
        for k, qk in enumerate(states):
            if not clear(prev, qk):
                return k
            prev = qk
        return len(states)

    # ------------------------------------------------------------------ solve
    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Descend f from the context's start towards its leg's goal.

        ``rng`` is unused: the method is deterministic (kept for the common signature).
        """
        del rng
        s = self.settings
        problem, robot, goal = ctx.problem, ctx.robot, ctx.goal
        checker, tracker, stepper = ctx.checker, ctx.tracker, ctx.stepper
        budget = tracker.budget
        run = ctx.run(self.name, s)
        q = ctx.q_start.copy()
        f = self.objective(problem, ctx.leg, checker)
        closed = s.mode == "closed_loop"
        if closed:
            if stepper is None:
                raise PlannerlabError(
                    f"{self.name} runs PyBullet in its loop: pass a stepper (plannerlab.sim)"
                )
            stepper.reset(q)

        clock: list[float] = []  # per state of the path: when it was reached [s]
        checks: list[int] = []  # … and the collision checks used by then

        def progress_rows(status: Status, path: list[Array]) -> Array:
            """The progress from the descent's states (bookkeeping: these FK calls are not
            counted), made once at the end."""
            dists = goal.distance(robot, np.array(path))
            return Progress.of_series(clock, checks, dists, run.cost(status, np.array(path)))

        if ctx.start_problem is not None:
            return run.result(Status.INVALID_START, ctx.start_problem, [q], fk_calls=f.evaluations)

        path = [q.copy()]
        value = f(q)
        trace = [value]
        clock.append(tracker.elapsed_s)
        checks.append(tracker.checks_used)
        best, best_iter = value, 0
        blocked_steps = 0
        iteration = 0
        while True:
            status, reason, extra = None, "", {}
            if goal.contains(robot, q):
                status = Status.SOLVED
                reason = f"in the goal region after {iteration} iterations"
            elif s.stop_at_epsilon and value < s.epsilon:
                status = Status.APPROXIMATE
                reason = f"f = {value:.3g} < epsilon = {s.epsilon} but outside the goal region"
            elif value >= s.epsilon and iteration - best_iter >= s.stall_window:
                status = Status.LOCAL_MINIMUM
                reason = (
                    f"stalled at iteration {iteration}: best f = {best:.4g} has not improved "
                    f"by {s.stall_min_decrease} in {s.stall_window} iterations "
                    f"({blocked_steps} steps blocked by contact)"
                )
                extra = {
                    "stall_iteration": iteration,
                    "q_stall": q.tolist(),
                    "blocked_steps": blocked_steps,
                }
            else:
                exhausted = tracker.exhausted(iteration)
                # An iteration costs the gradient's checks (dof + 1 with finite
                # differences), at least one state of the step and, in closed loop, one
                # check of the state reached: never start one the check budget cannot pay
                # for.
                grad_cost = robot.dof + 1 if s.gradient == "finite_difference" else 0
                left = tracker.checks_left()
                if exhausted is None and left is not None and left < grad_cost + 1 + int(closed):
                    exhausted = (
                        f"collision-check budget of {budget.max_collision_checks} used up "
                        f"(an iteration needs {grad_cost + 1 + int(closed)})"
                    )
                if exhausted:
                    status, reason = Status.BUDGET_EXHAUSTED, exhausted
            if status is not None:
                return run.result(
                    status,
                    reason,
                    path,
                    iterations=iteration,
                    fk_calls=f.evaluations,
                    trace=trace,
                    progress_rows=progress_rows(status, path),
                    local_minima=int(status is Status.LOCAL_MINIMUM),
                    extra=extra,
                )
            step = s.gamma * self.gradient(f, q)
            if s.max_step_rad > 0:
                step = np.clip(step, -s.max_step_rad, s.max_step_rad)
            # joints with limits stay inside them (continuous joints wrap)
            q_target = np.where(
                robot.continuous, q - step, np.clip(q - step, robot.lower, robot.upper)
            )
            if closed:
                assert stepper is not None  # closed-loop mode checked for a stepper above
                q_next = wrap_to_pi(stepper.move_towards(q_target, s.sim_steps), robot.continuous)
            else:
                left = tracker.checks_left()
                q_next, blocked = self._advance_kinematic(problem, checker, q, q_target, left)
                blocked_steps += int(blocked)
                q_next = wrap_to_pi(q_next, robot.continuous)
            iteration += 1
            q = q_next
            # a kinematic step ends on a checked, collision-free state: A(S) = 0 there
            value = f(q) if closed else float(f.smooth(q))
            path.append(q.copy())
            trace.append(value)
            clock.append(tracker.elapsed_s)
            checks.append(tracker.checks_used)
            if value < best - s.stall_min_decrease:
                best, best_iter = value, iteration


def make(name: str, overrides: dict) -> GradientPlanner:
    """Registry factory for ``gradient``, ``gradient.closed_loop``, ``gradient.analytic``."""
    if name not in VARIANTS:
        raise PlannerlabError(f"{name} is not a gradient variant ({', '.join(VARIANTS)})")
    base = GradientSettings(**VARIANTS[name])  # type: ignore[arg-type]
    return GradientPlanner(name, with_overrides(base, overrides, name))

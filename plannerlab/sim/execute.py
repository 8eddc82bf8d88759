"""Executing planned paths in PyBullet and reporting what really happened.

:func:`execute` takes a problem and a joint path (m, dof) and

1. re-checks the path with the FCL :class:`~plannerlab.collision.fcl_checker.CollisionChecker` at a
   finer resolution than planners use (``problem.joint_step / 4`` by default), before any
   simulation, and records the verdict and the colliding pairs;
2. drives the simulated robot along it by position control with the Arm-Z paper's
   parameters (``000_a8ed938e94518caf.txt``: 1/240 s steps, 100 N·m motors, gravity on;
   see :mod:`plannerlab.sim.world`) on PyBullet's direct constraint solver, logging the
   state reached at every step, the deviation from the plan, the tracking
   error and every contact;
3. measures the smallest simulated clearance along the execution, and the final tip
   error against the leg's goal.

Decisions:

* **Steps per waypoint.** The path is densified to ``problem.joint_step`` per joint and
  every densified waypoint is commanded for ``steps_per_waypoint`` steps (default
  :data:`STEPS_PER_WAYPOINT` = 24, i.e. 0.1 s: Arm-Z's 0.02 rad waypoints at 0.2 rad/s),
  then the last waypoint is held for ``settle_steps`` (default :data:`SETTLE_STEPS` = 240,
  1 s). The paper's 100 steps per command belong to its gradient loop, whose commands are
  whole gradient steps. Fewer steps are not safe with the paper's 100 N·m motors: on a
  straight-segment path moving all 23 joints of the 24-module arm at once, 10 steps per
  waypoint (0.48 rad/s) left the arm 0.9 rad behind and still 0.46 rad off after settling;
  20 steps gave 0.036 rad, 24 steps 0.024 rad. The base joints carry the whole arm and
  saturate first.
* **Contacts.** Contacts are read after every physics step. A point counts when its
  penetration depth exceeds ``contact_tol_m`` (default :data:`CONTACT_TOL_M` = 0, i.e.
  PyBullet's contact distance < 0: real penetration; the points PyBullet reports up to its
  contact-breaking threshold apart are ignored). No larger tolerance is used because
  PyBullet resolves contacts stiffly: an 8-module arm driven into a wall at 100 N·m
  penetrates it by only about 1e-5 m, so a 1 mm threshold would miss a real collision.
  Contacts are aggregated per (link, other) pair: the largest depth, where it was, and the
  simulated time the pair was first seen.
* **Errors.** Tracking error per waypoint = max over joints of the wrapped
  |q_cmd − q_actual| [rad]; tip tracking error = distance between the tips of the
  commanded and actual states [m] (forward kinematics of the robot model).
* **Gravity and torque limits.** A path the FCL re-check passes can still fail here: the
  paper's 100 N·m motors cannot hold poses whose static gravity torque is larger (a
  200-waypoint 24-module path through poses needing up to 285 N·m sagged by 3 rad onto
  the room floor). ``gravity_mps2=(0, 0, 0)`` separates such failures from kinematic ones.
* **Success** ("executed cleanly") = the path passed the re-check, no contact was
  recorded, the smallest simulated clearance is >= 0, the largest deviation of the
  robot's collision geometry from the *plan* stays within the problem's
  ``[simulation] max_deviation_m`` (default 0.01 m) and, when a leg was given, the final
  state lies inside that leg's goal region. A path that reached its goal while the arm
  was far off the planned path did not execute *that* path, so it is not clean. The joint
  tracking error is still logged (``track_err_rad``), for information only: 0.05 rad at
  the base of the 16-m Arm-Z moves its tip 0.8 m, so a limit in radians cannot tell a
  clean run from a crash.
* **Deviation and clearance** (:mod:`plannerlab.sim.measure`). Every physics step's
  simulated state is kept; the deviation is the bound of
  :func:`~plannerlab.sim.measure.geometry_deviation_m` (every capsule's axis end points
  plus radius × the turn of its axis) between it and the *plan's* state at the retimed
  reference's path parameter for that step, settling included: every physics step, so
  nothing between samples is left to argue about. So ``max_deviation_m`` bounds how far
  the simulated geometry was from the plan, the reference's own distance from the plan
  included (recorded apart as ``reference_deviation_m``: at most
  :data:`~plannerlab.sim.retime.PCHIP_BOUND` × :data:`~plannerlab.sim.retime.CORNER_M`
  = 7.7 mm by construction, at most 2.1 mm measured on the 20 room variants; see
  :mod:`plannerlab.sim.retime`). Until
  issue 17's reference fix it was measured against the reference, which strayed 12-47 mm
  from the plan on the paper's task and room variant v12 while "0 mm" was reported; a
  plan's clearance minus ``max_deviation_m`` is now a true lower bound of the simulated
  clearance (minus twice it between two links). With ``"waypoints"`` timing the
  target jumps from waypoint to waypoint and the arm moves towards it over the window, so
  the deviation is taken where it should have arrived (each window's last step) and at
  every settling step. The clearance is read from PyBullet's closest points in a second,
  probe world set kinematically to the executed states, sampled as dense as the
  clearance requires (no state closer than 1 mm to a collision missed): about 30–220
  queries per leg of the paper's task instead of 12 000 steps.

**Why the arm strayed, and the design (issue 17).** Before, the 24-module Arm-Z strayed
up to 0.17 m from the commanded path on the paper's task (leg D, 0.016 rad of joint
error) and grazed ``wall_right``. Two causes, found by logging every motor's applied
torque and the reference trajectory's inverse-dynamics torque along leg D:

1. **The iterative constraint solver did not converge.** PyBullet's position motor is a
   velocity constraint row per joint, solved with the contacts each step. With the
   default projected Gauss-Seidel (50 iterations) the 23 motor rows of the chain, whose
   first joints carry the inertia of the whole 16-m arm, are solved only approximately:
   the arm lags, the motors then saturate at 100 N·m catching up (37 % of the steps of
   leg D had a saturated joint, joints 0–10). More iterations help (200: 7.6 mm) and cost
   time; the direct (Dantzig) solver solves the rows exactly, and is *cheaper* per step
   on this chain (0.39 against 0.49 ms, measured in one process). With an exact solve,
   a position gain of 1 and the velocity feed-forward, PyBullet's motor is a dead-beat
   controller: the arm lands on the reference at every step, within the torque limit.
2. **The retimed trajectory asked for more torque than the motors have, between
   TOPP-RA's grid points.** TOPP-RA holds the torque budget (half the effort) only at its
   grid points, which were the spline's knots; between them the cubic spline bends round
   the path's corners and the reference needed up to 1.33 x (leg D), 1.66 x (leg E) the
   100 N·m effort, so even an exact solver saturates there (dantzig alone: 11 mm on leg
   D). With :data:`~plannerlab.sim.retime.GRID_PER_KNOT` = 4 grid points per knot
   interval the peak is 0.59–0.66 x the effort on legs A, D, E, and the trajectories are
   *shorter* (leg D 51 s -> 19 s: the coarse grid's interpolated constraints were also
   conservative), so there are fewer physics steps to run.

What each option buys on the paper's task (``gradient.clearance+detour``, seed 0, the
seven legs enter, A-E, leave in one world; largest deviation per leg [mm]; wall time as
a ratio within one run of ``bench/execution_bench.py`` on a shared 2-core machine):

============================  ==========================================  =========
option                        deviation per leg [mm]                      wall
============================  ==========================================  =========
before (pgs, grid at knots)   15.2 48.9 14.5 28.7 171.3 114.0 12.8        1.00
pgs, 200 iterations           4.3 4.7 4.4 3.8 7.6 7.2 2.2                 0.76
pgs, dt = 1/960 s             3.0 1.5 1.6 3.4 10.6 22.4 14.0              1.71
dantzig                       1.6 0.3 0.3 2.9 11.7 2.3 0.9                0.22
pgs, grid 4 per knot          5.7 33.0 56.0 15.9 11.7 53.7 123.1          0.19
dantzig, grid 2               0.0 0.0 0.4 0.0 0.0 0.0 0.0                 0.15
dantzig, grid 4 (chosen)      0.0 0.0 0.0 0.0 0.0 0.0 0.0                 0.16
============================  ==========================================  =========

(The first run's early options ran under a heavier load; in a later run of two rounds,
interleaved, the chosen executor took 0.80 x the wall time of the executor before this
change, run from an exported copy of its commit.) Inverse dynamics as feed-forward under
an explicit PD loop (torque control, computed torque, ω = 30 rad/s) was tried on leg D
alone: 3 mm at the tip but joint errors up to 0.076 rad, one inverse-dynamics call per
step, and gains to tune per robot; not kept. The executor keeps PyBullet's motors on
the direct solver (:data:`SOLVER`) and the finer TOPP-RA grid.

**The reference's distance from the plan.** The deviations in the table above were
measured against the reference, a natural cubic spline that, measured against the plan
(at the same path parameter), strayed 47 / 33 / 19 / 40 / 20 / 15 / 41 mm on those seven
legs. The reference is now a PCHIP with corner knots (:mod:`plannerlab.sim.retime`,
bound 7.7 mm), and the deviation is measured against the plan. ``bench/execution_bench.py
--options spline,chosen`` on that plan (the spline option: the old reference, measured
against the plan): deviation per leg 1.7 / 1.6 / 2.0 / 1.8 / 1.9 / 1.4 / 1.7 mm against
the spline's 47 / 33 / 19 / 40 / 20 / 15 / 41 mm (all of it the reference's: the arm
tracks either exactly), all seven clean against none. The price is time: a faithful
reference turns the plan's corners, under the same torque budget: 473 s simulated
instead of 224 s (2.1 x). The wall time follows the physics steps (profiled on leg D:
about 1 ms per step either way; retiming 2.9 s): the expected wall ratio is the
simulated one, 2.1 x; the bench's own wall ratio, 5.4 x (216 s against 40 s), was taken
under a load average of 4.5-10 on 2 cores and is not a measure. That misses issue 17's
"1.5 x today's execution wall time"; the alternatives measured (the table in
:mod:`plannerlab.sim.retime`) trade the distance from the plan for time, and none kept
both.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker, PathCheck, problem_checker
from plannerlab.errors import PlannerlabError
from plannerlab.problem.load import Problem
from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.sim.measure import (
    Clearance,
    geometry_notes,
    plan_deviation,
    sampled_clearance,
)
from plannerlab.sim.retime import GRID_PER_KNOT, INTERPOLANT
from plannerlab.sim.track import (
    StepRecorder,
    Tracked,
    retimed,
    track_trajectory,
    track_waypoints,
)
from plannerlab.sim.world import DT_S, SimWorld

#: physics steps per densified waypoint (0.1 s)
STEPS_PER_WAYPOINT: int = 24
#: physics steps holding the last waypoint at the end (1 s)
SETTLE_STEPS: int = 240
#: penetration depth above which a contact point counts [m]
CONTACT_TOL_M: float = 0.0
#: PyBullet's constraint solver for executions (see the module docstring)
SOLVER: str = "dantzig"


# ---------------------------------------------------------------------- running
def _check_path(problem: Problem, path: Any) -> Array:
    path = np.atleast_2d(np.asarray(path, dtype=float))
    dof = problem.robot.dof
    if path.ndim != 2 or path.shape[1] != dof or len(path) == 0:
        raise PlannerlabError(f"a path of shape (m, {dof}) for {problem.name}, got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise PlannerlabError("the path holds NaN or infinite joint values")
    return path


def _limits(
    problem: Problem,
    joint_step: float | None,
    waypoint_step: float | None,
    steps_per_waypoint: int,
    settle_steps: int,
    track_err_limit_rad: float | None,
    max_deviation_m: float | None,
) -> tuple[float, float, float, float]:
    """The run's settings, checked, the problem's where not given: (track_limit [rad],
    dev_limit [m], recheck_step [rad], wp_step [rad])."""
    if steps_per_waypoint < 1 or settle_steps < 0:
        raise PlannerlabError(
            f"steps_per_waypoint >= 1 and settle_steps >= 0, got {steps_per_waypoint}, "
            f"{settle_steps}"
        )
    track_limit = (
        float(track_err_limit_rad)
        if track_err_limit_rad is not None
        else problem.simulation.max_track_err_rad
    )
    if not track_limit > 0:
        raise PlannerlabError(f"max_track_err_rad must be positive, got {track_limit}")
    dev_limit = (
        float(max_deviation_m)
        if max_deviation_m is not None
        else problem.simulation.max_deviation_m
    )
    if not dev_limit > 0:
        raise PlannerlabError(f"max_deviation_m must be positive, got {dev_limit}")
    recheck_step = float(joint_step) if joint_step is not None else problem.joint_step / 4.0
    wp_step = float(waypoint_step) if waypoint_step is not None else problem.joint_step
    if not (recheck_step > 0 and wp_step > 0):
        raise PlannerlabError(f"joint steps must be positive, got {recheck_step}, {wp_step}")
    return track_limit, dev_limit, recheck_step, wp_step


def _measure(
    robot: Robot,
    probe: SimWorld,
    rec: StepRecorder,
    tracked: Tracked,
    settle_steps: int,
    steps_per_waypoint: int,
) -> tuple[Array, float, float, Clearance]:
    """Every physics step's deviation from the plan (per log sample, the largest and its
    time: :func:`~plannerlab.sim.measure.plan_deviation`) and the simulated clearance
    sampled along them (in the probe world)."""
    states = np.array(rec.q_step).reshape(len(rec.q_step), robot.dof)
    deviation, max_dev, max_dev_t = plan_deviation(
        robot,
        states,
        np.array(rec.q_step_cmd).reshape(len(rec.q_step), robot.dof),
        tracked.t_s,
        rec.world.dt_s,
        q_plan=tracked.q_plan,
        settle_steps=settle_steps,
        window_steps=steps_per_waypoint,
    )
    return deviation, max_dev, max_dev_t, sampled_clearance(robot, probe, states)


def _tracking_errors(robot: Robot, tracked: Tracked) -> tuple[Array, Array, float, float]:
    """Per logged sample the joint tracking error [rad] (over its window when the tracking
    measured one) and the tip's [m]; the same of the final state."""
    cont = np.asarray(robot.continuous, dtype=bool)
    q_cmd, q_act, q_final = tracked.q_cmd, tracked.q_act, tracked.q_final
    track = (
        tracked.window_track
        if tracked.window_track is not None
        else np.max(np.abs(joint_difference(q_cmd, q_act, cont)), axis=1)
    )
    tip_track = np.linalg.norm(robot.tip(q_cmd)[0] - robot.tip(q_act)[0], axis=1)
    final_track = float(np.max(np.abs(joint_difference(q_cmd[-1], q_final, cont)), initial=0.0))
    final_tip_track = float(np.linalg.norm(robot.tip(q_cmd[-1])[0] - robot.tip(q_final)[0]))
    return track, tip_track, final_track, final_tip_track


def _goal_errors(
    problem: Problem, leg: int | None, q_final: Array
) -> tuple[str | None, float, float, bool | None, str | None]:
    """The final state against the leg's goal: (goal name, tip position error [m], angle
    error [deg], reached, why not in words); no goal without a leg."""
    if leg is None:
        return None, math.nan, math.nan, None, None
    goal = problem.goal(leg)
    pe, ae = goal.errors(problem.robot, q_final)
    pos_err, ang_err = float(pe), float(ae)
    reached = bool(pos_err <= goal.pos_tol_m and ang_err <= goal.angle_tol_deg)
    missed = (
        None
        if reached
        else f"final tip {pos_err:.3g} m / {ang_err:.3g} deg from goal {goal.name!r} "
        f"(tolerance {goal.pos_tol_m:g} m / {goal.angle_tol_deg:g} deg)"
    )
    return goal.name, pos_err, ang_err, reached, missed


def _problems(
    check: PathCheck,
    traj_check: PathCheck | None,
    recheck_step: float,
    contacts: tuple[ContactRecord, ...],
    missed_goal: str | None,
    max_dev: float,
    max_dev_t: float,
    dev_limit: float,
    ref_dev: float,
    clear: Clearance,
    clear_t: float,
) -> list[str]:
    """Why an execution is not clean, in words (empty: it is)."""
    problems: list[str] = []
    if not check.valid:
        listing = ", ".join(f"{a} x {b}" for a, b in check.pairs)
        problems.append(
            f"FCL re-check at {recheck_step:.3g} rad: collision on edge "
            f"{check.first_invalid_edge} ({listing})"
        )
    if traj_check is not None and not traj_check.valid:
        listing = ", ".join(f"{a} x {b}" for a, b in traj_check.pairs)
        problems.append(
            f"FCL re-check of the retimed trajectory at {recheck_step:.3g} rad: collision "
            f"({listing})"
        )
    if contacts:
        worst = max(contacts, key=lambda c: c.max_depth_m)
        problems.append(
            f"{len(contacts)} contact pair(s) in simulation, deepest "
            f"{worst.link_name} x {worst.other_name} "
            f"{worst.max_depth_m * 1e3:.1f} mm at t = {worst.first_time_s:.3f} s"
        )
    if missed_goal is not None:
        problems.append(missed_goal)
    if max_dev > dev_limit:
        problems.append(
            f"the robot strayed {max_dev * 1e3:.3g} mm from the plan at "
            f"t = {max_dev_t:.3f} s (limit {dev_limit * 1e3:g} mm, [simulation] "
            f"max_deviation_m; the reference within {ref_dev * 1e3:.3g} mm of the plan)"
        )
    if clear.clearance_m < 0:
        a, b = clear.pair or ("?", "?")
        problems.append(
            f"simulated clearance {clear.clearance_m * 1e3:.3g} mm ({a} x {b}) at "
            f"t = {clear_t:.3f} s"
        )
    return problems


def _run(
    world: SimWorld,
    checker: CollisionChecker,
    problem: Problem,
    path: Array,
    leg: int | None,
    carried_over: bool,
    joint_step: float | None,
    waypoint_step: float | None,
    steps_per_waypoint: int,
    settle_steps: int,
    contact_tol_m: float,
    track_err_limit_rad: float | None,
    timing: str,
    *,
    probe: SimWorld,
    max_deviation_m: float | None = None,
    grid_per_knot: int = GRID_PER_KNOT,
    interpolant: str = INTERPOLANT,
) -> Execution:
    """One leg: re-checked, retimed, tracked, measured and judged (see :func:`execute`)."""
    t0 = time.perf_counter()
    robot = problem.robot
    track_limit, dev_limit, recheck_step, wp_step = _limits(
        problem,
        joint_step,
        waypoint_step,
        steps_per_waypoint,
        settle_steps,
        track_err_limit_rad,
        max_deviation_m,
    )
    check = checker.check_path(path, recheck_step)
    if not carried_over:
        world.reset(path[0])
    q_start = world.state()
    offsets = joint_difference(q_start, path[0], np.asarray(robot.continuous, dtype=bool))
    start_offset = float(np.max(np.abs(offsets), initial=0.0))
    rec = StepRecorder(world, contact_tol_m)
    notes: list[str] = []
    traj = retimed(
        world,
        checker.reach_m,
        path,
        q_start,
        start_offset,
        timing,
        recheck_step,
        grid_per_knot,
        interpolant,
        notes,
    )
    traj_check = None
    if traj is not None:
        tracked = track_trajectory(world, rec, traj, settle_steps)
        assert tracked.q_ref is not None
        # The commanded states are re-checked too, with the plan's margin: the spline must
        # keep the room the plan left. Every physics step's reference state is checked
        # (and the edges between them in metres): thinning them to one per joint step,
        # as before, joined the kept states by straight lines and missed the spline
        # bulging between them (a room variant: re-check passed, the reference came
        # within 4 mm of a wall the plan kept 28 mm from).
        traj_check = checker.check_path(tracked.q_ref, recheck_step)
        wp_step = recheck_step
    else:
        tracked = track_waypoints(world, rec, path, wp_step, steps_per_waypoint, settle_steps)
    t_s, q_cmd, q_act, q_final = tracked.t_s, tracked.q_cmd, tracked.q_act, tracked.q_final
    ref_dev = tracked.reference_deviation_m
    deviation, max_dev, max_dev_t, clear = _measure(
        robot, probe, rec, tracked, settle_steps, steps_per_waypoint
    )
    clear_t = float((clear.index + 1) * world.dt_s)
    track, tip_track, final_track, final_tip_track = _tracking_errors(robot, tracked)
    goal_name, pos_err, ang_err, reached, missed_goal = _goal_errors(problem, leg, q_final)
    contacts = rec.contacts()
    problems = _problems(
        check,
        traj_check,
        recheck_step,
        contacts,
        missed_goal,
        max_dev,
        max_dev_t,
        dev_limit,
        ref_dev,
        clear,
        clear_t,
    )
    if not problems:
        moved = (
            f"executed a {tracked.duration_s:.3g} s trajectory (toppra)"
            if traj is not None
            else f"executed {len(q_cmd)} waypoints"
        )
        done = f"; final tip {pos_err:.3g} m / {ang_err:.3g} deg from {goal_name!r}"
        problems = [
            f"{moved} without contact; deviation from the plan <= {max_dev * 1e3:.3g} mm "
            f"(reference <= {ref_dev * 1e3:.3g} mm), clearance >= "
            f"{clear.clearance_m * 1e3:.3g} mm" + (done if reached else "")
        ]
    reason = "; ".join([*problems, *notes])

    return Execution(
        problem=problem.name,
        leg=leg,
        goal=goal_name,
        path_valid=check.valid,
        recheck_joint_step=recheck_step,
        recheck_states=check.states_checked,
        recheck_first_invalid_edge=check.first_invalid_edge,
        recheck_pairs=check.pairs,
        waypoint_step=wp_step,
        steps_per_waypoint=int(tracked.steps_logged),
        settle_steps=int(settle_steps),
        dt_s=world.dt_s,
        contact_tol_m=float(contact_tol_m),
        gravity_mps2=world.gravity_mps2,
        t_s=t_s,
        q_cmd_rad=q_cmd,
        q_actual_rad=q_act,
        track_err_rad=track,
        tip_track_err_m=tip_track,
        contacts=contacts,
        q_start_rad=q_start,
        carried_over=carried_over,
        start_offset_rad=start_offset,
        q_final_rad=q_final,
        final_track_err_rad=final_track,
        final_tip_track_err_m=final_tip_track,
        final_pos_err_m=pos_err,
        final_angle_err_deg=ang_err,
        goal_reached=reached,
        sim_time_s=rec.elapsed_s(),
        wall_time_s=time.perf_counter() - t0,
        reason=reason,
        track_err_limit_rad=track_limit,
        timing="waypoints" if traj is None else "toppra",
        duration_s=tracked.duration_s,
        trajectory_valid=None if traj_check is None else traj_check.valid,
        spline_dev=math.nan if traj is None else traj.max_dev,
        deviation_m=deviation,
        max_deviation_m=max_dev,
        reference_deviation_m=ref_dev,
        max_deviation_time_s=max_dev_t,
        max_deviation_limit_m=dev_limit,
        min_clearance_m=clear.clearance_m,
        min_clearance_time_s=clear_t,
        min_clearance_pair=clear.pair,
        clearance_samples=clear.samples,
        solver=world.solver,
    )


def execute(
    problem: Problem,
    path: Array,
    *,
    joint_step: float | None = None,
    waypoint_step: float | None = None,
    steps_per_waypoint: int = STEPS_PER_WAYPOINT,
    settle_steps: int = SETTLE_STEPS,
    contact_tol_m: float = CONTACT_TOL_M,
    gravity_mps2: tuple[float, float, float] | None = None,
    max_track_err_rad: float | None = None,
    timing: str = "toppra",
    gui: bool = False,
    leg: int | str | None = None,
    max_deviation_m: float | None = None,
    solver: str = SOLVER,
    solver_iterations: int | None = None,
    dt_s: float = DT_S,
    grid_per_knot: int = GRID_PER_KNOT,
    interpolant: str = INTERPOLANT,
) -> Execution:
    """Re-check a path with FCL, then execute it in a fresh PyBullet world.

    The robot is reset to ``path[0]`` (at rest) before the first command.

    Args:
        problem: robot, scene and goals.
        path: (m, dof) joint path.
        joint_step: FCL re-check resolution [rad per joint]; default
            ``problem.joint_step / 4``.
        waypoint_step: densification of the commanded path [rad per joint]; default
            ``problem.joint_step``.
        steps_per_waypoint: physics steps (1/240 s each) per commanded waypoint.
        settle_steps: physics steps holding the last waypoint at the end.
        contact_tol_m: penetration depth above which a contact point counts [m].
        gravity_mps2: gravity in the world frame [m/s²]; default: the problem's
            ``[simulation] gravity_mps2`` (zero it to separate kinematic from torque-limit
            failures).
        max_track_err_rad: the joint tracking limit recorded in the execution
            (``track_err_limit_rad``; informational, it no longer decides the verdict);
            default: the problem's ``[simulation] max_track_err_rad``.
        max_deviation_m: the largest deviation of the robot's collision geometry from
            the plan of a clean execution [m]; default: the problem's
            ``[simulation] max_deviation_m``.
        solver: PyBullet's constraint solver (:data:`SOLVER`, see the module docstring;
            "pgs" is PyBullet's default iterative one).
        solver_iterations: the iterative solver's iterations per step (None: 50).
        dt_s: physics time step [s].
        grid_per_knot: TOPP-RA grid points per knot interval
            (:data:`~plannerlab.sim.retime.GRID_PER_KNOT`).
        interpolant: the reference's interpolant, "pchip" or "spline"
            (:data:`~plannerlab.sim.retime.INTERPOLANT`).
        timing: ``"toppra"`` (default): the path is time-parameterised under the robot's
            velocity limits and half its torque limits (:mod:`plannerlab.sim.retime`)
            and tracked with position+velocity targets every physics step; when that is
            infeasible, the reason says so and the densified waypoints are executed.
            ``"waypoints"``: the path densified to ``waypoint_step``, each waypoint a
            position target for ``steps_per_waypoint`` steps.
        gui: show PyBullet's GUI.
        leg: the leg (index or goal name) whose goal the final state is measured against.

    Returns:
        the :class:`Execution` record (the re-check verdict is in it; an invalid path is
        still simulated, to see what it does).

    Raises:
        PlannerlabError: the path has the wrong shape or holds non-finite values, or a
            parameter is out of range.
    """
    path = _check_path(problem, path)
    leg_i = problem.resolve_leg(leg) if leg is not None else None
    checker = problem_checker(problem)
    if gravity_mps2 is None:
        gravity_mps2 = problem.simulation.gravity_mps2
    with (
        SimWorld(
            problem.robot,
            problem.scene,
            gui=gui,
            gravity_mps2=gravity_mps2,
            solver=solver,
            solver_iterations=solver_iterations,
            dt_s=dt_s,
        ) as world,
        SimWorld(problem.robot, problem.scene) as probe,
    ):
        ex = _run(
            world,
            checker,
            problem,
            path,
            leg_i,
            False,
            joint_step,
            waypoint_step,
            steps_per_waypoint,
            settle_steps,
            contact_tol_m,
            max_track_err_rad,
            timing,
            probe=probe,
            max_deviation_m=max_deviation_m,
            grid_per_knot=grid_per_knot,
            interpolant=interpolant,
        )
    return dataclasses.replace(ex, geometry=geometry_notes(problem))


def execute_legs(
    problem: Problem,
    leg_paths: Sequence[Array],
    *,
    first_leg: int = 0,
    joint_step: float | None = None,
    waypoint_step: float | None = None,
    steps_per_waypoint: int = STEPS_PER_WAYPOINT,
    settle_steps: int = SETTLE_STEPS,
    contact_tol_m: float = CONTACT_TOL_M,
    gravity_mps2: tuple[float, float, float] | None = None,
    max_track_err_rad: float | None = None,
    timing: str = "toppra",
    gui: bool = False,
    max_deviation_m: float | None = None,
    solver: str = SOLVER,
    solver_iterations: int | None = None,
    dt_s: float = DT_S,
    grid_per_knot: int = GRID_PER_KNOT,
    interpolant: str = INTERPOLANT,
    checker: CollisionChecker | None = None,
) -> list[Execution]:
    """Execute consecutive legs in ONE world, each from where the previous one ended.

    The world is reset to the first path's first waypoint; every later leg starts from
    the state the simulator actually reached (``carried_over=True`` in its record, with
    ``start_offset_rad`` saying how far that was from its path's first waypoint).
    ``leg_paths[i]`` is leg ``first_leg + i``; legs past the problem's last goal are run
    without a goal. Arguments are those of :func:`execute`; ``checker`` the problem's
    checker (``problem_checker(problem)``) when the caller has it (built once per trial
    and shared with the solve), else built here.

    Returns:
        one :class:`Execution` per path, in order.
    """
    paths = [_check_path(problem, p) for p in leg_paths]
    if checker is None:
        checker = problem_checker(problem)
    out: list[Execution] = []
    if gravity_mps2 is None:
        gravity_mps2 = problem.simulation.gravity_mps2
    with (
        SimWorld(
            problem.robot,
            problem.scene,
            gui=gui,
            gravity_mps2=gravity_mps2,
            solver=solver,
            solver_iterations=solver_iterations,
            dt_s=dt_s,
        ) as world,
        SimWorld(problem.robot, problem.scene) as probe,
    ):
        for i, path in enumerate(paths):
            leg = first_leg + i
            out.append(
                _run(
                    world,
                    checker,
                    problem,
                    path,
                    leg if leg < problem.legs else None,
                    i > 0,
                    joint_step,
                    waypoint_step,
                    steps_per_waypoint,
                    settle_steps,
                    contact_tol_m,
                    max_track_err_rad,
                    timing,
                    probe=probe,
                    max_deviation_m=max_deviation_m,
                    grid_per_knot=grid_per_knot,
                    interpolant=interpolant,
                )
            )
    geometry = geometry_notes(problem)
    return [dataclasses.replace(ex, geometry=geometry) for ex in out]

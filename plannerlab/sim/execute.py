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

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.collision.reach import joint_reach_m
from plannerlab.errors import PlannerlabError
from plannerlab.problem.load import Problem
from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.robots.base import Array, as_xyz, joint_difference
from plannerlab.robots.paths import densify
from plannerlab.sim.measure import geometry_deviation_m, sampled_clearance
from plannerlab.sim.retime import GRID_PER_KNOT, INTERPOLANT, retime, unwrap_path
from plannerlab.sim.world import DT_S, SimWorld

#: physics steps per densified waypoint (0.1 s)
STEPS_PER_WAYPOINT: int = 24
#: physics steps holding the last waypoint at the end (1 s)
SETTLE_STEPS: int = 240
#: penetration depth above which a contact point counts [m]
CONTACT_TOL_M: float = 0.0
#: physics steps between logged samples of a retimed execution (20 Hz)
LOG_EVERY_STEPS: int = 12
#: PyBullet position gain when tracking a retimed trajectory: 1 corrects the whole
#: position error within one step (PyBullet's default 0.1 lags); with the velocity
#: feed-forward it kept the 24-module arm within 3e-4 rad on a 9.9 rad RRT-Connect path
TRACK_POSITION_GAIN: float = 1.0
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
    t0 = time.perf_counter()
    robot = problem.robot
    cont = np.asarray(robot.continuous, dtype=bool)
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
    check = checker.check_path(path, recheck_step)

    if not carried_over:
        world.reset(path[0])
    q_start = world.state()
    start_offset = float(np.max(np.abs(joint_difference(q_start, path[0], cont)), initial=0.0))

    steps0 = world.steps_taken
    seen: dict[tuple[str, str, bool], list[Any]] = {}
    # Every physics step's simulated state, and the state commanded for it.
    q_step: list[Array] = []
    q_step_cmd: list[Array] = []

    def run_steps(n: int, q_target: Array) -> None:
        for _ in range(n):
            world.step(1)
            q_step.append(world.state())
            q_step_cmd.append(q_target)
            t = (world.steps_taken - steps0) * world.dt_s
            for c in world.contacts(min_depth_m=contact_tol_m):
                key = (c.link_name, c.other_name, c.other_is_link)
                rec = seen.get(key)
                if rec is None:
                    seen[key] = [c.depth_m, t, c.p_world_m]
                elif c.depth_m > rec[0]:
                    rec[0], rec[2] = c.depth_m, c.p_world_m

    timing_used = "waypoints"
    notes: list[str] = []
    ref_dev = 0.0
    traj = None
    traj_check = None
    if timing == "toppra":
        # The path continues from where the arm really is (carried over from the previous
        # leg: a short move to the path's first state is prepended).
        q_path = unwrap_path(path, cont, q_from=q_start)
        if start_offset > 1e-9:
            q_path = np.vstack([q_start[None, :], q_path])
        try:
            traj = retime(
                q_path,
                velocity_limit=world.max_velocity,
                effort_limit=world.max_force,
                inverse_dynamics=world.inverse_dynamics,
                knot_step=recheck_step,
                grid_per_knot=grid_per_knot,
                reach_m=checker.reach_m if checker.reach_m is not None else joint_reach_m(robot),
                to_urdf=world.to_urdf,
                interpolant=interpolant,
            )
            timing_used = "toppra"
        except Exception as exc:  # toppra or the simulator's inverse dynamics
            notes.append(f"not retimed ({exc}); executed along densified waypoints")
    elif timing != "waypoints":
        raise PlannerlabError(f"timing: expected 'toppra' or 'waypoints', got {timing!r}")

    if traj is not None:
        n = max(1, int(math.ceil(traj.duration_s / world.dt_s - 1e-9)))
        t_all: Array = np.arange(1, n + 1, dtype=np.float64) * world.dt_s
        q_urdf = traj.sample(np.concatenate([[0.0], t_all]))[0]
        # Step k goes from t_k to t_k+1: the position target is the reference at t_k and
        # the velocity target the reference's mean velocity over the step (PyBullet's
        # motor adds gain × the *current* position error to the velocity target; a
        # position target at t_k+1 would make the arm lead by one step, v·dt).
        qd_urdf = np.diff(q_urdf, axis=0) / world.dt_s
        q_all = world.from_urdf(q_urdf[1:])
        # The plan's state at each step's path parameter: what the deviation is measured
        # against (the reference is within traj.bound_m of it, measured below).
        q_plan_all = traj.plan_states(t_all)
        ref_dev = float(np.max(geometry_deviation_m(robot, q_plan_all, q_all), initial=0.0))
        # The commanded states are re-checked too, with the plan's margin: the spline must
        # keep the room the plan left. Every physics step's reference state is checked
        # (and the edges between them in metres): thinning them to one per joint step,
        # as before, joined the kept states by straight lines and missed the spline
        # bulging between them (a room variant: re-check passed, the reference came
        # within 4 mm of a wall the plan kept 28 mm from).
        traj_check = checker.check_path(q_all, recheck_step)
        err_all = np.empty(n)
        logged = sorted(set(range(LOG_EVERY_STEPS - 1, n, LOG_EVERY_STEPS)) | {n - 1})
        q_act_list: list[Array] = []
        for k in range(n):
            world.command_urdf(q_urdf[k], qd_urdf[k], position_gain=TRACK_POSITION_GAIN)
            run_steps(1, q_all[k])
            q_now = q_step[-1]
            err_all[k] = np.max(np.abs(joint_difference(q_all[k], q_now, cont)), initial=0.0)
            if k == logged[len(q_act_list)]:
                q_act_list.append(q_now)
        q_cmd = q_all[logged]
        q_act = np.array(q_act_list)
        t_s = t_all[logged]
        window_track = np.maximum.reduceat(err_all, [0, *[k + 1 for k in logged[:-1]]])
        world.command_urdf(q_urdf[-1], np.zeros(robot.dof), position_gain=TRACK_POSITION_GAIN)
        run_steps(settle_steps, q_all[-1])
        q_final = world.state()
        duration = traj.duration_s
        steps_logged = LOG_EVERY_STEPS
        wp_step = recheck_step
    else:
        q_cmd, _ = densify(path, wp_step, cont)
        M = len(q_cmd)
        q_act = np.empty_like(q_cmd)
        t_s = np.empty(M)
        for k in range(M):
            world.command(q_cmd[k])
            run_steps(steps_per_waypoint, q_cmd[k])
            q_act[k] = q_step[-1]
            t_s[k] = (world.steps_taken - steps0) * world.dt_s
        world.command(q_cmd[-1])
        run_steps(settle_steps, q_cmd[-1])
        q_final = world.state()
        window_track = None
        duration = M * steps_per_waypoint * world.dt_s
        steps_logged = steps_per_waypoint

    # Deviation from the PLAN: every physics step of a retimed trajectory against the
    # planned polyline's state at the reference's path parameter (so it holds the
    # reference's own distance from the plan, reference_deviation_m, and the tracking);
    # with "waypoints" timing the commands are the densified plan itself and the arm
    # moves towards each waypoint over its window, so it is measured where it should
    # have arrived (the window's last step), and at every settling step.
    states = np.array(q_step).reshape(len(q_step), robot.dof)
    targets = np.array(q_step_cmd).reshape(len(q_step), robot.dof)
    if traj is not None:
        targets = np.vstack([q_plan_all, targets[len(q_plan_all) :]])
    n_moving = len(states) - settle_steps
    if traj is not None:
        judged = np.arange(len(states))
    else:
        judged = np.concatenate(
            [
                np.arange(steps_per_waypoint - 1, n_moving, steps_per_waypoint),
                np.arange(n_moving, len(states)),
            ]
        ).astype(int)
    dev_steps = geometry_deviation_m(robot, targets[judged], states[judged])
    worst_dev = int(np.argmax(dev_steps)) if len(dev_steps) else 0
    max_dev = float(dev_steps[worst_dev]) if len(dev_steps) else 0.0
    max_dev_t = float((judged[worst_dev] + 1) * world.dt_s) if len(dev_steps) else 0.0
    # per log sample: the largest deviation since the previous sample (settling excluded)
    step_of_sample = np.rint(t_s / world.dt_s).astype(int) - 1
    dev_full = np.zeros(len(states))
    dev_full[judged] = dev_steps
    bounds = np.concatenate([[0], step_of_sample[:-1] + 1]) if len(t_s) else np.zeros(0, int)
    deviation = np.maximum.reduceat(dev_full, bounds) if len(t_s) else np.zeros(0)
    clear = sampled_clearance(robot, probe, states)
    clear_t = float((clear.index + 1) * world.dt_s)

    track = (
        window_track
        if window_track is not None
        else np.max(np.abs(joint_difference(q_cmd, q_act, cont)), axis=1)
    )
    tip_track = np.linalg.norm(robot.tip(q_cmd)[0] - robot.tip(q_act)[0], axis=1)
    final_track = float(np.max(np.abs(joint_difference(q_cmd[-1], q_final, cont)), initial=0.0))
    final_tip_track = float(np.linalg.norm(robot.tip(q_cmd[-1])[0] - robot.tip(q_final)[0]))

    goal_name: str | None = None
    pos_err = ang_err = math.nan
    reached: bool | None = None
    if leg is not None:
        goal = problem.goal(leg)
        goal_name = goal.name
        pe, ae = goal.errors(robot, q_final)
        pos_err, ang_err = float(pe), float(ae)
        reached = bool(pos_err <= goal.pos_tol_m and ang_err <= goal.angle_tol_deg)

    contacts = tuple(
        ContactRecord(link, other, is_link, float(rec[0]), float(rec[1]), as_xyz(rec[2]))
        for (link, other, is_link), rec in sorted(seen.items(), key=lambda kv: kv[1][1])
    )

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
    if reached is False:
        goal = problem.goal(leg)  # type: ignore[arg-type]
        problems.append(
            f"final tip {pos_err:.3g} m / {ang_err:.3g} deg from goal "
            f"{goal.name!r} (tolerance {goal.pos_tol_m:g} m / "
            f"{goal.angle_tol_deg:g} deg)"
        )
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
    if problems:
        reason = "; ".join(problems)
    else:
        moved = (
            f"executed a {duration:.3g} s trajectory (toppra)"
            if traj is not None
            else f"executed {len(q_cmd)} waypoints"
        )
        reason = (
            f"{moved} without contact; deviation from the plan <= {max_dev * 1e3:.3g} mm "
            f"(reference <= {ref_dev * 1e3:.3g} mm), clearance >= "
            f"{clear.clearance_m * 1e3:.3g} mm"
        )
        if reached:
            reason += f"; final tip {pos_err:.3g} m / {ang_err:.3g} deg from {goal_name!r}"

    if notes:
        reason = "; ".join([reason, *notes])

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
        steps_per_waypoint=int(steps_logged),
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
        sim_time_s=(world.steps_taken - steps0) * world.dt_s,
        wall_time_s=time.perf_counter() - t0,
        reason=reason,
        track_err_limit_rad=track_limit,
        timing=timing_used,
        duration_s=duration,
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
        return _run(
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
) -> list[Execution]:
    """Execute consecutive legs in ONE world, each from where the previous one ended.

    The world is reset to the first path's first waypoint; every later leg starts from
    the state the simulator actually reached (``carried_over=True`` in its record, with
    ``start_offset_rad`` saying how far that was from its path's first waypoint).
    ``leg_paths[i]`` is leg ``first_leg + i``; legs past the problem's last goal are run
    without a goal. Arguments are those of :func:`execute`.

    Returns:
        one :class:`Execution` per path, in order.
    """
    paths = [_check_path(problem, p) for p in leg_paths]
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
    return out

"""Driving the simulated robot along a path, for :mod:`plannerlab.sim.execute`: every
physics step recorded (:class:`StepRecorder`: the state reached, the state commanded,
the contacts), the path retimed from where the arm is (:func:`retimed`), and the two ways
of commanding a path: a retimed trajectory tracked with position+velocity targets every
step (:func:`track_trajectory`) or densified waypoints, each a position target for a
window of steps (:func:`track_waypoints`). The decisions behind both are in
:mod:`plannerlab.sim.execute`'s docstring."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.collision.reach import joint_reach_m
from plannerlab.errors import PlannerlabError
from plannerlab.record.execution import ContactRecord
from plannerlab.robots.base import Array, as_xyz, joint_difference
from plannerlab.robots.paths import densify
from plannerlab.sim.measure import geometry_deviation_m
from plannerlab.sim.retime import Trajectory, retime, unwrap_path
from plannerlab.sim.world import SimWorld

#: physics steps between logged samples of a retimed execution (20 Hz)
LOG_EVERY_STEPS: int = 12
#: PyBullet position gain when tracking a retimed trajectory: 1 corrects the whole
#: position error within one step (PyBullet's default 0.1 lags); with the velocity
#: feed-forward it kept the 24-module arm within 3e-4 rad on a 9.9 rad RRT-Connect path
TRACK_POSITION_GAIN: float = 1.0


class StepRecorder:
    """Runs physics steps in ``world`` and keeps, per step, the simulated state, the state
    commanded for it, and the contacts deeper than ``contact_tol_m`` (per (link, other)
    pair: the largest depth, where it was, and the time the pair was first seen)."""

    def __init__(self, world: SimWorld, contact_tol_m: float) -> None:
        self.world = world
        self.contact_tol_m = contact_tol_m
        self.steps0 = world.steps_taken
        self.seen: dict[tuple[str, str, bool], list[Any]] = {}
        #: every physics step's simulated state, and the state commanded for it
        self.q_step: list[Array] = []
        self.q_step_cmd: list[Array] = []

    def run(self, n: int, q_target: Array) -> None:
        """``n`` physics steps under the current command, ``q_target`` the state commanded."""
        world = self.world
        for _ in range(n):
            world.step(1)
            self.q_step.append(world.state())
            self.q_step_cmd.append(q_target)
            t = self.elapsed_s()
            for c in world.contacts(min_depth_m=self.contact_tol_m):
                key = (c.link_name, c.other_name, c.other_is_link)
                rec = self.seen.get(key)
                if rec is None:
                    self.seen[key] = [c.depth_m, t, c.p_world_m]
                elif c.depth_m > rec[0]:
                    rec[0], rec[2] = c.depth_m, c.p_world_m

    def elapsed_s(self) -> float:
        """Simulated time since the recorder was made [s]."""
        return (self.world.steps_taken - self.steps0) * self.world.dt_s

    def contacts(self) -> tuple[ContactRecord, ...]:
        """The contact pairs seen, in the order they were first seen."""
        return tuple(
            ContactRecord(link, other, is_link, float(rec[0]), float(rec[1]), as_xyz(rec[2]))
            for (link, other, is_link), rec in sorted(self.seen.items(), key=lambda kv: kv[1][1])
        )


@dataclass
class Tracked:
    """What commanding a path logged: per logged sample the time, the commanded and the
    reached state and the tracking error over its window (None: take it at the sample);
    the final state; the duration; the steps per logged sample; and for a retimed
    trajectory, per moving step, the plan's state at its path parameter (``q_plan``) and
    the reference's state commanded (``q_ref``)."""

    t_s: Array
    q_cmd: Array
    q_act: Array
    window_track: Array | None
    q_final: Array
    duration_s: float
    steps_logged: int
    q_plan: Array | None = None
    q_ref: Array | None = None
    #: the reference's largest deviation from the plan [m] (0 without a reference)
    reference_deviation_m: float = 0.0


def track_trajectory(
    world: SimWorld, rec: StepRecorder, traj: Trajectory, settle_steps: int
) -> Tracked:
    """Track a retimed trajectory with position+velocity targets every physics step, then
    hold its last state for ``settle_steps``; a sample is logged every
    :data:`LOG_EVERY_STEPS` steps and at the last one."""
    robot = world.robot
    cont = np.asarray(robot.continuous, dtype=bool)
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
    # against (the reference is within traj.bound_m of it, measured here).
    q_plan_all = traj.plan_states(t_all)
    ref_dev = float(np.max(geometry_deviation_m(robot, q_plan_all, q_all), initial=0.0))
    err_all = np.empty(n)
    logged = sorted(set(range(LOG_EVERY_STEPS - 1, n, LOG_EVERY_STEPS)) | {n - 1})
    q_act_list: list[Array] = []
    for k in range(n):
        world.command_urdf(q_urdf[k], qd_urdf[k], position_gain=TRACK_POSITION_GAIN)
        rec.run(1, q_all[k])
        q_now = rec.q_step[-1]
        err_all[k] = np.max(np.abs(joint_difference(q_all[k], q_now, cont)), initial=0.0)
        if k == logged[len(q_act_list)]:
            q_act_list.append(q_now)
    window_track = np.maximum.reduceat(err_all, [0, *[k + 1 for k in logged[:-1]]])
    world.command_urdf(q_urdf[-1], np.zeros(robot.dof), position_gain=TRACK_POSITION_GAIN)
    rec.run(settle_steps, q_all[-1])
    return Tracked(
        t_s=t_all[logged],
        q_cmd=q_all[logged],
        q_act=np.array(q_act_list),
        window_track=window_track,
        q_final=world.state(),
        duration_s=traj.duration_s,
        steps_logged=LOG_EVERY_STEPS,
        q_plan=q_plan_all,
        q_ref=q_all,
        reference_deviation_m=ref_dev,
    )


def track_waypoints(
    world: SimWorld,
    rec: StepRecorder,
    path: Array,
    waypoint_step: float,
    steps_per_waypoint: int,
    settle_steps: int,
) -> Tracked:
    """Command the path densified to ``waypoint_step``, each waypoint a position target for
    ``steps_per_waypoint`` steps (a sample logged at the window's end), then hold the last
    one for ``settle_steps``."""
    q_cmd, _ = densify(path, waypoint_step, np.asarray(world.robot.continuous, dtype=bool))
    M = len(q_cmd)
    q_act = np.empty_like(q_cmd)
    t_s = np.empty(M)
    for k in range(M):
        world.command(q_cmd[k])
        rec.run(steps_per_waypoint, q_cmd[k])
        q_act[k] = rec.q_step[-1]
        t_s[k] = rec.elapsed_s()
    world.command(q_cmd[-1])
    rec.run(settle_steps, q_cmd[-1])
    return Tracked(
        t_s=t_s,
        q_cmd=q_cmd,
        q_act=q_act,
        window_track=None,
        q_final=world.state(),
        duration_s=M * steps_per_waypoint * world.dt_s,
        steps_logged=steps_per_waypoint,
    )


def retimed(
    world: SimWorld,
    reach_m: Array | None,
    path: Array,
    q_start: Array,
    start_offset: float,
    timing: str,
    recheck_step: float,
    grid_per_knot: int,
    interpolant: str,
    notes: list[str],
) -> Trajectory | None:
    """The path retimed by TOPP-RA (:func:`~plannerlab.sim.retime.retime`) from where the arm
    really is (``timing="toppra"``), or None: ``"waypoints"``, or retiming failed (``notes``
    says why). ``reach_m``: the robot's joint reach bounds (None: computed here)."""
    if timing == "waypoints":
        return None
    if timing != "toppra":
        raise PlannerlabError(f"timing: expected 'toppra' or 'waypoints', got {timing!r}")
    robot = world.robot
    # The path continues from where the arm really is (carried over from the previous
    # leg: a short move to the path's first state is prepended).
    q_path = unwrap_path(path, np.asarray(robot.continuous, dtype=bool), q_from=q_start)
    if start_offset > 1e-9:
        q_path = np.vstack([q_start[None, :], q_path])
    try:
        return retime(
            q_path,
            velocity_limit=world.max_velocity,
            effort_limit=world.max_force,
            inverse_dynamics=world.inverse_dynamics,
            knot_step=recheck_step,
            grid_per_knot=grid_per_knot,
            reach_m=reach_m if reach_m is not None else joint_reach_m(robot),
            to_urdf=world.to_urdf,
            interpolant=interpolant,
        )
    except Exception as exc:  # toppra or the simulator's inverse dynamics
        notes.append(f"not retimed ({exc}); executed along densified waypoints")
        return None


__all__ = [
    "LOG_EVERY_STEPS",
    "TRACK_POSITION_GAIN",
    "retimed",
    "StepRecorder",
    "Tracked",
    "track_trajectory",
    "track_waypoints",
]

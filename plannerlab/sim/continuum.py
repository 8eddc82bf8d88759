"""Executing a ``chord_arc`` plan in PyBullet and sorting its contacts.

The ``chord_arc`` planner (:mod:`plannerlab.planners.chord_arc`) is the one planner whose
paths touch obstacles on purpose: its robot bears on the problem's collision points
(obstacle corners) and is pushed on past them. :func:`execute_chord_arc` drives the
simulated link chain (a :class:`plannerlab.sim.SimWorld`, position control) along the
chosen solution's joint path (the push-and-bend motion sequence), reads every contact
point after every physics step and classifies it:

* **expected**: a robot link touching the obstacle that owns one of the *chosen*
  solution's collision points, with the contact point within ``tolerance_m`` of that
  collision point (in the robot's plane). The default is the planner's
  ``contact_plan.contact_tolerance_m`` = 2·link radius + ``contact_slack_m`` (10 mm): the
  capsule's axis passes through the corner, so the capsule overlaps the obstacle there by
  up to one radius, and when the robot meets the corner at a shallow angle ``α`` to one of
  its edges the overlap runs ``r / tan(α)`` along that edge (measured up to 7.6 mm for
  the three paper cases with r = 2 mm);
* **guided**: a link touching one of the problem's guide obstacles
  (``[continuum] guide_obstacles``, the insertion sleeve behind the port): the chain
  slides in its channel and may rub its walls; counted as expected;
* **unexpected**: anything else: another obstacle, the same obstacle elsewhere, and
  every self-contact. One unexpected contact point makes the execution a failure.

Every point is classified (not only the deepest per pair); per (link, other, verdict)
the deepest point is kept. Points count from a penetration depth above ``min_depth_m``
(0: touching, as :mod:`plannerlab.sim.execute`).

**Constraint solver (what fixed the tip error).** The chain's links are light (10 g,
12.5 mm: rotational inertia ~1e-7 kg·m²) while the first joint carries the whole chain,
and 41 position motors act in series. PyBullet's default iterative solver (projected
Gauss-Seidel, 50 iterations) does not converge on such a chain: the motors' constraint
rows are solved only approximately every step, the chain never comes to rest and its
joints wander by ~0.01 rad each, which put the tip 5-10 mm off the target *with every
obstacle removed* (case 1: 10.0 mm, case 2: 10.4 mm after a 1 s hold at 1/2400 s; the
error grew while holding). Higher gains, more iterations, a finer time step or a closing
correction on the joints' error only moved that around (``results/continuum.md``). A
direct solver of the mixed LCP (:data:`SOLVER` = "dantzig") solves the motors exactly:
the chain follows the joint path to 0.8 mm at the waypoints and comes to rest on the
last one, so the executed tip error is the planned one (0.04-0.13 mm from the 40-link
discretisation of the arcs) at PyBullet's usual 1/240 s step (:data:`DT_S`), 0.05 s per
waypoint, 1 s hold, PyBullet's default gains and the URDF's 100 N·m / 100 N efforts.
:func:`plannerlab.sim.execute.execute` has no solver or time-step parameter, hence the
loop here (on :class:`plannerlab.sim.world.SimWorld`).

**Contact.** The position-controlled joints impose the planned shape; contact with a
corner carries no load in this simulation. Planned for the robot's radius (the
planner's default), the capsules graze the corner: their axes pass 1.87-1.90 mm from it
on the paper's cases (the links are chords of the arcs), and PyBullet reports no
penetrating contact there.

**The record.** The result is the one execution record,
:class:`plannerlab.record.execution.Execution` (what :mod:`plannerlab.sim.execute`
returns for every other plan), so ``plannerlab execute`` and ``plannerlab continuum
--execute`` write it to the same execution file. The continuum's facts sit in its
fields: the tip error is ``final_pos_err_m`` (the final tip's distance to the leg's
target; the goals of the paper's cases constrain position only), every contact a
:class:`~plannerlab.record.execution.ContactRecord` with ``expected`` (and the nearest
``collision_point``), and the rest (chosen solution, tolerance, closest approaches) in
``extra``. ``path_valid`` is None: an FCL re-check of the path is not made here, it
reports the collision-point contacts by design; the planner's
``contact_plan.expected_contacts`` holds its classification.
:attr:`~plannerlab.record.execution.Execution.success` = the tip ends inside the goal
region, no contact is unexpected and the chain followed the path within the problem's
``[simulation] max_deviation_m``: the largest deviation of its capsules from the
commanded state (:func:`plannerlab.sim.measure.geometry_deviation_m`), measured where the
chain should have arrived, at the end of every waypoint's window and after settling.
``min_clearance_m`` is not measured (NaN): the plan touches its collision points by
design; the closest approaches to the other obstacles are in ``extra["approaches"]``.

Takes plain data (the leg's :class:`~plannerlab.record.leg.PlanResult`, from the planner
or from a plan file), imports no planner; nothing is printed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.problem.load import Problem
from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.record.leg import PlanResult
from plannerlab.robots.base import Array, as_xyz
from plannerlab.robots.paths import densify
from plannerlab.sim.measure import geometry_deviation_m
from plannerlab.sim.world import SOLVERS, Contact, SimWorld

#: physics time step [s] (PyBullet's and the Arm-Z paper's; see the module docstring)
DT_S: float = 1.0 / 240.0
#: physics steps per commanded waypoint (0.05 s; a waypoint moves at most 2 mm / 0.02 rad)
STEPS_PER_WAYPOINT: int = 12
#: physics steps holding the last waypoint (1 s)
SETTLE_STEPS: int = 240
#: PyBullet position-control gains (None: PyBullet's defaults 0.1 and 1.0)
POSITION_GAIN: float | None = None
VELOCITY_GAIN: float | None = None
#: closest approaches to the obstacles are recorded up to this distance [m]
NEAR_M: float = 1e-3
#: PyBullet constraint solver: "dantzig" (a direct MLCP solver) or "pgs" (PyBullet's
#: default iterative projected Gauss-Seidel); see the module docstring
SOLVER: str = "dantzig"
#: PyBullet constraint-solver iterations per step (None: PyBullet's default, 50)
SOLVER_ITERATIONS: int | None = None


def classify_point(
    contact: Contact,
    points_m: Mapping[int, tuple[float, float]],
    owners: Mapping[int, str],
    tolerance_m: float,
) -> tuple[bool, int | None, float | None]:
    """(expected, nearest collision point on that obstacle, its planar distance [m]).

    Args:
        contact: one contact point from :meth:`plannerlab.sim.SimWorld.contacts`.
        points_m: collision point index -> (x, y) [m] of the chosen solution.
        owners: collision point index -> name of the obstacle it lies on.
        tolerance_m: largest planar distance from the contact point [m].
    """
    best: tuple[float, int | None] = (math.inf, None)
    if not contact.other_is_link:
        p = np.asarray(contact.p_world_m[:2])
        for i, q in points_m.items():
            if owners[i] == contact.other_name:
                d = float(np.linalg.norm(p - np.asarray(q)))
                if d < best[0]:
                    best = (d, i)
    if best[1] is None:
        return False, None, None
    return best[0] <= tolerance_m, best[1], best[0]


def densify_chord_arc_path(path: Array, settings: Mapping[str, Any]) -> Array:
    """The joint path as the planner sampled it, from its waypoints.

    A plan file stores a path as its waypoints (states inside a straight joint-space
    segment left out: the straight chain sliding through the sleeve is one such segment).
    The planner's path moves the insertion by at most ``path_step_m`` and every bend
    joint by at most ``path_joint_step_rad`` per waypoint; every segment is cut to those
    steps again (joint 0 is the insertion [m], the rest bend joints [rad]). A path that
    already keeps to them comes back unchanged (its steps may exceed them by the
    planner's 1e-9 refinement slack; 1e-6 is allowed).

    Args:
        path: (m, dof) joint path.
        settings: the plan's settings (:attr:`PlanResult.settings` of ``chord_arc``); a
            path without ``path_step_m`` and ``path_joint_step_rad`` is returned as is.
    """
    path = np.atleast_2d(np.asarray(path, dtype=float))
    if "path_step_m" not in settings or "path_joint_step_rad" not in settings:
        return path
    steps = np.full(path.shape[1], float(settings["path_joint_step_rad"]))
    steps[0] = float(settings["path_step_m"])
    if not np.all(steps > 0):
        raise PlannerlabError(
            f"settings path_step_m and path_joint_step_rad must be positive, got "
            f"{steps[0]}, {steps[-1]}"
        )
    slack = 1.0 + 1e-6
    if len(path) < 2 or np.max(np.abs(np.diff(path, axis=0)) / steps) <= slack:
        return path
    scaled, _ = densify(path / steps, slack, np.zeros(path.shape[1], dtype=bool))
    return scaled * steps


def _note_approaches(
    world: Any,
    watched: Mapping[int, str],
    points: Mapping[int, tuple[float, float]],
    owners: Mapping[int, str],
    tol: float,
    near_m: float,
    closest: dict[str, dict[str, Any]],
) -> None:
    """Update ``closest`` (per obstacle name) with the chain's closest points to each
    watched obstacle within ``near_m``, and the nearest chosen collision point."""
    for uid, name in watched.items():
        for pt in world.client.getClosestPoints(world.body, uid, near_m):
            d = float(pt[8])
            rec = closest.get(name)
            if rec is not None and d >= rec["distance_m"]:
                continue
            p = tuple(float(v) for v in pt[5])
            best = min(
                (
                    (float(np.hypot(p[0] - xy[0], p[1] - xy[1])), i)
                    for i, xy in points.items()
                    if owners[i] == name
                ),
                default=(math.inf, None),
            )
            closest[name] = {
                "obstacle": name,
                "distance_m": d,
                "link": world.link_name(pt[3])[0],
                "p_world_m": list(p),
                "collision_point": best[1],
                "point_distance_m": None if best[1] is None else best[0],
                "at_collision_point": best[0] <= tol,
            }


def _contact_records(
    seen: Mapping[tuple[str, str, bool, bool], list[Any]],
) -> tuple[ContactRecord, ...]:
    """The contact pairs seen, in order of their first time: (link, other, other is a
    link, expected) -> [deepest depth, first time, point, collision point, distance]."""
    return tuple(
        ContactRecord(
            link_name=link,
            other_name=other,
            other_is_link=is_link,
            max_depth_m=float(rec[0]),
            first_time_s=float(rec[1]),
            p_world_m=as_xyz(rec[2]),
            expected=ok,
            collision_point=rec[3],
            distance_m=None if rec[4] is None else float(rec[4]),
        )
        for (link, other, is_link, ok), rec in sorted(seen.items(), key=lambda kv: kv[1][1])
    )


def _verdict_words(
    contacts: Sequence[ContactRecord],
    closest: Mapping[str, Mapping[str, Any]],
    points: Sequence[int],
    tip_err_m: float,
    reached: bool,
    pos_tol_m: float,
) -> list[str]:
    """The execution's reason in words: the tip, the expected and unexpected contacts,
    the closest approach to each watched obstacle."""
    unexpected = [c for c in contacts if not c.expected]
    words = [
        f"tip {tip_err_m * 1e3:.3g} mm from the target"
        + ("" if reached else f" (outside the {pos_tol_m * 1e3:g} mm goal region)"),
        f"{len(contacts) - len(unexpected)} expected contact pair(s) at collision "
        f"point(s) {list(points)}",
    ]
    if unexpected:
        u = max(unexpected, key=lambda c: c.max_depth_m)
        if u.other_is_link:
            where = "self-contact"
        elif u.distance_m is None:
            where = "no chosen collision point on it"
        else:
            where = f"{u.distance_m * 1e3:.3g} mm from point {u.collision_point}"
        words.append(
            f"{len(unexpected)} UNEXPECTED, deepest {u.link_name} x {u.other_name} "
            f"{u.max_depth_m * 1e3:.2g} mm at "
            f"{np.round(u.p_world_m[:2], 4).tolist()} ({where})"
        )
    else:
        words.append("no unexpected contact")
    for name in sorted(closest):
        a = closest[name]
        where = (
            f"at collision point {a['collision_point']}"
            if a["at_collision_point"]
            else "AWAY from the collision points"
        )
        words.append(f"closest to {name}: {a['distance_m'] * 1e3:.2f} mm, {where}")
    return words


@dataclass(frozen=True)
class _ContactRules:
    """How a contact is judged: the chosen collision points (index -> (x, y) [m]), the
    obstacle each lies on, the tolerance [m] and the guide obstacles."""

    points: Mapping[int, tuple[float, float]]
    owners: Mapping[int, str]
    tol: float
    guides: frozenset[str]


@dataclass(frozen=True)
class _Run:
    """What one simulated run of a path gave (see :func:`_simulate`)."""

    q_act: Array
    t_s: Array
    q_start: Array
    q_final: Array
    sim_time_s: float
    gravity_mps2: tuple[float, float, float]
    seen: dict[tuple[str, str, bool, bool], list[Any]]
    closest: dict[str, dict[str, Any]]


def _simulate(
    problem: Problem,
    path: Array,
    rules: _ContactRules,
    *,
    gravity_mps2: tuple[float, float, float],
    dt_s: float,
    steps_per_waypoint: int,
    settle_steps: int,
    position_gain: float | None,
    velocity_gain: float | None,
    solver: str,
    solver_iterations: int | None,
    min_depth_m: float,
    near_m: float,
    gui: bool,
) -> _Run:
    """Run ``path`` in a fresh world: each waypoint for ``steps_per_waypoint`` steps, then
    ``settle_steps``; every contact judged by ``rules`` at every step, the closest
    approaches read after every waypoint."""
    seen: dict[tuple[str, str, bool, bool], list[Any]] = {}
    closest: dict[str, dict[str, Any]] = {}
    q_act = np.empty_like(path)
    t_s = np.empty(len(path))
    robot = problem.robot
    points, owners, tol, guides = rules.points, rules.owners, rules.tol, rules.guides
    with SimWorld(
        robot,
        problem.scene,
        gui=gui,
        dt_s=dt_s,
        gravity_mps2=gravity_mps2,
        position_gain=position_gain,
        velocity_gain=velocity_gain,
    ) as world:

        def run(n: int) -> None:
            for _ in range(n):
                world.step(1)
                t = world.steps_taken * world.dt_s
                for c in world.contacts(min_depth_m=min_depth_m):
                    if not c.other_is_link and c.other_name in guides:
                        ok, near, dist = True, None, None  # sliding in the sleeve
                    else:
                        ok, near, dist = classify_point(c, points, owners, tol)
                    key = (c.link_name, c.other_name, c.other_is_link, ok)
                    rec = seen.get(key)
                    if rec is None:
                        seen[key] = [c.depth_m, t, c.p_world_m, near, dist]
                    elif c.depth_m > rec[0]:
                        rec[0], rec[2], rec[3], rec[4] = c.depth_m, c.p_world_m, near, dist

        world.client.setPhysicsEngineParameter(constraintSolverType=SOLVERS[solver])
        if solver_iterations is not None:
            world.client.setPhysicsEngineParameter(numSolverIterations=int(solver_iterations))
        watched = {uid: n for uid, n in world.obstacle_names.items() if n not in guides}

        def approach() -> None:
            _note_approaches(world, watched, points, owners, tol, near_m, closest)

        world.reset(path[0])
        steps0 = world.steps_taken
        q_start = world.state()
        for k, q in enumerate(path):
            world.command(q)
            run(steps_per_waypoint)
            approach()
            q_act[k] = world.state()
            t_s[k] = (world.steps_taken - steps0) * world.dt_s
        run(settle_steps)
        q_final = world.state()
        sim_time = (world.steps_taken - steps0) * world.dt_s
        gravity_used = world.gravity_mps2

    return _Run(q_act, t_s, q_start, q_final, sim_time, gravity_used, seen, closest)


def execute_chord_arc(
    problem: Problem,
    result: PlanResult,
    *,
    tolerance_m: float | None = None,
    dt_s: float = DT_S,
    steps_per_waypoint: int = STEPS_PER_WAYPOINT,
    settle_steps: int = SETTLE_STEPS,
    position_gain: float | None = POSITION_GAIN,
    velocity_gain: float | None = VELOCITY_GAIN,
    solver: str = SOLVER,
    solver_iterations: int | None = SOLVER_ITERATIONS,
    min_depth_m: float = 0.0,
    near_m: float = NEAR_M,
    gravity_mps2: tuple[float, float, float] | None = None,
    gui: bool = False,
) -> Execution:
    """Execute a ``chord_arc`` leg's joint path in PyBullet and classify its contacts.

    Plain data in (no planner import): the leg's :class:`PlanResult`, as the planner
    returned it or as :meth:`plannerlab.record.plan.Plan.load` read it back (its path is
    cut to the planner's steps again, :func:`densify_chord_arc_path`). The world is reset
    to the path's first state (the retracted robot); each waypoint is commanded for
    ``steps_per_waypoint`` steps of ``dt_s``, the last one held for ``settle_steps``.

    Returns:
        the one execution record, :class:`Execution`, with ``timing = "waypoints"``:
        ``path_valid`` None (no FCL re-check: the path touches the collision points by
        design, the planner classified its contacts), every contact a
        :class:`ContactRecord` with ``expected`` / ``collision_point`` / ``distance_m``,
        the tip error in ``final_pos_err_m``, the per-waypoint log (``track_err_rad``
        mixes the bend joints [rad] and the insertion [m]) and in ``extra``:
        ``executor`` ("chord_arc"), ``chosen``, ``collision_points_used``,
        ``contact_tolerance_m``, ``guide_obstacles``, ``solver``, ``solver_iterations``
        and ``approaches``: per obstacle (guides excepted) that the chain came within
        ``near_m`` of, the closest approach over the waypoints: ``obstacle``,
        ``distance_m`` (negative: penetration), ``link``, ``p_world_m`` (on the link),
        ``collision_point`` (nearest chosen one on that obstacle, or None),
        ``point_distance_m`` and ``at_collision_point`` (within the tolerance). With
        position-controlled joints contact carries no load, so a plan for the robot's
        radius grazes its corners: this shows where.

    Args:
        problem: the problem the plan was made for.
        result: the leg: its ``path``, ``leg``, ``settings`` and ``contact_plan`` (the
            chosen solution's collision points and their obstacles, the contact
            tolerance, the guide obstacles).
        tolerance_m: expected-contact radius [m]; default the contact plan's
            ``contact_tolerance_m``.
        dt_s: physics time step [s].
        steps_per_waypoint: physics steps per waypoint.
        settle_steps: physics steps holding the last waypoint.
        position_gain, velocity_gain: PyBullet's position-control gains (see
            :data:`POSITION_GAIN`); None keeps PyBullet's defaults (0.1, 1.0).
        solver: the constraint solver (:data:`SOLVERS`).
        solver_iterations: PyBullet's constraint-solver iterations per step (None: its
            default).
        min_depth_m: penetration depth above which a contact point counts [m].
        near_m: after every waypoint, the chain's closest points to every obstacle
            but the guides are read up to this distance [m].
        gravity_mps2: default: the problem's ``[simulation] gravity_mps2``.
        gui: PyBullet's GUI instead of DIRECT.

    Raises:
        PlannerlabError: no chosen solution in a ``contact_plan`` (not a chord_arc plan, or
            nothing was solved), a path of the wrong shape, or a bad parameter.
    """
    t0 = time.perf_counter()
    contact_plan = result.contact_plan
    sol = None if contact_plan is None else contact_plan.chosen_solution
    if contact_plan is None or sol is None:
        raise PlannerlabError(
            f"{problem.name} leg {result.leg}: execute_chord_arc needs a chord_arc plan "
            "with a chosen solution (its contact_plan); "
            f"this leg is {result.status.value}"
        )
    chosen = contact_plan.chosen
    if solver not in SOLVERS:
        raise PlannerlabError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
    if steps_per_waypoint < 1 or settle_steps < 0 or not dt_s > 0:
        raise PlannerlabError(
            f"need dt_s > 0, steps_per_waypoint >= 1, settle_steps >= 0; "
            f"got {dt_s}, {steps_per_waypoint}, {settle_steps}"
        )
    robot = problem.robot
    leg = result.leg
    path = np.asarray(result.path, dtype=float)
    if path.ndim != 2 or path.shape[1] != robot.dof or len(path) < 1:
        raise PlannerlabError(
            f"path must be (m >= 1, {robot.dof}) for {problem.name}, got {path.shape}"
        )
    path = densify_chord_arc_path(path, result.settings)
    tol = float(contact_plan.contact_tolerance_m if tolerance_m is None else tolerance_m)
    idx = list(sol.contact_indices)
    points = dict(zip(idx, sol.contact_points_m, strict=True))
    owners = dict(zip(idx, sol.contact_obstacles, strict=True))
    goal = problem.goal(leg)
    gravity = problem.simulation.gravity_mps2 if gravity_mps2 is None else gravity_mps2
    guides = frozenset(contact_plan.guide_obstacles)

    tips_cmd = robot.tip(path)[0]
    run = _simulate(
        problem,
        path,
        _ContactRules(points, owners, tol, guides),
        gravity_mps2=gravity,
        dt_s=dt_s,
        steps_per_waypoint=steps_per_waypoint,
        settle_steps=settle_steps,
        position_gain=position_gain,
        velocity_gain=velocity_gain,
        solver=solver,
        solver_iterations=solver_iterations,
        min_depth_m=min_depth_m,
        near_m=near_m,
        gui=gui,
    )
    seen, closest = run.seen, run.closest
    q_act, t_s, q_start, q_final = run.q_act, run.t_s, run.q_start, run.q_final
    sim_time, gravity_used = run.sim_time_s, run.gravity_mps2
    tip_track = np.linalg.norm(robot.tip(q_act)[0] - tips_cmd, axis=1)
    # The deviation where the chain should have arrived: the end of every waypoint's
    # window, and after settling (each waypoint moves it by at most path_step_m).
    deviation = geometry_deviation_m(robot, path, q_act)
    final_dev = float(geometry_deviation_m(robot, path[-1], q_final)[0])
    worst = int(np.argmax(deviation))
    max_dev, max_dev_t = float(deviation[worst]), float(t_s[worst])
    if final_dev > max_dev:
        max_dev, max_dev_t = final_dev, float(sim_time)
    dev_limit = problem.simulation.max_deviation_m
    track = np.max(np.abs(q_act - path), axis=1)
    pe, ae = goal.errors(robot, q_final)
    tip_err = float(pe)
    reached = bool(goal.contains(robot, q_final))
    contacts = _contact_records(seen)
    words = _verdict_words(contacts, closest, sorted(points), tip_err, reached, goal.pos_tol_m)
    track_limit = problem.simulation.max_track_err_rad
    words.append(f"deviation <= {max_dev * 1e3:.3g} mm")
    if max_dev > dev_limit:
        words.append(
            f"the chain strayed {max_dev * 1e3:.3g} mm from the commanded state at "
            f"t = {max_dev_t:.3f} s (limit {dev_limit * 1e3:g} mm, [simulation] "
            "max_deviation_m)"
        )
    return Execution(
        problem=problem.name,
        leg=leg,
        goal=goal.name,
        path_valid=None,
        recheck_joint_step=math.nan,
        recheck_states=0,
        recheck_first_invalid_edge=None,
        recheck_pairs=(),
        waypoint_step=float(np.max(np.abs(np.diff(path, axis=0)), initial=0.0)),
        steps_per_waypoint=int(steps_per_waypoint),
        settle_steps=int(settle_steps),
        dt_s=float(dt_s),
        contact_tol_m=float(min_depth_m),
        gravity_mps2=gravity_used,
        t_s=t_s,
        q_cmd_rad=path,
        q_actual_rad=q_act,
        track_err_rad=track,
        tip_track_err_m=tip_track,
        contacts=contacts,
        q_start_rad=q_start,
        carried_over=False,
        start_offset_rad=float(np.max(np.abs(q_start - path[0]), initial=0.0)),
        q_final_rad=q_final,
        final_track_err_rad=float(np.max(np.abs(q_final - path[-1]), initial=0.0)),
        final_tip_track_err_m=float(np.linalg.norm(robot.tip(q_final)[0] - tips_cmd[-1])),
        final_pos_err_m=tip_err,
        final_angle_err_deg=float(ae),
        goal_reached=reached,
        sim_time_s=float(sim_time),
        wall_time_s=time.perf_counter() - t0,
        reason="; ".join(words),
        track_err_limit_rad=track_limit,
        timing="waypoints",
        duration_s=len(path) * steps_per_waypoint * float(dt_s),
        deviation_m=deviation,
        max_deviation_m=max_dev,
        max_deviation_time_s=max_dev_t,
        max_deviation_limit_m=dev_limit,
        solver=solver,
        extra={
            "executor": "chord_arc",
            "chosen": chosen,
            "collision_points_used": idx,
            "contact_tolerance_m": tol,
            "guide_obstacles": sorted(guides),
            "solver": solver,
            "solver_iterations": solver_iterations,
            "approaches": [closest[n] for n in sorted(closest)],
        },
    )


__all__ = [
    "DT_S",
    "SETTLE_STEPS",
    "STEPS_PER_WAYPOINT",
    "classify_point",
    "densify_chord_arc_path",
    "execute_chord_arc",
]

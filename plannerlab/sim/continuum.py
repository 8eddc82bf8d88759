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
  ``extra["contact_tolerance_m"]`` = 2·link radius + ``contact_margin_m`` (10 mm): the
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

The tip error is the final tip's distance to the leg's target (the goals of the paper's
cases constrain position only). :attr:`ContinuumExecution.success` = the tip ends inside
the goal region and no contact is unexpected. An FCL re-check of the path is not made
here: it reports the collision-point contacts by design; the planner's
``extra["expected_contacts"]`` holds its classification.

Takes plain data (the path and the plan's ``extra``), imports no planner; nothing is
printed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pybullet

from plannerlab.errors import PlannerlabError
from plannerlab.problem.load import Problem
from plannerlab.robots.base import as_xyz
from plannerlab.sim.world import Contact, SimWorld

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
APPROACH_M: float = 1e-3
#: PyBullet constraint solver: "dantzig" (a direct MLCP solver) or "pgs" (PyBullet's
#: default iterative projected Gauss-Seidel); see the module docstring
SOLVER: str = "dantzig"
SOLVERS: dict[str, int] = {
    "pgs": pybullet.CONSTRAINT_SOLVER_LCP_SI,
    "dantzig": pybullet.CONSTRAINT_SOLVER_LCP_DANTZIG,
}
#: PyBullet constraint-solver iterations per step (None: PyBullet's default, 50)
SOLVER_ITERATIONS: int | None = None


@dataclass(frozen=True)
class ClassifiedContact:
    """The deepest contact point of one (robot link, other, verdict) during the execution.

    Attributes:
        link_name, other_name, other_is_link: the pair (see :class:`plannerlab.sim.Contact`).
        expected: at one of the chosen solution's collision points.
        p_world_m: (3,) deepest such contact point on the link [m].
        max_depth_m: its penetration depth [m].
        first_time_s: simulated time the pair was first seen with this verdict [s].
        points: contact points (steps × points) with this verdict.
        collision_point: index (into the problem's collision points) of the nearest
            collision point on that obstacle at the deepest point, or None.
        distance_m: planar distance from ``p_world_m`` to that point [m] (None if none).
    """

    link_name: str
    other_name: str
    other_is_link: bool
    expected: bool
    p_world_m: tuple[float, float, float]
    max_depth_m: float
    first_time_s: float
    points: int
    collision_point: int | None
    distance_m: float | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "link_name": self.link_name,
            "other_name": self.other_name,
            "other_is_link": self.other_is_link,
            "expected": self.expected,
            "p_world_m": list(self.p_world_m),
            "max_depth_m": self.max_depth_m,
            "first_time_s": self.first_time_s,
            "points": self.points,
            "collision_point": self.collision_point,
            "distance_m": self.distance_m,
        }


def _num(v: float | None) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


@dataclass(frozen=True)
class ContinuumExecution:
    """What the chosen chord_arc solution did in PyBullet.

    Attributes:
        problem, leg, goal: what was executed.
        chosen: index of the executed solution in the plan's ``extra["solutions"]``.
        collision_points_used: indices of its collision points.
        tolerance_m: contacts within this of one of them are expected [m].
        tip_error_m: final tip distance to the target [m].
        goal_reached: final tip inside the goal region.
        max_tip_track_err_m: largest commanded-vs-actual tip distance at the waypoints [m].
        final_track_err: largest |q_cmd − q| after settling [rad; m for the insertion].
        q_final: the state reached at the end.
        contacts: every (link, other, verdict) seen, deepest point each.
        approaches: per obstacle (guides excepted) that the chain came within
            ``approach_m`` of, the closest approach over the waypoints: ``obstacle``,
            ``distance_m`` (negative: penetration), ``link``, ``p_world_m`` (on the
            link), ``collision_point`` (nearest chosen one on that obstacle, or None) and
            ``point_distance_m``, and ``at_collision_point`` (within ``tolerance_m``).
            With position-controlled joints contact carries no load, so a plan for the
            robot's radius grazes its corners: this shows where.
        waypoints, dt_s, steps_per_waypoint, settle_steps: how it was run.
        sim_time_s, wall_time_s: duration.
        reason: the verdict in words.
    """

    problem: str
    leg: int
    goal: str
    chosen: int
    collision_points_used: tuple[int, ...]
    tolerance_m: float
    tip_error_m: float
    goal_reached: bool
    max_tip_track_err_m: float
    final_track_err: float
    q_final: tuple[float, ...]
    contacts: tuple[ClassifiedContact, ...]
    approaches: tuple[dict[str, Any], ...]
    waypoints: int
    dt_s: float
    steps_per_waypoint: int
    settle_steps: int
    sim_time_s: float
    wall_time_s: float
    reason: str

    @property
    def expected_contacts(self) -> tuple[ClassifiedContact, ...]:
        return tuple(c for c in self.contacts if c.expected)

    @property
    def unexpected_contacts(self) -> tuple[ClassifiedContact, ...]:
        return tuple(c for c in self.contacts if not c.expected)

    @property
    def success(self) -> bool:
        """The tip reached the goal region and every contact was expected."""
        return self.goal_reached and not self.unexpected_contacts

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able data (non-finite numbers become None)."""
        return {
            "problem": self.problem,
            "leg": self.leg,
            "goal": self.goal,
            "chosen": self.chosen,
            "collision_points_used": list(self.collision_points_used),
            "tolerance_m": self.tolerance_m,
            "tip_error_m": _num(self.tip_error_m),
            "goal_reached": self.goal_reached,
            "max_tip_track_err_m": _num(self.max_tip_track_err_m),
            "final_track_err": _num(self.final_track_err),
            "q_final": list(self.q_final),
            "contacts": [c.to_dict() for c in self.contacts],
            "approaches": [dict(a) for a in self.approaches],
            "expected": len(self.expected_contacts),
            "unexpected": len(self.unexpected_contacts),
            "success": self.success,
            "waypoints": self.waypoints,
            "dt_s": self.dt_s,
            "steps_per_waypoint": self.steps_per_waypoint,
            "settle_steps": self.settle_steps,
            "sim_time_s": self.sim_time_s,
            "wall_time_s": self.wall_time_s,
            "reason": self.reason,
        }


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


def execute_chord_arc(
    problem: Problem,
    path: Any,
    extra: Mapping[str, Any],
    *,
    leg: int = 0,
    tolerance_m: float | None = None,
    dt_s: float = DT_S,
    steps_per_waypoint: int = STEPS_PER_WAYPOINT,
    settle_steps: int = SETTLE_STEPS,
    position_gain: float | None = POSITION_GAIN,
    velocity_gain: float | None = VELOCITY_GAIN,
    solver: str = SOLVER,
    solver_iterations: int | None = SOLVER_ITERATIONS,
    min_depth_m: float = 0.0,
    approach_m: float = APPROACH_M,
    gravity_mps2: tuple[float, float, float] | None = None,
    gui: bool = False,
) -> ContinuumExecution:
    """Execute a ``chord_arc`` plan's joint path in PyBullet and classify its contacts.

    Plain data in (no planner import): the path and the plan's ``extra`` (a
    :attr:`plannerlab.planners.base.PlanResult.extra` of the ``chord_arc`` planner, or
    the same mapping read back from a plan file). The world is reset to the path's first
    state (the retracted robot); each waypoint is commanded for ``steps_per_waypoint``
    steps of ``dt_s``, the last one held for ``settle_steps``. The path is not densified
    further (it moves at most the planner's ``path_step_m`` / ``path_joint_step_rad`` per
    waypoint).

    Args:
        problem: the problem the plan was made for.
        path: (m, dof) joint path of the chosen solution.
        extra: the plan's extra data: ``chosen``, ``solutions`` (its
            ``contact_indices``, ``contact_points_m``, ``contact_obstacles``),
            ``contact_tolerance_m`` and ``guide_obstacles`` (names; optional).
        leg: the leg the path was planned for (its goal gives the tip error).
        tolerance_m: expected-contact radius [m]; default ``extra["contact_tolerance_m"]``.
        dt_s: physics time step [s].
        steps_per_waypoint: physics steps per waypoint.
        settle_steps: physics steps holding the last waypoint.
        position_gain, velocity_gain: PyBullet's position-control gains (see
            :data:`POSITION_GAIN`); None keeps PyBullet's defaults (0.1, 1.0).
        solver: the constraint solver (:data:`SOLVERS`).
        solver_iterations: PyBullet's constraint-solver iterations per step (None: its
            default).
        min_depth_m: penetration depth above which a contact point counts [m].
        approach_m: after every waypoint, the chain's closest points to every obstacle
            but the guides are read up to this distance [m] (see
            :attr:`ContinuumExecution.approaches`).
        gravity_mps2: default: the problem's ``[simulation] gravity_mps2``.
        gui: PyBullet's GUI instead of DIRECT.

    Raises:
        PlannerlabError: no chosen solution in ``extra`` (not a chord_arc plan, or
            nothing was solved), a path of the wrong shape, or a bad parameter.
    """
    t0 = time.perf_counter()
    chosen = extra.get("chosen") if isinstance(extra, Mapping) else None
    if chosen is None or "solutions" not in extra:
        raise PlannerlabError(
            "execute_chord_arc needs a chord_arc plan with a chosen solution "
            "(extra['chosen'] and extra['solutions'])"
        )
    if solver not in SOLVERS:
        raise PlannerlabError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
    if steps_per_waypoint < 1 or settle_steps < 0 or not dt_s > 0:
        raise PlannerlabError(
            f"need dt_s > 0, steps_per_waypoint >= 1, settle_steps >= 0; "
            f"got {dt_s}, {steps_per_waypoint}, {settle_steps}"
        )
    robot = problem.robot
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != robot.dof or len(path) < 1:
        raise PlannerlabError(
            f"path must be (m >= 1, {robot.dof}) for {problem.name}, got {path.shape}"
        )
    sol = extra["solutions"][int(chosen)]
    tol = float(extra["contact_tolerance_m"] if tolerance_m is None else tolerance_m)
    idx = [int(i) for i in sol["contact_indices"]]
    points = {
        i: (float(p[0]), float(p[1])) for i, p in zip(idx, sol["contact_points_m"], strict=True)
    }
    owners = dict(zip(idx, sol["contact_obstacles"], strict=True))
    goal = problem.goal(leg)
    gravity = problem.simulation.gravity_mps2 if gravity_mps2 is None else gravity_mps2
    guides = frozenset(str(n) for n in extra.get("guide_obstacles", ()))

    seen: dict[tuple[str, str, bool, bool], list[Any]] = {}
    closest: dict[str, dict[str, Any]] = {}
    tips_cmd = robot.tip(path)[0]
    tip_track = np.empty(len(path))
    with SimWorld(
        robot,
        problem.scene,
        gui=gui,
        dt_s=dt_s,
        gravity_mps2=gravity,
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
                        seen[key] = [c.depth_m, t, c.p_world_m, 1, near, dist]
                    else:
                        rec[3] += 1
                        if c.depth_m > rec[0]:
                            rec[0], rec[2], rec[4], rec[5] = c.depth_m, c.p_world_m, near, dist

        world.client.setPhysicsEngineParameter(constraintSolverType=SOLVERS[solver])
        if solver_iterations is not None:
            world.client.setPhysicsEngineParameter(numSolverIterations=int(solver_iterations))
        watched = {uid: n for uid, n in world.obstacle_names.items() if n not in guides}

        def approach() -> None:
            for uid, name in watched.items():
                for pt in world.client.getClosestPoints(world.body, uid, approach_m):
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

        world.reset(path[0])
        for k, q in enumerate(path):
            world.command(q)
            run(steps_per_waypoint)
            approach()
            tip_track[k] = np.linalg.norm(robot.tip(world.state())[0] - tips_cmd[k])
        run(settle_steps)
        q_final = world.state()
        sim_time = world.steps_taken * world.dt_s

    pe, _ = goal.errors(robot, q_final)
    tip_err = float(pe)
    reached = bool(goal.contains(robot, q_final))
    contacts = tuple(
        ClassifiedContact(
            link,
            other,
            is_link,
            ok,
            as_xyz(rec[2]),
            float(rec[0]),
            float(rec[1]),
            int(rec[3]),
            rec[4],
            None if rec[5] is None else float(rec[5]),
        )
        for (link, other, is_link, ok), rec in sorted(seen.items(), key=lambda kv: kv[1][1])
    )
    unexpected = [c for c in contacts if not c.expected]
    words = [
        f"tip {tip_err * 1e3:.3g} mm from the target"
        + ("" if reached else f" (outside the {goal.pos_tol_m * 1e3:g} mm goal region)"),
        f"{len(contacts) - len(unexpected)} expected contact pair(s) at collision "
        f"point(s) {sorted(points)}",
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
    return ContinuumExecution(
        problem=problem.name,
        leg=leg,
        goal=goal.name,
        chosen=int(chosen),
        collision_points_used=tuple(idx),
        tolerance_m=tol,
        tip_error_m=tip_err,
        goal_reached=reached,
        max_tip_track_err_m=float(np.max(tip_track, initial=0.0)),
        final_track_err=float(np.max(np.abs(q_final - path[-1]), initial=0.0)),
        q_final=tuple(float(v) for v in q_final),
        contacts=contacts,
        approaches=tuple(closest[n] for n in sorted(closest)),
        waypoints=len(path),
        dt_s=float(dt_s),
        steps_per_waypoint=int(steps_per_waypoint),
        settle_steps=int(settle_steps),
        sim_time_s=float(sim_time),
        wall_time_s=time.perf_counter() - t0,
        reason="; ".join(words),
    )


__all__ = [
    "ClassifiedContact",
    "ContinuumExecution",
    "DT_S",
    "SETTLE_STEPS",
    "STEPS_PER_WAYPOINT",
    "classify_point",
    "execute_chord_arc",
]

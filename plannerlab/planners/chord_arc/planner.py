"""``chord_arc``: the continuum paper's chord-arc tree search as a plannerlab planner.

Source: ``003_d410ec97f064abf9.txt`` (digest in ``docs/papers.md`` §3). The search itself,
the contact-type check and the motion sequence live in
:mod:`.search` and :mod:`.motion` (pure functions over planar data, :mod:`.geometry`); this module
wraps them behind the planner contract ``solve(problem, leg, budget, rng) -> PlanResult``
for a :class:`~plannerlab.robots.continuum.model.ContinuumChain` problem.

Build, then solve:

* :meth:`ChordArcPlanner.query` builds the planar query from the problem: the robot's base
  port (``T_world_base``: origin, insertion direction = base x) and length, the scene's
  obstacles cut by the robot's plane z = base z (a box standing upright: a rectangle with
  its yaw; a vertical cylinder: a circle; a sphere: the circle of its cross-section; shapes
  that miss the plane are left out), the collision points of the problem file's
  ``[continuum] collision_points_m`` and the leg's goal position as the target.
* :meth:`ChordArcPlanner.solve` runs :func:`~plannerlab.planners.chord_arc.motion.
  solve_chord_arc` and turns **every** solution that survives into data, then picks one
  (``choose``) and returns its motion sequence as the joint path.

The leg's :attr:`~plannerlab.record.leg.PlanResult.contact_plan` (a
:class:`~plannerlab.record.contact_plan.ContactPlan`) is the typed record of what it found,
which the executor, the figures and the CLI read. **Every solution is returned**
(``contact_plan.solutions``: arcs, collision points used, their obstacles and contact
types), not only the first. Solutions are dropped, with the reason kept
(``contact_plan.dropped``), when

1. a contact does not behave as its type requires, or the initial push or the re-bend
   sweeps into an obstacle (the search module's motion check), or
2. the chain cannot follow the motion: a joint of the rigid-link chain would leave its
   bounds (the curve is too sharp for ``n_links`` links of ±``max_joint_rad``), or
3. the robot's thickness (the search treats it as a curve) makes it touch an obstacle
   away from the solution's collision points somewhere along the motion (below).

**The path** is the joint path (m, dof) of the chosen solution's motion sequence: each
:class:`~plannerlab.planners.chord_arc.motion.MotionStep` is sampled so that neither the
robot's inserted length nor the last arc's length changes by more than ``path_step_m``
between waypoints, and no joint by more than ``path_joint_step_rad`` (resampled finer if
it would), and every shape is mapped to joints by ``ContinuumChain.q_from_arcs`` (the
leftover length stays straight behind the port). The path starts at the retracted,
straight robot (insertion 0, every joint 0): ``q_start`` must be that state.

**Robot thickness.** By default (``inflate_by_radius = True``) the search plans the
chain's *axis*: obstacles grown by the link radius r (:func:`grow_query`), collision
points moved out of their obstacle by r, so that the capsules graze the corners instead
of cutting them, and a returned solution is one the 2 mm robot can execute. With
``inflate_by_radius = False`` the search is the paper's: the robot is a curve through
the corners. The two differ on the paper's case 2 only: 1 solution instead of the
paper's 2, because the lost one's curve meets the wall's lower right corner and the
post's lower left corner at shallow angles, where a 2 mm robot along it would overlap
their edges for several millimetres (:func:`thickness_cuts`; ``results/continuum.md``).

**Contact is allowed by design.** The curve passes *through* each collision point (an
obstacle corner; with ``inflate_by_radius``, r from it), so the chain's capsules
(radius r) overlap or touch the obstacle there while the robot bears on it and slides
past it. The FCL re-check of this path (e.g.
:func:`plannerlab.sim.execute.execute`'s ``path_valid``, or the shared planner check's
"every edge collision-free") therefore reports collisions at those points. This planner
is the one contact-permitting planner: :attr:`ChordArcPlanner.allows_contact` is True.
During ``solve`` every state of every surviving solution's path is checked in one
batched call (:func:`capsule_distances`: every state × link × obstacle; the robot and
the obstacles' cuts lie in one plane, so a capsule touches an obstacle exactly when its
axis comes closer than r to the cut; it gives the same pairs as python-fcl state by
state, 30-40 times faster); a touching (link, obstacle) pair is *expected* when the
link's axis passes within ``contact_tolerance_m`` (= 2·r + ``contact_slack_m``) of one
of the solution's collision points on that obstacle; ``contact_plan.expected_contacts``
lists the chosen solution's expected pairs. Any other touching pair drops the solution
(3. above). Every state checked counts as one of ``collision_checks``.

**Budget.** ``iterations`` = bases expanded by the search; ``budget.max_iterations`` caps
``max_expansions``. The search (milliseconds) is not interruptible: a ``time_limit_s``
is compared with the search time afterwards (status ``budget_exhausted`` if it was
exceeded), and the contact classification stops at ``max_collision_checks`` (status
``budget_exhausted``). The method is deterministic: ``rng`` is unused.

``trace``: the distance from the tip to the target [m] at each waypoint of the returned
path (it falls as the robot advances; flat stretches are the pushes and re-bends).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    BudgetTracker,
    PlanResult,
    Status,
    with_overrides,
)
from plannerlab.planners.chord_arc.geometry import (
    ChordArcInputError,
    ChordArcQuery,
    ChordArcSolution,
    Circle,
    PlanarObstacle,
)
from plannerlab.planners.chord_arc.motion import (
    ChordArcPlan,
    ChordArcResult,
    MotionStep,
    solve_chord_arc,
)
from plannerlab.planners.chord_arc.scene import (
    _point_segment_distance,
    capsule_distances,
    collision_points,
    grow_query,
    guide_obstacles,
    planar_obstacles,
    thickness_cuts,
)
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.record.contact_plan import (
    ContactPlan,
    ContactSolution,
    PlanarArc,
    PlanarShape,
    PlannedContact,
)
from plannerlab.robots.base import Array
from plannerlab.robots.continuum.model import ContinuumChain


@dataclass(frozen=True)
class PaperCase:
    """One row of the continuum paper's Table I (MATLAB 2019a on an i7-4790K)."""

    time_s: float
    collision_points: int
    solutions: int


#: the paper's Table I by problem name (``docs/papers.md`` §3): the one copy of it
PAPER_TABLE: dict[str, PaperCase] = {
    "continuum_case1": PaperCase(0.07, 8, 2),
    "continuum_case2": PaperCase(0.06, 6, 2),
    "continuum_case3": PaperCase(0.04, 5, 1),
}


def _shape(o: PlanarObstacle) -> PlanarShape:
    """An obstacle's cut as record data."""
    if isinstance(o, Circle):
        return PlanarShape(o.name, center_m=o.center_m, radius_m=o.radius_m)
    return PlanarShape(o.name, vertices_m=o.vertices_m)


def _solution(
    sol: ChordArcSolution,
    real: ChordArcQuery,
    *,
    plan: ChordArcPlan | None = None,
    path_waypoints: int = 0,
    expected_contacts: Sequence[PlannedContact] = (),
    reason: str = "",
    stage: str = "",
    unexpected_contacts: Sequence[PlannedContact] = (),
    cuts_radius_m: float = 0.0,
) -> ContactSolution:
    """A solution as record data; ``contact_points_m`` are the problem's collision points
    (the obstacle corners), ``axis_points_m`` where the robot's axis passes them;
    ``cuts_radius_m`` > 0 records where a robot of that radius along this zero-thickness
    curve would cut an obstacle (:func:`thickness_cuts`)."""
    cuts = thickness_cuts(real, sol, cuts_radius_m) if cuts_radius_m > 0 else np.zeros((0, 2))
    return ContactSolution(
        contact_indices=tuple(sol.contact_indices),
        contact_points_m=tuple(real.collision_points_m[i] for i in sol.contact_indices),
        axis_points_m=tuple(sol.contact_points_m),
        arcs=tuple(
            PlanarArc(a.start_xy_m, a.start_tangent, a.theta_rad, a.length_m) for a in sol.arcs
        ),
        total_length_m=sol.total_length_m,
        leftover_m=sol.leftover_m,
        contact_obstacles=() if plan is None else tuple(ck.obstacle for ck in plan.contacts),
        contact_types=() if plan is None else tuple(ck.contact_type for ck in plan.contacts),
        contact_sides=() if plan is None else tuple(ck.side for ck in plan.contacts),
        motion=() if plan is None else tuple((m.kind, m.description) for m in plan.motion),
        path_waypoints=path_waypoints,
        expected_contacts=tuple(expected_contacts),
        reason=reason,
        stage=stage,
        unexpected_contacts=tuple(unexpected_contacts),
        cuts_xy_m=tuple((float(x), float(y)) for x, y in cuts),
    )


def _candidate_solution(c: _Candidate, real: ChordArcQuery, cut_r: float) -> ContactSolution:
    """A chain-checked solution as record data: kept (its path and expected contacts) or
    dropped by the chain's check (its reason and unexpected contacts)."""
    if c.reason:
        return _solution(
            c.plan.solution,
            real,
            plan=c.plan,
            reason=c.reason,
            stage="chain",
            unexpected_contacts=c.unexpected,
            cuts_radius_m=cut_r,
        )
    return _solution(
        c.plan.solution,
        real,
        plan=c.plan,
        path_waypoints=len(c.path),
        expected_contacts=c.expected,
        cuts_radius_m=cut_r,
    )


def _empty_record(
    problem: Any, real: ChordArcQuery, query: ChordArcQuery, tol: float, inflated: bool
) -> ContactPlan:
    """The leg's contact plan before the search: the plane, the points, the tolerances."""
    robot = problem.robot
    return ContactPlan(
        base_xy_m=real.base_xy_m,
        base_tangent=real.base_tangent,
        target_xy_m=real.target_xy_m,
        obstacles=tuple(_shape(o) for o in real.obstacles),
        planning_obstacles=tuple(_shape(o) for o in query.obstacles),
        collision_points_m=real.collision_points_m,
        link_radius_m=robot.link_radius_m,
        inflated_by_m=robot.link_radius_m if inflated else 0.0,
        contact_tolerance_m=tol,
        guide_obstacles=tuple(sorted(guide_obstacles(problem))),
    )


def _search_counts(srch: Any, search_s: float) -> dict[str, Any]:
    """The search's counters as record data."""
    return {
        "time_s": search_s,
        "expansions": srch.expansions,
        "arcs_built": srch.arcs_built,
        "arcs_checked": srch.arcs_checked,
        "rejected_bend": srch.arcs_rejected_bend,
        "rejected_length": srch.arcs_rejected_length,
        "rejected_obstacle": srch.arcs_rejected_obstacle,
        "depth_reached": srch.depth_reached,
        "budget_exhausted": srch.budget_exhausted,
        "geometric_solutions": len(srch.solutions),
    }


def _nothing_kept(srch: Any, dropped: Sequence[ContactSolution], n_pts: int) -> tuple[Status, str]:
    """Status and reason of a leg without a solution to execute."""
    if not srch.solutions:
        status = Status.BUDGET_EXHAUSTED if srch.budget_exhausted else Status.FAILED
        return status, (
            f"no chord-arc shape reaches the target through the {n_pts} "
            f"collision points ({srch.expansions} expansions, depth "
            f"{srch.depth_reached}"
            + (", expansion budget used up)" if srch.budget_exhausted else ")")
        )
    why = "; ".join(d.reason for d in dropped[:3])
    return Status.FAILED, (
        f"all {len(srch.solutions)} geometric solution(s) dropped: {why}"
        + (" …" if len(dropped) > 3 else "")
    )


def _capped(settings: ChordArcSettings, max_iterations: int | None) -> ChordArcSettings:
    """``settings`` with ``max_expansions`` capped by a budget's ``max_iterations``."""
    if max_iterations is None:
        return settings
    cap = max(1, min(settings.max_expansions, int(max_iterations)))
    return dataclasses.replace(settings, max_expansions=cap)


def _steps(a: float, b: float, step: float) -> int:
    return max(1, math.ceil(abs(b - a) / step - 1e-12))


@dataclass(frozen=True)
class _Candidate:
    """A solution that survived the search's motion check, as the chain will move it."""

    plan: ChordArcPlan
    path: Array  # (m, dof)
    step_of: Array  # (m,) motion step index of each waypoint (-1: the start)
    reason: str  # why it is dropped; "" if it holds
    expected: tuple[PlannedContact, ...]
    unexpected: tuple[PlannedContact, ...]


# --------------------------------------------------------------------------- planner


class ChordArcPlanner(LegPlanner):
    """The chord-arc search as a planner (see the module docstring)."""

    #: the one contact-permitting planner: its paths touch obstacles at the problem's
    #: collision points by design, so "every edge collision-free" does not apply (its
    #: leg's context checks no start state and its tracker counts no checker).
    allows_contact: ClassVar[bool] = True

    def __init__(self, name: str, settings: ChordArcSettings) -> None:
        self.name = name
        self.settings = settings

    def with_settings(self, **changes: Any) -> ChordArcPlanner:
        """The same planner with some settings changed."""
        return ChordArcPlanner(self.name, dataclasses.replace(self.settings, **changes))

    # ------------------------------------------------------------------ build
    def query(self, problem: Any, leg: int) -> ChordArcQuery:
        """The planar query of one leg (base port, obstacles, collision points, target).

        Raises:
            PlannerlabError: not a continuum chain; a problem that cannot be cut by the
                robot's plane; missing or malformed collision points.
        """
        robot = problem.robot
        if not isinstance(robot, ContinuumChain):
            raise PlannerlabError(
                f"{self.name} plans for the continuum_chain robot, got "
                f"{getattr(robot, 'kind', type(robot).__name__)!r}"
            )
        guide_obstacles(problem)  # validated here, used when the plan is executed
        T = robot.T_world_base
        return ChordArcQuery(
            base_xy_m=(float(T[0, 3]), float(T[1, 3])),
            base_tangent=(float(T[0, 0]), float(T[1, 0])),
            total_length_m=robot.length_m,
            obstacles=planar_obstacles(problem.scene, float(T[2, 3])),
            collision_points_m=collision_points(problem),
            target_xy_m=(
                float(problem.goal(leg).p_world_m[0]),
                float(problem.goal(leg).p_world_m[1]),
            ),
        )

    def planning_query(self, problem: Any, query: ChordArcQuery) -> ChordArcQuery:
        """The query the search runs on: :func:`grow_query` by the link radius if
        ``inflate_by_radius``, else ``query`` itself."""
        if not self.settings.inflate_by_radius:
            return query
        return grow_query(query, problem.robot.link_radius_m, self.settings.boundary_tol_m)

    def search(
        self, problem: Any, leg: int, max_iterations: int | None = None
    ) -> tuple[ChordArcQuery, ChordArcResult]:
        """The problem's query (real obstacles and collision points) and the search
        module's result (search + motion check) on the planning query, e.g. for figures."""
        query = self.query(problem, leg)
        plan_q = self.planning_query(problem, query)
        return query, solve_chord_arc(plan_q, _capped(self.settings, max_iterations))

    def motion_path(
        self, robot: ContinuumChain, motion: Sequence[MotionStep]
    ) -> tuple[Array, Array]:
        """Joint path (m, dof) of a motion sequence and the step index of each waypoint.

        Starts at the retracted straight robot (all zeros); see the module docstring for
        the spacing.
        """
        s = self.settings
        states = [robot.q_from_arcs([], insertion_m=0.0)]
        owner = [-1]
        for k, step in enumerate(motion):
            (t0, l0), (t1, l1) = step.start_shape[-1], step.end_shape[-1]
            fixed = np.array(step.start_shape[:-1], dtype=float).reshape(-1, 2)
            n = _steps(l0, l1, s.path_step_m)
            for _ in range(4):  # refine until no joint jumps more than path_joint_step_rad
                a = np.linspace(0.0, 1.0, n + 1)[:, None]
                th = np.hstack(
                    [np.broadcast_to(fixed[:, 0], (n + 1, len(fixed))), t0 + a * (t1 - t0)]
                )
                ln = np.hstack(
                    [np.broadcast_to(fixed[:, 1], (n + 1, len(fixed))), l0 + a * (l1 - l0)]
                )
                Q = robot.q_from_arcs_batch(th, ln)
                jump = float(np.max(np.abs(np.diff(Q[:, 1:], axis=0)), initial=0.0))
                if jump <= s.path_joint_step_rad * (1.0 + 1e-9):
                    break
                n = math.ceil(n * jump / s.path_joint_step_rad)
            gap = np.max(np.abs(Q[0] - states[-1]))
            if gap > 1e-9:  # pragma: no cover - the search's steps are continuous
                raise PlannerlabError(
                    f"motion step {k} ({step.kind}) does not start where "
                    f"the previous one ended ({gap:.3g} apart)"
                )
            states.extend(Q[1:])
            owner.extend([k] * (len(Q) - 1))
        return np.array(states), np.array(owner, dtype=int)

    def _classify(
        self,
        robot: ContinuumChain,
        tracker: BudgetTracker,
        plan: ChordArcPlan,
        query: ChordArcQuery,
        path: Array,
        tol: float,
    ) -> tuple[list[PlannedContact], list[PlannedContact], bool]:
        """Contacts of the chain's capsules along a path, split into expected and
        unexpected (link, obstacle) pairs, in one batched planar test
        (:func:`capsule_distances`: every state × link × obstacle at once).

        A colliding pair is expected while the link's axis passes within ``tol`` of one
        of the solution's collision points on that obstacle; once it collides anywhere
        else it is unexpected. Every state counts as one collision check.

        Returns (expected, unexpected, cut short by the check budget).
        """
        left = tracker.checks_left()
        if left is not None and left < len(path):
            return [], [], True
        tracker.charge_checks(len(path))
        seg = robot.link_segments(path)[..., :2]  # (S, L, 2, 2)
        dist = capsule_distances(seg, query.obstacles, robot.link_radius_m)  # (S, L, O)
        touching = dist < robot.link_radius_m
        if not touching.any():
            return [], [], False
        names = [o.name for o in query.obstacles]
        st, li, ob = np.nonzero(touching)  # every touching (state, link, obstacle)
        near = np.full(len(st), math.inf)  # link axis to the nearest own collision point
        nearest = np.full(len(st), -1, dtype=int)
        for i, ck in zip(plan.solution.contact_indices, plan.contacts, strict=True):
            m = np.flatnonzero(ob == names.index(ck.obstacle))
            p = np.asarray(query.collision_points_m[i], dtype=float)
            d = _point_segment_distance(p, seg[st[m], li[m], 0], seg[st[m], li[m], 1])
            better = d < near[m]
            near[m[better]] = d[better]
            nearest[m[better]] = i
        away = near > tol
        # per (link, obstacle) pair, in order of states: the first state, and the first
        # state away from the collision points (if any)
        key = li * len(names) + ob
        order = np.lexsort((~away, st, key))  # by pair, then state; away first on ties
        key, st, li, ob = key[order], st[order], li[order], ob[order]
        near, nearest, away = near[order], nearest[order], away[order]
        starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        ends = np.r_[starts[1:], len(key)]
        expected: list[PlannedContact] = []
        unexpected: list[PlannedContact] = []
        for a0, a1 in zip(starts, ends, strict=True):
            hits = np.flatnonzero(away[a0:a1])
            k = a0 + (int(hits[0]) if len(hits) else 0)
            ci = int(nearest[k])
            rec = PlannedContact(
                link=robot.link_names[int(li[k])],
                obstacle=names[int(ob[k])],
                first_state=int(st[k]),
                collision_point=None if ci < 0 else ci,
                distance_m=None if ci < 0 else float(near[k]),
            )
            (unexpected if len(hits) else expected).append(rec)
        expected.sort(key=lambda r: r.first_state)
        unexpected.sort(key=lambda r: r.first_state)
        return expected, unexpected, False

    def _chain_check(
        self,
        robot: ContinuumChain,
        tracker: BudgetTracker,
        plans: Sequence[ChordArcPlan],
        real: ChordArcQuery,
        tol: float,
    ) -> tuple[list[_Candidate], bool]:
        """Each searched solution as the chain moves it: its joint path, whether a joint
        leaves its bounds, and its contacts (:meth:`_classify`); a candidate with a
        ``reason`` is dropped. Returns the candidates and whether the check budget cut the
        contact classification short."""
        cands: list[_Candidate] = []
        cut_short = False
        for plan in plans:
            path, owner = self.motion_path(robot, plan.motion)
            reason = ""
            lo_ok = path >= robot.lower - 1e-12
            hi_ok = path <= robot.upper + 1e-12
            if not (lo_ok.all() and hi_ok.all()):
                k, j = np.argwhere(~(lo_ok & hi_ok))[0]
                reason = (
                    f"the chain cannot follow it: {robot.joint_names[j]} would reach "
                    f"{path[k, j]:.3g} (bounds [{robot.lower[j]:.3g}, "
                    f"{robot.upper[j]:.3g}]) during step {owner[k]} "
                    f"({plan.motion[owner[k]].kind})"
                )
            exp: list[PlannedContact] = []
            unexp: list[PlannedContact] = []
            if not reason and self.settings.check_contacts and not cut_short:
                exp, unexp, cut_short = self._classify(robot, tracker, plan, real, path, tol)
                if unexp:
                    u = unexp[0]
                    reason = (
                        f"the {robot.link_radius_m * 1e3:.3g} mm-radius chain touches "
                        f"{u.obstacle!r} with {u.link} away from the solution's "
                        f"collision points (waypoint {u.first_state}; "
                        f"{len(unexp)} such pair(s))"
                    )
            cands.append(_Candidate(plan, path, owner, reason, tuple(exp), tuple(unexp)))
        return cands, cut_short

    def _choose(self, kept: Sequence[_Candidate]) -> int:
        """The index of the solution to execute (``settings.choose``)."""
        if self.settings.choose == "shortest":
            return min(range(len(kept)), key=lambda i: kept[i].plan.solution.total_length_m)
        if self.settings.choose == "fewest_contacts":
            return min(
                range(len(kept)),
                key=lambda i: (
                    len(kept[i].plan.solution.contact_indices),
                    kept[i].plan.solution.total_length_m,
                ),
            )
        return 0

    # ------------------------------------------------------------------ solve
    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Search every chord-arc solution to the leg's target; return the chosen one.

        Args:
            ctx: the leg's context: a continuum_chain problem with ``[continuum]
                collision_points_m``, the leg (its goal position is the target), its
                budget (see the module docstring) and its start, which must be the
                retracted straight robot.
            rng: unused (deterministic).

        Raises:
            PlannerlabError: bad input (see :meth:`query`; a collision point off every
                obstacle boundary).
        """
        del rng
        s = self.settings
        problem, leg, budget = ctx.problem, ctx.leg, ctx.tracker.budget
        tracker = ctx.tracker  # checks: the contact classification's states, charged
        run = ctx.run(self.name, s)
        robot = problem.robot
        goal = ctx.goal
        real = self.query(problem, leg)
        query = self.planning_query(problem, real)
        q0 = ctx.q_start.reshape(robot.dof)
        tol = 2.0 * robot.link_radius_m + s.contact_slack_m
        record = _empty_record(problem, real, query, tol, s.inflate_by_radius)

        # progress: the search starts at the straight robot, at time 0 with no checks
        run.progress.note(float(goal.distance(robot, q0)), time_s=0.0, checks=0)

        def result(
            status: Status,
            reason: str,
            path: Array,
            iterations: int = 0,
            trace: Array | None = None,
        ) -> PlanResult:
            """The leg's result, with what the search found so far."""
            r = run.result(status, reason, path, iterations=iterations, trace=trace)
            return r.replace(contact_plan=record)

        straight = robot.q_from_arcs([], insertion_m=0.0)
        if not np.allclose(q0, straight, atol=1e-9):
            return result(
                Status.INVALID_START,
                "chord_arc moves the robot from the retracted straight state "
                "(insertion 0, every joint 0); the start differs by "
                f"{float(np.max(np.abs(q0 - straight))):.3g}",
                q0[None],
            )
        z_base = float(robot.T_world_base[2, 3])
        if abs(float(goal.p_world_m[2]) - z_base) > goal.pos_tol_m:
            return result(
                Status.INVALID_GOAL,
                f"target {goal.p_world_m.tolist()} m is {goal.p_world_m[2] - z_base:.3g} "
                "m off the robot's plane",
                q0[None],
            )
        t_search = tracker.clock()
        try:
            res = solve_chord_arc(query, _capped(s, budget.max_iterations))
        except ChordArcInputError as exc:  # only the target can be wrong per leg
            if "target" not in str(exc):
                raise
            grown = " (obstacles grown by the link radius)" if s.inflate_by_radius else ""
            return result(Status.INVALID_GOAL, str(exc) + grown, q0[None])
        search_s = tracker.clock() - t_search
        srch = res.search
        search = _search_counts(srch, search_s)
        dropped: list[ContactSolution] = [
            _solution(d.solution, real, reason=d.reason, stage="contact_type") for d in res.dropped
        ]
        record = dataclasses.replace(record, search=search, dropped=tuple(dropped))
        iters = srch.expansions
        if budget.time_limit_s is not None and search_s >= budget.time_limit_s:
            return result(
                Status.BUDGET_EXHAUSTED,
                f"time limit of {budget.time_limit_s:g} s reached: the search took "
                f"{search_s:.3g} s",
                q0[None],
                iters,
            )

        # the chain's view of each surviving solution: joint bounds, then its contacts
        cands, cut_short = self._chain_check(robot, tracker, res.plans, real, tol)
        cut_r = 0.0 if s.inflate_by_radius else robot.link_radius_m
        kept = [c for c in cands if not c.reason]
        solutions = tuple(_candidate_solution(c, real, cut_r) for c in kept)
        dropped += [_candidate_solution(c, real, cut_r) for c in cands if c.reason]
        record = dataclasses.replace(record, solutions=solutions, dropped=tuple(dropped))
        n_pts = len(query.collision_points_m)

        if cut_short:
            return result(
                Status.BUDGET_EXHAUSTED,
                f"collision-check budget of {budget.max_collision_checks} used up "
                "while checking the solutions' contacts",
                q0[None],
                iters,
            )
        if not kept:
            status, reason = _nothing_kept(srch, dropped, n_pts)
            return result(status, reason, q0[None], iters)

        chosen = self._choose(kept)
        c = kept[chosen]
        tips = robot.tip(c.path)[0]
        trace = np.linalg.norm(tips - goal.p_world_m, axis=1)
        record = dataclasses.replace(
            record, chosen=chosen, motion_step_of_waypoint=tuple(int(k) for k in c.step_of)
        )
        q_end = c.path[-1]
        summary = (
            f"{len(kept)} solution(s) of {len(srch.solutions)} geometric "
            f"({len(dropped)} dropped) in {srch.expansions} expansions; chose "
            f"{s.choose} #{chosen}: {len(c.plan.solution.contact_indices)} contact(s) "
            f"at point(s) {list(c.plan.solution.contact_indices)}, "
            f"{c.plan.solution.total_length_m:.4g} m"
        )
        if not goal.contains(robot, q_end):
            pe, _ = goal.errors(robot, q_end)
            return result(
                Status.APPROXIMATE,
                f"{summary}; the chain's tip ends {float(pe):.3g} m from the target "
                f"(tolerance {goal.pos_tol_m:g} m)",
                c.path,
                iters,
                trace,
            )
        return result(
            Status.SOLVED,
            summary + "; contact at the collision points by design",
            c.path,
            iters,
            trace,
        )


def make(name: str, overrides: dict[str, Any]) -> ChordArcPlanner:
    """Registry factory for ``chord_arc``."""
    if name != "chord_arc":
        raise PlannerlabError(f"{name} is not served by plannerlab.planners.chord_arc")
    return ChordArcPlanner(name, with_overrides(ChordArcSettings(), overrides, name))

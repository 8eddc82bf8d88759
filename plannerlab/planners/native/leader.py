"""``native.rrtconnect+leader``: the compiled RRT-Connect helped by follow-the-leader.

Plain sampling does not find the window of a room for a 23-joint arm (``armz_deep_a``,
``armz_deep_b``, ``armz_inspection_direct``: no OMPL sampler solves them in 30 s); a
guided descent does (:mod:`plannerlab.planners.follow_leader`). This planner hands the
guided descent's body states to the sampler; it stays random and probabilistically
complete (a share ``1 − guide_bias`` of its samples is uniform, the trees are RRT-Connect's).

Guidance, built in the leg's context (its time, checks and iterations are the leg's; it
stops when they are spent):

1. **Forwards**: (when the leader's path runs back through the start's own body, as it
   does leaving a room from its far wall, first a branch that draws the tip back along
   the body until it sees the goal's approach point, then the leader from there: what got
   the body in gets it out; :meth:`~plannerlab.planners.follow_leader.FollowLeader.
   retract`) follow-the-leader from the start (:meth:`~plannerlab.planners.
   follow_leader.FollowLeader.track`: the leader's tip path on a voxel grid shifted by a
   random fraction of a voxel, its centring weight scaled at random, tracked by the
   clearance descent, then the descent into the goal). The body states it passes through
   are a branch of the start tree (their edges re-checked on the search's grid first);
   where a branch stalls, the clearance descent's detour from there is one more
   (``detour``).
2. **Goal states**: the forward branch's end when it reached the goal, the problem's
   start state when it lies in the goal region (a task that ends at rest), and the goal
   pool's IK states (``goal_samples``) when those give none.
3. **Backwards** ("what gets a body in gets it out"): from each of ``backward_goals`` goal
   states, follow-the-leader into the start's tip pose (its tip, looking along the start
   tip's normal), unless the forward branch already reached the goal. Its states are a
   branch of the goal tree rooted at that goal state. Leaving a room from deep inside,
   the forward leader leads the tip back through the window its own body fills and the
   tracking stalls; backwards, the body enters the way it would have come in, and the
   search has only to join the start to a body whose tip already is where the start's is.
4. **Guide states**: every ``guide_stride``-th state of both branches; a sample is one of
   them perturbed by ``guide_sigma_rad`` with probability ``guide_bias``.

Then the compiled RRT-Connect (:mod:`plannerlab.planners.native.kernels`) grows both
seeded trees, shortcuts the path and re-checks it, as ``native.rrtconnect`` does. The
seed draws the grid's shift, the centring weight, the IK pool and the search: its seeds
are different runs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult, Status, with_overrides
from plannerlab.planners.clearance.descent import ClearanceSettings
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.follow_leader.moves import Track, body_opening, leaves_from_inside
from plannerlab.planners.follow_leader.planner import FollowLeader, FollowLeaderSettings
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native.planner import NativePlanner, _check_settings
from plannerlab.planners.native.settings import RRTConnectSettings
from plannerlab.planners.native.solve import (
    FIRST_ROWS,
    KD_ROW_BYTES,
    UNLIMITED,
    NativeSolve,
    free_rows,
    space_extent,
)
from plannerlab.robots.base import Array, wrap_to_pi

__all__ = ["LeaderSettings", "LeaderPlanner", "Guidance", "make"]


@dataclass(frozen=True)
class LeaderSettings(RRTConnectSettings):
    """Settings of ``native.rrtconnect+leader`` (besides :class:`RRTConnectSettings`).

    Attributes:
        guide_bias: (here 0.5) the share of samples drawn near a guide state.
        guide_sigma_rad: (here 0.05) their Gaussian noise per joint [rad].
        forward: follow the leader from the start (a branch of the start tree).
        retract: a second branch from the start: the tip drawn back along the start's
            own body (as ``gradient.follow_leader``'s ``retract``), then the leader from
            there; first when the leader's path runs back through the body, else
            when the forward branch does not reach the goal.
        backward: follow the leader from goal states into the start's tip (branches of
            the goal tree), when the forward branch did not reach the goal.
        backward_goals: goal states to go backwards from, at most.
        guide_stride: every this many states of a branch (thinned to every 8th state of
            the descent) is a guide state.
        detour: when no branch reached the goal, from where each ended the clearance
            descent's detour (``gradient.follow_leader+detour``'s escape: the tip drawn
            back 2, 4, ... modules along the body, each followed by the leg's descent), a
            branch of the start tree (measured: ``armz_inspection_v28`` and ``v34``, leg E
            from C's witness: the forward branch's finish stalls by E, the detour gets in
            from there, RRT-Connect did not in 30 s).
        leader_max_replans: new leader paths the forward tracking draws from a stall.
    """

    guide_bias: float = 0.5
    guide_sigma_rad: float = 0.05
    forward: bool = True
    retract: bool = True
    backward: bool = True
    backward_goals: int = 2
    guide_stride: int = 1
    leader_max_replans: int = 0
    detour: bool = True


@dataclass(frozen=True)
class Guidance:
    """What the leader gives the search: the seeded trees and the guide states.

    Attributes:
        start_states, start_parents: (a, dof), (a,) the start tree (row 0 the start,
            parent -1).
        goal_states, goal_parents: (b, dof), (b,) the goal tree (a root, parent -1, per
            goal state).
        guides: (k, dof) guide states of the sampler.
        log: what each step did (the result's ``extra["leader"]``).
        iterations: descent iterations used.
        reached_node: a node of the start tree in the goal region (-1: none): the trees
            are joined there (it is a root of the goal tree) before any sample is drawn.
    """

    start_states: Array
    start_parents: Array
    goal_states: Array
    goal_parents: Array
    guides: Array
    log: dict[str, Any]
    iterations: int
    reached_node: int = -1


class _Tree:
    """A tree under construction: states and parents."""

    def __init__(self) -> None:
        self.Q: list[Array] = []
        self.P: list[int] = []

    def root(self, q: Array) -> int:
        self.Q.append(np.asarray(q, dtype=float))
        self.P.append(-1)
        return len(self.Q) - 1

    def chain(self, parent: int, states: Array) -> int:
        """Hang ``states`` (a chain whose first state is the parent's, dropped) below
        ``parent``; returns the index of its last state."""
        for q in states[1:]:
            self.Q.append(np.asarray(q, dtype=float))
            self.P.append(parent)
            parent = len(self.Q) - 1
        return parent

    def arrays(self, dof: int) -> tuple[Array, Array]:
        return np.array(self.Q, dtype=float).reshape(-1, dof), np.array(self.P, dtype=np.int64)


def _verified(
    ctx: PlanningContext, states: list[Array], step: float, used: int, thin: int = 8
) -> Array:
    """A chain of the descent's states fit for a tree, wrapped: every ``thin``-th state
    (and the last) when the edges between them pass the search's grid check (the
    descent's states lie a few hundredths of a radian apart; fewer, longer edges make
    the path's simplification cheaper), else the longest prefix of all of them whose
    edges pass it (the descent checks states; the search and the re-check check edges).
    Within the leg's budget (``used``: its iterations so far): a check cut short by it
    keeps the first state only."""
    tracker = ctx.tracker
    P = wrap_to_pi(np.array(states, dtype=float).reshape(-1, ctx.robot.dof), ctx.robot.continuous)
    if len(P) < 2:
        return P

    def stop() -> bool:
        return tracker.exhausted(used) is not None

    if thin > 1 and len(P) > thin:
        keep = np.unique(np.concatenate([np.arange(0, len(P), thin), [len(P) - 1]]))
        check = ctx.checker.check_path(P[keep], step, stop=stop, chunk=64, mode="grid")
        if not check.complete:
            return P[:1]
        if check.valid:
            return P[keep]
    check = ctx.checker.check_path(P, step, stop=stop, chunk=64, mode="grid")
    if not check.complete:
        return P[:1]
    if check.valid:
        return P
    bad = check.first_invalid_edge
    return P[: max(int(bad) + 1, 1)] if bad is not None else P[:1]


def build_guidance(
    leader: FollowLeader,
    settings: LeaderSettings,
    solve: NativeSolve,
    ctx: PlanningContext,
    rng: np.random.Generator,
) -> Guidance | PlanResult:
    """The guidance of one leg (see the module docstring), or the result when the budget
    ran out or no goal state was found."""
    s = settings
    leader = leader.for_robot(ctx.robot)  # its distances derived for this robot
    robot, tracker, goal = ctx.robot, ctx.tracker, ctx.goal
    dof = robot.dof
    q0 = solve.q0
    step = solve.step
    log: dict[str, Any] = {}
    used = 0
    A, B = _Tree(), _Tree()
    A.root(q0)
    chains: list[Array] = [q0[None]]
    reached: list[Array] = []
    reached_nodes: list[int] = []

    def out_of_budget() -> PlanResult | None:
        why = tracker.exhausted(used)
        return None if why is None else solve.result(Status.BUDGET_EXHAUSTED, why, q0[None])

    def grow_start(parent: int, tr: Track, key: str) -> int:
        nonlocal used
        used += tr.iterations
        chain = _verified(ctx, tr.states, step, used)
        chains.append(chain)
        whole = bool(np.allclose(chain[-1], wrap_to_pi(tr.states[-1], robot.continuous)))
        log[key] = {"status": tr.status.value, "states": len(chain), "reason": tr.reason}
        end = A.chain(parent, chain)
        if tr.status is Status.SOLVED and whole and bool(goal.contains(robot, chain[-1])):
            reached.append(chain[-1])
            reached_nodes.append(end)
        return end

    def detour(node: int, key: str) -> None:
        """The clearance descent's detour from where a branch stalled (its tip drawn back
        along its body, then the leg's descent): a branch of the start tree."""
        if s.detour and not reached and tracker.exhausted(used) is None:
            grow_start(node, leader.detour_from(ctx, A.Q[node], rng, used), key)

    # leaving from inside: where the start's body leaves the room (its pivot face); the
    # leader's paths are routed by it and the retract ends when the tip sees the approach
    # point by it (a room with more than one opening: the body's own way out)
    opening: Array | None = None

    def via(q: Array) -> Array | None:
        """The opening as the leader's waypoint from ``q``, unless its tip sees the
        approach point by it already."""
        if opening is None or leader.sees_approach(ctx, q, opening):
            return None
        return opening

    def retract_branch() -> None:
        end = grow_start(0, leader.retract(ctx, q0, used, opening), "retract")
        if tracker.exhausted(used) is None:
            q = A.Q[end]
            end = grow_start(
                end, leader.track(ctx, q, goal, rng, used, via_m=via(q)), "after_retract"
            )
            detour(end, "detour_after_retract")

    if s.forward:
        lead = leader.leader_path(
            ctx.problem, ctx.leg, q0, rng, lambda: tracker.exhausted(used) is not None
        )
        if s.retract and leaves_from_inside(leader, ctx, q0, lead):
            # the leader's path runs back through the body: the retract branch first
            log["retract_first"] = True
            opening = body_opening(leader, ctx, q0)
            if opening is not None:
                log["opening_m"] = [round(float(x), 3) for x in opening]
            retract_branch()
        if not reached and tracker.exhausted(used) is None:
            if opening is not None:
                tr = leader.track(ctx, q0, goal, rng, used, via_m=via(q0))
            else:
                tr = leader.track(ctx, q0, goal, rng, used, leader=lead)
            end = grow_start(0, tr, "forward")
            detour(end, "detour_after_forward")
        if not reached and s.retract and "retract" not in log and tracker.exhausted(used) is None:
            # leaving from deep inside: the tip drawn back along its own body, then the
            # leader from there (a second branch of the start tree)
            retract_branch()
    failed = out_of_budget()
    if failed is not None:
        return failed
    goal_states = list(reached)
    q_rest = wrap_to_pi(np.asarray(ctx.problem.q_start, dtype=float), robot.continuous)
    if bool(goal.contains(robot, q_rest)) and ctx.checker.is_valid(q_rest):
        goal_states.append(q_rest)
    if not goal_states:
        G, failed = solve.goal_pool()
        if failed is not None:
            return failed
        goal_states.extend(G)
    roots = [B.root(g) for g in goal_states]
    if s.backward and not reached:
        # from goal states into the start's tip pose (branches of the goal tree)
        from plannerlab.problem.goals import GoalRegion

        p0, n0 = robot.tip(q0)
        ls = leader.settings
        tip_goal = GoalRegion("start tip", p0, n0, ls.subgoal_pos_tol_m, ls.subgoal_angle_tol_deg)
        log["backward"] = []
        for i in roots[: s.backward_goals]:
            if tracker.exhausted(used) is not None:
                break
            tb = leader.track(ctx, B.Q[i], tip_goal, rng, used, via_m=opening)
            used += tb.iterations
            chain = _verified(ctx, tb.states, step, used)
            chains.append(chain)
            B.chain(i, chain)
            log["backward"].append({"status": tb.status.value, "states": len(chain)})
    failed = out_of_budget()
    if failed is not None:
        return failed
    stride = max(int(s.guide_stride), 1)
    guides = np.vstack([c[::stride] for c in chains] + [c[-1:] for c in chains])
    QA, PA = A.arrays(dof)
    QB, PB = B.arrays(dof)
    log.update(goal_states=len(roots), guides=len(guides), iterations=used)
    return Guidance(QA, PA, QB, PB, guides, log, used, reached_nodes[0] if reached_nodes else -1)


class LeaderSolve(NativeSolve):
    """One leg's solve: the guidance, then RRT-Connect from the seeded trees."""

    def __init__(
        self,
        name: str,
        settings: LeaderSettings,
        ctx: PlanningContext,
        rng: np.random.Generator,
        leader: FollowLeader,
    ) -> None:
        super().__init__(name, settings, ctx, rng, np.zeros((0, ctx.robot.dof)))
        self.leader = leader
        self.lsettings = settings

    def rrtconnect(self) -> PlanResult:
        q0 = self.q0
        if self.ctx.start_problem is not None:
            return self.result(Status.INVALID_START, self.ctx.start_problem, q0[None])
        model = self.checker.model
        self.run.progress.note(float(self.goal.distance(self.robot, q0)))
        t0, c0 = self.tracker.elapsed_s, self.tracker.checks_used
        g = build_guidance(self.leader, self.lsettings, self, self.ctx, self.rng)
        if isinstance(g, PlanResult):
            return g
        # the guidance's time per check (the descents' steps with their checks): a
        # conservative first rate, so that the simplification keeps back enough time for
        # the re-check when the trees are joined before any chunk of the search measured
        # the kernels' rate
        made = self.tracker.checks_used - c0
        if made > 0:
            self.rate_s = max(self.rate_s, (self.tracker.elapsed_s - t0) / made)
        self.extra["leader"] = g.log
        self.guides = np.ascontiguousarray(g.guides)
        self.run.progress.note(float(np.min(self.goal.distance(self.robot, g.start_states))))
        rng_state = K.seed_state(self.rng)
        dof = len(q0)
        range_rad = self.s.range_rad or 0.2 * space_extent(model)
        self.extra["range_rad"] = range_rad
        need_free = free_rows(model, self.s, range_rad)
        seeded = max(len(g.start_states), len(g.goal_states))
        hard0 = self.hard_checks()
        cap = max(
            self.tree_rows(hard0 + need_free, seeded, dof, KD_ROW_BYTES), need_free + seeded + 1
        )
        self.extra["tree_rows"] = cap
        rows = min(cap, max(FIRST_ROWS, need_free + seeded + 1))
        # the trees as the leader seeded them (the start's branches, the goal states'
        # roots with their backward branches), their edges checked in full
        na, nb = len(g.start_states), len(g.goal_states)
        seeds = ((g.start_states, g.start_parents), (g.goal_states, g.goal_parents))
        trees = self.new_trees(seeds, rows, dof)
        sizes = np.array([na, nb], dtype=np.int64)
        counters = np.zeros(6, dtype=np.int64)
        if g.reached_node >= 0:
            # joined already: the meeting node is the reached state, the goal tree's root 0
            counters[3], counters[4] = g.reached_node, 0
            self.iterations = g.iterations
            self.extra["nodes"] = [na, nb]
            return self._finish(trees, counters, na + nb, rng_state)
        b = self.budget
        max_it = UNLIMITED if b.max_iterations is None else max(b.max_iterations - g.iterations, 1)
        O = self.options(range_rad, max_it, need_free)
        code = self.search(trees, sizes, counters, rng_state, O, cap, iterations0=g.iterations)
        self.extra["planning_checks"] = int(counters[1])
        self.extra["search_iterations"] = int(counters[0])
        self.extra["nodes"] = [int(sizes[0]), int(sizes[1])]
        if code != K.DONE:
            return self.stopped(code, f"{int(sizes[0])} + {int(sizes[1])} tree nodes")
        return self._finish(trees, counters, int(sizes.sum()), rng_state)

    def _finish(
        self, trees: list[np.ndarray], counters: np.ndarray, rows: int, rng_state: Array
    ) -> PlanResult:
        """The path through the meeting nodes (``counters[3]`` in A, ``counters[4]`` in
        B), shortcut and re-checked."""
        out = np.empty((rows, trees[0].shape[1]))
        A = K.Tree(trees[0], trees[1], trees[2], trees[3], trees[8])
        B = K.Tree(trees[4], trees[5], trees[6], trees[7], trees[9])
        k = K.tree_path(A, counters[3], B, counters[4], out)
        path = out[:k].copy()
        self.extra["waypoints_raw"] = k
        if self.s.simplify:
            path = self.simplify(path, rng_state)
        return self.checked(path)


@dataclass(frozen=True)
class LeaderPlanner(NativePlanner):
    """``native.rrtconnect+leader`` (see the module docstring)."""

    leader: FollowLeader | None = None

    def warm_up(self, problem: Any, leg: int, q_start: Array) -> None:
        """The kernels and the descent's field, before the leg's clock starts."""
        super().warm_up(problem, leg, q_start)
        if self.leader is not None:
            self.leader.warm_up(problem, leg, q_start)

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        self.require(ctx)
        assert self.leader is not None
        assert isinstance(self.settings, LeaderSettings)
        return LeaderSolve(self.name, self.settings, ctx, rng, self.leader).rrtconnect()


def make(name: str, overrides: Mapping[str, Any] | None = None) -> LeaderPlanner:
    """Registry factory of ``native.rrtconnect+leader``; the leader's settings are
    overridden as ``leader.<key>``, its descent's as ``leader.descent.<key>``."""
    over = dict(overrides or {})
    own = {k: v for k, v in over.items() if not k.startswith("leader.")}
    lead = {k[len("leader.") :]: v for k, v in over.items() if k.startswith("leader.")}
    settings = with_overrides(LeaderSettings(), own, name)
    _check_settings(name, settings)
    if settings.backward_goals < 1 or settings.guide_stride < 1:
        raise PlannerlabError(
            f"{name}: backward_goals and guide_stride must be >= 1, got "
            f"{settings.backward_goals}, {settings.guide_stride}"
        )
    f_over = {k: v for k, v in lead.items() if not k.startswith("descent.")}
    d_over = {k[len("descent.") :]: v for k, v in lead.items() if k.startswith("descent.")}
    base = FollowLeaderSettings(
        random_grid=True, max_replans=settings.leader_max_replans, retract=False
    )
    fls = with_overrides(base, f_over, f"{name} (leader)")
    descent = with_overrides(ClearanceSettings(), d_over, f"{name} (leader's descent)")
    leader = FollowLeader(name, fls, descent)
    return LeaderPlanner(name=name, algorithm="rrtconnect", settings=settings, leader=leader)

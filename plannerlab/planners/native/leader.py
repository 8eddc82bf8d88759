"""``native.rrtconnect+leader``: the compiled RRT-Connect helped by follow-the-leader.

Plain sampling does not find the window of a room for a 23-joint arm (``armz_deep_a``,
``armz_deep_b``, ``armz_inspection_direct``: no OMPL sampler solves them in 30 s); a
guided descent does (:mod:`plannerlab.planners.follow_leader`). This planner hands the
guided descent's body states to the sampler; it stays random and probabilistically
complete (a share ``1 − guide_bias`` of its samples is uniform, the trees are RRT-Connect's).

Guidance, built in the leg's context (its time, checks and iterations are the leg's; it
stops when they are spent):

1. **Forwards**: follow-the-leader from the start (:meth:`~plannerlab.planners.
   follow_leader.FollowLeader.track`: the leader's tip path on a voxel grid shifted by a
   random fraction of a voxel, its centring weight scaled at random, tracked by the
   clearance descent, then the descent into the goal). The body states it passes through
   are a branch of the start tree (their edges re-checked on the search's grid first).
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

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult, Status, with_overrides
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.follow_leader import FollowLeader, FollowLeaderSettings, Track
from plannerlab.planners.gradient_clearance import ClearanceSettings
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native.planner import (
    FIRST_ROWS,
    UNLIMITED,
    K_views,
    NativePlanner,
    NativeSolve,
    _check_settings,
    space_extent,
)
from plannerlab.planners.native.settings import NativeSettings
from plannerlab.robots.base import Array, wrap_to_pi

__all__ = ["LeaderSettings", "LeaderPlanner", "Guidance", "make"]


@dataclass(frozen=True)
class LeaderSettings(NativeSettings):
    """Settings of ``native.rrtconnect+leader`` (besides :class:`NativeSettings`).

    Attributes:
        guide_bias: (here 0.5) the share of samples drawn near a guide state.
        guide_sigma_rad: (here 0.05) their Gaussian noise per joint [rad].
        forward: follow the leader from the start (a branch of the start tree).
        backward: follow the leader from goal states into the start's tip (branches of
            the goal tree), when the forward branch did not reach the goal.
        backward_goals: goal states to go backwards from, at most.
        guide_stride: every this many states of a branch is a guide state.
        leader_max_replans: new leader paths the forward tracking draws from a stall.
    """

    guide_bias: float = 0.5
    guide_sigma_rad: float = 0.05
    forward: bool = True
    backward: bool = True
    backward_goals: int = 2
    guide_stride: int = 4
    leader_max_replans: int = 0


@dataclass(frozen=True)
class Guidance:
    """What the leader gives the search.

    Attributes:
        start_branch: (m, dof) states from the start (the first is the start), a chain.
        goal_states: (g, dof) goal states (roots of the goal tree).
        goal_branches: per goal root index, a chain of states from it (its first state is
            the root).
        guides: (k, dof) guide states of the sampler.
        log: what each step did (the result's ``extra["leader"]``).
        iterations: descent iterations used.
    """

    start_branch: Array
    goal_states: Array
    goal_branches: dict[int, Array]
    guides: Array
    log: dict[str, Any]
    iterations: int


def _verified(ctx: PlanningContext, states: list[Array], step: float) -> Array:
    """The longest prefix of a chain of states whose edges pass the search's grid check
    (the descent checks states; the search and the re-check check edges)."""
    P = np.array(states, dtype=float).reshape(-1, ctx.robot.dof)
    if len(P) < 2:
        return P
    check = ctx.checker.check_path(P, step, mode="grid")
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
    robot, tracker, goal = ctx.robot, ctx.tracker, ctx.goal
    cont = robot.continuous
    q0 = solve.q0
    step = solve.step
    log: dict[str, Any] = {}
    used = 0
    start_branch = q0[None].copy()
    goal_states: list[Array] = []
    fwd_reached = False
    if s.forward:
        tr: Track = leader.track(ctx, q0, goal, rng, used)
        used += tr.iterations
        start_branch = wrap_to_pi(_verified(ctx, tr.states, step), cont)
        fwd_reached = tr.status is Status.SOLVED and len(start_branch) == len(tr.states)
        log["forward"] = {"status": tr.status.value, "states": len(start_branch)}
        if fwd_reached:
            goal_states.append(start_branch[-1])
    if tracker.exhausted(0) is not None:
        return solve.result(Status.BUDGET_EXHAUSTED, str(tracker.exhausted(0)), q0[None])
    q_rest = wrap_to_pi(np.asarray(ctx.problem.q_start, dtype=float), cont)
    if bool(goal.contains(robot, q_rest)) and ctx.checker.is_valid(q_rest):
        goal_states.append(q_rest)
    if not goal_states:
        G, failed = solve.goal_pool()
        if failed is not None:
            return failed
        goal_states.extend(G)
    G = np.unique(np.array(goal_states, dtype=float), axis=0)
    # the forward branch's end first (a goal state that is already joined)
    if fwd_reached:
        end = start_branch[-1]
        G = np.vstack([end[None], G[np.any(G != end, axis=1)]])
    branches: dict[int, Array] = {}
    if s.backward and not fwd_reached:
        p0, n0 = robot.tip(q0)
        from plannerlab.problem.goals import GoalRegion

        ls = leader.settings
        tip_goal = GoalRegion("start tip", p0, n0, ls.subgoal_pos_tol_m, ls.subgoal_angle_tol_deg)
        log["backward"] = []
        for i in range(min(s.backward_goals, len(G))):
            if tracker.exhausted(0) is not None:
                break
            tb = leader.track(ctx, G[i], tip_goal, rng, used)
            used += tb.iterations
            chain = wrap_to_pi(_verified(ctx, tb.states, step), cont)
            branches[i] = chain
            log["backward"].append({"status": tb.status.value, "states": len(chain)})
    if tracker.exhausted(0) is not None:
        return solve.result(Status.BUDGET_EXHAUSTED, str(tracker.exhausted(0)), q0[None])
    chains = [start_branch, *branches.values()]
    stride = max(int(s.guide_stride), 1)
    guides = np.vstack([c[::stride] for c in chains] + [c[-1:] for c in chains])
    log["goal_states"] = len(G)
    log["guides"] = len(guides)
    log["iterations"] = used
    return Guidance(start_branch, G, branches, guides, log, used)


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
        g = build_guidance(self.leader, self.lsettings, self, self.ctx, self.rng)
        if isinstance(g, PlanResult):
            return g
        self.extra["leader"] = g.log
        self.guides = np.ascontiguousarray(g.guides)
        self.run.progress.note(float(np.min(self.goal.distance(self.robot, g.start_branch))))
        rng_state = K.seed_state(self.rng)
        V, S = K_views(model)
        dof = len(q0)
        range_rad = self.s.range_rad or 0.2 * space_extent(model)
        self.extra["range_rad"] = range_rad
        need_free = 2 + math.ceil(space_extent(model) / range_rad)
        A0 = g.start_branch
        B_roots = g.goal_states
        nb = len(B_roots) + sum(len(c) - 1 for c in g.goal_branches.values())
        seeded = max(len(A0), nb)
        hard0 = self.hard_checks()
        cap = max(self.tree_rows(hard0, seeded, dof), need_free + seeded + 1)
        self.extra["tree_rows"] = cap
        rows = min(cap, max(FIRST_ROWS, need_free + seeded + 1))
        QA, PA = np.empty((rows, dof)), np.full(rows, -1, dtype=np.int64)
        QB, PB = np.empty((rows, dof)), np.full(rows, -1, dtype=np.int64)
        # the start tree: the forward branch, a chain from the start
        QA[: len(A0)] = A0
        PA[1 : len(A0)] = np.arange(len(A0) - 1)
        # the goal tree: a root per goal state, the backward branches hanging from theirs
        QB[: len(B_roots)] = B_roots
        nB = len(B_roots)
        for root, chain in g.goal_branches.items():
            parent = root
            for q in chain[1:]:
                QB[nB] = q
                PB[nB] = parent
                parent = nB
                nB += 1
        sizes = np.array([len(A0), nB], dtype=np.int64)
        counters = np.zeros(5, dtype=np.int64)
        buf = np.empty((4, dof))
        b = self.budget
        max_it = UNLIMITED if b.max_iterations is None else max(b.max_iterations - g.iterations, 1)
        trees = [QA, PA, QB, PB]
        self._charged = 0
        s = self.s

        def call(soft: int, hard: int) -> int:
            return int(
                K.rrtc_run(
                    model,
                    V,
                    S,
                    trees[0],
                    trees[1],
                    trees[2],
                    trees[3],
                    sizes,
                    counters,
                    rng_state,
                    self.guides,
                    s.guide_bias,
                    s.guide_sigma_rad,
                    range_rad,
                    self.step,
                    max_it,
                    soft,
                    hard,
                    need_free,
                    buf,
                )
            )

        while True:
            code = self.run_chunks(call, counters)
            self.iterations = g.iterations + int(counters[0])
            if code == K.FULL and len(trees[0]) < cap:
                grown = min(cap, 4 * len(trees[0]))
                for t in (0, 2):
                    Q = np.empty((grown, dof))
                    Q[: len(trees[t])] = trees[t]
                    P = np.full(grown, -1, dtype=np.int64)
                    P[: len(trees[t + 1])] = trees[t + 1]
                    trees[t], trees[t + 1] = Q, P
                continue
            break
        self.extra["planning_checks"] = int(counters[1])
        self.extra["search_iterations"] = int(counters[0])
        self.extra["nodes"] = [int(sizes[0]), int(sizes[1])]
        if code != K.DONE:
            return self.stopped(code, f"{int(sizes[0])} + {int(sizes[1])} tree nodes")
        out = np.empty((int(sizes.sum()), dof))
        k = K.tree_path(trees[0], trees[1], counters[3], trees[2], trees[3], counters[4], out)
        path = out[:k].copy()
        self.extra["waypoints_raw"] = k
        if self.s.simplify:
            path = self.simplify(path, model, V, S, rng_state)
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
        b = ctx.tracker.budget
        if b.max_iterations is None and b.max_collision_checks is None and b.time_limit_s is None:
            raise PlannerlabError(
                f"{self.name}: the budget needs at least one limit "
                "(max_iterations, max_collision_checks or time_limit_s)"
            )
        if ctx.checker is None:
            raise PlannerlabError(f"{self.name}: needs a collision checker")
        try:
            ctx.checker.model  # noqa: B018 - built once, raises when it cannot be
        except ValueError as e:
            raise PlannerlabError(f"{self.name}: no compiled model of this problem: {e}") from e
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

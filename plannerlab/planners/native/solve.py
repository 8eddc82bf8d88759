"""One compiled solve of one leg: :class:`NativeSolve` (the goal pool, the compiled search
in chunks, the compiled shortcuts, the re-check), shared by the compiled planners.

The search runs in :mod:`~plannerlab.planners.native.kernels`, a chunk of work per call;
between chunks this module charges the chunk's checks to the leg's tracker, looks at the
clock and sizes the next chunk by counting work: a chunk gets the checks the last chunks
made in about ``CHUNK_TIME_FRACTION`` of the time limit, so a search stops within about
that fraction of its limit. Without a time limit the search is one chunk: the same seed
gives the same path, checks and iterations on any machine.

Checks are counted as every planner counts them: every state the kernels check is one
collision check, charged to the leg's tracker (:meth:`~plannerlab.planners.base.
BudgetTracker.charge_checks`); the goal pool's IK and the re-check go through the
checker, which counts its own. The search never crosses the check budget (its hard
limit); the shortcuts keep back the checks and the time of the found path's re-check;
the re-check may use 1 % beyond the budget, as the OMPL planners' (``planners/ompl/``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from plannerlab.planners.base import BudgetTracker, PlanResult, Status
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.goal_pool import fill_goal_pool
from plannerlab.planners.native import kernels as K
from plannerlab.planners.native.kdtree import split_dims
from plannerlab.planners.native.settings import NativeSettings
from plannerlab.robots.base import Array, wrap_to_pi
from plannerlab.robots.paths import path_length

#: a chunk is sized to take about this fraction of the time limit
CHUNK_TIME_FRACTION = 0.004
#: the first chunk's guess of the time per check [s] (the next chunks measure it)
FIRST_RATE_S = 1e-6
#: checks per chunk at least / at most (with a time limit; without one, one chunk)
CHUNK_MIN, CHUNK_MAX = 64, 1 << 22
#: the re-check may run this fraction past the time limit (as the OMPL planners')
TIME_SLACK = 0.01
#: the time kept for the re-check is this many times its checks at the search's rate
RESERVE_FACTOR = 1.25
#: the re-check's states between two looks at the clock
RECHECK_CHUNK = 4096
#: the trees' first rows (grown fourfold up to the cap)
FIRST_ROWS = 4096
#: no limit
UNLIMITED = 1 << 62
#: a tree's k-d tree takes this many bytes a row (:meth:`NativeSolve.new_trees`)
KD_ROW_BYTES = 24


class _PoolGuard:
    """The goal pool's checker behind the leg's tracker: it refuses (invalid, unchecked)
    once the checks are spent or the time is up (what ``fill_goal_pool`` asks of it)."""

    def __init__(self, checker: Any, tracker: BudgetTracker) -> None:
        self.checker, self.tracker = checker, tracker

    def exhausted(self) -> str | None:
        return self.tracker.exhausted(0)

    def out_of_time(self) -> bool:
        tl = self.tracker.budget.time_limit_s
        return tl is not None and self.tracker.elapsed_s >= tl

    def is_valid(self, q: Array) -> bool:
        left = self.tracker.checks_left()
        if (left is not None and left <= 0) or self.out_of_time():
            return False
        return bool(self.checker.is_valid(q))


def space_extent(model: Any) -> float:
    """The joint box's diagonal [rad]: π per continuous joint (its farthest state)."""
    span = np.where(model.continuous, math.pi, model.upper - model.lower)
    return float(np.sqrt(np.sum(span**2)))


def range_ladder(settings: Any, range_rad: float) -> list[float]:
    """The lengths the extension's range cycles over (``range_levels``, default one: the
    range itself), longest first."""
    levels = max(1, int(getattr(settings, "range_levels", 1)))
    return [range_rad / 2.0**k for k in range(levels)]


def free_rows(model: Any, settings: Any, range_rad: float) -> int:
    """Free rows a tree needs before an iteration (a connection adds at most one node per
    step of the shortest range over the space's extent, plus the extension's)."""
    return 2 + math.ceil(space_extent(model) / range_ladder(settings, range_rad)[-1])


class NativeSolve:
    """One compiled solve of the leg of ``ctx`` (see the module docstring).

    Args:
        name: the planner's registry name; ``settings`` its settings.
        ctx: the leg's context; ``rng`` the trial's generator (the IK pool, then the
            kernels' generator's seed).
        guides: (k, dof) guide states of the sampler (k = 0: none), used with probability
            ``settings.guide_bias``.
    """

    def __init__(
        self,
        name: str,
        settings: NativeSettings,
        ctx: PlanningContext,
        rng: np.random.Generator,
        guides: Array,
    ) -> None:
        self.name, self.s, self.ctx, self.rng = name, settings, ctx, rng
        self.robot, self.goal, self.checker = ctx.robot, ctx.goal, ctx.checker
        self.tracker = ctx.tracker
        self.budget = self.tracker.budget
        self.run = ctx.run(name, settings)
        self.q0 = wrap_to_pi(np.asarray(ctx.q_start, dtype=float), self.robot.continuous)
        self.step = ctx.joint_step / 4.0  # the re-check's step
        self.extra: dict[str, Any] = {}
        self.iterations = 0
        self.time_limit = self.budget.time_limit_s
        self.max_checks = self.budget.max_collision_checks
        self.guides = np.ascontiguousarray(
            np.asarray(guides, dtype=float).reshape(-1, len(self.q0))
        )
        #: seconds per check measured over the chunks so far (the search's rate)
        self.rate_s = FIRST_RATE_S
        self._charged = 0

    # ------------------------------------------------------------------ shared steps
    def result(self, status: Status, reason: str, path: Array) -> PlanResult:
        return self.run.result(status, reason, path, iterations=self.iterations, extra=self.extra)

    def out_of_time(self, slack: float = 0.0) -> bool:
        tl = self.time_limit
        return tl is not None and self.tracker.elapsed_s >= tl * (1.0 + slack)

    def charge(self, counters: np.ndarray) -> None:
        """Charge the kernels' checks made since the last charge to the leg's tracker."""
        done = int(counters[1])
        self.tracker.charge_checks(done - self._charged)
        self._charged = done

    def hard_checks(self) -> int:
        """Checks the kernels may still make (from their counter's current value)."""
        left = self.tracker.checks_left()
        return UNLIMITED if left is None else self._charged + left

    def chunk_checks(self) -> int:
        """Checks of the next chunk: about ``CHUNK_TIME_FRACTION`` of the time limit at
        the measured rate (all of them without a time limit: one chunk)."""
        if self.time_limit is None:
            return UNLIMITED
        n = CHUNK_TIME_FRACTION * self.time_limit / max(self.rate_s, 1e-9)
        return int(min(max(n, CHUNK_MIN), CHUNK_MAX))

    def run_chunks(self, call: Any, counters: np.ndarray, stop: Any = None) -> int:
        """Run ``call(soft_checks, hard_checks)`` (a kernel call) chunk after chunk until
        it returns anything but :data:`~plannerlab.planners.native.kernels.CHUNK`, or
        ``stop()`` (default: the time limit) says so: its last code (:data:`CHUNK` when
        stopped)."""
        stop = stop or self.out_of_time
        while True:
            t0, c0 = self.tracker.elapsed_s, int(counters[1])
            code = call(c0 + self.chunk_checks(), self.hard_checks())
            self.charge(counters)
            made = int(counters[1]) - c0
            if made > 0:
                self.rate_s = max(self.tracker.elapsed_s - t0, 1e-9) / made
            if code != K.CHUNK or stop():
                return int(code)

    def goal_pool(self) -> tuple[Array, PlanResult | None]:
        """The goal states (k, dof) (the tree roots), or the result when there are none."""
        pool, cut_short = fill_goal_pool(
            self.ctx, self.s, _PoolGuard(self.checker, self.tracker), self.rng, self.q0, self.extra
        )
        if pool:
            G = np.unique(np.array(pool, dtype=float), axis=0)
            self.extra["goal_pool"] = len(G)
            return np.ascontiguousarray(G), None
        q0 = self.q0[None]
        if cut_short:
            return q0, self.result(
                Status.BUDGET_EXHAUSTED,
                f"the budget ran out while sampling goal states by IK ({cut_short}): give a "
                "larger budget",
                q0,
            )
        return q0, self.result(Status.INVALID_GOAL, self._no_goal_reason(), q0)

    def _no_goal_reason(self) -> str:
        """Why the pool is empty: a goal state's colliding links (a joint goal), or the IK
        found no valid state."""
        q_goal = getattr(self.goal, "q_rad", None)
        if q_goal is None or len(q_goal) != len(self.q0):
            return (
                f"no valid goal state: the goal is in collision or IK found none in "
                f"{self.s.max_goal_attempts} attempts"
            )
        q_goal = np.asarray(q_goal, dtype=float)
        if np.any(q_goal < self.robot.lower) or np.any(q_goal > self.robot.upper):
            return "the goal state is outside the joint limits"
        pairs = self.checker.colliding_pairs(q_goal)
        links = dict.fromkeys(
            " x ".join(name.split("#", 1)[0] for name in pair) for pair in pairs
        )  # a checker's body names carry their sphere's number: ``link#3``
        return "the goal state collides: " + (", ".join(links) or "(no pair named)")

    def tree_rows(self, hard: int, roots: int, dof: int, index_bytes: int = 0) -> int:
        """Rows a tree may have: the memory cap (``max_tree_mb`` for both trees: states,
        parents and ``index_bytes`` a row of the nearest-node index) and, with a check
        budget, the nodes its checks can add (each costs at least one check; callers add
        the free rows an iteration needs, :func:`free_rows`, to ``hard``)."""
        by_memory = int(self.s.max_tree_mb * 1e6 / 2 / (8 * dof + 8 + index_bytes))
        return max(min(by_memory, hard + roots + 1), roots + 1)

    def simplify(self, P: Array, rng_state: np.ndarray) -> Array:
        """The path shortened in compiled code (:func:`~plannerlab.planners.native.
        kernels.shortcut_run`), keeping back the checks and the time of its re-check."""
        P = np.ascontiguousarray(P.copy())
        k = len(P)
        cost = int(self.checker.grid_states(P, self.step))
        tries = self.s.shortcut_tries or max(32, 4 * k)
        counters = np.zeros(4, dtype=np.int64)
        self._charged = 0
        left = self.tracker.checks_left()
        hard = UNLIMITED if left is None else left - cost
        if hard <= 0 or self._time_reserve_reached(cost):
            self.extra["simplify_checks"] = 0
            return P
        box = [k]
        aux = self.aux(rng_state, k)

        def call(soft: int, _hard: int) -> int:
            limits = np.array([soft, hard], dtype=np.int64)
            box[0], code = K.shortcut_entry(
                self.packed, aux, (P, box[0]), self.step, tries, counters, limits
            )
            return int(code)

        self.run_chunks(call, counters, lambda: self._time_reserve_reached(cost))
        self.extra["simplify_checks"] = int(counters[1])
        self.extra["shortcut_tries"] = int(counters[0])
        return P[: box[0]].copy()

    @property
    def packed(self) -> tuple[np.ndarray, ...]:
        """The checker's packed compiled model (what the kernels' entries take)."""
        return self.checker.packed_model

    def aux(self, rng_state: np.ndarray, rows: int) -> tuple[Any, ...]:
        """The kernels' scratch for trees of ``rows`` rows: (generator state, scratch
        states, the k-d trees' split joints, their search's scratch)."""
        dof = len(self.q0)
        depth = rows + 2
        ks = (np.empty(depth, dtype=np.int64), np.empty(depth), np.empty((depth, dof)))
        return (rng_state, np.empty((4, dof)), split_dims(self.checker.model.continuous), ks)

    def options(self, range_rad: float, max_it: int, need_free: int) -> K.Options:
        """The search's options (:class:`~plannerlab.planners.native.kernels.Options`)."""
        s = self.s
        dd = np.zeros(3)
        if getattr(s, "dynamic_domain", False):
            dd[:] = (2.0 * range_rad, 0.5 * range_rad, 1e-4)  # VAMP's 4, 1 for its range 2
        return K.Options(
            self.guides,
            np.array([s.guide_bias, s.guide_sigma_rad, range_rad, self.step]),
            dd,
            np.array(
                [
                    max_it,
                    need_free,
                    int(getattr(s, "lazy_every", 1)),
                    int(getattr(s, "balance", False)),
                ],
                dtype=np.int64,
            ),
        )

    def _time_reserve_reached(self, recheck_checks: int) -> bool:
        """The time left is the re-check's (at the search's rate, with a margin)."""
        tl = self.time_limit
        if tl is None:
            return False
        return self.tracker.elapsed_s + RESERVE_FACTOR * recheck_checks * self.rate_s >= tl

    def checked(self, path: Array) -> PlanResult:
        """The path re-checked on the grid at ``joint_step / 4`` within the budget (+1 %)
        and the time limit (+1 %): solved, or why it is not trusted."""
        extra, checker = self.extra, self.checker
        path[0] = self.q0
        extra["path_length_rad"] = path_length(path, self.robot.continuous)
        extra["waypoints"] = len(path)
        cost = int(checker.grid_states(path, self.step))
        if self.max_checks is not None:
            left = self.max_checks + self.max_checks // 100 - self.tracker.checks_used
            if cost > left:
                extra["validation_checks"] = 0
                return self.result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.name} found a path but re-checking it at joint_step/4 needs "
                    f"{cost} collision checks and the budget of {self.max_checks} (+1 %) "
                    f"leaves {max(left, 0)}: the path is not trusted; give a larger "
                    "--max-checks",
                    path,
                )
        c0 = checker.checks
        check = checker.check_path(
            path,
            self.step,
            stop=lambda: self.out_of_time(TIME_SLACK),
            chunk=RECHECK_CHUNK,
            mode="grid",
        )
        extra["validation_checks"] = checker.checks - c0
        if not check.complete:
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"{self.name} found a path but the time limit of {self.time_limit:g} s "
                f"(+{TIME_SLACK:.0%}) ran out before its re-check at joint_step/4 finished: "
                "the path is not trusted; give a larger --time-limit",
                path,
            )
        if not check.valid:  # the search checked these very states: a bug
            pairs = ", ".join(f"{a} x {b}" for a, b in check.pairs)
            return self.result(
                Status.INVALID_PATH,
                f"{self.name}: the path fails the re-check at joint_step/4 on edge "
                f"{check.first_invalid_edge} ({pairs}), a state the search found free",
                path,
            )
        if bool(self.goal.contains(self.robot, path[-1])):
            return self.result(Status.SOLVED, f"{self.name}: exact solution", path)
        return self.result(
            Status.APPROXIMATE, f"{self.name}: the path ends outside the goal region", path
        )

    def stopped(self, code: int, what: str) -> PlanResult:
        """The result of a search that ended without a path (``code``: why)."""
        q0 = self.q0[None]
        if code == K.HARD:
            why = f"collision-check budget of {self.max_checks} used up"
        elif code == K.ITERATIONS:
            why = f"iteration budget of {self.budget.max_iterations} used up"
        elif code == K.FULL:
            why = (
                f"the trees filled their memory cap (max_tree_mb = {self.s.max_tree_mb:g}, "
                f"{self.extra.get('tree_rows')} states each)"
            )
        else:
            why = f"time limit of {self.time_limit:g} s reached"
        return self.result(Status.BUDGET_EXHAUSTED, f"{self.name}: no path ({what}); {why}", q0)

    # ------------------------------------------------------------------ RRT-Connect
    @staticmethod
    def new_trees(
        seeds: tuple[tuple[np.ndarray, np.ndarray | None], ...], rows: int, dof: int
    ) -> list[np.ndarray]:
        """The two trees' arrays (states, parents, check flags, dynamic-domain radii, then
        each tree's k-d tree, rows -1: not in it yet; 10 in all: A's four, B's four, A's
        and B's k-d trees) with ``rows`` rows each, seeded with (states, parents or None:
        roots)."""
        trees: list[np.ndarray] = []
        for Q0, P0 in seeds:
            Q, P = np.empty((rows, dof)), np.full(rows, -1, dtype=np.int64)
            F = np.full(rows, K.CHECKED, dtype=np.int8)
            R = np.full(rows, np.inf)
            Q[: len(Q0)] = Q0
            if P0 is not None:
                P[: len(P0)] = P0
            trees += [Q, P, F, R]
        trees += [np.full((rows, 3), -1, dtype=np.int64) for _ in range(2)]
        return trees

    def search(
        self,
        trees: list[np.ndarray],
        sizes: np.ndarray,
        counters: np.ndarray,
        rng_state: np.ndarray,
        O: K.Options,
        cap: int,
        iterations0: int = 0,
        fresh: Any = None,
    ) -> int:
        """The compiled RRT-Connect on ``trees`` in chunks (:meth:`run_chunks`), the trees
        grown (up to ``cap`` rows) when full; ``iterations`` counts from ``iterations0``.
        The range cycles over :func:`range_ladder`, ``level_checks`` checks at each (a
        chunk ends at a level's end: the ladder depends on counted checks only, so the
        same seed and check budget give the same search anywhere; ``O``'s range is set for
        each call). ``O``'s ``need_free`` must be :func:`free_rows`'. ``fresh()``: the
        trees and sizes to restart from (``restart_cycles``; None: no restarts): a run
        without a path ends at its restart point, counted in checks like the ladder, and
        the next starts from ``fresh()`` with the ladder's first level. Returns the
        kernel's last code."""
        self._charged = 0
        ladder = range_ladder(self.s, float(O.f[2]))
        per_level = (
            max(1, int(getattr(self.s, "level_checks", 0))) if len(ladder) > 1 else UNLIMITED
        )
        cycles = int(getattr(self.s, "restart_cycles", 0)) if fresh is not None else 0
        first_run = (
            cycles * len(ladder) * max(1, int(getattr(self.s, "level_checks", 0)))
            if cycles > 0
            else UNLIMITED
        )
        run = [int(counters[1]), first_run]  # this run's first check, its length
        self.extra.setdefault("restarts", 0)

        def call(soft: int, hard: int) -> int:
            if int(counters[1]) >= run[0] + run[1]:
                new_trees, new_sizes = fresh()
                trees[:] = new_trees
                sizes[:] = new_sizes
                counters[2] = 0  # the first tree extends first, as in the first run
                run[0], run[1] = int(counters[1]), 2 * run[1]
                self.extra["restarts"] += 1
            if run[1] < UNLIMITED:
                soft = min(soft, run[0] + run[1])
            level = (int(counters[1]) - run[0]) // per_level
            if len(ladder) > 1:
                soft = min(soft, run[0] + (level + 1) * per_level)
                O.f[2] = ladder[level % len(ladder)]
            A = K.Tree(trees[0], trees[1], trees[2], trees[3], trees[8])
            B = K.Tree(trees[4], trees[5], trees[6], trees[7], trees[9])
            aux = self.aux(rng_state, max(len(trees[0]), len(trees[4])))
            limits = np.array([soft, hard], dtype=np.int64)
            return int(K.rrtc_entry(self.packed, aux, A, B, sizes, O, counters, limits))

        while True:
            code = self.run_chunks(call, counters)
            self.iterations = iterations0 + int(counters[0])
            if code == K.FULL and len(trees[0]) < cap:
                grown = min(cap, 4 * len(trees[0]))
                for i, a in enumerate(trees):
                    bigger = np.full((grown,) + a.shape[1:], -1, dtype=a.dtype)  # rows unused
                    bigger[: len(a)] = a
                    trees[i] = bigger
                continue
            return code

    def rrtconnect(self) -> PlanResult:
        """RRT-Connect from the start to a tree rooted at every goal state."""
        q0 = self.q0
        if self.ctx.start_problem is not None:
            return self.result(Status.INVALID_START, self.ctx.start_problem, q0[None])
        model = self.checker.model
        self.run.progress.note(float(self.goal.distance(self.robot, q0)))
        G, failed = self.goal_pool()
        if failed is not None:
            return failed
        rng_state = K.seed_state(self.rng)
        dof = len(q0)
        range_rad = self.s.range_rad or 0.2 * space_extent(model)
        self.extra["range_rad"] = range_rad
        need_free = free_rows(model, self.s, range_rad)
        hard0 = self.hard_checks()
        cap = max(
            self.tree_rows(hard0 + need_free, len(G), dof, KD_ROW_BYTES), need_free + len(G) + 1
        )
        self.extra["tree_rows"] = cap
        rows = min(cap, max(FIRST_ROWS, need_free + len(G) + 1))

        def fresh() -> tuple[list[np.ndarray], np.ndarray]:
            """The trees as the search starts them: the start, and every goal state."""
            trees = self.new_trees(((q0[None], None), (G, None)), rows, dof)
            return trees, np.array([1, len(G)], dtype=np.int64)

        trees, sizes = fresh()
        counters = np.zeros(6, dtype=np.int64)
        max_it = UNLIMITED if self.budget.max_iterations is None else self.budget.max_iterations
        O = self.options(range_rad, max_it, need_free)
        code = self.search(trees, sizes, counters, rng_state, O, cap, fresh=fresh)
        self.extra["planning_checks"] = int(counters[1])
        self.extra["nodes"] = [int(sizes[0]), int(sizes[1])]
        self.extra["paths_failing_fine_check"] = int(counters[5])
        if code != K.DONE:
            return self.stopped(code, f"{int(sizes[0])} + {int(sizes[1])} tree nodes")
        out = np.empty((int(sizes.sum()), dof))
        A = K.Tree(trees[0], trees[1], trees[2], trees[3], trees[8])
        B = K.Tree(trees[4], trees[5], trees[6], trees[7], trees[9])
        k = K.tree_path(A, counters[3], B, counters[4], out)
        path = out[:k].copy()
        self.extra["waypoints_raw"] = k
        self.extra["length_raw"] = path_length(path, self.robot.continuous)
        if self.s.simplify:
            path = self.simplify(path, rng_state)
        return self.checked(path)

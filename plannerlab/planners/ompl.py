"""OMPL geometric planners behind plannerlab's planner contract.

This is the only module that imports ``ompl`` (the ``ompl`` 2.0.1 nanobind wheel). Every
planner in :data:`plannerlab.planners.OMPL_PLANNERS` is served as ``ompl.<suffix>`` by
:func:`make`. Everything OMPL-specific is kept here, and every OMPL object lives only
inside one :meth:`OMPLPlanner.solve` call (none at module level: the wheel reports
"leaked" objects still alive at interpreter exit).

Design (measured on ``armz_inspection``, 23 continuous joints):

* **State space.** Continuous joints are ``SO2StateSpace`` subspaces (they wrap; the
  Arm-Z twists are continuous), bounded joints one ``RealVectorStateSpace`` with the
  joint limits; a robot without continuous joints gets a plain ``RealVectorStateSpace``.
  Reading or writing a 23-joint compound state from Python costs ~4-6 µs, against
  ~150-200 µs for one collision check, so the compound space costs nothing measurable.
  OMPL's compound metric is the *sum* of the subspace distances (L1 over the continuous
  joints, L2 over the bounded block); ``range`` is in those units.
* **Validity and motions.** The state validity checker is plannerlab's
  :class:`~plannerlab.collision.fcl_checker.CollisionChecker` (every state counts in ``.checks``).
  Motions are checked by default by a Python ``MotionValidator`` (``motion_check =
  "batched"``) that interpolates the edge exactly as :func:`plannerlab.robots.paths.densify` does
  (no joint moves more than ``problem.joint_step`` between checked states) and asks
  ``checker.check_edge`` for the whole edge at once: on the compiled core
  (:mod:`plannerlab.collision.core`) interpolation, kinematics and checks of the edge are
  one call, a few µs per state. ``motion_check = "ompl"`` uses OMPL's
  discrete validator with the longest-valid-segment fraction set to ``joint_step /
  max_extent``: because the compound metric is L1, that is ``joint_step`` in the *sum*
  of joint changes, conservative and ~several times more states per edge. Limitation of
  the wheel: the ``checkMotion(s1, s2, lastValid)`` overload cannot be overridden from
  Python, so with the batched validator KPIECE1/LBKPIECE1 never keep the valid prefix
  of a failed motion (still correct, a little less efficient).
* **Projection.** KPIECE1, BKPIECE1 and LBKPIECE1 get an explicit 3-D projection: the
  tip position ``p_world`` [m], with cells of ``projection_cell_m`` (default: reach / 20,
  reach = the sum of the link lengths; 0.84 m for the 24-module Arm-Z).
* **Goal.** A ``GoalSampleableRegion`` whose ``distanceGoal`` is the normalised goal
  distance :meth:`~plannerlab.problem.goals.GoalRegion.distance` (threshold 0: inside means
  inside both tolerances; OMPL tests ``distance < threshold`` strictly, so the threshold
  is 1e-9) and whose ``sampleGoal`` hands out a pool of up to
  ``goal_samples`` goal states found by :func:`plannerlab.problem.ik.sample_goal_state`
  (seeded from the leg start) *before* planning, within the budget; their checks count.
* **Budget.** A ``PlannerTerminationCondition(callable)`` stops on iterations, collision
  checks or time; in addition the validity checker and motion validator *refuse* (report
  invalid, without checking) once the check budget is spent, so no planner can overshoot
  it, even inside loops that do not poll the termination condition (RRT-Connect's
  connect step). Iterations: the planner's own count where the wheel exposes it
  (``numIterations`` of the RRT* family and BIT*, ``milestoneCount`` of PRM), else the
  number of termination-condition polls (one per loop iteration of RRT, RRT-Connect,
  KPIECE, …). The final fine re-validation of a found path (below) is part of the
  budget, and its reserve is sound: as soon as a path exists whose re-check fits the
  checks not yet spent, that path (its waypoints) is *held* and its exact re-check cost
  is reserved: the validity checker and motion validator refuse to spend the reserve, so
  whatever planning and simplification do afterwards, the held path can still be
  re-checked within ``max_collision_checks``. The held path is replaced by a better one
  (every few polls) when that one's re-check fits too: optimizing planners (RRT*,
  Informed RRT*, BIT*) hand their path to the problem definition only when they stop, so
  it is read from their tree (``getPlannerData``: the chain of parents from the goal
  vertex); other planners' from the problem definition. After planning, the path
  re-checked is the simplified one if its re-check fits, else the held one; a path found
  whose re-check never fitted (found with fewer checks left than its re-check needs, and
  not simplified down to fit) is BUDGET_EXHAUSTED with the numbers, not trusted. How a
  planner spends its budget (which varies with the machine's floating point) thus never
  decides whether a found path can be re-checked.
  The time limit is held the same way: once a path exists, planning stops early enough
  to re-check it at the rate measured so far (seconds per check), and the steps after
  planning (interpolation, conversion, the re-check) stop at ``time_limit_s`` + 1 %;
  a path whose re-check did not finish is BUDGET_EXHAUSTED, not trusted. FMT* and BFMT*
  (``_HARD_STOP``) run long stretches of C++ that poll nothing (their first expansion
  computes every sample's neighbourhood): past the limit their callbacks raise
  ``_TimeUp``, which unwinds OMPL's loop back to ``solve``.
* **PRM / PRM\\***: OMPL's ``PRM::solve`` checks for a solution in a second thread; with
  Python callbacks the wheel deadlocks there (the caller keeps the GIL while joining).
  These two are therefore driven single-threaded: ``growRoadmap``/``expandRoadmap`` in
  slices of termination polls (not OMPL's ``constructRoadmap``, whose sub-slices are
  timed and so depend on the machine's load), then
  the start and the goal pool are connected to their nearest roadmap vertices and the
  roadmap is searched (Dijkstra, scipy) in Python.
* **After solving.** OMPL's ``PathSimplifier`` (within the remaining budget; path length
  before and after in ``extra``), ``interpolate``, conversion to ``(m, dof)`` with
  continuous joints wrapped into ``[-pi, pi)``, then ``checker.check_path(path,
  problem.joint_step / 4)``: only a path that passes is SOLVED; an approximate solution is
  APPROXIMATE. A path the re-check refuses (one the simplifier pulled taut against an
  obstacle grazes it between the states checked at ``joint_step``) is repaired within the
  budget left, on motions checked as the re-check sees them (:meth:`OMPLPlanner._repair`),
  and re-checked again; INVALID_PATH when that fails too.
* **Logging.** The wheel's ``OutputHandler`` cannot be subclassed from Python (no
  constructor is bound), so during a solve OMPL writes to an ``OutputHandlerFile`` in a
  temporary file; afterwards each message is re-emitted on the ``plannerlab.ompl``
  logger at its level, and the previous handler and log level are restored. OMPL's log
  level follows that logger's effective level.
* **Seeding.** OMPL's seed is process-global and only takes effect before OMPL's first
  random generator exists. ``solve`` asks for a seed derived from ``rng``
  (``ompl.util.RNG.setSeed``): in a fresh process the first solve's request takes
  effect (before it, no OMPL generator exists, whatever :func:`seed_ompl` set), so a
  seeded trial, which runs in its own process, is reproducible; every later request in
  that process has no effect (OMPL logs an error, re-emitted here at DEBUG level). OMPL
  is thus seeded once per process, and every leg records the seed **in effect**
  (``extra["ompl_seed"]``, ``ompl.util.RNG.getSeed()``), not the one it asked for.
"""

from __future__ import annotations

import ctypes
import dataclasses
import logging
import math
import os
import tempfile
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
import ompl.base as ob
import ompl.geometric as og
import ompl.util as ou

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker
from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    BudgetTracker,
    LegRun,
    PlanResult,
    Status,
    start_collision,
    with_overrides,
)
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.ik import sample_goal_state
from plannerlab.robots.base import Array, Robot, joint_difference, wrap_to_pi
from plannerlab.robots.paths import path_length

LOGGER = logging.getLogger("plannerlab.ompl")

#: OMPL seeds must be in [1, 2**31 - 1] (0 means "random" to OMPL)
_SEED_MAX = 2**31 - 1
#: how the goal pool is filled (``goal_selection`` setting)
GOAL_SELECTIONS = ("ik", "near", "near_or_ik")


# ---------------------------------------------------------------------------- settings
@dataclass(frozen=True)
class OMPLSettings:
    """Settings every OMPL planner shares.

    Attributes:
        simplify: run OMPL's PathSimplifier on the solution (within the remaining budget).
        interpolate: densify the returned path so no joint moves more than
            ``problem.joint_step`` between consecutive states.
        goal_samples: size of the IK goal-state pool handed out by ``sampleGoal``.
        max_goal_attempts: IK descents at most to fill the pool.
        motion_check: ``"batched"`` (plannerlab edge check, Linf steps of joint_step) or
            ``"ompl"`` (OMPL's discrete motion validator).
        goal_selection: ``"ik"`` (numeric IK restarts seeded from the leg start, see
            :func:`~plannerlab.problem.ik.sample_goal_state`) or ``"near"`` (the goal state
            ``gradient.clearance`` selects: its descent from the leg start with the path
            unchecked, so the goal stays near the start; one state, one check) or
            ``"near_or_ik"`` (that near state; when its descent ends in no collision-free
            goal state, ``goal_samples`` IK states as with ``"ik"``: the escape of
            ``gradient.clearance+rrtconnect``, which gave up with ``invalid_goal`` before).
    """

    simplify: bool = True
    interpolate: bool = True
    goal_samples: int = 4
    max_goal_attempts: int = 200
    motion_check: str = "batched"
    goal_selection: str = "ik"


@dataclass(frozen=True)
class RangeSettings(OMPLSettings):
    """Planners with a step size. ``range``: longest motion added at once, in the state
    space's metric [rad, summed over joints]; 0 = OMPL's default (20 % of the extent)."""

    range: float = 0.0


@dataclass(frozen=True)
class GoalBiasSettings(RangeSettings):
    """Planners with a goal bias: probability of sampling a goal state instead of a
    random one."""

    goal_bias: float = 0.05


@dataclass(frozen=True)
class RRTstarSettings(GoalBiasSettings):
    """RRT* family. ``rewire_factor`` scales the rewiring radius / k."""

    rewire_factor: float = 1.1


@dataclass(frozen=True)
class SORRTstarSettings(RRTstarSettings):
    """SORRT*: ``batch_size`` ordered informed samples per batch. Each sample's ordering
    evaluates the goal heuristic (Python ``distanceGoal``) many times: measured ~1e6 calls
    and ~30 s on a 5-joint toy problem with batch_size 10, and no termination with OMPL's
    default 100 (the sampler does not poll the termination condition)."""

    batch_size: int = 10


@dataclass(frozen=True)
class KPIECESettings(GoalBiasSettings):
    """KPIECE1. ``projection_cell_m``: cell edge of the tip-position projection [m]
    (None: reach / 20)."""

    border_fraction: float = 0.9
    failed_expansion_score_factor: float = 0.5
    min_valid_path_fraction: float = 0.2
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class BKPIECESettings(RangeSettings):
    """BKPIECE1 (bidirectional KPIECE)."""

    border_fraction: float = 0.9
    failed_expansion_score_factor: float = 0.5
    min_valid_path_fraction: float = 0.5
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class LBKPIECESettings(RangeSettings):
    """LBKPIECE1 (lazy bidirectional KPIECE)."""

    border_fraction: float = 0.9
    min_valid_path_fraction: float = 0.5
    projection_cell_m: float | None = None


@dataclass(frozen=True)
class PRMSettings(OMPLSettings):
    """PRM. ``max_nearest_neighbors``: k of the k-nearest connection strategy (also used
    to connect the start and the goal pool); ``roadmap_slice_polls``: termination polls
    per roadmap-growing slice between solution searches."""

    max_nearest_neighbors: int = 10
    roadmap_slice_polls: int = 50


@dataclass(frozen=True)
class PRMstarSettings(OMPLSettings):
    """PRM* (k chosen by OMPL). See :class:`PRMSettings`."""

    roadmap_slice_polls: int = 50


@dataclass(frozen=True)
class BITstarSettings(OMPLSettings):
    """BIT*."""

    samples_per_batch: int = 100
    rewire_factor: float = 1.1
    use_k_nearest: bool = True


@dataclass(frozen=True)
class FMTSettings(OMPLSettings):
    """FMT* / BFMT*: ``num_samples`` states are sampled up front."""

    num_samples: int = 1000
    radius_multiplier: float = 1.1
    nearest_k: bool = True


#: OMPL class -> settings dataclass
SETTINGS_BY_CLASS: Mapping[str, type[OMPLSettings]] = {
    "RRTConnect": RangeSettings,
    "RRT": GoalBiasSettings,
    "RRTstar": RRTstarSettings,
    "InformedRRTstar": RRTstarSettings,
    "SORRTstar": SORRTstarSettings,
    "KPIECE1": KPIECESettings,
    "BKPIECE1": BKPIECESettings,
    "LBKPIECE1": LBKPIECESettings,
    "PRM": PRMSettings,
    "PRMstar": PRMstarSettings,
    "BITstar": BITstarSettings,
    "FMT": FMTSettings,
    "BFMT": FMTSettings,
    "AORRTC": RangeSettings,
}

#: settings field -> OMPL setter (called when the planner has it)
_SETTERS: Mapping[str, str] = {
    "range": "setRange",
    "goal_bias": "setGoalBias",
    "rewire_factor": "setRewireFactor",
    "batch_size": "setBatchSize",
    "border_fraction": "setBorderFraction",
    "failed_expansion_score_factor": "setFailedExpansionCellScoreFactor",
    "min_valid_path_fraction": "setMinValidPathFraction",
    "max_nearest_neighbors": "setMaxNearestNeighbors",
    "samples_per_batch": "setSamplesPerBatch",
    "use_k_nearest": "setUseKNearest",
    "num_samples": "setNumSamples",
    "radius_multiplier": "setRadiusMultiplier",
    "nearest_k": "setNearestK",
}

_KPIECE = frozenset({"KPIECE1", "BKPIECE1", "LBKPIECE1"})
_ROADMAP = frozenset({"PRM", "PRMstar"})
#: optimizing planners that are made to return on their first path, which is then held and
#: the search resumed (BIT*: reading its tree through ``getPlannerData`` leaks its space
#: information in the wheel, and once it has a path, ``stopOnSolnImprovement`` makes every
#: later solve return at once); later improvements are not held: if the final path's
#: re-check does not fit, the first one is re-checked
_STOP_ON_FIRST = frozenset({"BITstar"})
#: planners whose informed samplers need a RealVector space (see ``_Space``)
#: how often (termination polls) a better path is looked for to hold (its re-check's
#: checks reserved) while an optimizing planner improves it
_RESERVE_EVERY_POLLS = 8
#: the *time* reserve is this many times the held path's re-check at the solve's rate:
#: planners poll their termination condition between steps, so they stop a little late
#: (the check reserve needs no factor: the guard refuses to spend it)
_RESERVE_FACTOR = 1.25
#: the steps after planning (the fine re-check) may run this fraction past the time limit
_TIME_SLACK = 0.01
#: planners whose expansion runs long stretches of C++ without polling the termination
#: condition (FMT*'s and BFMT*'s first expansion computes every sample's neighbourhood):
#: past the time limit a validity callback raises, and the exception unwinds their solve
_HARD_STOP = frozenset({"FMT", "BFMT"})
#: states converted / re-checked between two looks at the clock
_CHUNK_STATES = 2048
_LIFTED = frozenset({"InformedRRTstar", "SORRTstar", "BITstar", "AORRTC"})
_MOTION_CHECKS = ("batched", "ompl")
#: OMPL's GoalRegion is satisfied when distanceGoal < threshold (strict)
_GOAL_THRESHOLD = 1e-9


def seed_ompl(seed: int) -> None:
    """Seed OMPL's process-global RNG. Call before any OMPL object exists (fresh process).

    Args:
        seed: any integer; mapped into OMPL's valid range [1, 2**31 - 1].
    """
    ou.RNG.setSeed(int(seed) % (_SEED_MAX - 1) + 1)


# ---------------------------------------------------------------------------- logging
_OMPL_PREFIXES = (
    ("Debug:", logging.DEBUG),
    ("Info:", logging.INFO),
    ("Warning:", logging.WARNING),
    ("Error:", logging.ERROR),
)


def _ompl_level(logger: logging.Logger) -> Any:
    level = logger.getEffectiveLevel()
    if level <= logging.DEBUG:
        return ou.LOG_DEBUG
    if level <= logging.INFO:
        return ou.LOG_INFO
    if level <= logging.WARNING:
        return ou.LOG_WARN
    if level <= logging.ERROR:
        return ou.LOG_ERROR
    return ou.LOG_NONE


def _forward_log(text: str, logger: logging.Logger) -> None:
    """Re-emit the lines an ``OutputHandlerFile`` wrote, one record per OMPL message."""
    messages: list[tuple[int, str]] = []
    for line in text.splitlines():
        for prefix, level in _OMPL_PREFIXES:
            if line.startswith(prefix):
                messages.append((level, line[len(prefix) :].strip()))
                break
        else:
            if messages and line.strip():
                lvl, msg = messages[-1]
                messages[-1] = (lvl, f"{msg} ({line.strip()})")
    for level, msg in messages:
        if "Random number generation already started" in msg:
            level = logging.DEBUG  # expected for every solve after the first in a process
        logger.log(level, "OMPL: %s", msg)


@contextmanager
def _ompl_logging(logger: logging.Logger) -> Iterator[None]:
    """Route OMPL's output into ``logger`` for the duration of the block."""
    fd, filename = tempfile.mkstemp(prefix="plannerlab_ompl_", suffix=".log")
    os.close(fd)
    previous_level = ou.getLogLevel()
    handler = ou.OutputHandlerFile(filename)
    ou.useOutputHandler(handler)
    ou.setLogLevel(_ompl_level(logger))
    try:
        yield
    finally:
        ou.restorePreviousOutputHandler()
        ou.setLogLevel(previous_level)
        del handler  # closes the file
        try:
            with open(filename, encoding="utf-8", errors="replace") as f:
                _forward_log(f.read(), logger)
        finally:
            os.unlink(filename)


# ---------------------------------------------------------------------------- helpers
def _recheck_cost(path: Array, joint_step: float, checker: CollisionChecker) -> int:
    """Collision checks ``checker.check_path(path, joint_step)`` will make at most (all
    states of the path as the checker densifies it, metric edge resolution included;
    conservative advancement makes no more), computed without checking anything."""
    return checker.grid_states(path, joint_step)


def _goal_chain(data: Any, space: _Space) -> Array | None:
    """The chain of parents from the first goal vertex of OMPL planner data to a start
    vertex, as joint vectors (start first); None if there is none."""
    if data.numGoalVertices() == 0 or data.numStartVertices() == 0:
        return None
    v = int(data.getGoalIndex(0))
    chain = [v]
    seen = {v}
    while not data.isStartVertex(v):
        parents = data.getIncomingEdges(v)
        if not parents or parents[0] in seen:
            return None  # not a tree chain
        v = int(parents[0])
        seen.add(v)
        chain.append(v)
    return np.array([space.to_q(data.getVertex(i).getState()) for i in reversed(chain)])


def _reach_m(robot: Robot, q: Array) -> float:
    """An upper bound of the tip's distance from the base [m]: the sum of link lengths."""
    seg = robot.link_segments(np.asarray(q, dtype=float))
    return float(np.sum(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=-1)))


#: most states of a path handed to OMPL's PathSimplifier.simplify (its collapseCloseVertices
#: takes time cubic in them, with no termination condition polled)
_SIMPLIFY_MAX_STATES = 400

#: the capsule name nanobind reads a ``void *`` argument from (see ``_Space._fast_reader``)
_NB_HANDLE = b"nb_handle"


class _Space:
    """Conversion between joint vectors and OMPL states for one robot (one solve).

    ``lifted=False``: SO2 subspaces for continuous joints (+ one RealVector block for the
    bounded ones). ``lifted=True``: a single RealVectorStateSpace in which each continuous
    joint ranges over ``[c - 2 pi, c + 2 pi]`` around the start ``c`` (a double cover of
    the circle: every path in it is a valid path of the robot, and every path that turns a
    joint by less than ±pi net from the start is in it). Used by planners whose informed
    samplers only accept real-vector spaces (InformedRRT*, SORRT*, BIT*, AORRTC).
    """

    def __init__(self, robot: Robot, lifted: bool = False, center: Array | None = None) -> None:
        self.robot = robot
        self.dof = robot.dof
        self.lifted = lifted
        cont = np.asarray(robot.continuous, dtype=bool)
        self.center = (
            np.zeros(self.dof) if center is None else np.asarray(center, dtype=float).copy()
        )
        if lifted:
            self.cont_idx: list[int] = []
            self.bound_idx = list(range(self.dof))
            lo = np.where(cont, self.center - 2.0 * np.pi, robot.lower)
            hi = np.where(cont, self.center + 2.0 * np.pi, robot.upper)
            self.space = self._real_vector(lo, hi)
            self.compound = False
            self._use_fast_reader()
            return
        self.cont_idx = [int(i) for i in np.flatnonzero(cont)]
        self.bound_idx = [int(i) for i in np.flatnonzero(~cont)]
        self.compound = bool(self.cont_idx)
        if self.compound:
            space = ob.CompoundStateSpace()
            for _ in self.cont_idx:
                space.addSubspace(ob.SO2StateSpace(), 1.0)
            if self.bound_idx:
                space.addSubspace(
                    self._real_vector(robot.lower[self.bound_idx], robot.upper[self.bound_idx]), 1.0
                )
        else:
            space = self._real_vector(robot.lower, robot.upper)
        self.space = space
        self._use_fast_reader()

    def _use_fast_reader(self) -> None:
        reader = self._fast_reader()
        if reader is not None:
            self.to_q = reader  # type: ignore[method-assign, assignment]

    def _fast_reader(self) -> Callable[[Any], Array] | None:
        """One-call reading of a state, or None: OMPL's ``StateSpace::serialize`` writes
        the state's reals (SO2 values, then the RealVector block: :meth:`to_q`'s order)
        into a buffer this space owns, passed as the ``void *`` capsule nanobind accepts;
        one binding call instead of two per joint. Used only if the layout is confirmed on
        a test state (else None, and :meth:`to_q` reads joint by joint)."""
        buf = np.zeros(self.dof)
        try:
            if int(self.space.getSerializationLength()) != buf.nbytes:
                return None
            new = ctypes.pythonapi.PyCapsule_New
            new.restype = ctypes.py_object
            new.argtypes = (ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p)
            capsule = new(buf.ctypes.data, _NB_HANDLE, None)
            serialize = self.space.serialize
            probe = self.space.allocState()  # freed with its Python object
            q = wrap_to_pi(self.center + 0.1 + 0.01 * np.arange(self.dof), self.robot.continuous)
            self.set_state(probe, q)
            serialize(capsule, probe)
            order = self.cont_idx + self.bound_idx  # the joint of each serialized real
            ok = np.array_equal(buf[np.argsort(order)], self._read(probe))
        except (TypeError, AttributeError, ValueError):
            return None
        if not ok:
            return None
        self._buf = buf  # the capsule points into it: kept alive with this space
        if order == list(range(self.dof)):

            def read(state: Any) -> Array:
                serialize(capsule, state)
                return buf.copy()

            return read
        joint_of = np.argsort(order)  # q = buf[joint_of] (a new array)

        def read_permuted(state: Any) -> Array:
            serialize(capsule, state)
            return buf[joint_of]

        return read_permuted

    @staticmethod
    def _real_vector(lower: Array, upper: Array) -> Any:
        n = len(lower)
        rv = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for j in range(n):
            bounds.setLow(j, float(lower[j]))
            bounds.setHigh(j, float(upper[j]))
        rv.setBounds(bounds)
        return rv

    def to_q(self, state: Any) -> Array:
        """The joint vector (dof,) of an OMPL state (a new array)."""
        return self._read(state)

    def _read(self, state: Any) -> Array:
        """:meth:`to_q` joint by joint (two binding calls per joint)."""
        q = np.empty(self.dof)
        if self.compound:
            for k, i in enumerate(self.cont_idx):
                q[i] = state[k].value
            if self.bound_idx:
                rv = state[len(self.cont_idx)]
                for j, i in enumerate(self.bound_idx):
                    q[i] = rv[j]
        else:
            for j, i in enumerate(self.bound_idx):
                q[i] = state[j]
        return q

    def set_state(self, state: Any, q: Array) -> None:
        q = np.asarray(q, dtype=float)
        if self.lifted:  # the lift of q nearest to the centre
            q = self.center + joint_difference(q, self.center, self.robot.continuous)
        else:
            q = wrap_to_pi(q, self.robot.continuous)
        if self.compound:
            for k, i in enumerate(self.cont_idx):
                state[k].value = float(q[i])
            if self.bound_idx:
                rv = state[len(self.cont_idx)]
                for j, i in enumerate(self.bound_idx):
                    rv[j] = float(q[i])
        else:
            for j, i in enumerate(self.bound_idx):
                state[j] = float(q[i])

    def pair_metric(self, A: Array, B: Array) -> Array:
        """OMPL's distance between the rows of A and B (k, dof) pairwise."""
        d = np.abs(joint_difference(A, B, self.robot.continuous)).reshape(len(A), -1)
        out = d[:, self.cont_idx].sum(axis=1) if self.cont_idx else np.zeros(len(A))
        if self.bound_idx:
            out = out + np.linalg.norm(d[:, self.bound_idx], axis=1)
        return out

    def metric(self, Q: Array, q: Array) -> Array:
        """OMPL's distance from each row of Q (k, dof) to q: L1 continuous + L2 bounded."""
        d = np.abs(joint_difference(Q, q[None, :], self.robot.continuous))
        out = d[:, self.cont_idx].sum(axis=1) if self.cont_idx else np.zeros(len(Q))
        if self.bound_idx:
            out = out + np.linalg.norm(d[:, self.bound_idx], axis=1)
        return out


class _TimeUp(Exception):
    """Raised by a validity callback past the time limit: it unwinds OMPL's C++ loop."""


class _Guard:
    """One solve's collision checker and termination condition, behind its
    :class:`~plannerlab.planners.base.BudgetTracker`: the checker refuses (reports
    invalid, without checking) once the checks are spent or the time limit is reached;
    the termination condition counts its polls, which are the iterations of planners that
    expose no count of their own (``iteration_source``)."""

    def __init__(self, checker: CollisionChecker, tracker: BudgetTracker) -> None:
        self.checker = checker
        self.tracker = tracker
        self.polls = 0
        self.refused = 0
        self.iteration_source: Callable[[], int] | None = None
        #: raise _TimeUp past the time limit (set while an OMPL solve runs, for planners
        #: with loops that poll nothing, see _HARD_STOP)
        self.hard_stop = False
        #: checks held back for the re-check of the best path found so far: the checker
        #: refuses to spend them, so that path's re-check always fits the budget
        self.reserve = 0

    def iterations(self) -> int:
        return self.iteration_source() if self.iteration_source is not None else self.polls

    def exhausted(self) -> str | None:
        return self.tracker.exhausted(self.iterations())

    def poll(self) -> bool:
        """The termination condition: True once any limit is reached."""
        self.polls += 1
        if self.hard_stop and self.out_of_time():
            raise _TimeUp()
        return self.exhausted() is not None

    def out_of_time(self) -> bool:
        """The time limit is reached."""
        tl = self.tracker.budget.time_limit_s
        return tl is not None and self.tracker.elapsed_s >= tl

    def _out_of_time(self) -> bool:
        """Past the time limit: refuse, so that loops which do not poll the termination
        condition (the goal pool's IK) end quickly too; with ``hard_stop``, raise
        :class:`_TimeUp` instead, out through OMPL's C++ to the solve."""
        if self.out_of_time():
            self.refused += 1
            if self.hard_stop:
                raise _TimeUp()
            return True
        return False

    def checks_left(self) -> int | None:
        """Checks the planning may still spend: the budget's, less the reserve."""
        left = self.tracker.checks_left()
        return None if left is None else max(left - self.reserve, 0)

    def is_valid(self, q: Array) -> bool:
        left = self.checks_left()
        if left is not None and left <= 0:
            self.refused += 1
            return False
        if self._out_of_time():
            return False
        return self.checker.is_valid(q)

    def edge_valid(self, q_a: Array, q_b: Array, joint_step: float) -> bool:
        """Every state of the edge after q_a (q_b included) is valid, checked in order.

        One call to the checker for the whole edge (interpolation included); with too
        little budget left for the whole edge, checks what it may, then refuses.
        """
        if self._out_of_time():
            return False
        left = self.checks_left()
        n, bad = self.checker.check_edge(q_a, q_b, joint_step, left)
        if left is not None and left < n:
            self.refused += 1
            return False
        return bad is None

    def path_valid(self, Q: Array, joint_step: float) -> bool:
        """Every state ``checker.check_path(Q, joint_step)`` checks is valid (the re-check's
        own states of a motion, for the repair); refused without checking when they do not
        all fit the checks left."""
        if self._out_of_time():
            return False
        left = self.checks_left()
        if left is not None and self.checker.grid_states(Q, joint_step) > left:
            self.refused += 1
            return False
        return self.checker.check_path(Q, joint_step).valid


def _goal_class() -> type:
    """The goal type (created per solve so no OMPL-derived type outlives a solve)."""

    class PoolGoal(ob.GoalSampleableRegion):
        """Goal region with normalised distance and a precomputed IK pool."""

        def __init__(
            self,
            si: Any,
            distance: Callable[[Any], float],
            fill: Callable[[Any, int], None],
            pool_size: int,
        ) -> None:
            super().__init__(si)
            # GoalRegion.distance is exactly 0 inside the region; OMPL's isSatisfied tests
            # distance < threshold (strictly), so "threshold 0" is a tiny positive number.
            self.setThreshold(_GOAL_THRESHOLD)
            self._distance = distance
            self._fill = fill
            self._size = pool_size
            self._next = 0

        def distanceGoal(self, state: Any) -> float:  # noqa: N802 - OMPL's name
            return self._distance(state)

        def sampleGoal(self, state: Any) -> None:  # noqa: N802
            self._fill(state, self._next % self._size)
            self._next += 1

        def maxSampleCount(self) -> int:  # noqa: N802
            return self._size

        def couldSample(self) -> bool:  # noqa: N802
            return self._size > 0

    return PoolGoal


def _projection(
    space: _Space, cell_m: float, center: Array, reach: float, counter: list[int]
) -> Any:
    """Tip-position projection (3-D, metres) for the KPIECE family."""

    class TipProjection(ob.ProjectionEvaluator):
        def getDimension(self) -> int:  # noqa: N802
            return 3

        def project(self, state: Any, projection: Any) -> None:
            counter[0] += 1
            p, _ = space.robot.tip(space.to_q(state))
            projection[:] = p

    proj = TipProjection(space.space)
    bounds = ob.RealVectorBounds(3)
    for d in range(3):
        bounds.setLow(d, float(center[d] - reach))
        bounds.setHigh(d, float(center[d] + reach))
    proj.setBounds(bounds)
    proj.inferCellSizes()  # sizes the cell vector; then set the real sizes
    for d in range(3):
        proj.setCellSizes(d, float(cell_m))
    return proj


def _near_goal(
    problem: Any, leg: int, q0: Array, checker: CollisionChecker, tracker: BudgetTracker
) -> Array | None:
    """The goal state ``gradient.clearance`` selects near q0 (see ``goal_selection``)."""
    from plannerlab.planners.gradient_clearance import make as make_clearance

    return make_clearance("gradient.clearance", {}).near_goal_state(
        problem, leg, q0, checker, tracker
    )


@dataclass(frozen=True)
class _RepairKit:
    """What :meth:`OMPLPlanner._repair` works with: one solve's OMPL objects, its guard,
    how a path becomes the states re-checked (``rows_of``), the clock of the steps after
    planning (``past_time``), the re-check's step and the leg's ``extra``."""

    si: Any
    space: _Space
    guard: _Guard
    planner: Any
    pdef: Any
    goal_obj: Any
    rows_of: Callable[[Any], Array]
    past_time: Callable[[], bool]
    recheck_step: float
    extra: dict[str, Any]


# ---------------------------------------------------------------------------- planner
@dataclass(frozen=True)
class OMPLPlanner:
    """One OMPL geometric planner with frozen settings (see the module docstring)."""

    name: str
    ompl_class: str
    settings: OMPLSettings

    def solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None = None,
        stepper: Any | None = None,
    ) -> PlanResult:
        """Plan leg ``leg`` of ``problem`` within ``budget``.

        Args:
            problem: the problem (robot, scene, goals, joint_step).
            leg: leg index.
            budget: iterations / collision checks / time; at least one must be set.
            rng: the trial's generator (IK pool, OMPL seed).
            q_start: (dof,) start; default: the problem's start.
            stepper: unused (OMPL planners are open-loop).

        Returns:
            A :class:`PlanResult`; failures are statuses with reasons.
        """
        del stepper
        if (
            budget.max_iterations is None
            and budget.max_collision_checks is None
            and budget.time_limit_s is None
        ):
            raise PlannerlabError(
                f"{self.name}: the budget needs at least one limit "
                "(max_iterations, max_collision_checks or time_limit_s)"
            )
        if self.settings.motion_check not in _MOTION_CHECKS:
            raise PlannerlabError(
                f"{self.name}: motion_check must be one of "
                f"{', '.join(_MOTION_CHECKS)}, got "
                f"{self.settings.motion_check!r}"
            )
        if self.settings.goal_selection not in GOAL_SELECTIONS:
            raise PlannerlabError(
                f"{self.name}: goal_selection must be one of "
                f"{', '.join(map(repr, GOAL_SELECTIONS))}, got "
                f"{self.settings.goal_selection!r}"
            )
        requested = int(rng.integers(1, _SEED_MAX))
        with _ompl_logging(LOGGER):
            # effective only before OMPL's first generator exists (the first solve of a
            # process); every leg records the seed in effect, whether or not this took
            ou.RNG.setSeed(requested)
            ompl_seed = int(ou.RNG.getSeed())
            result = self._solve(problem, leg, budget, rng, q_start, ompl_seed)
        return result

    def _solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None,
        ompl_seed: int,
    ) -> PlanResult:
        checker = problem_checker(problem)
        if self.settings.goal_selection != "ik":
            # the near goal's descent is compiled: its kernels are loaded (or compiled)
            # before the tracker starts, as the checker's core is
            from plannerlab.planners._descent_core import warm_up

            warm_up()
        guard = _Guard(checker, BudgetTracker(budget, checker))
        try:
            return self._plan(problem, leg, rng, q_start, ompl_seed, guard)
        finally:
            # Python callbacks held by OMPL objects reference the planner through this
            # bound method: break the cycle so every OMPL object is freed with the solve.
            guard.iteration_source = None

    # ------------------------------------------------------------------ internals
    def _plan(
        self,
        problem: Any,
        leg: int,
        rng: np.random.Generator,
        q_start: Array | None,
        ompl_seed: int,
        guard: _Guard,
    ) -> PlanResult:
        s = self.settings
        robot: Robot = problem.robot
        goal: GoalRegion = problem.goal(leg)
        checker, tracker = guard.checker, guard.tracker
        max_checks = tracker.budget.max_collision_checks
        q0 = wrap_to_pi(
            np.asarray(problem.q_start if q_start is None else q_start, dtype=float).reshape(
                robot.dof
            ),
            robot.continuous,
        )
        fk = [0]
        trace: list[float] = []
        run = LegRun(self.name, s, problem, leg, tracker)
        progress = run.progress
        extra: dict[str, Any] = {"ompl_class": self.ompl_class, "ompl_seed": ompl_seed}

        def result(status: Status, reason: str, path: Array, iterations: int) -> PlanResult:
            """The leg's result, with the counts of the solve so far."""
            extra["refused_checks"] = guard.refused
            return run.result(
                status,
                reason,
                path,
                iterations=iterations,
                fk_calls=fk[0],
                trace=trace,
                extra=extra,
            )

        start_problem = start_collision(checker, q0)
        if start_problem is not None:
            return result(Status.INVALID_START, start_problem, q0[None], 0)
        fk[0] += 1
        progress.note(float(goal.distance(robot, q0)))  # where the search starts from

        # Goal pool (IK), within the budget.
        pool: list[Array] = []
        c_pool = checker.checks
        per_slot = max(1, s.max_goal_attempts // max(s.goal_samples, 1))
        pool_cut_short = ""
        selection = s.goal_selection
        if selection == "near_or_ik":
            # the near goal first; when its descent finds none, the IK pool
            q_near = (
                None
                if guard.exhausted() is not None
                else _near_goal(problem, leg, q0, checker, tracker)
            )
            extra["goal_near_found"] = q_near is not None
            if q_near is not None:
                pool.append(wrap_to_pi(q_near, robot.continuous))
            selection = "near" if pool else "ik"
        for _ in range(s.goal_samples if not pool else 0):
            if guard.exhausted() is not None:
                pool_cut_short = guard.exhausted() or ""
                break
            if selection == "near":
                q_goal = _near_goal(problem, leg, q0, checker, tracker)
            else:
                q_goal = sample_goal_state(
                    robot, goal, guard, rng, seeds=[q0], attempts=per_slot, stop=guard.out_of_time
                )
            if q_goal is not None:
                pool.append(wrap_to_pi(q_goal, robot.continuous))
        extra["goal_pool"] = len(pool)
        extra["goal_pool_checks"] = checker.checks - c_pool

        space = _Space(robot, lifted=self.ompl_class in _LIFTED, center=q0)
        extra["state_space"] = (
            "lifted_real_vector"
            if space.lifted
            else "so2_compound"
            if space.compound
            else "real_vector"
        )
        si = ob.SpaceInformation(space.space)

        def state_valid(state: Any) -> bool:
            return guard.is_valid(space.to_q(state))

        si.setStateValidityChecker(state_valid)
        extent = space.space.getMaximumExtent()
        si.setStateValidityCheckingResolution(min(problem.joint_step / extent, 1.0))
        if s.motion_check == "batched":
            step = problem.joint_step

            class EdgeValidator(ob.MotionValidator):
                def checkMotion(self, a: Any, b: Any) -> bool:  # noqa: N802
                    return guard.edge_valid(space.to_q(a), space.to_q(b), step)

            motion_validator = EdgeValidator(si)
            si.setMotionValidator(motion_validator)
        si.setup()

        best = [math.inf]

        tip = checker.tip  # compiled kinematics where the checker has them
        # a goal whose distance is GoalRegion's (the tip's) takes the compiled tip; a goal
        # with a distance of its own (a joint goal, say) is asked as it is
        by_tip = type(goal).distance is GoalRegion.distance

        def distance(state: Any) -> float:
            fk[0] += 1
            q = space.to_q(state)
            d = float(goal.distance_from_tip(*tip(q)) if by_tip else goal.distance(robot, q))
            if d < best[0]:
                best[0] = d
                trace.append(d)
                progress.note(d)
            return d

        def fill(state: Any, i: int) -> None:
            space.set_state(state, pool[i])

        goal_obj = _goal_class()(si, distance, fill, len(pool))
        pdef = ob.ProblemDefinition(si)
        start = space.space.allocState()
        space.set_state(start, q0)
        pdef.addStartState(start)
        pdef.setGoal(goal_obj)

        planner = getattr(og, self.ompl_class)(si)
        for field in dataclasses.fields(s):
            setter = _SETTERS.get(field.name)
            if setter is not None and hasattr(planner, setter):
                getattr(planner, setter)(getattr(s, field.name))
        if self.ompl_class in _KPIECE:
            reach = _reach_m(robot, q0)
            cell = s.projection_cell_m or reach / 20.0  # type: ignore[attr-defined]
            extra["projection_cell_m"] = cell
            planner.setProjectionEvaluator(
                _projection(space, cell, robot.T_world_base[:3, 3], reach, fk)
            )
        if hasattr(planner, "numIterations"):
            guard.iteration_source = planner.numIterations
        elif self.ompl_class in _ROADMAP:
            guard.iteration_source = planner.milestoneCount
        planner.setProblemDefinition(pdef)
        planner.setup()

        recheck_step = problem.joint_step / 4.0

        def rows_of(ompl_path: Any) -> Array:
            """The path that will be re-checked: interpolated (if set), wrapped, from q0."""
            if s.interpolate:
                ompl_path = og.PathGeometric(ompl_path)
                ompl_path.interpolate()
            n = ompl_path.getStateCount()
            Q = wrap_to_pi(
                np.array([space.to_q(ompl_path.getState(i)) for i in range(n)]), robot.continuous
            )
            if len(Q):
                Q[0] = q0
            return Q

        def recheck_cost(ompl_path: Any) -> int:
            return _recheck_cost(rows_of(ompl_path), recheck_step, checker)

        def ompl_path_of(Q: Array) -> Any:
            """An OMPL path through the waypoints Q (k, dof) (states copied in)."""
            p = og.PathGeometric(si)
            st = space.space.allocState()
            for q in Q:
                space.set_state(st, q)
                p.append(st)  # appends a copy
            return p

        #: the path the check reserve holds (waypoints, start first) and its re-check cost
        held: list[Any] = [None, 0]

        def hold(Q: Array) -> bool:
            """Hold back the re-check cost of the path through Q, if it fits the checks not
            yet spent: from now on planning cannot spend them (the guard refuses), so this
            path (or a better one that fits) can always be re-checked within the budget."""
            cost = recheck_cost(ompl_path_of(Q))
            left = tracker.checks_left()
            if left is not None and cost > left:
                return False
            held[0], held[1] = Q, cost
            guard.reserve = cost if left is not None else 0
            extra.setdefault("reserve_held_at_checks", tracker.checks_used)
            extra["reserve_checks"] = cost
            return True

        def waypoints_of(ompl_path: Any) -> Array:
            return np.array(
                [space.to_q(ompl_path.getState(i)) for i in range(ompl_path.getStateCount())]
            )

        def tree_best_path() -> Array | None:
            """The best path of an optimizing planner's tree (RRT*, Informed RRT*, BIT*:
            they hand their path to the problem definition only when they stop): the chain
            of parents from its goal vertex to the start, from OMPL's planner data."""
            data = ob.PlannerData(si)
            try:
                planner.getPlannerData(data)
                return _goal_chain(data, space)
            finally:
                data.clear()

        best_seen = [math.inf]

        time_limit = tracker.budget.time_limit_s

        def past_time() -> bool:
            """The steps after planning are over the time limit (+ its slack)."""
            return time_limit is not None and tracker.elapsed_s > time_limit * (1.0 + _TIME_SLACK)

        def planning_done() -> bool:
            """Any limit reached, or a path is held and the checks left are its reserve
            (asymptotically optimal planners would otherwise spend the whole budget
            improving it)."""
            if guard.poll():
                return True
            if max_checks is None and time_limit is None:
                return False
            due = held[0] is None or guard.polls % _RESERVE_EVERY_POLLS == 0
            if self.ompl_class in _STOP_ON_FIRST:
                pass  # its first path is held when its first solve returns (below)
            elif hasattr(planner, "bestCost"):
                best = float(planner.bestCost().value())
                if math.isfinite(best) and best < best_seen[0] and due:
                    best_seen[0] = best  # read the tree once per improvement
                    Q = tree_best_path()
                    if Q is not None:
                        hold(Q)
            elif pdef.hasSolution() and due:
                hold(waypoints_of(og.PathGeometric(pdef.getSolutionPath())))
            if held[0] is None:
                return False
            if time_limit is not None:
                # the re-check's time at this solve's own rate (planning overhead included)
                used = tracker.checks_used
                rate_s = tracker.elapsed_s / max(used, 1)
                if tracker.elapsed_s + _RESERVE_FACTOR * held[1] * rate_s >= time_limit:
                    return True
            left = guard.checks_left()
            return left is not None and left <= 0

        stopped = [False]

        def planning_done_once() -> bool:
            """:func:`planning_done`, remembered (a planner that returns on an improvement
            is resumed only if its termination condition did not stop it)."""
            stopped[0] = stopped[0] or planning_done()
            return stopped[0]

        if self.ompl_class in _STOP_ON_FIRST:
            planner.setStopOnSolnImprovement(True)
        ptc = ob.PlannerTerminationCondition(planning_done_once)
        if self.ompl_class in _ROADMAP:
            ompl_path, exact, status_text = self._roadmap_solve(
                planner, si, space, guard, pool, q0, goal, robot, problem.joint_step
            )
        else:
            guard.hard_stop = self.ompl_class in _HARD_STOP
            try:
                status = planner.solve(ptc)
                if (
                    self.ompl_class in _STOP_ON_FIRST
                    and status.getStatus() == ob.PlannerStatus.PlannerStatusType.EXACT_SOLUTION
                    and pdef.hasSolution()
                    and not stopped[0]
                ):
                    # it returned on its first path: hold it, then resume the search
                    hold(waypoints_of(og.PathGeometric(pdef.getSolutionPath())))
                    planner.setStopOnSolnImprovement(False)
                    status = planner.solve(ptc)
            except _TimeUp:
                return result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.ompl_class}: time limit of {time_limit:g} s reached (stopped "
                    "inside its expansion, which polls no termination condition)",
                    q0[None],
                    guard.iterations(),
                )
            finally:
                guard.hard_stop = False
            status_text = status.asString()
            kind = status.getStatus()
            exact = kind == ob.PlannerStatus.PlannerStatusType.EXACT_SOLUTION
            usable = exact or kind == ob.PlannerStatus.PlannerStatusType.APPROXIMATE_SOLUTION
            ompl_path = (
                og.PathGeometric(pdef.getSolutionPath()) if usable and pdef.hasSolution() else None
            )
        iterations = guard.iterations()
        extra["ompl_status"] = status_text
        extra["planning_checks"] = checker.checks - c_pool - extra["goal_pool_checks"] + 0
        why_stopped = guard.exhausted()

        if ompl_path is None:
            if not pool and pool_cut_short:
                return result(
                    Status.BUDGET_EXHAUSTED,
                    f"the budget ran out while sampling goal states by IK ({pool_cut_short}) "
                    f"and {self.ompl_class} reached no goal: give a larger budget",
                    q0[None],
                    iterations,
                )
            if not pool:
                return result(
                    Status.INVALID_GOAL,
                    f"IK found no valid goal state in {s.max_goal_attempts} "
                    f"attempts and {self.ompl_class} reached none "
                    f"({status_text}; {why_stopped or 'no limit hit'})",
                    q0[None],
                    iterations,
                )
            return result(
                Status.BUDGET_EXHAUSTED if why_stopped else Status.FAILED,
                f"{self.ompl_class}: {status_text}" + (f"; {why_stopped}" if why_stopped else ""),
                q0[None],
                iterations,
            )

        extra["length_raw"] = float(ompl_path.length())
        extra["waypoints_raw"] = int(ompl_path.getStateCount())
        if max_checks is not None:
            # the path to re-check: the final one if its re-check fits the checks left, else
            # the best one held during planning (whose re-check always fits)
            hold(waypoints_of(ompl_path))
            if held[0] is not None:
                ompl_path = ompl_path_of(held[0])
        simplified = og.PathGeometric(ompl_path)
        unsimplified = og.PathGeometric(ompl_path)  # for the repair (below)

        def simplify_done() -> bool:
            """Stop simplifying at any limit, or once only the held path's reserve is left;
            with no path held yet (its re-check did not fit), once the simplified path's
            re-check fits, it is held."""
            if guard.poll():
                return True
            if max_checks is None:
                return False
            if held[0] is None:
                hold(waypoints_of(simplified))
            left = guard.checks_left()
            return left is not None and left <= 0

        if s.simplify and guard.exhausted() is None:
            simplifier = og.PathSimplifier(si, goal_obj)
            c0 = checker.checks
            # OMPL's simplify runs one whole pass whatever the termination condition says,
            # and its collapseCloseVertices compares every vertex pair at each of up to n
            # steps without polling it: on the chain of hundreds of tiny edges an
            # optimizing planner's dense tree gives (cheap edge checks make dense trees),
            # that pass takes minutes. Such a path is thinned first by reduceVertices
            # (random shortcuts, each a checked motion), and left as it is if it stays long.
            thinning = 0
            while (
                simplified.getStateCount() > _SIMPLIFY_MAX_STATES
                and thinning < 20
                and not simplify_done()
            ):
                simplifier.reduceVertices(simplified)
                thinning += 1
            if thinning:
                extra["thinning_passes"] = thinning
            if simplified.getStateCount() <= _SIMPLIFY_MAX_STATES:
                simplifier.simplify(simplified, ob.PlannerTerminationCondition(simplify_done))
            extra["simplify_checks"] = checker.checks - c0
        left = tracker.checks_left()
        if left is None or recheck_cost(simplified) <= left:
            ompl_path = simplified
        elif held[0] is not None:  # simplifying made the re-check dearer: re-check the held
            ompl_path = ompl_path_of(held[0])
            extra["simplified_path_dropped"] = True
        else:
            cost = recheck_cost(simplified)
            extra["validation_checks"] = 0
            return result(
                Status.BUDGET_EXHAUSTED,
                f"{self.ompl_class} found a path ({status_text}) but re-checking it at "
                f"joint_step/4 needs {cost} collision checks and the budget of "
                f"{max_checks} leaves {left}: the path is not trusted; give a larger "
                "--max-checks",
                waypoints_of(simplified),
                iterations,
            )
        extra["length_simplified"] = float(ompl_path.length())
        extra["waypoints_simplified"] = int(ompl_path.getStateCount())
        waypoints = wrap_to_pi(
            np.array([space.to_q(ompl_path.getState(i)) for i in range(ompl_path.getStateCount())]),
            robot.continuous,
        )
        if guard.out_of_time():  # a path found at the limit: no time left to densify it
            return self._out_of_time(result, status_text, waypoints, iterations, time_limit)
        if s.interpolate:
            ompl_path.interpolate()
        rows: list[Array] = []
        for i in range(ompl_path.getStateCount()):
            if i % _CHUNK_STATES == 0 and past_time():
                return self._out_of_time(result, status_text, waypoints, iterations, time_limit)
            rows.append(space.to_q(ompl_path.getState(i)))
        path = wrap_to_pi(np.array(rows), robot.continuous)
        if float(np.max(np.abs(joint_difference(path[0], q0, robot.continuous)))) > 1e-6:
            return result(
                Status.FAILED,
                f"{self.ompl_class} returned a path that does not "
                f"start at the start state ({status_text})",
                q0[None],
                iterations,
            )
        path[0] = q0  # exact copy (removes float noise of the OMPL round trip)
        extra["path_length_rad"] = path_length(path, robot.continuous)

        cost = _recheck_cost(path, recheck_step, checker)
        if max_checks is not None:
            left = max_checks + max_checks // 100 - tracker.checks_used
            if cost > left:
                extra["validation_checks"] = 0
                return result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.ompl_class} found a path ({status_text}) but re-checking it at "
                    f"joint_step/4 needs {cost} collision checks and the budget of "
                    f"{max_checks} (+1 %) leaves {max(left, 0)}: the path is not "
                    "trusted; give a larger --max-checks",
                    path,
                    iterations,
                )
        c0 = checker.checks
        check = checker.check_path(path, recheck_step, stop=past_time, chunk=_CHUNK_STATES)
        extra["validation_checks"] = checker.checks - c0
        if not check.complete:
            return self._out_of_time(result, status_text, path, iterations, time_limit)
        if not check.valid:
            failed = (
                f"{self.ompl_class} path fails the re-check at joint_step/4 on "
                f"edge {check.first_invalid_edge}: "
                + ", ".join(f"{a} x {b}" for a, b in check.pairs)
            )
            extra["recheck_failed"] = failed
            kit = _RepairKit(
                si, space, guard, planner, pdef, goal_obj, rows_of, past_time, recheck_step, extra
            )
            c0 = checker.checks
            fixed = self._repair(kit, unsimplified, replan=exact)
            extra["repair_checks"] = checker.checks - c0
            if fixed is None and past_time():
                return self._out_of_time(result, status_text, path, iterations, time_limit)
            if fixed is None:
                return result(
                    Status.INVALID_PATH, f"{failed}; repair: {extra['repair']}", path, iterations
                )
            path = fixed
            extra["path_length_rad"] = path_length(path, robot.continuous)
        if exact and bool(goal.contains(robot, path[-1])):
            return result(Status.SOLVED, f"{self.ompl_class}: {status_text}", path, iterations)
        return result(
            Status.APPROXIMATE,
            f"{self.ompl_class}: {status_text}; ends outside the goal region"
            + (f" ({why_stopped})" if why_stopped else ""),
            path,
            iterations,
        )

    def _repair(self, kit: _RepairKit, raw: Any, replan: bool) -> Array | None:
        """A path that passes the re-check, after the simplified one failed it, or None
        (``extra["repair"]`` says how it went).

        The planner's motions are checked at ``joint_step``, the re-check looks at the
        states of the interpolated path at ``joint_step / 4``: a path that OMPL's
        simplifier pulled taut against an obstacle passes the first and can graze the
        obstacle between its checked states. From here on every motion is checked as the
        re-check will see it (OMPL's interpolation of the motion), on a grid twice as fine
        as the re-check's (a repaired path is one that runs close to an obstacle):

        1. the path as planned, before simplification, is re-checked; if it passes, it
           is simplified again with the strict motion checks (if that one fails the
           re-check, the path as planned is the result);
        2. else (``replan``: the planner found an exact solution; not for the roadmap
           planners, nor for the optimizing ones, which would spend all that is left) the
           planner is cleared and solves again, with the strict motion checks, within the
           budget left, and its path is simplified with them.

        Whatever comes out is re-checked as the first path was: the re-check stays the
        judge. The checks and time of the repair are the leg's.
        """
        si, space, guard = kit.si, kit.space, kit.guard
        interpolate, step = self.settings.interpolate, kit.recheck_step
        state_space, between = space.space, space.space.allocState()

        def edge_rows(a: Any, b: Any) -> Array:
            """The motion a -> b as the re-check gets it: OMPL's ``PathGeometric.interpolate``
            of it (``validSegmentCount`` pieces, states at j / n), if set."""
            n = max(int(state_space.validSegmentCount(a, b)), 1) if interpolate else 1
            Q = np.empty((n + 1, space.dof))
            Q[0], Q[n] = space.to_q(a), space.to_q(b)
            for j in range(1, n):
                state_space.interpolate(a, b, j / n, between)
                Q[j] = space.to_q(between)
            return wrap_to_pi(Q, space.robot.continuous)

        class StrictValidator(ob.MotionValidator):
            def checkMotion(self, a: Any, b: Any) -> bool:  # noqa: N802
                return guard.path_valid(edge_rows(a, b), step / 2.0)

        previous, strict = si.getMotionValidator(), StrictValidator(si)
        si.setMotionValidator(strict)
        guard.reserve = 0  # the held path was re-checked: nothing left to hold back
        try:
            return self._repair_steps(kit, raw, replan)
        finally:
            si.setMotionValidator(previous)  # no OMPL object outlives the solve

    def _repair_steps(self, kit: _RepairKit, raw: Any, replan: bool) -> Array | None:
        """:meth:`_repair`'s steps, on the strict motion checks."""
        si, guard, extra = kit.si, kit.guard, kit.extra

        def recheck(ompl_path: Any) -> Array | None:
            """The rows of the path if they pass the re-check within the budget."""
            rows = kit.rows_of(ompl_path)
            left = guard.checks_left()
            if left is not None and _recheck_cost(rows, kit.recheck_step, guard.checker) > left:
                return None
            check = guard.checker.check_path(
                rows, kit.recheck_step, stop=kit.past_time, chunk=_CHUNK_STATES
            )
            return rows if check.valid else None

        def simplified(ompl_path: Any) -> Array | None:
            """The path simplified with the strict motion checks, if it passes."""
            if ompl_path.getStateCount() > _SIMPLIFY_MAX_STATES or guard.exhausted():
                return None
            short = og.PathGeometric(ompl_path)
            og.PathSimplifier(si, kit.goal_obj).simplify(
                short, ob.PlannerTerminationCondition(guard.poll)
            )
            return recheck(short)

        rows = recheck(raw)
        if rows is not None:
            better = simplified(raw) if self.settings.simplify else None
            extra["repair"] = (
                "the path as planned, simplified again with strict motion checks"
                if better is not None
                else "the path as planned (before simplification)"
            )
            return better if better is not None else rows
        if (
            not replan
            or self.ompl_class in _ROADMAP
            or hasattr(kit.planner, "bestCost")  # an optimizing one would spend all that is left
            or guard.exhausted()
        ):
            extra["repair"] = "the path as planned fails the re-check too"
            return None
        # resume with the budget left, on strict motion checks
        kit.planner.clear()
        kit.pdef.clearSolutionPaths()
        status = kit.planner.solve(ob.PlannerTerminationCondition(guard.poll))
        if status.getStatus() != ob.PlannerStatus.PlannerStatusType.EXACT_SOLUTION:
            extra["repair"] = f"solved again with strict motion checks: {status.asString()}"
            return None
        again = og.PathGeometric(kit.pdef.getSolutionPath())
        rows = simplified(again) if self.settings.simplify else None
        if rows is None:
            rows = recheck(again)
        extra["repair"] = (
            "solved again with strict motion checks"
            if rows is not None
            else "solved again with strict motion checks, and that path fails the re-check"
        )
        return rows

    def _out_of_time(
        self,
        result: Callable[..., PlanResult],
        status_text: str,
        path: Array,
        iterations: int,
        time_limit: float | None,
    ) -> PlanResult:
        """The time limit (+ its slack) ran out after planning, before the path's re-check
        finished: the path is not trusted."""
        return result(
            Status.BUDGET_EXHAUSTED,
            f"{self.ompl_class} found a path ({status_text}) but the time limit of "
            f"{time_limit:g} s (+{_TIME_SLACK:.0%}) ran out before its re-check at "
            "joint_step/4 finished: the path is not trusted; give a larger --time-limit",
            path,
            iterations,
        )

    def _roadmap_solve(
        self,
        planner: Any,
        si: Any,
        space: _Space,
        guard: _Guard,
        pool: list[Array],
        q0: Array,
        goal: GoalRegion,
        robot: Robot,
        joint_step: float,
    ) -> tuple[Any, bool, str]:
        """PRM / PRM* without OMPL's solution thread (see the module docstring)."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        k = getattr(self.settings, "max_nearest_neighbors", 10)
        slice_polls = self.settings.roadmap_slice_polls  # type: ignore[attr-defined]
        if not pool:
            return None, False, "no goal states to connect"
        while True:
            # OMPL's constructRoadmap alternates growing and expanding in *timed* sub-slices
            # (so the roadmap would depend on the machine's load): do the alternation here,
            # sliced by termination polls, which are deterministic.
            grow_until = guard.polls + max(1, (2 * slice_polls) // 3)
            planner.growRoadmapPtc(
                ob.PlannerTerminationCondition(
                    lambda s=grow_until: guard.poll() or guard.polls >= s
                )
            )
            expand_until = guard.polls + max(1, slice_polls // 3)
            planner.expandRoadmapPtc(
                ob.PlannerTerminationCondition(
                    lambda s=expand_until: guard.poll() or guard.polls >= s
                )
            )
            if guard.out_of_time():
                return None, False, "Timeout"  # no search of a roadmap grown past the time
            data = ob.PlannerData(si)
            planner.getPlannerData(data)
            n = data.numVertices()
            if n:
                V = np.array([space.to_q(data.getVertex(i).getState()) for i in range(n)])
                rows, cols = [], []
                for i in range(n):
                    for j in data.getEdges(i):
                        rows.append(i)
                        cols.append(int(j))
                special = [q0, *pool]  # index n = start, n+1.. = goals
                extra_rows, extra_cols, extra_w = [], [], []
                for m, q in enumerate(special):
                    dist = space.metric(V, q)
                    for i in np.argsort(dist)[:k]:
                        if guard.edge_valid(q, V[i], joint_step):
                            extra_rows.append(n + m)
                            extra_cols.append(int(i))
                            extra_w.append(float(dist[i]))
                allV = np.vstack([V, np.array(special)])
                r = np.array(rows + extra_rows, dtype=int)
                c = np.array(cols + extra_cols, dtype=int)
                if len(r):
                    w = (
                        np.concatenate(
                            [space.pair_metric(allV[r[: len(rows)]], allV[c[: len(rows)]]), extra_w]
                        )
                        + 1e-12
                    )
                    size = len(allV)
                    graph = coo_matrix((w, (r, c)), shape=(size, size)).tocsr()
                    dist_from_start, pred = dijkstra(
                        graph, directed=False, indices=n, return_predecessors=True
                    )
                    goals = np.arange(n + 1, size)
                    reachable = goals[np.isfinite(dist_from_start[goals])]
                    if len(reachable):
                        g = int(reachable[np.argmin(dist_from_start[reachable])])
                        chain = [g]
                        while chain[-1] != n:
                            chain.append(int(pred[chain[-1]]))
                        path = og.PathGeometric(si)
                        for idx in reversed(chain):
                            st = space.space.allocState()
                            space.set_state(st, allV[idx])
                            path.append(st)
                        return path, True, "Exact solution"
            if guard.exhausted() is not None:
                return None, False, "Timeout"


def make(name: str, overrides: Mapping[str, Any] | None = None, *, ompl_class: str) -> OMPLPlanner:
    """Registry factory: the OMPL geometric planner ``ompl_class`` (``"RRTConnect"``, as
    the registry entry ``name`` says), with settings overridden by name.

    Raises:
        UnknownNameError: unknown setting name (lists the known ones).
        PlannerlabError: ``ompl_class`` has no settings here.
    """
    if ompl_class not in SETTINGS_BY_CLASS:
        raise PlannerlabError(f"{name}: OMPL class {ompl_class!r} is not served by this adapter")
    settings = with_overrides(SETTINGS_BY_CLASS[ompl_class](), dict(overrides or {}), name)
    return OMPLPlanner(name=name, ompl_class=ompl_class, settings=settings)


__all__ = [
    "LOGGER",
    "OMPLPlanner",
    "OMPLSettings",
    "SETTINGS_BY_CLASS",
    "make",
    "seed_ompl",
]

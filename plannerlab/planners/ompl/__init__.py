"""OMPL geometric planners behind plannerlab's planner contract.

This is the only package that imports ``ompl`` (the ``ompl`` 2.0.1 nanobind wheel). Every
planner in :data:`plannerlab.planners.OMPL_PLANNERS` is served as ``ompl.<suffix>`` by
:func:`make`. Everything OMPL-specific is kept here, one concept per module:
``settings`` (the settings per family and the adapter's constants; no ``ompl`` import),
``bridge`` (OMPL's seed and log output), ``space`` (joint vectors <-> OMPL states, the
KPIECE projection), ``guard`` (the budget-guarded checker and termination condition),
``goal`` (the goal region and its pool), ``driver`` (one solve: build, search, simplify,
re-check), ``roadmap`` (PRM and PRM* driven single-threaded) and ``planner``
(:class:`OMPLPlanner`, :func:`make`). Every OMPL object lives only inside one
:meth:`OMPLPlanner.plan` call (none at module level: the wheel reports
"leaked" objects still alive at interpreter exit). A leg is planned in its
:class:`~plannerlab.planners.context.PlanningContext` (its checker, tracker and start
check); as an escape of another planner, in a sub-solve's context of the caller's leg.

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
  With ``goal_selection = "near"`` (or ``"near_or_ik"``, IK when it finds none) the pool
  holds the goal state a clearance descent finds near the start: the caller's, with its
  settings, when OMPL is an escape of ``gradient.clearance+rrtconnect``
  (``PlanningContext.near_goal``), else ``gradient.clearance``'s defaults.
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
  (``HARD_STOP``) run long stretches of C++ that poll nothing (their first expansion
  computes every sample's neighbourhood): past the limit their callbacks raise
  ``TimeUp``, which unwinds OMPL's loop back to ``solve``.
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
  budget left, on motions checked as the re-check sees them (``repair.py``), and re-checked
  again; INVALID_PATH when that fails too.
* **Logging.** The wheel's ``OutputHandler`` cannot be subclassed from Python (no
  constructor is bound), so during a solve OMPL writes to an ``OutputHandlerFile`` in a
  temporary file; afterwards each message is re-emitted on the ``plannerlab.ompl``
  logger at its level, and the previous handler and log level are restored. OMPL's log
  level follows that logger's effective level.
* **Seeding.** OMPL's seed is process-global. Each solve (``plan``) draws a seed from
  ``rng`` and calls ``ompl.util.RNG.setSeed`` with it before it builds any OMPL object:
  that reseeds OMPL's seed generator, which seeds every generator the solve builds, so
  the solve is determined by its own seed (and ``rng``) whether it is the first of its
  process or a later one (for a later one OMPL logs that "random number generation
  already started", re-emitted here at DEBUG level, and ``RNG.getSeed()`` keeps
  returning the process's first seed: measured, a leg solved after another gives the
  path it gives alone in a fresh process with the same seed). Every leg records that
  seed, the one in effect (``extra["ompl_seed"]``), so any leg can be re-run alone.
"""

from __future__ import annotations

from plannerlab.planners.ompl.bridge import LOGGER, seed_ompl
from plannerlab.planners.ompl.planner import OMPLPlanner, make
from plannerlab.planners.ompl.settings import GOAL_SELECTIONS, SETTINGS_BY_CLASS, OMPLSettings

__all__ = [
    "GOAL_SELECTIONS",
    "LOGGER",
    "OMPLPlanner",
    "OMPLSettings",
    "SETTINGS_BY_CLASS",
    "make",
    "seed_ompl",
]

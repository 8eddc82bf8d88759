"""Settings of the compiled sampling planners (frozen; overridden by name, see
:func:`plannerlab.planners.base.with_overrides`). No numba here: read without compiling."""

from __future__ import annotations

from dataclasses import dataclass

#: how the goal pool is filled (as the OMPL planners': ``planners/goal_pool.py``)
GOAL_SELECTIONS = ("ik", "near", "near_or_ik")


@dataclass(frozen=True)
class NativeSettings:
    """Settings every compiled sampling planner shares.

    Attributes:
        range_rad: longest motion added to a tree at once, Euclidean in joint space
            (continuous joints the short way round) [rad]; 0: OMPL's default, 20 % of the
            space's extent (the diagonal of the joint box, π per continuous joint).
        goal_samples: goal states drawn by IK for a position + normal goal (a joint goal
            is its one state), as the OMPL planners' pool.
        max_goal_attempts: IK descents at most to fill the pool.
        goal_selection: ``"ik"``, ``"near"`` or ``"near_or_ik"`` (see
            :class:`~plannerlab.planners.ompl.settings.OMPLSettings`).
        simplify: shorten the found path in compiled code (random shortcuts, then
            dropping the waypoints whose neighbours see each other), within the budget.
        shortcut_tries: random shortcuts tried (0: four per waypoint of the found path,
            at least 32).
        max_tree_mb: the trees' memory at most [MB] (states, parents and the k-d trees of
            RRT-Connect's nearest nodes); a search that
            fills it stops with ``budget_exhausted`` and says so.
        guide_bias: probability that a sample is a guide state (``guides`` of the
            kernel: a state drawn uniformly from them) perturbed by Gaussian noise
            ``guide_sigma_rad`` per joint; 0: plain sampling. Set by planners that guide
            the search (``native.rrtconnect+leader``), which pass their guide states.
        guide_sigma_rad: standard deviation of that noise [rad].
    """

    range_rad: float = 0.0
    goal_samples: int = 4
    max_goal_attempts: int = 200
    goal_selection: str = "ik"
    simplify: bool = True
    shortcut_tries: int = 0
    max_tree_mb: float = 256.0
    guide_bias: float = 0.0
    guide_sigma_rad: float = 0.1


@dataclass(frozen=True)
class RRTConnectSettings(NativeSettings):
    """RRT-Connect.

    Attributes:
        lazy_every: a tree edge is checked, when it is added, on its coarse states only:
            its ends and every ``lazy_every``-th state of its grid (a power of two); the
            others only when a path through it is found (a failure there drops the
            edge's subtree and the search goes on). Most tree edges are never on a path,
            so most of their states are never checked; the returned path's are all. 1:
            every edge in full at once.
        dynamic_domain: the dynamic domain of the extension step (Yershova et al. 2005;
            VAMP's RRT-Connect has it on): a sample farther from its nearest node than
            that node's radius is dropped unchecked; a failed extension gives its node a
            radius of 2 ``range_rad`` and shrinks it slowly to ``range_rad`` / 2. Off:
            OMPL's RRT-Connect (``ompl.rrtconnect``'s algorithm).
    """

    lazy_every: int = 16
    dynamic_domain: bool = False


@dataclass(frozen=True)
class RRTstarSettings(NativeSettings):
    """RRT* (one tree from the start, goal-biased, rewired in a ball of ``k`` nearest).

    Attributes:
        goal_bias: probability that a sample is a goal state of the pool.
        rewire_factor: scales ``k = rewire_factor · e · (1 + 1/dof) · log(n)`` nearest
            neighbours considered for the parent and rewired (OMPL's k-nearest RRT*).
    """

    goal_bias: float = 0.05
    rewire_factor: float = 1.1


@dataclass(frozen=True)
class KPIECESettings(NativeSettings):
    """KPIECE (:mod:`~plannerlab.planners.native.kpiece`; OMPL's ``KPIECE1``, its defaults).

    Attributes:
        goal_bias: probability that a motion heads for a goal state of the pool.
        border_fraction: the least probability of expanding an exterior cell.
        failed_score_factor: a cell's score is multiplied by it when a motion from it
            is refused, in (0, 1].
        min_valid_fraction: a motion is kept when more than this fraction of it is free,
            in (0, 1].
        projection_dims: the projection's dimensions; 0: max(2, ceil(ln dof)).
        cell_size_sd: a cell's width, in standard deviations of the projected coordinate
            of states uniform in the joint box (0.275: the width OMPL infers, 1/20 of
            the spread of 100 such states grown by 10 %, in expectation).
    """

    goal_bias: float = 0.05
    border_fraction: float = 0.9
    failed_score_factor: float = 0.5
    min_valid_fraction: float = 0.2
    projection_dims: int = 0
    cell_size_sd: float = 0.275
    range_octaves: float = 3.0
    lazy_every: int = 1

"""Settings of the compiled sampling planners (frozen; overridden by name, see
:func:`plannerlab.planners.base.with_overrides`). Plain Python: no compiled code here."""

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
        goal_selection: ``"ik"``, ``"near"`` or ``"near_or_ik"``, as for the OMPL
            planners (``plannerlab planners ompl.rrtconnect`` says what each does).
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
        lazy_every: a tree edge is checked, when it is added, on its coarse states: its
            grid cut into stretches of ``lazy_every`` states, each stretch's middle state
            tested grown by the stretch's half-length, eight at a time (the whole edge is
            then proved when every grown state is free); an edge not proved so is checked
            in full only when a path through it is found (a failure there drops the
            edge's subtree and the search goes on). Most tree edges are never on a path.
            1: every edge in full at once.
        dynamic_domain: the dynamic domain of the extension step (Yershova et al. 2005;
            VAMP's RRT-Connect has it on): a sample farther from its nearest node than
            that node's radius is dropped unchecked; a failed extension gives its node a
            radius of 2 ``range_rad`` and shrinks it slowly to ``range_rad`` / 2. Off:
            OMPL's RRT-Connect (``ompl.rrtconnect``'s algorithm).
        range_levels: the longest motion added at once cycles over a ladder of this many
            lengths, the range and its halves (``range_rad``, ``range_rad`` / 2, ...,
            ``range_rad`` / 2^(levels - 1)), ``level_checks`` collision checks at each,
            the full range first; both trees keep what they grew at every level. Long
            steps cross open space in few nodes; short ones grow a tree out of a pocket
            from which no long straight motion is free (a grasp deep in a shelf: from the
            median goal state of MotionBenchMaker's Fetch in a bookshelf none of 48
            motions of the default range is free, 8 % of those of a quarter of it;
            ``bench/mbm_why.py``). A problem solved within the first ``level_checks``
            checks is planned exactly as with one range. 1: one range (OMPL's RRT-Connect).
        level_checks: collision checks spent at each level of the ladder before the next.
        restart_cycles: restarts of a search that has found no path (both trees dropped,
            grown again from the start and the goal states with the generator where it
            is): the first after this many whole cycles of the ladder
            (``range_levels`` × ``level_checks`` checks), each next run twice as long
            as the one before. RRT-Connect's checks to a path are heavy-tailed: on
            MotionBenchMaker's Panda the same problem takes 13-70 thousand checks on 17
            to 19 seeds of 20 and more than 300 thousand on the others (the trees grow
            on both sides of a passage they never join), and a fresh run is as likely
            to be a quick one as the first was (Wedge and Branicky 2008 on RRT's
            heavy tails; doubling runs cost at most about twice a run that needed the
            whole budget). 0: never. The restarts made are in ``extra["restarts"]``.
        balance: grow the smaller tree while it has at most half the other's nodes,
            instead of the two in turn (VAMP's RRT-Connect: ``balance``, its default). A
            goal deep in a shelf, from which few motions are free, then gets the
            iterations its tree needs to get out, instead of the start tree sprawling
            in the open (MotionBenchMaker's Fetch: goal trees of 15-96 nodes beside
            start trees of 7 000-42 000 when 10 s ran out). Off: OMPL's RRT-Connect.
            Measured on (``bench/mbm_tail_settings.py --configs default,balance``,
            ``bench/mbm_robots_bench.py --set balance=true``; ``results/native.md``): the
            Panda's slowest 20 MotionBenchMaker problems take 2.4x fewer checks on
            average and 3.8x less CPU, the others 1.6x fewer; the Fetch solves 47 of 54
            valid problems in 10 s of CPU where alternating solved 42; Arm-Z's traps are
            as before and ``armz_deep_e`` is solved on 3 of 5 seeds (0 of 5).
    """

    lazy_every: int = 16
    dynamic_domain: bool = False
    range_levels: int = 5
    level_checks: int = 16384
    restart_cycles: int = 1
    balance: bool = True


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

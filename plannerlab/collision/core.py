"""The compiled collision and kinematics core: batched, exact, FCL's equal on capsules.

:class:`Core` answers, for one robot in one scene, the questions the planners ask millions
of times: is a batch of states valid, which state of an edge is the first invalid one, and
how far is every pair of shapes (:meth:`Core.pair_distances`, for clearance-aware
optimisation). Everything on the hot path is one numba call over the whole batch (``cache=
True``: compiled once per machine into ``__pycache__``, loaded in later processes):

* **One road for every chain.** A robot that gives its serial chain (Arm-Z, IRb-6, the
  continuum chain, URDF chains) has its states, batches and edges tested by the compiled
  model's fused test (:mod:`plannerlab.collision.chain_valid`; batches in vector lanes,
  :mod:`plannerlab.collision.lanes`), the test the native planners certify their edges
  with, so a path they return passes the re-check bit for bit. Arm-Z keeps its own
  compiled kinematics (:mod:`plannerlab.collision.armz`) only for the conservative
  advancement below; other robots give their segments through their own numpy
  ``link_segments``.
* **Broad phase.** Per state, world-aligned boxes of every capsule and a bounding-box tree
  over the chain's consecutive links (:func:`~plannerlab.collision.kernels.chain_tree`:
  topology built once, boxes refit per state), traversed against each obstacle and
  against itself; node pairs that are apart or hold no checked pair are pruned, so the
  cost grows as ``L log L`` with the number of links, not ``L²``.
* **Narrow phase.** Exact capsule tests (:mod:`plannerlab.collision.geometry`).

The pairs checked are the checker's: moving links against every obstacle, and the robot's
link pairs except ``excluded_pairs`` and pairs of two fixed links.

**Edges in metres by conservative advancement** (:meth:`Core.path_advance`; the checker's
``edge_check="advance"``, its default with a margin on the core). With a clearance margin
``m`` an edge must be checked so that nothing slips between two checked states. The grid
(``edge_check="grid"``, :meth:`~plannerlab.collision.fcl_checker.CollisionChecker.densify`)
cuts each edge into equal steps over which no point moves more than ``m`` (the bound
``Σ |Δq_i| r_i`` of :func:`~plannerlab.collision.reach.joint_reach_m`): about 40 times the
states of radian steps on the 16-m Arm-Z. Conservative advancement measures instead, at
each checked state, the distance ``d_p`` of every checked pair with the capsules inflated
(:func:`~plannerlab.collision.kernels.advance_dt`), and steps as far as a bound ``v_p``
of how fast that distance can change allows: ``Δt = min_p (d_p + m) / v_p``, never less
than the grid's step and never more than ``joint_step`` on any joint. The guarantee is
the grid's, pair by pair:

* every checked state keeps the margin (the ordinary inflated check, unchanged);
* every state between two checked ones keeps at least ``m / 2`` to the scene and between
  links: a pair at ``t + s`` is at least ``d_p + m − v_p s`` from the left and at least
  ``m − v_p (Δt − s)`` from the right, whose larger is ``≥ m / 2`` when
  ``v_p Δt ≤ d_p + m``. (The grid gives the same ``m / 2`` against the scene, and ``≥ 0``
  between two links, both of which move.)

The rates ``v_p`` (:func:`~plannerlab.collision.kernels.edge_rates`, from
:func:`~plannerlab.collision.reach.reach_bounds`): per joint and link, how fast the
link's points move (the chain sum of ``joint_reach_m`` stopped at that link), and per link
pair only the joints that move one link and not the other (a joint that turns both
rigidly leaves their distance alone). On Arm-Z the bound is taken at the configuration
(:func:`~plannerlab.collision.armz.armz_advance_dt`): a link's speed from joint ``f`` is
``|Δq_f|`` times the link's real distance from ``f``'s axis, which is grown along the step
by how far the link can move relative to that axis (a quadratic term, sound), instead of
the length of the chain behind the joint.

Counting: each state visited is one check (its validity, plus its pair distances when
the step needs them), and an edge measured at its start costs one more. A visited state
costs more than a plain check (a distance pass, with box pruning, after it); its cost
ratio has not been measured in isolation: the wall times in the table are the honest
account. A path's states never
outnumber its grid's (each step is at least the grid's), so a planner's re-check reserve
computed from the grid (``_recheck_cost`` in planners/ompl.py) stays an upper bound.

Measured on ``bench/mplib_bench.py --seeds 10`` (12-module Arm-Z, ``ompl.rrtconnect``,
margin 0.01 m; median per solve, this 2-core machine under other jobs, ``nice -n 19``)::

    option                                          checks/solve  wall s  MPlib/pl  solved
    grid, Σ|Δq_i| r_i ≤ m (main at bc741f5)               479 003   0.643     0.40x   10/10
    advance, per-link chain bounds                         44 803   0.302        -    10/10
    advance, + bounds at the configuration (Arm-Z)         14 888   0.181     1.13x   10/10
    ... + joint and link bounds in one pass                14 888   0.157     1.31x   10/10

Then, on main f729c34 (the same checks per solve; ``MPlib/pl`` is now given for wall and
CPU time, both from the bench's own lines; the machine shared by about five jobs, load
4-10, so wall times vary by about ±30 % from run to run)::

    option                                          checks/solve  CPU s   MPlib/pl wall, CPU
    rebased, as above                                     14 888   0.173     1.57x, 1.35x
    + reach bounds vectorised, goal distance from the
      compiled tip, path clearance in one call            14 888   ~0.141         -
    + OMPL states read in one binding call                14 888   0.113     1.95x, 1.89x
    + joint axes with the capsule axes, leaner calls,
      scalar goal distance                                14 888   0.096     2.14x, 2.34x
    the same, merged with main 689e916 (a second run)     14 888   0.096     2.19x, 2.19x

Where a solve's time went before these (cProfile with CPU time, and timers around the
callbacks): edge checks about a third (their compiled part ~2.5 µs per visited state, of
which the distance pass 1.5 µs), reading OMPL states joint by joint ~20 %, the goal
heuristic's NumPy kinematics ~15 %, building the checker's reach bounds ~10 %, the
planned clearance ~5 %; OMPL itself (nearest neighbours on the SO(2) compound metric)
about a fifth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.collision.armz import (
    armz_frames,
    armz_path_advance,
    armz_segments,
)
from plannerlab.collision.chain import chain_arrays, chain_parts, chain_segments
from plannerlab.collision.chain_check import ChainValidity
from plannerlab.collision.chain_pack import _pack
from plannerlab.collision.chain_valid import chain_state_valid
from plannerlab.collision.geometry import BOX, CYLINDER, SPHERE
from plannerlab.collision.kernels import (
    advance_dt,
    all_hits,
    chain_first_invalid,
    chain_tree,
    edge_rates,
    edge_states,
    first_invalid,
    min_clearance_kernel,
    pair_distances_kernel,
    scratch,
    valid_batch,
)
from plannerlab.collision.reach import pair_rates
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere
from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.robots.paths import (
    MAX_EDGE_STATES,
    edge_steps,
    edge_too_long,
    require_joint_step,
)

_NO_LIMIT = 2**62  # "check every state of the edge"


@dataclass(frozen=True)
class PairDistances:
    """Signed distances of the checked pairs of one state below a margin.

    Attributes:
        link: (m,) link index.
        other: (m,) obstacle index (``other_is_link`` False) or link index (True).
        other_is_link: (m,) bool.
        d_m: (m,) signed distance [m]; negative = penetration depth (exact while the
            capsule axes stay outside the other shape, a lower bound on it otherwise).
        t_link: (m,) parameter in [0, 1] of the closest point on the link's axis
            ``p = a + t (b − a)``.
        t_other: (m,) the same on the other link's axis (0 for obstacles).
        n_world: (m, 3) unit direction that increases the distance when the link's
            closest point moves along it.
    """

    link: np.ndarray
    other: np.ndarray
    other_is_link: np.ndarray
    d_m: np.ndarray
    t_link: np.ndarray
    t_other: np.ndarray
    n_world: np.ndarray


def supports(scene: Scene) -> bool:
    """True when every obstacle of the scene is a shape the core tests exactly."""
    return all(isinstance(o, Box | Cylinder | Sphere) for o in scene.obstacles)


def _module_chain(robot: Robot) -> tuple[np.ndarray, np.ndarray] | None:
    """Arm-Z's fixed transforms (base -> first joint, one module) from its chain, or None
    for a robot that is not an Arm-Z or whose chain is not a row of identical modules
    turning about z with a capsule along each module's chord (what collision/armz.py
    computes)."""
    if getattr(robot, "kind", "") != "armz" or not callable(getattr(robot, "chain_data", None)):
        return None
    parent, pre, axes, prismatic, cap_body, cap_a, cap_b, coupling = chain_parts(robot)
    n = len(parent)
    if n < 2:  # one joint: the chain does not hold a whole module (the tip's turn)
        return None
    pre = np.asarray(pre, dtype=float)
    M = pre[1]
    same = (
        coupling is None
        and np.array_equal(parent, np.arange(n))
        and np.array_equal(axes, np.tile([0.0, 0.0, 1.0], (n, 1)))
        and not np.any(prismatic)
        and all(np.array_equal(pre[i], M) for i in range(1, n))
        and np.array_equal(cap_body, np.arange(n + 1))
        and not np.any(cap_a)
        and np.array_equal(cap_b[0], pre[0, :3, 3])
        and np.array_equal(cap_b[1:], np.tile(M[:3, 3], (n, 1)))
    )
    return (pre[0], M) if same else None


class Core:
    """Compiled validity and distances for one robot in one scene (no check counter:
    :class:`~plannerlab.collision.fcl_checker.CollisionChecker` counts)."""

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        margin_m: float = 0.0,
        edge_weights: Array | None = None,
        link_rates: tuple[Array, Array] | None = None,
    ) -> None:
        if not supports(scene):
            raise ValueError("the core tests boxes, cylinders and spheres only")
        self.robot = robot
        self.scene = scene
        self.margin_m = float(margin_m)
        r = np.asarray(robot.link_radii_m, dtype=float)
        #: capsule radii against the scene: inflated by the whole margin
        self.radii = np.ascontiguousarray(r + self.margin_m)
        #: capsule radii against each other: by half of it (a pair keeps one margin)
        self.radii_self = np.ascontiguousarray(r + self.margin_m / 2.0)
        #: metric edge bound (see :func:`~plannerlab.collision.kernels.edge_states`); zeros:
        #: radian steps only
        self.edge_weights = np.ascontiguousarray(
            np.zeros(robot.dof) if edge_weights is None else edge_weights, dtype=float
        )
        L = len(self.radii)
        self.n_links = L
        self.moving = np.array([i not in robot.fixed_links for i in range(L)])
        allowed = np.zeros((L, L), dtype=bool)
        excluded = set(robot.excluded_pairs)  # a property: computed once here
        fixed = set(robot.fixed_links)
        for i in range(L):
            for j in range(i + 1, L):
                allowed[i, j] = (i, j) not in excluded and not (i in fixed and j in fixed)
        self.allowed = allowed
        n = len(scene.obstacles)
        self.kinds = np.zeros(n, dtype=np.int64)
        self.Rs = np.zeros((n, 3, 3))
        self.cs = np.zeros((n, 3))
        self.hs = np.zeros((n, 3))
        for k, o in enumerate(scene.obstacles):
            T = o.T_world_obstacle
            self.Rs[k] = T[:3, :3]
            self.cs[k] = T[:3, 3]
            if isinstance(o, Box):
                self.kinds[k] = BOX
                self.hs[k] = np.asarray(o.size_m, dtype=float) / 2.0
            elif isinstance(o, Cylinder):
                self.kinds[k] = CYLINDER
                self.hs[k] = (o.radius_m, o.length_m / 2.0, 0.0)
            else:
                self.kinds[k] = SPHERE
                self.hs[k] = (o.radius_m, 0.0, 0.0)
        lo, hi = scene.aabbs()
        self.olo = np.ascontiguousarray(lo, dtype=float).reshape(n, 3)
        self.ohi = np.ascontiguousarray(hi, dtype=float).reshape(n, 3)
        self.tree = chain_tree(allowed)
        #: conservative advancement (:meth:`path_advance`): per joint and link, and per
        #: joint and link pair, bounds of how fast they move (see reach.py); None: off
        self._rates: tuple[np.ndarray, np.ndarray] | None = None
        if link_rates is not None:
            W, rigid = link_rates
            self._rates = (
                np.ascontiguousarray(W, dtype=float),
                np.ascontiguousarray(pair_rates(np.asarray(W), np.asarray(rigid), allowed)),
            )
        self._geo = (
            self.radii,
            self.radii_self,
            self.moving,
            self.allowed,
            self.tree,
            self.kinds,
            self.Rs,
            self.cs,
            self.hs,
            self.olo,
            self.ohi,
        )
        self._continuous = np.ascontiguousarray(robot.continuous, dtype=np.bool_)
        #: Arm-Z's own road (collision/armz.py: its frames, and paths by conservative
        #: advancement with bounds at the configuration): the module chain's fixed
        #: transforms, read from its chain (None: another robot)
        modules = _module_chain(robot)
        self._armz = modules is not None
        #: a chain (collision/chain.py): its capsules from compiled kinematics
        self._chain: Any = None
        #: its validity in one fused call per query (collision/chain_valid.py)
        self._fused: ChainValidity | None = None
        if callable(getattr(robot, "chain_data", None)):
            # every chain's validity (Arm-Z's too) takes the fused test, the compiled
            # model's own (its batches in vector lanes): the verdicts the native
            # planners certify edges with are the re-check's, bit for bit
            self._fused = ChainValidity.of(self)
            if not self._armz:
                self._chain = chain_arrays(robot)
        if modules is not None:
            T0 = np.ascontiguousarray(robot.T_world_base, dtype=np.float64)
            self._T0 = T0
            self._T1 = T0 @ modules[0]
            self._M = np.ascontiguousarray(modules[1], dtype=np.float64)
        #: armz_path_advance's arguments after (P, first, joint_step, limit)
        self._advance_args: tuple[Any, ...] = ()
        if self._armz and self._rates is not None:
            self._advance_args = (
                self._continuous,
                MAX_EDGE_STATES,
                self.edge_weights,
                *self._rates,
                self.margin_m,
                self._T0,
                self._T1,
                self._M,
                *self._geo,
            )
        #: the compiled robot–scene model (:attr:`model`), built on first use
        self._model: Any = None
        #: the packed arrays (:meth:`packed`) when no fused validity holds them
        self._packed: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._warm_up()

    def _warm_up(self) -> None:
        """Call every compiled kernel once, so that numba's compilation (first run on an
        empty cache, about 11 s) or loading from its cache (about 0.5 s per process) happens
        here, when the checker is built, and not inside a planner's time limit."""
        kernels: tuple[Any, ...] = (
            (armz_frames, armz_segments, edge_states)
            + ((armz_path_advance,) if self._rates is not None else ())
            if self._armz
            else (first_invalid, edge_states, chain_segments, chain_first_invalid)
            if self._chain is not None
            else (first_invalid, edge_states)
            + ((advance_dt, edge_rates) if self._rates is not None else ())
        ) + (valid_batch, all_hits, pair_distances_kernel, min_clearance_kernel)
        if all(k.signatures for k in kernels):
            return  # compiled or loaded already in this process
        q = np.clip(np.zeros(self.robot.dof), self.robot.lower, self.robot.upper)
        q2 = np.vstack([q, q])
        self.fk(q)
        self.valid(q2)
        self.is_valid(q)
        self.first_invalid(q2)
        self.edge_first_invalid(q, q, 1.0)
        self.hits(q)
        self.pair_distances(q, 0.0)
        self.min_clearance(q2)
        if self._rates is not None:
            q1 = q.copy()
            q1[0] += 0.5 if q[0] + 0.5 <= self.robot.upper[0] else -0.5
            self.path_advance(np.vstack([q, q1]), 1, 0.05, None)

    def packed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The chain, capsules, checked pairs and scene packed for the compiled state test
        (:func:`~plannerlab.collision.chain_pack._pack`: ``P``, ``M``, ``idat``, ``perm``,
        bodies in the default order), packed once per core: the fused validity's own
        arrays when it has them (the model then shares them), else packed here and kept.
        """
        if self._fused is not None:
            return (*self._fused.args, self._fused.perm)
        if self._packed is None:
            self._packed = _pack(
                self.robot,
                self.radii,
                self.radii_self,
                self.moving,
                self.allowed,
                self.kinds,
                self.Rs,
                self.cs,
                self.hs,
                None,
            )
        return self._packed

    @property
    def model(self) -> Any:
        """The compiled robot–scene model of this core
        (:class:`~plannerlab.collision.model.CompiledModel`), built on first use and kept.

        Raises:
            ModelError: the robot gives no serial chain (``chain_data``) to compile and
                its family registers no builder of its own.
        """
        if self._model is None:
            from plannerlab.collision.model_old import build_model

            self._model = build_model(self)
        return self._model

    # ------------------------------------------------------------------ kinematics
    def _Q(self, Q: Array) -> np.ndarray:
        Q = np.ascontiguousarray(np.atleast_2d(np.asarray(Q, dtype=float)))
        if Q.shape[1] != self.robot.dof:
            raise ValueError(f"q must have {self.robot.dof} joints, got shape {Q.shape}")
        return Q

    def fk(self, Q: Array) -> np.ndarray:
        """Frames (k, F, 4, 4) for Q (k, dof), or (F, 4, 4) for one q (compiled for Arm-Z)."""
        single = np.ndim(Q) == 1
        if not self._armz:
            return self.robot.fk(Q)
        Qc = self._Q(Q)
        out = np.empty((len(Qc), self.robot.dof + 2, 4, 4))
        armz_frames(Qc, self._T0, self._T1, self._M, out)
        return out[0] if single else out

    def tip(self, q: Array) -> tuple[Array, Array]:
        """The robot's ``tip(q)`` (position [m], face normal) for one q (dof,): compiled for
        Arm-Z (its last frame, as ``ArmZ.tip``), else the robot's own."""
        if not self._armz:
            return self.robot.tip(q)
        F = self.fk(q)[-1]
        return F[:3, 3].copy(), F[:3, 2].copy()

    def segments(self, Q: Array) -> np.ndarray:
        """Capsule axes (k, L, 2, 3) for Q (k, dof)."""
        Qc = self._Q(Q)
        if self._armz:
            out = np.empty((len(Qc), self.n_links, 2, 3))
            return armz_segments(Qc, self._T0, self._T1, self._M, out)
        if self._chain is not None:
            out = np.empty((len(Qc), self.n_links, 2, 3))
            kinematics: Any = chain_segments  # a numba dispatcher
            return kinematics(Qc, *self._chain, out)
        return np.ascontiguousarray(self.robot.link_segments(Qc), dtype=float)

    # ------------------------------------------------------------------ queries
    def valid(self, Q: Array) -> np.ndarray:
        """(k,) bool validity of Q (k, dof)."""
        if self._fused is not None:
            return self._fused.valid(Q)
        segs = self.segments(Q)
        out = np.empty(len(segs), dtype=bool)
        return valid_batch(segs, *self._geo, out)

    def is_valid(self, q: Array) -> bool:
        """Validity of one state q (dof,): one compiled call for Arm-Z."""
        if (
            type(q) is np.ndarray
            and q.shape == (self.robot.dof,)
            and q.dtype == np.float64
            and q.flags.c_contiguous
        ):
            Qc = q.reshape(1, -1)  # a view: what _Q would make, without its checks
        else:
            Qc = self._Q(q)
        if len(Qc) != 1:
            raise ValueError(f"q must be one state ({self.robot.dof},), got shape {np.shape(q)}")
        if self._fused is not None:
            kernel: Any = chain_state_valid  # a numba dispatcher
            return bool(kernel(Qc[0], *self._fused.args))
        return bool(self.valid(Qc)[0])

    def first_invalid(self, Q: Array) -> int:
        """Index of the first invalid state of Q (k, dof) in order, -1 if all are valid."""
        Qc = self._Q(Q)
        if self._fused is not None:
            return self._fused.first_invalid(Qc)
        return int(first_invalid(self.segments(Qc), *self._geo))

    def edge_first_invalid(
        self, q_a: Array, q_b: Array, joint_step: float, limit: int | None = None
    ) -> tuple[int, int]:
        """Check the states of ``interpolate_edge(q_a, q_b, joint_step)[1:]`` in order.

        Only the first ``limit`` states are looked at (all when None). Returns (n, bad):
        n the edge's number of states, bad the index of the first invalid one, -1 if none.

        Raises:
            PlannerlabError: as ``interpolate_edge`` (bad ``joint_step``, or more than
                ``MAX_EDGE_STATES`` states).
        """
        qa = np.ascontiguousarray(q_a, dtype=float)
        qb = np.ascontiguousarray(q_b, dtype=float)
        step = float(joint_step)
        require_joint_step(step)
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        n, Q = edge_states(qa, qb, step, self._continuous, lim, MAX_EDGE_STATES, self.edge_weights)
        bad = (
            -1
            if n > MAX_EDGE_STATES or len(Q) == 0
            else self._fused.first_invalid(Q)
            if self._fused is not None
            else first_invalid(self.segments(Q), *self._geo)
        )
        if n > MAX_EDGE_STATES:
            span = float(np.max(np.abs(joint_difference(qb, qa, self._continuous))))
            raise edge_too_long(span, step, max(n, edge_steps(qa, qb, step, self._continuous)))
        return int(n), int(bad)

    def path_advance(
        self, path: Array, first: int, joint_step: float, limit: int | None
    ) -> tuple[int, int, int, float]:
        """Check a path (m, dof) edge by edge with conservative advancement.

        Along each edge ``q(t) = P[e] + t · d_e`` (the short way round for continuous
        joints), from a valid state at ``t`` the next checked state is at
        ``t + max(1/n, min(dt_ca, joint_step / span))``: ``n`` the edge's uniform count
        (:func:`~plannerlab.collision.kernels.edge_states`, radian and metric steps),
        ``dt_ca`` the conservative advancement step
        (:func:`~plannerlab.collision.kernels.advance_dt`). Each state visited is one query (its
        validity, plus its pair distances when the step needs them). The first state:
        ``first`` 1 checks it (one query), 0 only measures it when a step needs it (one
        query then), 2 measures it without counting (the caller queried it already: a
        path checked in pieces). At most ``limit`` queries (None: no limit).

        Returns (queries, status, edge, t): status 0 every checked state valid, 1 the
        state at ``t`` on edge ``edge`` invalid, 2 the limit was reached first.

        Raises:
            PlannerlabError: as ``interpolate_edge``, an edge whose grid would have more
                than ``MAX_EDGE_STATES`` states (the edges before it are checked).
        """
        if self._rates is None:
            raise ValueError("path_advance needs link rates (a checker with a margin)")
        P = path
        if not (
            type(P) is np.ndarray and P.ndim == 2 and P.dtype == np.float64 and P.flags.c_contiguous
        ):
            P = np.ascontiguousarray(np.atleast_2d(np.asarray(path, dtype=float)))
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        step = float(joint_step)
        require_joint_step(step)
        if self._armz:
            qn, status, e, t = armz_path_advance(P, int(first), step, lim, *self._advance_args)
        else:
            qn, status, e, t = self._path_advance_py(P, int(first), step, lim)
        if status == 3:
            qa, qb = P[e], P[e + 1]
            span = float(np.max(np.abs(joint_difference(qb, qa, self._continuous))))
            raise edge_too_long(
                span, step, max(MAX_EDGE_STATES + 1, edge_steps(qa, qb, step, self._continuous))
            )
        return int(qn), int(status), int(e), float(t)

    def _path_advance_py(
        self, P: np.ndarray, first: int, joint_step: float, limit: int
    ) -> tuple[int, int, int, float]:
        """:meth:`path_advance` for robots whose kinematics are not compiled: the same
        steps, one compiled call per state."""
        W, Pr = self._rates  # type: ignore[misc]
        r, rs, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi = self._geo
        L = self.n_links
        buf = scratch(L)
        v_link = np.empty(L)
        v_pair = np.empty((L, L))
        queries = 0
        seg: np.ndarray | None = self.segments(P[0]) if first == 2 else None
        if first == 1:
            if limit < 1:
                return queries, 2, 0, 0.0
            seg = self.segments(P[0])
            queries += 1
            if first_invalid(seg, *self._geo) >= 0:
                return queries, 1, 0, 0.0
        for e in range(len(P) - 1):
            d = joint_difference(P[e + 1], P[e], self._continuous)
            span = float(np.max(np.abs(d), initial=0.0))
            metric = float(np.abs(d) @ self.edge_weights)
            n = max(1.0, math.ceil(span / joint_step - 1e-12), math.ceil(metric - 1e-12))
            if n > MAX_EDGE_STATES:
                return queries, 3, e, 0.0
            dt_min = 1.0 / n
            dt_cap = joint_step / span if span > 0.0 else 1.0
            adaptive = dt_cap > dt_min * (1.0 + 1e-12)
            t, dt = 0.0, dt_min
            if adaptive:
                edge_rates(d, W, Pr, v_link, v_pair)
                if seg is None:
                    if queries >= limit:
                        return queries, 2, e, 0.0
                    seg = self.segments(P[e])
                    queries += 1
                dt = advance_dt(
                    seg[0],
                    r,
                    rs,
                    moving,
                    allowed,
                    kinds,
                    Rs,
                    cs,
                    hs,
                    olo,
                    ohi,
                    v_link,
                    v_pair,
                    self.margin_m,
                    1.0,
                    buf,
                )
            while True:
                tn = t + max(dt_min, min(dt, dt_cap))
                if tn >= 1.0 - 1e-9:
                    tn = 1.0
                if queries >= limit:
                    return queries, 2, e, t
                seg = self.segments(P[e] + tn * d)
                queries += 1
                if first_invalid(seg, *self._geo) >= 0:
                    return queries, 1, e, tn
                if tn == 1.0:
                    break
                if adaptive:
                    dt = advance_dt(
                        seg[0],
                        r,
                        rs,
                        moving,
                        allowed,
                        kinds,
                        Rs,
                        cs,
                        hs,
                        olo,
                        ohi,
                        v_link,
                        v_pair,
                        self.margin_m,
                        1.0 - tn,
                        buf,
                    )
                t = tn
        return queries, 0, len(P) - 1, 1.0

    def hits(self, q: Array) -> np.ndarray:
        """Every colliding pair at q: (m, 3) rows (link, other, other_is_link)."""
        h = all_hits(self.segments(q)[0], *self._geo)
        # the checker's order: scene pairs by (link, obstacle), then link pairs by (i, j)
        return h[np.lexsort((h[:, 1], h[:, 0], h[:, 2]))]

    def pair_distances(self, q: Array, margin_m: float) -> PairDistances:
        """Every checked pair at q (dof,) whose signed distance is below ``margin_m``."""
        seg = self.segments(q)[0]
        idx, d, tl, to, n = pair_distances_kernel(seg, *self._geo, float(margin_m))
        return PairDistances(
            link=idx[:, 0].copy(),
            other=idx[:, 1].copy(),
            other_is_link=idx[:, 2].astype(bool),
            d_m=d,
            t_link=tl,
            t_other=to,
            n_world=n,
        )

    def min_clearance(self, Q: Array, include_self: bool = True) -> float:
        """:meth:`clearance`'s smallest over the states Q (k, dof), in one compiled call
        (inf when there is no state or no pair)."""
        return float(min_clearance_kernel(self.segments(Q), *self._geo, bool(include_self)))

    def clearance(self, q: Array, include_self: bool = True) -> float:
        """Smallest signed distance [m] over every checked pair (inf when none)."""
        pd = self.pair_distances(q, np.inf)
        d = pd.d_m if include_self else pd.d_m[~pd.other_is_link]
        return float(d.min()) if len(d) else float("inf")

"""The compiled collision core's Python face: one robot in one scene, with a margin.

:class:`Core` answers, for one robot in one scene, what the planners ask millions of
times, on the compiled robot–scene model (:class:`~plannerlab.collision.model.
CompiledModel`, built once here) and its one state test
(:mod:`plannerlab.collision.state_test`: a float32 filter in vector lanes, confirmed in
float64):

* states: :meth:`Core.is_valid` (one), :meth:`Core.valid` (a batch, eight a call),
  :meth:`Core.first_invalid` (in order);
* edges on the checker's grid (:meth:`~plannerlab.collision.fcl_checker.CollisionChecker.
  densify`: at most ``joint_step`` per joint and, with a margin, no point moving more than
  the margin between two states): :meth:`Core.edge_certified`, the grid's verdict from a
  few certified stretches (:mod:`plannerlab.collision.edges`), and
  :meth:`Core.edge_first_invalid`, the grid's first invalid state in order;
* geometry from the same kinematics in float64: :meth:`Core.segments`, :meth:`Core.tip`;
  distances of every checked pair (:meth:`Core.pair_distances`, for clearance-aware
  optimisation), the smallest over a batch (:meth:`Core.min_clearance`), the colliding
  pairs (:meth:`Core.hits`), by the exact tests of :mod:`plannerlab.collision.geometry`
  (:mod:`plannerlab.collision.kernels`).

The pairs checked are the checker's: moving capsules against every obstacle (radii grown
by the whole margin), and the robot's link pairs except ``excluded_pairs`` and pairs of
two fixed links (radii grown by half the margin each: a pair keeps one margin); a mesh
robot's ``self_only_links`` never against the scene and grown by no margin, its
``scene_only_links`` never against links; an obstacle's declared contacts (its
``touch_links``' capsules) never against it.

Calls from Python pass the model packed (:mod:`plannerlab.collision.packing`): five
arrays, so a query's fixed cost is a few microseconds; compiled consumers (the native
planners, the sphere field) take :attr:`Core.model` itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plannerlab.collision import queries
from plannerlab.collision.geometry import BOX, CYLINDER, SPHERE
from plannerlab.collision.kernels import (
    PairGeometry,
    all_hits,
    body_pairs,
    chain_tree,
    min_clearance_kernel,
    pair_distances_kernel,
)
from plannerlab.collision.model import ChainGeometry, CompiledModel, build_model, has_chain
from plannerlab.collision.packing import pack
from plannerlab.collision.state_test import lanes
from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere, touch_mask
from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.robots.paths import MAX_EDGE_STATES, edge_steps, edge_too_long, require_joint_step

_NO_LIMIT = 2**62  # "check every state of the edge"
_F64 = np.dtype(np.float64)


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


class Core:
    """Compiled validity and distances for one robot in one scene (no check counter:
    :class:`~plannerlab.collision.fcl_checker.CollisionChecker` counts).

    Args:
        robot: a robot that gives its serial chain (``chain_data()``).
        scene: boxes, cylinders and spheres.
        margin_m: the clearance margin [m].
        edge_weights: (dof,) the grid's metric weights (reach / margin; None: radian steps
            only).
        link_rates: (dof, L) per joint and capsule how fast the capsule moves [m per rad or
            per m] (certified edges); None: taken from the robot (``reach.reach_bounds``).

    Raises:
        ValueError: a scene with other shapes, or a robot without a chain.
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        margin_m: float = 0.0,
        edge_weights: Array | None = None,
        link_rates: Array | None = None,
    ) -> None:
        if not supports(scene):
            raise ValueError("the core tests boxes, cylinders and spheres only")
        if not has_chain(robot):
            raise ValueError(
                f"the core needs the robot's serial chain (chain_data()); "
                f"{getattr(robot, 'kind', type(robot).__name__)!r} gives none"
            )
        self.robot = robot
        self.scene = scene
        self.margin_m = float(margin_m)
        r = np.asarray(robot.link_radii_m, dtype=float)
        #: capsule radii against the scene: inflated by the whole margin
        self.radii = np.ascontiguousarray(r + self.margin_m)
        #: capsule radii against each other: by half of it (a pair keeps one margin); a
        #: mesh robot's finer covers by none (their excess is the allowance: links built
        #: to pass within a centimetre of each other, a UR10's wrists, stay apart)
        half = np.full(len(r), self.margin_m / 2.0)
        half[[i for i in getattr(robot, "self_only_links", ()) if 0 <= i < len(r)]] = 0.0
        self.radii_self = np.ascontiguousarray(r + half)
        #: metric edge bound (zeros: radian steps only)
        self.edge_weights = np.ascontiguousarray(
            np.zeros(robot.dof) if edge_weights is None else edge_weights, dtype=float
        )
        L = len(self.radii)
        self.n_links = L
        # a mesh robot's finer covers judge self-collision only, its first covers the
        # scene only (robots.urdf.model: "Self-collision at the meshes' accuracy")
        self_only = set(getattr(robot, "self_only_links", ()))
        scene_only = set(getattr(robot, "scene_only_links", ()))
        self.moving = np.array(
            [i not in robot.fixed_links and i not in self_only for i in range(L)]
        )
        allowed = np.zeros((L, L), dtype=bool)
        excluded = set(robot.excluded_pairs)  # a property: computed once here
        fixed = set(robot.fixed_links)
        for i in range(L):
            if i in scene_only:
                continue
            for j in range(i + 1, L):
                allowed[i, j] = (
                    (i, j) not in excluded
                    and not (i in fixed and j in fixed)
                    and j not in scene_only
                )
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
        olo = np.ascontiguousarray(lo, dtype=float).reshape(n, 3)
        ohi = np.ascontiguousarray(hi, dtype=float).reshape(n, 3)
        #: (L, n) bool: the declared contacts (capsule, obstacle) never tested (an
        #: obstacle's ``touch_links``: :func:`~plannerlab.problem.scene.touch_mask`)
        self.touch = np.ascontiguousarray(touch_mask(robot, scene), dtype=np.bool_)
        geo = ChainGeometry(
            self.radii, self.radii_self, self.moving, allowed, self.kinds, self.Rs, self.cs,
            self.hs, self.touch if self.touch.any() else None,
        )  # fmt: skip
        #: the compiled robot–scene model (:class:`~plannerlab.collision.model.
        #: CompiledModel`), which compiled consumers take
        self.model: CompiledModel = build_model(
            robot, geo, self.margin_m, self.edge_weights, link_rates
        )
        cap_body = np.empty(L, dtype=np.int64)  # the model's bodies, in the robot's order
        cap_body[self.model.perm] = self.model.cap_body
        # the exact distance kernels' arguments (kernels.py: capsule axes and these)
        self._geo = PairGeometry(
            self.radii,
            self.radii_self,
            self.moving,
            self.allowed,
            chain_tree(allowed),
            self.kinds,
            self.Rs,
            self.cs,
            self.hs,
            olo,
            ohi,
            body_pairs(cap_body, allowed),
            self.touch,
        )
        self._P = tuple(pack(self.model, lanes(self.model)))
        #: the model and the state test's scratch packed (:mod:`plannerlab.collision.
        #: packing`): what compiled kernels called from Python take (five arrays)
        self.packed = self._P
        self._one = (robot.dof,)
        self._one_out = np.empty(1, dtype=np.bool_)
        self._tip: tuple[int, np.ndarray] | None = None
        tip_data = getattr(robot, "tip_data", None)
        if callable(tip_data):
            body, p, nrm = tip_data()
            A = self.model.fold[int(body)]
            self._tip = (int(body), np.ascontiguousarray(np.stack([A.T @ p, A.T @ nrm])))
        self._warm_up()

    def _warm_up(self) -> None:
        """Call every compiled query once, so that numba's compilation (first run on an
        empty cache) or loading from its cache happens here, when the checker is built,
        and not inside a planner's time limit."""
        q = np.clip(np.zeros(self.robot.dof), self.robot.lower, self.robot.upper)
        q2 = np.vstack([q, q])
        self.valid(q2)
        self.is_valid(q)
        self.first_invalid(q2)
        self.edge_first_invalid(q, q, 1.0)
        self.edge_certified(q, q, 1.0)
        self.hits(q)
        self.pair_distances(q, 0.0)
        self.min_clearance(q2)
        if self._tip is not None:
            self.tip(q)

    # ------------------------------------------------------------------ geometry
    def _Q(self, Q: Array) -> np.ndarray:
        Q = queries.kernel_states(np.atleast_2d(np.asarray(Q, dtype=float)))
        if Q.shape[1] != self.robot.dof:
            raise ValueError(f"q must have {self.robot.dof} joints, got shape {Q.shape}")
        return Q

    def _q(self, q: Array) -> np.ndarray:
        """One state as a contiguous float64 (dof,) (no copy when it is one already)."""
        if type(q) is np.ndarray and q.shape == self._one and q.dtype is _F64:
            return q if q.flags.c_contiguous and q.flags.writeable else queries.kernel_states(q)
        Q = self._Q(q)
        if len(Q) != 1:
            raise ValueError(f"q must be one state ({self.robot.dof},), got shape {np.shape(q)}")
        return Q[0]

    def segments(self, Q: Array) -> np.ndarray:
        """Capsule axes (k, L, 2, 3) for Q (k, dof), in the robot's capsule order (the one
        kinematics in float64: ``link_segments``' numbers to rounding)."""
        Qc = self._Q(Q)
        out = np.empty((len(Qc), self.n_links, 2, 3))
        return queries.segments(self._P, Qc, out)

    def tip(self, q: Array) -> tuple[Array, Array]:
        """The robot's ``tip(q)`` (position [m], face normal) for one q (dof,), from the
        compiled kinematics when the robot gives its tip on the chain (``tip_data``)."""
        if self._tip is None:
            return self.robot.tip(q)
        out = queries.tip(self._P, self._q(q), self._tip[0], self._tip[1], np.empty((2, 3)))
        return out[0].copy(), out[1].copy()

    # ------------------------------------------------------------------ states
    def valid(self, Q: Array) -> np.ndarray:
        """(k,) bool validity of Q (k, dof)."""
        Qc = self._Q(Q)
        out = np.empty(len(Qc), dtype=np.bool_)
        queries.states(self._P, Qc, out, queries.EACH)
        return out

    def is_valid(self, q: Array) -> bool:
        """Validity of one state q (dof,)."""
        q1 = self._q(q).reshape(1, -1)
        out = self._one_out
        queries.states(self._P, q1, out, queries.EACH)
        return bool(out[0])

    def first_invalid(self, Q: Array) -> int:
        """Index of the first invalid state of Q (k, dof) in order, -1 if all are valid."""
        Qc = self._Q(Q)
        return int(queries.states(self._P, Qc, np.empty(len(Qc), np.bool_), queries.FIRST))

    # ------------------------------------------------------------------ edges
    def _edge_args(
        self, q_a: Array, q_b: Array, joint_step: float
    ) -> tuple[np.ndarray, np.ndarray, float]:
        step = float(joint_step)
        require_joint_step(step)
        return self._q(q_a), self._q(q_b), step

    def _too_long(self, qa: np.ndarray, qb: np.ndarray, step: float, n: int) -> Exception:
        span = float(np.max(np.abs(joint_difference(qb, qa, self.robot.continuous))))
        return edge_too_long(span, step, max(n, edge_steps(qa, qb, step, self.robot.continuous)))

    def _grid_n(self, qa: np.ndarray, qb: np.ndarray, step: float) -> int:
        """The grid's number of states of edge qa -> qb (``robots.paths.edge_counts``).

        Raises:
            PlannerlabError: more than ``MAX_EDGE_STATES``.
        """
        d = joint_difference(qb, qa, self.robot.continuous)
        n = max(
            1,
            math.ceil(float(np.max(np.abs(d), initial=0.0)) / step - 1e-12),
            math.ceil(float(np.abs(d) @ self.edge_weights) - 1e-12),
        )
        if n > MAX_EDGE_STATES:
            raise self._too_long(qa, qb, step, int(n))
        return int(n)

    def edge_first_invalid(
        self, q_a: Array, q_b: Array, joint_step: float, limit: int | None = None
    ) -> tuple[int, int]:
        """Check the grid states of edge q_a → q_b (1..n, q_a excluded) in order, the first
        ``limit`` of them (all when None). Returns (n, bad): the grid's number of states
        and the index of the first invalid one, -1 if none.

        Raises:
            PlannerlabError: a bad ``joint_step``, or more than ``MAX_EDGE_STATES`` states.
        """
        qa, qb, step = self._edge_args(q_a, q_b, joint_step)
        self._grid_n(qa, qb, step)
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        n, bad, _ = queries.edge(self._P, qa, qb, step, (lim, queries.IN_ORDER))
        return int(n), int(bad)

    def edge_certified(
        self, q_a: Array, q_b: Array, joint_step: float, limit: int | None = None
    ) -> tuple[int, int, int]:
        """The grid's verdict on edge q_a → q_b from certified stretches
        (:func:`~plannerlab.collision.edges.edge_check`), at most ``limit`` state tests.
        Returns (status, tests, n): 0 free, 1 invalid, 2 the limit came first; the grid's
        number of states.

        Raises:
            PlannerlabError: a bad ``joint_step``, or more than ``MAX_EDGE_STATES`` states.
        """
        qa, qb, step = self._edge_args(q_a, q_b, joint_step)
        self._grid_n(qa, qb, step)
        lim = _NO_LIMIT if limit is None else max(int(limit), 0)
        status, tests, n = queries.edge(self._P, qa, qb, step, (lim, queries.CERTIFIED))
        return int(status), int(tests), int(n)

    # ------------------------------------------------------------------ distances
    def hits(self, q: Array) -> np.ndarray:
        """Every colliding pair at q: (m, 3) rows (link, other, other_is_link)."""
        h = all_hits(self.segments(q)[0], self._geo)
        # the checker's order: scene pairs by (link, obstacle), then link pairs by (i, j)
        return h[np.lexsort((h[:, 1], h[:, 0], h[:, 2]))]

    def pair_distances(self, q: Array, margin_m: float) -> PairDistances:
        """Every checked pair at q (dof,) whose signed distance is below ``margin_m``."""
        seg = self.segments(q)[0]
        idx, d, tl, to, n = pair_distances_kernel(seg, self._geo, float(margin_m))
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
        return float(min_clearance_kernel(self.segments(Q), self._geo, bool(include_self)))

    def clearance(self, q: Array, include_self: bool = True) -> float:
        """Smallest signed distance [m] over every checked pair (inf when none)."""
        pd = self.pair_distances(q, np.inf)
        d = pd.d_m if include_self else pd.d_m[~pd.other_is_link]
        return float(d.min()) if len(d) else float("inf")


__all__ = ["Core", "PairDistances", "supports"]

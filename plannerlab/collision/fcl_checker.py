"""Collision checking: the compiled core, with python-fcl as its reference and fallback.

The robot's links are capsules (see :class:`plannerlab.robots.base.Robot`); obstacles are
boxes, cylinders, spheres and meshes (the core checks a mesh's cover of boxes, FCL its
triangles: :mod:`plannerlab.problem.scene`). Two backends answer the same questions with
the same meaning:

* ``"core"`` (:mod:`plannerlab.collision.core`): numba-compiled kinematics, broad phase and
  exact capsule tests over whole batches; the default whenever every obstacle is a shape it
  covers.
* ``"fcl"``: FCL objects built once, each query updating the link transforms after a
  vectorised bounding-box pre-test. It answers what the core does not cover, and it is the
  reference the core is compared with (``bench/core_agreement.py``). This is the only module
  that imports ``fcl``.

:attr:`CollisionChecker.backend` says which one answers; :class:`PathCheck` carries it.

Pairs that are never checked: a fixed link against the scene (the base stands on its
pedestal by design), the robot's ``excluded_pairs`` (neighbours that always touch) and an
obstacle's declared contacts (the capsules of its ``touch_links`` against it: a grasped
object and the hand).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import fcl
import numpy as np

from plannerlab.collision.core import Core, PairDistances
from plannerlab.collision.core import supports as core_supports
from plannerlab.collision.reach import joint_reach_m, reach_bounds
from plannerlab.problem.scene import Box, Cylinder, Mesh, Scene, Sphere, touch_mask
from plannerlab.robots.base import Array, Robot, joint_difference
from plannerlab.robots.paths import densify, edge_counts

#: :meth:`CollisionChecker.check_path` without ``stop``: no limit on a kernel call's states
UNLIMITED_STATES = 1 << 62


@dataclass(frozen=True)
class PathCheck:
    """Outcome of checking a densified path.

    Attributes:
        valid: every checked state is collision-free.
        states_checked: how many interpolated states were checked.
        first_invalid_edge: index of the first waypoint edge with a collision (or None).
        first_invalid_state: the first colliding interpolated state (or None).
        pairs: the colliding pairs at that state (names).
        complete: False when ``stop`` ended the check early (``valid`` is then False,
            with no colliding state).
    """

    valid: bool
    states_checked: int
    first_invalid_edge: int | None = None
    first_invalid_state: Array | None = None
    pairs: tuple[tuple[str, str], ...] = ()
    backend: str = "fcl"
    complete: bool = True


def _rotations_z_to(d: Array) -> Array:
    """Rotation matrices (..., 3, 3) whose z axis is the unit vector d (..., 3)."""
    helper = np.where(np.abs(d[..., :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x = np.cross(helper, d)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    y = np.cross(d, x)
    return np.stack([x, y, d], axis=-1)


class CollisionChecker:
    """Validity, colliding pairs and distances for one robot in one scene.

    Holds its own FCL objects and a count of the states it has checked
    (``checks``: one per state, whichever backend answers); it is not thread-safe and not
    shared between trials.

    Args:
        backend: ``"auto"`` (the core when it covers the scene, else FCL), ``"core"`` or
            ``"fcl"``.
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        backend: str = "auto",
        margin_m: float = 0.0,
        edge_check: str = "auto",
    ) -> None:
        if backend not in ("auto", "core", "fcl"):
            raise ValueError(f"backend must be 'auto', 'core' or 'fcl', got {backend!r}")
        if edge_check not in ("auto", "grid", "certified"):
            raise ValueError(
                f"edge_check must be 'auto', 'grid' or 'certified', got {edge_check!r}"
            )
        if backend == "core" and not core_supports(scene):
            raise ValueError("backend 'core' covers boxes, cylinders and spheres only")
        if not (margin_m >= 0.0 and np.isfinite(margin_m)):
            raise ValueError(f"margin_m must be a finite number >= 0, got {margin_m!r}")
        #: clearance margin [m]: capsules are inflated by it against the scene, by half of
        #: it against each other (a pair of links keeps one margin between them)
        self.margin_m = float(margin_m)
        use_core = (backend == "core" or (backend == "auto" and core_supports(scene))) and (
            callable(getattr(robot, "chain_data", None))
        )
        if backend == "core" and not use_core:
            raise ValueError("backend 'core' needs a robot that gives its chain (chain_data())")
        #: per joint, how fast the geometry moves [m per rad or m] (see reach.py); with a
        #: margin, edges are checked so that no point moves more than the margin between
        #: two checked states (on top of the radian step asked for)
        self.reach_m: np.ndarray | None = None
        link_rates: np.ndarray | None = None
        if use_core:
            self.reach_m, link_rates, _ = reach_bounds(robot)
        elif margin_m > 0:
            self.reach_m = joint_reach_m(robot)
        self.edge_weights: np.ndarray | None = (
            None if self.reach_m is None or margin_m == 0 else self.reach_m / self.margin_m
        )
        if edge_check == "certified" and not use_core:
            raise ValueError("edge_check 'certified' needs the core backend")
        #: how edges and paths are checked: "grid" (every state of :meth:`densify`, in
        #: order) or "certified" (the same grid's verdict from a few certified stretches
        #: on the core, see collision/edges.py: far fewer states, never more than the grid
        #: and a few percent)
        self.edge_check = "grid" if edge_check == "grid" or not use_core else "certified"
        self._core: Core | None = None
        if use_core:
            self._core = Core(robot, scene, self.margin_m, self.edge_weights, link_rates)
        #: which backend answers the queries: "core" or "fcl"
        self.backend = "core" if self._core is not None else "fcl"
        self.robot = robot
        self.scene = scene
        self.checks = 0
        #: what consumers build once from this checker's robot, scene and model (a
        #: planner's packed sphere field): see :meth:`derived`
        self._derived: dict[str, Any] = {}
        self._radii = np.asarray(robot.link_radii_m, dtype=float) + self.margin_m
        # a mesh robot's finer covers (self-collision only) carry no margin (core.py)
        half = np.full(len(robot.link_radii_m), self.margin_m / 2.0)
        half[[i for i in getattr(robot, "self_only_links", ()) if 0 <= i < len(half)]] = 0.0
        self._radii_self = np.asarray(robot.link_radii_m, dtype=float) + half
        L = len(self._radii)
        self._n_links = L
        self._link_names = tuple(robot.link_names)
        # Reference lengths: capsules are rebuilt only if a link's length changes.
        seg0 = robot.link_segments(np.clip(np.zeros(robot.dof), robot.lower, robot.upper))
        self._lengths = np.linalg.norm(seg0[:, 1] - seg0[:, 0], axis=-1)
        self._links = [
            fcl.CollisionObject(fcl.Capsule(float(r), float(max(ln, 1e-9))), fcl.Transform())
            for r, ln in zip(self._radii, self._lengths, strict=True)
        ]
        # the same capsules for link pairs (half the margin each)
        self._links_self = (
            self._links
            if self.margin_m == 0.0
            else [
                fcl.CollisionObject(fcl.Capsule(float(r), float(max(ln, 1e-9))), fcl.Transform())
                for r, ln in zip(self._radii_self, self._lengths, strict=True)
            ]
        )
        # a mesh obstacle's cover boxes each stand for the mesh's real triangles (one
        # BVHModel per mesh, shared): the boxes' bounds pre-test, the triangles decide
        bvh = {m.name: self._make_mesh(m) for m in scene.meshes}
        cover_of = [getattr(o, "cover_of", "") for o in scene.obstacles]
        self._obstacles = [
            bvh[m] if m else self._make_obstacle(o)
            for o, m in zip(scene.obstacles, cover_of, strict=True)
        ]
        self._obs_lo, self._obs_hi = scene.aabbs()
        # a mesh robot's finer covers judge self-collision only, its first covers the
        # scene only (robots.urdf.model: "Self-collision at the meshes' accuracy")
        self_only = frozenset(getattr(robot, "self_only_links", ()))
        scene_only = frozenset(getattr(robot, "scene_only_links", ()))
        moving = np.array([i not in robot.fixed_links and i not in self_only for i in range(L)])
        self._against_scene = moving
        #: (L, n) the (capsule, obstacle) pairs checked: moving capsules, but an
        #: obstacle's declared contacts (its ``touch_links``, never checked against it)
        self._scene_mask = moving[:, None] & ~touch_mask(robot, scene)
        excluded = robot.excluded_pairs
        pairs = [
            (i, j)
            for i in range(L)
            if i not in scene_only
            for j in range(i + 1, L)
            if (i, j) not in excluded
            and not (i in robot.fixed_links and j in robot.fixed_links)
            and j not in scene_only
        ]
        self._self_pairs = np.array(pairs, dtype=int).reshape(-1, 2)
        self._request = fcl.CollisionRequest()
        self._contact_request = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)
        self._distance_request = fcl.DistanceRequest(enable_signed_distance=True)

    # ------------------------------------------------------------------ building
    @staticmethod
    def _make_obstacle(o: Box | Cylinder | Sphere) -> fcl.CollisionObject:
        if isinstance(o, Box):
            geom = fcl.Box(*(float(s) for s in o.size_m))
        elif isinstance(o, Cylinder):
            geom = fcl.Cylinder(float(o.radius_m), float(o.length_m))
        else:
            geom = fcl.Sphere(float(o.radius_m))
        T = o.T_world_obstacle
        return fcl.CollisionObject(geom, fcl.Transform(T[:3, :3].copy(), T[:3, 3].copy()))

    @staticmethod
    def _make_mesh(m: Mesh) -> fcl.CollisionObject:
        """A mesh obstacle's triangles as an FCL ``BVHModel`` at its pose."""
        bvh = fcl.BVHModel()
        bvh.beginModel(len(m.vertices_m), len(m.faces))
        bvh.addSubModel(
            np.ascontiguousarray(m.vertices_m, dtype=float),
            np.ascontiguousarray(m.faces, dtype=np.int32),
        )
        bvh.endModel()
        T = m.T_world_obstacle
        return fcl.CollisionObject(bvh, fcl.Transform(T[:3, :3].copy(), T[:3, 3].copy()))

    def _place(self, seg: Array) -> None:
        """Move the FCL link capsules to the segments (L, 2, 3) of one state."""
        a, b = seg[:, 0], seg[:, 1]
        axis = b - a
        lengths = np.linalg.norm(axis, axis=-1)
        safe = np.where(lengths > 1e-12, lengths, 1.0)[:, None]
        d = np.where(lengths[:, None] > 1e-12, axis / safe, [[0.0, 0.0, 1.0]])
        R = _rotations_z_to(d)
        centres = (a + b) / 2.0
        changed = np.flatnonzero(np.abs(lengths - self._lengths) > 1e-9)
        for i in changed:
            self._lengths[i] = lengths[i]
            self._links[i] = fcl.CollisionObject(
                fcl.Capsule(float(self._radii[i]), float(max(lengths[i], 1e-9))), fcl.Transform()
            )
            if self._links_self is not self._links:
                self._links_self[i] = fcl.CollisionObject(
                    fcl.Capsule(float(self._radii_self[i]), float(max(lengths[i], 1e-9))),
                    fcl.Transform(),
                )
        for k, obj in enumerate(self._links):
            tf = fcl.Transform(R[k], centres[k])
            obj.setTransform(tf)
            if self._links_self is not self._links:
                self._links_self[k].setTransform(tf)

    # ------------------------------------------------------------------ pre-test
    def _candidates(self, segs: Array) -> tuple[Array, Array]:
        """Pairs whose bounding boxes overlap, for a batch of segments (k, L, 2, 3).

        Returns:
            scene (k, L, n_obstacles) and self (k, n_self_pairs) boolean masks.
        """
        r = self._radii[None, :, None]
        lo = np.minimum(segs[:, :, 0], segs[:, :, 1]) - r  # (k, L, 3)
        hi = np.maximum(segs[:, :, 0], segs[:, :, 1]) + r
        if len(self._obstacles):
            scene = (
                np.all(
                    (lo[:, :, None, :] <= self._obs_hi[None, None])
                    & (hi[:, :, None, :] >= self._obs_lo[None, None]),
                    axis=-1,
                )
                & self._scene_mask[None]
            )
        else:
            scene = np.zeros(segs.shape[:2] + (0,), dtype=bool)
        if len(self._self_pairs):
            i, j = self._self_pairs[:, 0], self._self_pairs[:, 1]
            selfc = np.all((lo[:, i] <= hi[:, j]) & (hi[:, i] >= lo[:, j]), axis=-1)
        else:
            selfc = np.zeros((segs.shape[0], 0), dtype=bool)
        return scene, selfc

    def _collide(self, o1: fcl.CollisionObject, o2: fcl.CollisionObject) -> bool:
        return fcl.collide(o1, o2, self._request, fcl.CollisionResult()) > 0

    def _state_pairs(
        self, seg: Array, scene: Array, selfc: Array, first_only: bool
    ) -> list[tuple[int, int, bool]]:
        """Colliding pairs of one state among the candidates: (link, other, other_is_link)."""
        self._place(seg)
        hits: list[tuple[int, int, bool]] = []
        for li, oi in zip(*np.nonzero(scene), strict=True):
            if self._collide(self._links[li], self._obstacles[oi]):
                hits.append((int(li), int(oi), False))
                if first_only:
                    return hits
        for p in np.flatnonzero(selfc):
            i, j = self._self_pairs[p]
            if self._collide(self._links_self[i], self._links_self[j]):
                hits.append((int(i), int(j), True))
                if first_only:
                    return hits
        return hits

    # ------------------------------------------------------------------ queries
    def valid_batch(self, Q: Array) -> np.ndarray:
        """Validity of every state in Q (k, dof) -> (k,) bool. Counts k checks."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        if self._core is not None:
            self.checks += len(Q)
            return self._core.valid(Q)
        segs = self.robot.link_segments(Q)
        scene, selfc = self._candidates(segs)
        valid = np.ones(len(Q), dtype=bool)
        undecided = np.flatnonzero(scene.any(axis=(1, 2)) | selfc.any(axis=1))
        for s in undecided:
            valid[s] = not self._state_pairs(segs[s], scene[s], selfc[s], first_only=True)
        self.checks += len(Q)
        return valid

    def is_valid(self, q: Array) -> bool:
        """True when q (dof,) collides neither with the scene nor with itself."""
        if self._core is not None:
            self.checks += 1
            return bool(self._core.is_valid(q))
        return bool(self.valid_batch(np.asarray(q, dtype=float)[None, :])[0])

    def first_invalid(self, Q: Array) -> int | None:
        """Index of the first invalid state of Q (k, dof), checking in order; None if all valid.

        Counts only the states it had to look at.
        """
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        if self._core is not None:
            bad = self._core.first_invalid(Q)
            self.checks += len(Q) if bad < 0 else bad + 1
            return None if bad < 0 else bad
        segs = self.robot.link_segments(Q)
        scene, selfc = self._candidates(segs)
        undecided = np.flatnonzero(scene.any(axis=(1, 2)) | selfc.any(axis=1))
        for s in undecided:
            if self._state_pairs(segs[s], scene[s], selfc[s], first_only=True):
                self.checks += int(s) + 1
                return int(s)
        self.checks += len(Q)
        return None

    def check_edge(
        self, q_a: Array, q_b: Array, joint_step: float, max_states: int | None = None
    ) -> tuple[int, int | None]:
        """Check the edge q_a → q_b as :func:`~plannerlab.robots.paths.interpolate_edge`
        densifies it (q_a itself excluded), in order, at most ``max_states`` states.

        Returns (n, bad): the edge's number of states and the index of the first invalid
        one among those checked (None if none). Counts the states looked at, as
        :meth:`first_invalid` does. On the core, interpolation, kinematics and checks are
        one compiled call. With ``edge_check == "certified"`` the verdict is the same and
        n counts the state tests made (``max_states + 1`` when ``max_states`` came first:
        the edge unfinished), bad the last of them when the edge is invalid.
        """
        if self.edge_check == "certified":
            assert self._core is not None
            status, tests, _ = self._core.edge_certified(q_a, q_b, joint_step, max_states)
            self.checks += tests
            if status == 2:
                return (max(int(max_states or 0), tests) + 1), None
            return tests, (tests - 1 if status == 1 else None)
        if self._core is not None:
            n, bad = self._core.edge_first_invalid(q_a, q_b, joint_step, max_states)
            m = n if max_states is None else min(n, max(int(max_states), 0))
            self.checks += m if bad < 0 else bad + 1
            return n, (None if bad < 0 else bad)
        states = self.densify(np.array([q_a, q_b], dtype=float), joint_step)[0][1:]
        m = len(states) if max_states is None else min(len(states), max(int(max_states), 0))
        return len(states), (self.first_invalid(states[:m]) if m > 0 else None)

    def colliding_pairs(self, q: Array) -> tuple[tuple[str, str], ...]:
        """Every colliding pair at q: (link name, obstacle name) or (link name, link name)."""
        if self._core is not None:
            hits = [(int(a), int(b), bool(c)) for a, b, c in self._core.hits(q)]
        else:
            seg = self.robot.link_segments(np.asarray(q, dtype=float))
            scene, selfc = self._candidates(seg[None])
            hits = self._state_pairs(seg, scene[0], selfc[0], first_only=False)
        self.checks += 1
        names = self.scene.source_names  # a cover box names its mesh
        pairs = (
            (self._link_names[a], self._link_names[b] if is_link else names[b])
            for a, b, is_link in hits
        )
        return tuple(dict.fromkeys(pairs))

    def tip(self, q: Array) -> tuple[Array, Array]:
        """The robot's ``tip(q)`` (position [m], face normal) for one q (dof,), from the
        core's compiled kinematics when it has them (Arm-Z), else the robot's. Not a
        collision check (not counted)."""
        if self._core is not None:
            return self._core.tip(q)
        return self.robot.tip(q)

    def clearance(self, q: Array, include_self: bool = True) -> float:
        """Smallest signed distance [m] over every checked pair; negative = penetration.

        Exact for every pair (no pre-test), so slower than :meth:`is_valid`. Penetration
        depths follow FCL only approximately on the core (see
        :mod:`plannerlab.collision.geometry`).
        """
        if self._core is not None:
            self.checks += 1
            return self._core.clearance(q, include_self)
        seg = self.robot.link_segments(np.asarray(q, dtype=float))
        self._place(seg)
        best = np.inf
        for li in range(self._n_links):
            for oi, obj in enumerate(self._obstacles):
                if self._scene_mask[li, oi]:
                    best = min(best, self._signed_distance(self._links[li], obj))
        if include_self:
            for i, j in self._self_pairs:
                best = min(best, self._signed_distance(self._links_self[i], self._links_self[j]))
        self.checks += 1
        return float(best)

    def min_clearance(self, Q: Array, include_self: bool = True) -> float:
        """The smallest :meth:`clearance` over the states Q (k, dof) (inf when k = 0),
        counting one check per state; on the core in one compiled call."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        if self._core is None:
            return min((self.clearance(q, include_self) for q in Q), default=float("inf"))
        self.checks += len(Q)
        return self._core.min_clearance(Q, include_self)

    def pair_distances(self, q: Array, margin_m: float) -> PairDistances:
        """Every checked pair at q (dof,) whose signed distance is below ``margin_m`` [m].

        See :class:`plannerlab.collision.core.PairDistances`. Counts one check. Answered by
        the core; with the FCL backend it raises (FCL gives no axis parameters here).
        """
        if self._core is None:
            raise NotImplementedError("pair_distances needs the core backend")
        self.checks += 1
        return self._core.pair_distances(q, margin_m)

    def fcl_pair_distances(
        self, q: Array, link: Array, other: Array, other_is_link: Array
    ) -> np.ndarray:
        """FCL's signed distance [m] of the listed pairs at q (the reference; no count)."""
        self._place(self.robot.link_segments(np.asarray(q, dtype=float)))
        out = np.empty(len(link))
        for k, (a, b, is_link) in enumerate(zip(link, other, other_is_link, strict=True)):
            if is_link:
                out[k] = self._signed_distance(self._links_self[a], self._links_self[b])
            else:
                out[k] = self._signed_distance(self._links[a], self._obstacles[b])
        return out

    def _signed_distance(self, o1: fcl.CollisionObject, o2: fcl.CollisionObject) -> float:
        res = fcl.CollisionResult()
        if fcl.collide(o1, o2, self._contact_request, res) > 0:
            return -max((c.penetration_depth for c in res.contacts), default=0.0)
        return float(fcl.distance(o1, o2, self._distance_request, fcl.DistanceResult()))

    def densify(self, path: Array, joint_step: float) -> tuple[Array, Array]:
        """The states this checker checks on a path: :func:`~plannerlab.robots.paths.densify`
        at ``joint_step``, and with a margin each edge cut finer where needed so that no
        point of the robot moves more than the margin between two states (the bound
        ``Σ |Δq_i| · reach_i``). Returns (states, owning edge of each)."""
        return densify(path, joint_step, self.robot.continuous, self.edge_weights)

    def grid_states(self, path: Array, joint_step: float) -> int:
        """``len(self.densify(path, joint_step)[0])``, without making the states: the most
        checks :meth:`check_path` makes on the path (the grid's; certified edges make
        makes at most as many)."""
        path = np.atleast_2d(np.asarray(path, dtype=float))
        if len(path) < 2:
            return len(path)
        _, n = edge_counts(path, joint_step, self.robot.continuous, self.edge_weights)
        return 1 + int(n.sum())

    def _edge_counts(self, path: Array, joint_step: float) -> tuple[Array, np.ndarray]:
        """Per edge of a path (m ≥ 2 states): the joint change and the grid's number of
        states (:func:`~plannerlab.robots.paths.edge_counts`, radian and metric steps).
        Raises as ``interpolate_edge`` on a too long edge."""
        assert self.edge_weights is not None
        return edge_counts(path, joint_step, self.robot.continuous, self.edge_weights)

    @property
    def model(self) -> Any:
        """The compiled robot–scene model (:class:`~plannerlab.collision.model.
        CompiledModel`) of this checker's robot, scene and margin, built once.

        Raises:
            ValueError: the checker has no compiled core (an FCL-only scene).
            ModelError: the robot gives no serial chain (and its family no builder).
        """
        if self._core is None:
            raise ValueError(
                "the compiled model needs the core backend (boxes, cylinders, spheres)"
            )
        return self._core.model

    def derived(self, key: str, build: Callable[[], Any]) -> Any:
        """What ``build()`` gives, built on the first call with ``key`` and kept by this
        checker (one per problem and trial: its legs share it) for every later call: a
        consumer's packing of this checker's robot, scene and model (``trajopt``'s sphere
        field). ``build`` reads nothing but them; a build that raises keeps nothing."""
        if key not in self._derived:
            self._derived[key] = build()
        return self._derived[key]

    @property
    def packed_model(self) -> tuple[np.ndarray, ...]:
        """The compiled model and the state test's scratch, packed (five arrays:
        :mod:`plannerlab.collision.packing`), what compiled kernels called from Python
        take.

        Raises:
            ValueError: the checker has no compiled core.
        """
        if self._core is None:
            raise ValueError(
                "the compiled model needs the core backend (boxes, cylinders, spheres)"
            )
        return self._core.packed

    def check_path(
        self,
        path: Array,
        joint_step: float,
        stop: Callable[[], bool] | None = None,
        chunk: int = 4096,
        mode: str | None = None,
    ) -> PathCheck:
        """Check every state of a path densified to at most ``joint_step`` per joint.

        ``stop`` (a time limit, say) is asked before each ``chunk`` of states; once it says
        True the check ends, incomplete (``complete`` False). The same states are checked,
        and counted, as without it.

        With ``edge_check == "certified"`` each edge's grid is proved by a few certified
        stretches (:meth:`~plannerlab.collision.core.Core.edge_certified`: the grid's
        verdict, far fewer tests); an invalid edge's first invalid grid state is then found
        in order. ``mode`` "grid" checks the grid's states one by one whatever
        ``edge_check`` says.
        """
        if mode not in (None, "grid", "certified"):
            raise ValueError(f"mode must be None, 'grid' or 'certified', got {mode!r}")
        if (mode or self.edge_check) == "certified":
            if self.edge_check != "certified":
                raise ValueError("mode 'certified' needs a checker with edge_check 'certified'")
            return self._check_path_certified(path, joint_step, stop)
        states, owners = self.densify(path, joint_step)
        step = len(states) if stop is None else max(int(chunk), 1)
        bad = None
        for i in range(0, len(states), max(step, 1)):
            if stop is not None and stop():
                return PathCheck(
                    valid=False, states_checked=i, backend=self.backend, complete=False
                )
            b = self.first_invalid(states[i : i + step])
            if b is not None:
                bad = i + b
                break
        if bad is None:
            return PathCheck(valid=True, states_checked=len(states), backend=self.backend)
        q_bad = states[bad]
        return PathCheck(
            valid=False,
            states_checked=bad + 1,
            first_invalid_edge=int(owners[bad]),
            first_invalid_state=q_bad,
            pairs=self.colliding_pairs(q_bad),
            backend=self.backend,
        )

    def _check_path_certified(
        self, path: Array, joint_step: float, stop: Callable[[], bool] | None
    ) -> PathCheck:
        """:meth:`check_path` with certified edges, ``stop`` asked before each edge."""
        assert self._core is not None
        P = np.atleast_2d(np.asarray(path, dtype=float))
        done = 0
        ok = self.is_valid(P[0])
        done += 1
        if not ok:
            return PathCheck(
                valid=False,
                states_checked=done,
                first_invalid_edge=0,
                first_invalid_state=P[0].copy(),
                pairs=self.colliding_pairs(P[0]),
                backend=self.backend,
            )
        for e in range(len(P) - 1):
            if stop is not None and stop():
                return PathCheck(
                    valid=False, states_checked=done, backend=self.backend, complete=False
                )
            status, tests, n = self._core.edge_certified(P[e], P[e + 1], joint_step)
            self.checks += tests
            done += tests
            if status == 1:
                _, bad = self._core.edge_first_invalid(P[e], P[e + 1], joint_step)
                d = joint_difference(P[e + 1], P[e], self.robot.continuous)
                j = bad + 1
                t = 1.0 if j == n else j * (1.0 / n)
                q_bad = P[e] + t * d
                return PathCheck(
                    valid=False,
                    states_checked=done,
                    first_invalid_edge=e,
                    first_invalid_state=q_bad,
                    pairs=self.colliding_pairs(q_bad),
                    backend=self.backend,
                )
        return PathCheck(valid=True, states_checked=done, backend=self.backend)


def problem_checker(problem: Any, backend: str = "auto") -> CollisionChecker:
    """The checker of a problem: its robot and scene, with the problem's clearance margin
    (``[planning] safety_margin_m``) and the metric edge resolution it implies."""
    return CollisionChecker(
        problem.robot, problem.scene, backend, margin_m=float(problem.safety_margin_m)
    )


def colliding_link_pairs(
    robot: Any, adjacent: dict[frozenset[str], str], hulls: bool
) -> Callable[[np.ndarray], set[frozenset[str]]]:
    """The URDF link pairs (not ``adjacent``) whose real geometry intersects at a state:
    python-fcl's exact test of the links' triangle meshes (bounding-volume hierarchies),
    each collision mesh as its convex hull with ``hulls``."""
    from plannerlab.robots.urdf.link_meshes import link_meshes

    links = link_meshes(robot, hulls)
    objs = []
    for lm in links:
        bvh = fcl.BVHModel()
        bvh.beginModel(len(lm.vertices_m), len(lm.faces))
        bvh.addSubModel(lm.vertices_m, np.asarray(lm.faces, dtype=np.int32))
        bvh.endModel()
        objs.append(fcl.CollisionObject(bvh, fcl.Transform()))
    pairs = [
        (i, j)
        for i in range(len(links))
        for j in range(i + 1, len(links))
        if frozenset((links[i].link, links[j].link)) not in adjacent
    ]
    request = fcl.CollisionRequest()

    def colliding(q: np.ndarray) -> set[frozenset[str]]:
        B = robot._bodies(np.asarray(q, dtype=float))
        for lm, o in zip(links, objs, strict=True):
            T = B[lm.body]
            o.setTransform(fcl.Transform(T[:3, :3].copy(), T[:3, 3].copy()))
        return {
            frozenset((links[i].link, links[j].link))
            for i, j in pairs
            if fcl.collide(objs[i], objs[j], request, fcl.CollisionResult()) > 0
        }

    return colliding

"""How far the executed robot was from the commanded one, and from everything else, in metres.

Two measures make the verdict of an execution (:mod:`plannerlab.sim.execute`):

* :func:`geometry_deviation_m`: the largest displacement of any point of the robot's
  collision geometry between two states (commanded and simulated), over every link
  (:func:`plan_deviation`: over an execution's physics steps, against the plan);
* :func:`sampled_clearance`: the smallest simulated clearance along a sequence of states,
  to the scene and between links, from PyBullet's closest points
  (``getClosestPoints``) in a *probe* world: a second :class:`~plannerlab.sim.world.SimWorld`
  whose joints are set kinematically to each sampled state, so the measuring never
  disturbs the simulation being measured.

**The deviation bound.** A link's collision shape is a capsule: the points within its
radius ``r`` of its axis segment ``a → b`` (``robot.link_segments``, ``robot.link_radii_m``:
the robot model's own kinematics). Between two poses of the link, take the rigid motion
that maps the first axis onto the second (translation ``a₁ → a₂``, then the smallest
rotation turning the unit axis ``u₁`` into ``u₂``, by the angle ``α``; a capsule is
symmetric about its axis, so a spin about the axis moves no point of the *shape*). A point
``p = a₁ + s (b₁ − a₁) + r w`` (``0 ≤ s ≤ 1``, ``|w| ≤ 1``) moves by
``(1 − s)(a₂ − a₁) + s (b₂ − b₁) + r (R w − w)``. The first two terms are the motion of
the axis point, linear in ``s`` (its norm is convex, so largest at an end point); the last
is at most ``r · 2 sin(α/2) = r · |u₂ − u₁|`` (a rotation by ``α`` moves a unit vector by at
most the chord ``2 sin(α/2)``, reached in the plane of ``u₁`` and ``u₂``). So

    deviation(link) ≤ max(|a₂ − a₁|, |b₂ − b₁|) + r · |u₂ − u₁|

and :func:`geometry_deviation_m` returns that bound, maximised over links. It is exact for a
translation, and over-estimates a rotation by at most ``r · |u₂ − u₁|`` (for Arm-Z, r =
0.75 m: 0.75 mm per milliradian the module's axis turns). Since every point of the
executed shape lies within the deviation of the commanded shape, the simulated clearance
is never below the commanded clearance minus the deviation (minus twice the deviation
between two links): a plan that keeps a margin larger than the deviation executes
without contact.

**Clearance sampling.** One closest-point query of the 24-module Arm-Z (scene and every
link pair) takes 1-5 ms, a physics step about 0.4 ms, so the clearance is not read at
every step. A query at a sampled state gives each link's distance to the scene ``s_l``
and each pair's distance ``d_lm``. At a later state, where link ``l`` has moved by at
most ``δ_l`` (the bound above, per link, against the sampled state), the link is at least
``s_l − δ_l`` from the scene and the pair at least ``d_lm − δ_l − δ_m`` apart.
:func:`sampled_clearance` takes the next sample at the first state where that lower
bound falls below ``c − max(resolution_m, c / 8)``, ``c`` the sampled state's smallest
clearance (and always the last state). So every state between two samples has a
clearance of at least ``c − max(resolution_m, c / 8)``: no state closer than
``resolution_m`` to a collision is missed, the reported smallest clearance is within
``resolution_m`` of the true one below ``8 · resolution_m`` (above that, within 1/7 of
it), and links that move little near an obstacle (Arm-Z's first module, 5 cm above the
ground all the time) cost nothing while the far links swing. On the paper's task this is
27-223 queries per leg of 5 000-12 000 physics steps; on a leg of 12 248 states, querying
every second state found a smallest clearance of 31.32 mm, the sampling 31.54 mm with 54
queries. Pairs are read up to ``max_distance_m``; a pair farther apart counts as that
far.

Pairs: every link not in ``robot.fixed_links`` against every obstacle, and every pair of
links not in ``robot.excluded_pairs`` (the pairs the collision checker checks).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, Robot

#: states per batch of forward kinematics (bounds the memory of long executions)
_CHUNK = 2048
#: clearance resolution [m]: see the module docstring
CLEARANCE_RESOLUTION_M: float = 1e-3
#: closest points are read up to this distance [m]
CLEARANCE_MAX_DISTANCE_M: float = 1.0


def _segments_axes(robot: Robot, q: Array) -> tuple[Array, Array]:
    """Capsule end points (k, L, 2, 3) and unit axes (k, L, 3) (zero for a sphere) of the
    states q (k, dof), forward kinematics in batches of :data:`_CHUNK`."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    parts = [
        np.asarray(robot.link_segments(q[i : i + _CHUNK]), dtype=float).reshape(
            len(q[i : i + _CHUNK]), -1, 2, 3
        )
        for i in range(0, len(q), _CHUNK)
    ]
    seg = np.concatenate(parts) if parts else np.zeros((0, len(robot.link_radii_m), 2, 3))
    axis = seg[:, :, 1] - seg[:, :, 0]
    length = np.linalg.norm(axis, axis=-1, keepdims=True)
    unit = np.divide(axis, length, out=np.zeros_like(axis), where=length > 1e-12)
    return seg, unit


def _link_deviation(robot: Robot, seg_a: Array, u_a: Array, seg_b: Array, u_b: Array) -> Array:
    """(k, L): the bound of the module docstring per link."""
    ends = np.max(np.linalg.norm(seg_a - seg_b, axis=-1), axis=-1)  # (k, L)
    turn = np.linalg.norm(u_a - u_b, axis=-1) * np.asarray(robot.link_radii_m, dtype=float)
    out: Array = ends + turn
    return out


def _deviation(robot: Robot, seg_a: Array, u_a: Array, seg_b: Array, u_b: Array) -> Array:
    out: Array = np.max(_link_deviation(robot, seg_a, u_a, seg_b, u_b), axis=-1, initial=0.0)
    return out


def geometry_deviation_m(robot: Robot, q_a: Array, q_b: Array) -> Array:
    """Largest displacement of any point of the robot's collision capsules between the
    states ``q_a`` and ``q_b``, max over links (the bound of the module docstring) [m].

    Args:
        robot: the robot model (its ``link_segments`` and ``link_radii_m``).
        q_a, q_b: (k, dof) or (dof,) states, paired row by row (one may be a single state).

    Returns:
        (k,) deviations [m] (a float array of one element for two single states).
    """
    a = np.atleast_2d(np.asarray(q_a, dtype=float))
    b = np.atleast_2d(np.asarray(q_b, dtype=float))
    if a.shape[1] != robot.dof or b.shape[1] != robot.dof:
        raise PlannerlabError(f"states must have {robot.dof} joints, got {a.shape}, {b.shape}")
    k = max(len(a), len(b))
    if len(a) not in (1, k) or len(b) not in (1, k):
        raise PlannerlabError(f"{len(a)} and {len(b)} states cannot be paired")
    a = np.broadcast_to(a, (k, robot.dof))
    b = np.broadcast_to(b, (k, robot.dof))
    out = np.empty(k)
    for i in range(0, k, _CHUNK):
        sa, ua = _segments_axes(robot, a[i : i + _CHUNK])
        sb, ub = _segments_axes(robot, b[i : i + _CHUNK])
        out[i : i + _CHUNK] = _deviation(robot, sa, ua, sb, ub)
    return out


def plan_deviation(
    robot: Robot,
    states: Array,
    commanded: Array,
    t_s: Array,
    dt_s: float,
    *,
    q_plan: Array | None,
    settle_steps: int,
    window_steps: int,
) -> tuple[Array, float, float]:
    """The deviation of an execution's collision geometry from the PLAN: (per log sample
    at ``t_s`` the largest since the previous sample; the largest [m]; its time [s]).

    ``states`` (n, dof) are every physics step's simulated states, ``commanded`` the states
    commanded for them. A retimed trajectory (``q_plan``: the planned polyline's state at
    the reference's path parameter of each moving step) is measured at every step against
    the plan (so it holds the reference's own distance from the plan and the tracking),
    the settling steps against their command. With waypoints (``q_plan`` None) the
    commands are the densified plan itself and the arm moves towards each waypoint over
    its window of ``window_steps``, so it is measured where it should have arrived (the
    window's last step), and at every settling step.
    """
    targets = commanded
    if q_plan is not None:
        targets = np.vstack([q_plan, targets[len(q_plan) :]])
        judged = np.arange(len(states))
    else:
        n_moving = len(states) - settle_steps
        judged = np.concatenate(
            [
                np.arange(window_steps - 1, n_moving, window_steps),
                np.arange(n_moving, len(states)),
            ]
        ).astype(int)
    dev_steps = geometry_deviation_m(robot, targets[judged], states[judged])
    worst_dev = int(np.argmax(dev_steps)) if len(dev_steps) else 0
    max_dev = float(dev_steps[worst_dev]) if len(dev_steps) else 0.0
    max_dev_t = float((judged[worst_dev] + 1) * dt_s) if len(dev_steps) else 0.0
    # per log sample: the largest deviation since the previous sample (settling excluded)
    step_of_sample = np.rint(t_s / dt_s).astype(int) - 1
    dev_full = np.zeros(len(states))
    dev_full[judged] = dev_steps
    bounds = np.concatenate([[0], step_of_sample[:-1] + 1]) if len(t_s) else np.zeros(0, int)
    deviation = np.maximum.reduceat(dev_full, bounds) if len(t_s) else np.zeros(0)
    return deviation, max_dev, max_dev_t


@dataclass(frozen=True)
class Clearance:
    """The smallest clearance met along a sequence of states.

    Attributes:
        clearance_m: smallest closest-point distance over the samples [m] (negative:
            penetration); ``max_distance_m`` when no pair came that close.
        index: the state (row of the sequence) where it was met.
        pair: (robot link, obstacle or other link) names of that closest pair (None when
            nothing came within ``max_distance_m``).
        self_pair: True when ``pair`` is two links.
        samples: how many states were queried.
        resolution_m: the sampling resolution (module docstring).
        max_distance_m: pairs were read up to this distance [m].
    """

    clearance_m: float
    index: int
    pair: tuple[str, str] | None
    self_pair: bool
    samples: int
    resolution_m: float
    max_distance_m: float


class ClosestPoints(Protocol):
    """What :func:`sampled_clearance` queries: a probe world
    (:class:`plannerlab.sim.world.SimWorld`: ``set_state`` and ``link_distances``)."""

    def set_state(self, q_rad: Array) -> None: ...

    def link_distances(
        self, max_distance_m: float, starts: Array | None = None
    ) -> tuple[Array, list[str], Array]: ...


def _link_groups(robot: Robot) -> tuple[np.ndarray, list[str]] | None:
    """For a robot whose links are covers of meshes (a URDF robot with ``mesh_covers``):
    where each URDF link's run of capsules starts, and the URDF link names; None for the
    other robots (every capsule its own link)."""
    if not getattr(robot, "mesh_covers", ()) and getattr(robot, "sim_urdf_path", None) is None:
        return None
    urdf = list(robot.link_urdf_names)  # type: ignore[attr-defined]
    starts = [0] + [i for i in range(1, len(urdf)) if urdf[i] != urdf[i - 1]]
    names = [urdf[i] for i in starts]
    if len(set(names)) != len(names):  # pragma: no cover - UrdfChain keeps runs together
        raise PlannerlabError("a URDF link's capsules are not consecutive")
    return np.array(starts), names


def sampled_clearance(
    robot: Robot,
    probe: ClosestPoints,
    states: Array,
    *,
    resolution_m: float = CLEARANCE_RESOLUTION_M,
    max_distance_m: float = CLEARANCE_MAX_DISTANCE_M,
    always: Iterable[int] = (),
) -> Clearance:
    """Smallest simulated clearance along ``states`` (k, dof), sampled as the module
    docstring says (the first and last states, and those in ``always``, are sampled).

    Args:
        robot: the robot model.
        probe: a world to query (its state is overwritten).
        states: (k, dof) states in order (every physics step of an execution).
        resolution_m: sampling resolution [m] (> 0).
        max_distance_m: pairs are read up to this distance [m] (> resolution_m).
        always: indices that are sampled in any case.
    """
    q = np.atleast_2d(np.asarray(states, dtype=float))
    if not (resolution_m > 0 and max_distance_m > resolution_m):
        raise PlannerlabError(
            f"need 0 < resolution_m < max_distance_m, got {resolution_m}, {max_distance_m}"
        )
    k = len(q)
    forced = sorted({int(i) for i in always if 0 <= int(i) < k} | {k - 1})
    if getattr(robot, "sim_urdf_path", None) is not None:
        # PyBullet holds another geometry than the capsules (a sim_urdf): how far they
        # moved bounds nothing of it, so every state is queried
        forced = list(range(k))
    seg, unit = _segments_axes(robot, q)
    names = list(robot.link_names)
    # A mesh robot: PyBullet measures each URDF link's meshes once (reported on its first
    # capsule); its distance and how far it can have moved (the most any of its covering
    # capsules moved: the mesh lies inside them) are taken per URDF link.
    groups = _link_groups(robot)
    if groups is not None:
        starts, names = groups
    best: tuple[float, int, tuple[str, str] | None, bool] = (math.inf, 0, None, False)
    samples = 0
    i = 0
    next_forced = 0
    while True:
        probe.set_state(q[i])
        # distances beyond the smallest clearance found so far (plus the resolution) can
        # neither lower it nor bring the next sample nearer by more than they hold when
        # capped there: PyBullet computes only the pairs within reach (a mesh robot's
        # meshes against a triangle-mesh obstacle within 1 m cost 0.1 s a query)
        reach = min(max_distance_m, best[0] + 2.0 * resolution_m + 0.5 * abs(best[0]))
        # a mesh robot's distances come per URDF link (its run of capsules)
        scene, obstacle, pair = probe.link_distances(reach, starts if groups is not None else None)
        samples += 1
        l_scene = int(np.argmin(scene))
        l_a, l_b = np.unravel_index(int(np.argmin(pair)), pair.shape)
        c = float(min(scene[l_scene], pair[l_a, l_b], max_distance_m))
        if c < best[0]:
            if c >= max_distance_m:
                best = (c, i, None, False)
            elif scene[l_scene] <= pair[l_a, l_b]:
                best = (c, i, (names[l_scene], obstacle[l_scene]), False)
            else:
                best = (c, i, (names[min(l_a, l_b)], names[max(l_a, l_b)]), True)
        if i >= k - 1:
            break
        while forced[next_forced] <= i:
            next_forced += 1
        stop = forced[next_forced]
        floor = c - max(resolution_m, c / 8.0)
        j = stop
        lo = i + 1
        size = 4  # chunks double: the next sample is often a few steps on
        while lo < stop:
            hi = min(stop, lo + size)
            size = min(2 * size, 128)
            moved = _link_deviation(robot, seg[lo:hi], unit[lo:hi], seg[i][None], unit[i][None])
            if groups is not None:
                moved = np.maximum.reduceat(moved, starts, axis=1)
            lower = np.minimum(
                np.min(scene[None, :] - moved, axis=1),
                np.min(pair[None] - moved[:, :, None] - moved[:, None, :], axis=(1, 2)),
            )
            under = np.flatnonzero(lower < floor)
            if len(under):
                j = lo + int(under[0])
                break
            lo = hi
        i = j
    return Clearance(
        clearance_m=float(best[0]),
        index=int(best[1]),
        pair=best[2],
        self_pair=best[3],
        samples=samples,
        resolution_m=float(resolution_m),
        max_distance_m=float(max_distance_m),
    )


def geometry_notes(problem: Any) -> dict[str, str]:
    """Which geometry each figure of an execution is measured on (the record's
    ``geometry``): the re-check on the planning model; contacts and clearance on what
    PyBullet loads: the robot's URDF as it is (its collision meshes when it has any:
    the real geometry, not the covers planned with) and the scene's mesh obstacles as
    triangles; the deviation on the planning model's capsules."""
    robot = problem.robot
    covers = getattr(robot, "mesh_covers", ())
    meshes = problem.scene.meshes
    scene_note = (
        f"; mesh obstacles {', '.join(m.name for m in meshes)} as their triangles" if meshes else ""
    )
    sim_urdf = getattr(robot, "sim_urdf_path", None)
    if sim_urdf is not None:
        plan = "planning model: the robot's capsules" + (
            f" and sphere covers of {len(covers)} meshes" if covers else ""
        )
        sim = f"real meshes: the collision geometry of {Path(sim_urdf).name} (sim_urdf){scene_note}"
    elif covers:
        excess = max(c.max_excess_m for c in covers)
        plan = (
            f"planning model: {len(covers)} collision meshes as sphere covers "
            f"(outward excess <= {excess * 1e3:.3g} mm)"
        )
        sim = f"real meshes: the URDF's {len(covers)} collision meshes{scene_note}"
    else:
        plan = "planning model: the robot's capsules"
        sim = f"planning model: the robot's URDF as planned with{scene_note}"
    recheck_scene = "; mesh obstacles as their cover boxes" if meshes else ""
    return {
        "recheck": plan + recheck_scene,
        "contacts": sim,
        "min_clearance_m": sim,
        "max_deviation_m": "planning model: the robot's capsules (axis end points and radii)",
    }


__all__ = [
    "geometry_notes",
    "CLEARANCE_MAX_DISTANCE_M",
    "CLEARANCE_RESOLUTION_M",
    "Clearance",
    "ClosestPoints",
    "geometry_deviation_m",
    "plan_deviation",
    "sampled_clearance",
]

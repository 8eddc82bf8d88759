"""Time-parameterisation of joint paths with toppra, under velocity and torque limits.

A planner's path is a polyline in joint space without time. :func:`retime` turns it into
a trajectory q(t), q̇(t) that a position+velocity controlled arm can follow: a
shape-preserving cubic (PCHIP) through knots laid along the polyline, that stays within a
known distance of the plan (below), time-parameterised by TOPP-RA
(``toppra``, Pham & Pham 2018) so that every joint stays within

* its **velocity limit** (the URDF's ``velocity``; Arm-Z 10 rad/s), and
* a **torque budget** ``|τ_i(q, q̇, q̈) − g_i(q)| ≤ torque_fraction × (effort_i −
  |g_i(q)|)``: of the torque left after holding the pose against gravity g(q), the
  trajectory may use a fraction. τ is the
  inverse dynamics of the robot's URDF (masses, inertias, the world's gravity; Arm-Z:
  1 kg modules of inertia diag(0.25, 0.25, 0.5) kg·m², 100 N·m motors) evaluated along
  the path. This is the principled bound from the torque limit and the module inertia.
  A constant acceleration bound would have to take the worst pose: the inertia the
  first joint of the 24-module arm carries, M₁₁(q), is 90 kg·m² for the straight column
  (all θ = π) but ranges from 27 to 1 567 kg·m² over 1 000 uniformly random poses
  (median 618), i.e. 100 N·m buys between 0.06 and 3.7 rad/s²; a constant bound is
  either unsafe or needlessly slow, the configuration-dependent torque bound is
  neither.

Decisions:

* **Half the torque** (:data:`TORQUE_FRACTION` = 0.5) left after gravity goes to the
  trajectory, half is kept for the feedback that corrects tracking errors (the motors
  saturate at the URDF effort). Without gravity (the bundled Arm-Z problems) this is
  |τ| ≤ 0.5 × effort. A pose whose gravity torque exceeds the effort cannot be held at
  all: :func:`retime` raises, and the execution says so.
* **The interpolant and its distance from the plan (issue 17).** The reference was a
  natural cubic spline through knots every ``knot_step`` (0.005 rad) along the polyline.
  A gradient path turns at every waypoint, and a natural spline rings round each corner
  (its curvature is global): measured against the plan's state at the same path
  parameter, the reference's geometry strayed 12-44 mm from the plan on every leg of
  room variant v12 and 15-47 mm on the paper's task (``gradient.clearance+detour``, seed
  0), while the execution reported "deviation 0 mm" (the arm followed the *reference*
  exactly). Now the interpolant is scipy's :class:`~scipy.interpolate.PchipInterpolator`
  (Fritsch-Carlson monotone cubic Hermite, per joint, in the robot's coordinates; the
  path handed to TOPP-RA is its image under the robot's affine ``to_urdf``), through
  :func:`corner_knots`: every waypoint, a knot :data:`CORNER_M` (in metres of geometry
  motion, ``Σ |Δq_i| · reach_i`` with :func:`~plannerlab.collision.reach.joint_reach_m`)
  from each end of every edge, and knots every ``knot_step`` in between (the TOPP-RA
  grid).

  **The bound.** On a knot interval PCHIP is monotone per joint with end slopes in
  [0, 3] x the interval's secant, so each joint strays from the chord at the same path
  parameter by at most max over τ of τ(1 − τ)(2 − τ) = 2 / (3√3) = 0.385
  (:data:`PCHIP_BOUND`) of its change over the interval; the chord is the plan (the knots
  lie on it). So no point of the reference's geometry is further than ``0.385 × Σ_i
  |Δq_i| reach_i`` from the plan's at the same parameter. An interval that touches a
  waypoint spans at most ``CORNER_M`` of geometry motion; on every other interval both
  end knots have their neighbours on the same straight edge, the slopes equal the secant
  and PCHIP *is* the chord (zero deviation). Hence ``Trajectory.bound_m = 0.385 ×
  CORNER_M`` = 7.7 mm, whatever the path; the execution measures the real distance at
  every physics step (``reference_deviation_m``: at most 1.5-2.1 mm per problem on the
  paper's task and its 20 room variants) and counts it in the deviation the verdict
  judges.

  **What it costs, and the alternatives measured** (v12 leg C, 604 waypoints; reference's
  largest distance from the plan / TOPP-RA duration; ``/tmp``-scripts, one process):
  natural spline, knots every 0.005 rad (before): 43.7 mm / 37.0 s; PCHIP with corner
  knots at 2 mm: 0.12 mm / 98.8 s, 5 mm: 0.30 / 86.3, 10 mm: 0.61 / 77.8, 30 mm:
  1.82 / 65.5, 100 mm: 4.5 / 55.9, none (waypoints and ``knot_step`` only): 18.7 / 51.3;
  natural spline through the corner knots (5 mm): 14.6 / 74.2; natural spline with knots
  every 2 cm (metres): 2.2 / 58.0 (21 s to retime), every 5 cm: 5.5 / 49.5. A faithful
  reference is slower because the plan's corners must really be turned, under the same
  torque budget (the duration is torque-bound: the whole budget, 1.0 instead of 0.5 of
  the effort, took leg E from 41.4 to 29.2 s; the grid is not what binds, 8 points per
  knot: 40.6 s). :data:`CORNER_M` = 2 cm is a middle: the a-priori bound stays under the
  1-cm deviation limit (measured 1.4-2.0 mm on the paper's task), and the seven legs of
  the paper's task take 473 s of simulated time instead of the spline's 224 s, 2.1 x
  (see :mod:`plannerlab.sim.execute` for the wall time).
  ``interpolant="spline"`` keeps the old reference for comparison.
  :attr:`Trajectory.max_dev` reports the interpolant's max-norm distance from the
  polyline at the knot-interval midpoints [rad].
* **The grid.** TOPP-RA enforces the budget at its grid points only. With the knots
  as the grid, the spline bending round the path's corners between two knots asked for
  up to 1.33 x (leg D of the paper's task) and 1.66 x (leg E) the *effort limit*, with
  the budget at 0.5 x: the motors saturated and the arm strayed (see
  :mod:`plannerlab.sim.execute`). :data:`GRID_PER_KNOT` = 4 grid points per knot
  interval keep the peak at 0.59-0.66 x the effort on the legs measured (A, D, E), and
  the trajectories come out shorter (leg D 51 s -> 19 s; 2 points: 21 s but peaks of
  0.82-0.90 x), at 4 x the inverse-dynamics calls (0.2-0.8 s per leg of the paper's
  task). The reference between grid points can still exceed the budget a little; the
  motors' other half absorbs it, and the execution's deviation is what the verdict
  judges.

Inputs are plain arrays and a callable; this module imports neither PyBullet nor any
other engine (the simulator provides the inverse dynamics).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, joint_difference
from plannerlab.robots.paths import densify

#: share of each joint's effort limit the trajectory may use; the rest is feedback headroom
TORQUE_FRACTION: float = 0.5
#: TOPP-RA grid points per knot interval (see the module docstring)
GRID_PER_KNOT: int = 4
#: the reference's interpolant: "pchip" (shape-preserving, local) or "spline" (natural
#: cubic spline, rings round corners; kept for comparison)
INTERPOLANT: str = "pchip"
#: corner knots are laid this far from every waypoint, in metres of geometry motion
CORNER_M: float = 0.02
#: a monotone cubic Hermite piece with end slopes in [0, 3] x its secant strays from its
#: chord by at most 2 / (3 √3) of the chord's span (see the module docstring)
PCHIP_BOUND: float = 2.0 / (3.0 * math.sqrt(3.0))

InverseDynamics = Callable[[Array, Array, Array], Array]


def unwrap_path(path: Array, continuous: Array, q_from: Array | None = None) -> Array:
    """A path (m, dof) whose continuous joints never jump by 2π: each state is the previous
    one plus the short-way joint difference. The first state is ``path[0]``, or its
    equivalent nearest to ``q_from`` when given (so a trajectory can continue from where
    a simulated arm really is)."""
    path = np.atleast_2d(np.asarray(path, dtype=float))
    cont = np.asarray(continuous, dtype=bool)
    first = path[0].copy()
    if q_from is not None:
        q_from = np.asarray(q_from, dtype=float)
        first = np.where(cont, q_from + joint_difference(path[0], q_from, cont), path[0])
    steps = joint_difference(path[1:], path[:-1], cont)
    return np.vstack([first[None, :], first[None, :] + np.cumsum(steps, axis=0)])


def _knots(path: Array, knot_step: float) -> Array:
    """Densify a (non-wrapping) polyline to ``knot_step`` and merge near-duplicate knots
    (the natural cubic spline's knots, :data:`INTERPOLANT` = "spline")."""
    dense, _ = densify(path, knot_step, np.zeros(path.shape[1], dtype=bool))
    keep = [0]
    min_gap = knot_step / 4.0
    for i in range(1, len(dense)):
        if np.max(np.abs(dense[i] - dense[keep[-1]])) >= min_gap:
            keep.append(i)
    last = len(dense) - 1
    if keep[-1] != last:
        if len(keep) > 1 and np.max(np.abs(dense[last] - dense[keep[-1]])) < min_gap:
            keep[-1] = last  # the end state is kept exactly
        else:
            keep.append(last)
    return dense[keep]


def corner_knots(path: Array, knot_step: float, reach_m: Array, corner_m: float) -> Array:
    """The knots of the shape-preserving reference (see the module docstring): every
    waypoint of the polyline; on every edge, a knot ``corner_m`` (in metres of geometry
    motion, ``Σ |Δq_i| · reach_m[i]``) from each end (the edge's midpoint when it is
    shorter than ``2 corner_m``); and knots every ``knot_step`` per joint in between.
    Consecutive duplicate states are dropped. So every knot interval that touches a
    waypoint moves the geometry by at most ``corner_m``, and every other interval lies
    inside one straight edge, between knots whose neighbours are on that edge too."""
    path = np.atleast_2d(np.asarray(path, dtype=float))
    d = np.diff(path, axis=0)
    moving = np.max(np.abs(d), axis=1, initial=0.0) > 0.0
    path = np.concatenate([path[:1], path[1:][moving]])
    if len(path) < 2:
        return path
    d = np.diff(path, axis=0)
    metric = np.abs(d) @ np.asarray(reach_m, dtype=float)
    rows = [path[:1]]
    for a, de, m in zip(path[:-1], d, metric, strict=True):
        n = max(1, int(np.ceil(np.max(np.abs(de)) / knot_step - 1e-12)))
        f = np.arange(1, n) / n
        c = corner_m / m if m > 0 else 0.5
        ends = [0.5] if c >= 0.5 else [c, 1.0 - c]
        f = np.concatenate([f[(f > ends[0]) & (f < ends[-1])], ends, [1.0]])
        f = np.unique(f)
        rows.append(a + f[:, None] * de)
    return np.concatenate(rows)


class _LinearPath:
    """A geometric path for toppra: ``to_urdf`` (affine) of a piecewise polynomial in the
    robot's coordinates, with its first and second derivatives."""

    def __init__(self, pp: object, ss: Array, to_urdf: Callable[[Array], Array]) -> None:
        self._pp = pp
        self._d1 = pp.derivative(1)  # type: ignore[attr-defined]
        self._d2 = pp.derivative(2)  # type: ignore[attr-defined]
        self._ss = ss
        self._to_urdf = to_urdf
        dof = int(np.shape(pp(ss[:1]))[-1])  # type: ignore[operator]
        self._zero: Array = np.asarray(to_urdf(np.zeros(dof)), dtype=np.float64)

    @property
    def dof(self) -> int:
        return int(len(self._zero))

    @property
    def path_interval(self) -> Array:
        return np.array([self._ss[0], self._ss[-1]])

    @property
    def waypoints(self) -> None:
        return None

    def __call__(self, s: Array | float, order: int = 0) -> Array:
        f = (self._pp, self._d1, self._d2)[order]
        q: Array = np.asarray(f(s), dtype=np.float64)  # type: ignore[operator]
        out: Array = np.asarray(self._to_urdf(q), dtype=np.float64)
        return out if order == 0 else out - self._zero

    def eval(self, s: Array | float) -> Array:
        return self(s, 0)

    def evald(self, s: Array | float) -> Array:
        return self(s, 1)

    def evaldd(self, s: Array | float) -> Array:
        return self(s, 2)


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A time-parameterised joint path q(s(t)).

    Attributes:
        duration_s: length of the trajectory in time [s].
        knots: (K, dof) the interpolant's knots in the robot's coordinates (K = 1: a
            trajectory that stays put); they lie on the planned polyline.
        max_dev: largest max-norm distance between the interpolant and the polyline
            through the knots, sampled at the knot-interval midpoints [rad or m].
        gridpoints: number of TOPP-RA grid points.
        interpolant: "pchip" or "spline" (see the module docstring).
        bound_m: for "pchip" with the robot's reach given, the a-priori bound of how far
            any point of the reference's geometry is from the plan's at the same path
            parameter [m] (:data:`PCHIP_BOUND` × ``corner_m``); NaN otherwise.
    """

    duration_s: float
    knots: Array
    max_dev: float
    gridpoints: int
    interpolant: str = "pchip"
    bound_m: float = math.nan
    _path: object | None = None
    _ss: Array | None = None
    _grid: Array | None = None
    _sd: Array | None = None
    _to_urdf: Callable[[Array], Array] | None = None

    def _s(self, t_s: Array) -> tuple[Array, Array]:
        """Path parameter s and its rate ṡ at times ``t_s`` (TOPP-RA's constant
        acceleration between grid points, as ``toppra.ParametrizeConstAccel``)."""
        assert self._grid is not None and self._sd is not None
        grid, sd = self._grid, self._sd
        dt_grid = 2.0 * np.diff(grid) / (sd[:-1] + sd[1:])
        ts = np.concatenate([[0.0], np.cumsum(dt_grid)])
        us = 0.5 * (sd[1:] ** 2 - sd[:-1] ** 2) / np.diff(grid)
        i = np.clip(np.searchsorted(ts, t_s, side="right") - 1, 0, len(us) - 1)
        dt = t_s - ts[i]
        s = grid[i] + dt * sd[i] + 0.5 * dt**2 * us[i]
        return np.clip(s, grid[0], grid[-1]), sd[i] + dt * us[i]

    def sample(self, t_s: Array) -> tuple[Array, Array]:
        """Positions and velocities at times ``t_s`` (n,), in the coordinates the
        inverse dynamics takes (the URDF's): two (n, dof) arrays; times are clipped to
        [0, duration]."""
        t = np.clip(np.atleast_1d(np.asarray(t_s, dtype=float)), 0.0, self.duration_s)
        to_urdf = self._to_urdf or (lambda q: q)
        if self._path is None:
            q = np.asarray(to_urdf(np.repeat(self.knots[-1:], len(t), axis=0)), dtype=float)
            return q, np.zeros_like(q)
        s, sd = self._s(t)
        path = self._path
        q_t = np.asarray(path(s), dtype=np.float64).reshape(len(t), -1)  # type: ignore[operator]
        qs = np.asarray(path(s, 1), dtype=np.float64).reshape(len(t), -1)  # type: ignore[operator]
        return q_t, qs * sd[:, None]

    def plan_states(self, t_s: Array) -> Array:
        """The planned polyline's states (the robot's coordinates) at the reference's path
        parameter at times ``t_s`` (n,): (n, dof). The reference's distance to the plan
        is measured against these."""
        t = np.clip(np.atleast_1d(np.asarray(t_s, dtype=float)), 0.0, self.duration_s)
        if self._path is None or self._ss is None:
            return np.repeat(self.knots[-1:], len(t), axis=0)
        s, _ = self._s(t)
        k = np.clip(np.searchsorted(self._ss, s, side="right") - 1, 0, len(self._ss) - 2)
        f = (s - self._ss[k]) / (self._ss[k + 1] - self._ss[k])
        out: Array = self.knots[k] + f[:, None] * (self.knots[k + 1] - self.knots[k])
        return out


def retime(
    path: Array,
    *,
    velocity_limit: Array,
    effort_limit: Array,
    inverse_dynamics: InverseDynamics,
    knot_step: float,
    torque_fraction: float = TORQUE_FRACTION,
    grid_per_knot: int = GRID_PER_KNOT,
    reach_m: Array | None = None,
    corner_m: float = CORNER_M,
    to_urdf: Callable[[Array], Array] | None = None,
    interpolant: str = INTERPOLANT,
) -> Trajectory:
    """Time-optimal trajectory along a joint path under velocity and torque limits.

    Args:
        path: (m, dof) states in the robot's coordinates (``to_urdf`` maps them to the
            coordinates ``inverse_dynamics`` takes), already unwrapped (see
            :func:`unwrap_path`): consecutive states are joined by straight segments.
        velocity_limit: (dof,) largest |q̇| per joint [rad/s or m/s] (URDF coordinates).
        effort_limit: (dof,) motor torque/force limit per joint [N·m or N].
        inverse_dynamics: ``(q, q̇, q̈) -> τ`` (dof,) for the robot (URDF coordinates).
        knot_step: largest per-joint distance between knots [rad or m].
        torque_fraction: share of ``effort_limit`` the trajectory may use.
        grid_per_knot: TOPP-RA grid points per knot interval (>= 1): the constraints
            hold at the knots and at ``grid_per_knot - 1`` points evenly between them.
        reach_m: (dof,) how fast the geometry moves per joint
            (:func:`~plannerlab.collision.reach.joint_reach_m`) [m per rad or m]; with
            "pchip", the corner knots are laid ``corner_m`` from every waypoint in these
            metres (None: 1 m per unit, i.e. ``corner_m`` in joint units, and no bound).
        corner_m: see ``reach_m`` and :func:`corner_knots` [m].
        to_urdf: the robot's coordinates -> the URDF's, affine (None: the identity).
        interpolant: "pchip" (default) or "spline" (the natural cubic spline through knots
            every ``knot_step``, as before; kept for comparison).

    Returns:
        the :class:`Trajectory`, starting and ending at rest.

    Raises:
        PlannerlabError: bad limits, or TOPP-RA finds no feasible parameterisation (for
            instance a pose whose static gravity torque exceeds the budget).
    """
    import toppra.algorithm as algo
    import toppra.constraint as constraint
    from scipy.interpolate import CubicSpline, PchipInterpolator

    logging.getLogger("toppra").setLevel(logging.WARNING)
    path = np.atleast_2d(np.asarray(path, dtype=float))
    dof = path.shape[1]
    convert: Callable[[Array], Array] = to_urdf if to_urdf is not None else (lambda q: q)
    v = np.broadcast_to(np.asarray(velocity_limit, dtype=float), (dof,))
    tau = np.broadcast_to(np.asarray(effort_limit, dtype=float), (dof,))
    if not 0.0 < torque_fraction <= 1.0:
        raise PlannerlabError(f"torque_fraction must be in (0, 1], got {torque_fraction}")
    if not (np.all(v > 0) and np.all(np.isfinite(v))):
        raise PlannerlabError(f"velocity limits must be positive and finite, got {v}")
    if not (np.all(tau > 0) and np.all(np.isfinite(tau))):
        raise PlannerlabError(f"effort limits must be positive and finite, got {tau}")
    if not knot_step > 0:
        raise PlannerlabError(f"knot_step must be positive, got {knot_step}")
    if not corner_m > 0:
        raise PlannerlabError(f"corner_m must be positive, got {corner_m}")
    if int(grid_per_knot) != grid_per_knot or grid_per_knot < 1:
        raise PlannerlabError(f"grid_per_knot must be an integer >= 1, got {grid_per_knot}")
    if interpolant not in ("pchip", "spline"):
        raise PlannerlabError(f"interpolant: 'pchip' or 'spline', got {interpolant!r}")
    bound = math.nan
    if interpolant == "pchip":
        reach = np.ones(dof) if reach_m is None else np.asarray(reach_m, dtype=float)
        knots = corner_knots(path, float(knot_step), reach, float(corner_m))
        if reach_m is not None:
            bound = PCHIP_BOUND * float(corner_m)
    else:
        knots = _knots(path, float(knot_step))
    if len(knots) < 2:
        return Trajectory(0.0, knots[-1:], 0.0, 0, interpolant, bound, _to_urdf=to_urdf)
    ss = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(knots, axis=0), axis=1))])
    ss /= ss[-1]
    pp = (
        PchipInterpolator(ss, knots, axis=0)
        if interpolant == "pchip"
        else CubicSpline(ss, knots, axis=0, bc_type="natural")
    )
    geometric = _LinearPath(pp, ss, convert)
    mid = 0.5 * (ss[1:] + ss[:-1])
    max_dev = float(np.max(np.abs(pp(mid) - 0.5 * (knots[1:] + knots[:-1]))))

    # The budget: of the torque left after holding the pose against gravity, g(q), the
    # trajectory may use ``torque_fraction``: |τ − g(q)| ≤ f·(effort − |g(q)|). Dividing
    # by the per-pose headroom keeps the constraint affine in (s̈, ṡ²) at every s.
    zeros = np.zeros(dof)
    effort = np.broadcast_to(np.asarray(effort_limit, dtype=float), (dof,))
    held: dict[bytes, tuple[Array, Array]] = {}

    def gravity_and_room(q: Array) -> tuple[Array, Array]:
        key = np.asarray(q, dtype=float).tobytes()
        if key not in held:
            g = np.asarray(inverse_dynamics(q, zeros, zeros), dtype=float)
            room = effort - np.abs(g)
            if np.any(room <= 1e-9 * effort):
                j = int(np.argmin(room / effort))
                raise PlannerlabError(
                    f"a pose on the path needs {abs(g[j]):.3g} N·m (or N) at joint {j} to "
                    f"hold against gravity; the motor has {effort[j]:.3g}"
                )
            held[key] = (g, room)
        return held[key]

    def inv_dyn(q: Array, qd: Array, qdd: Array) -> Array:
        g, room = gravity_and_room(q)
        return (np.asarray(inverse_dynamics(q, qd, qdd), dtype=float) - g) / room

    class _TorqueConstraint(constraint.JointTorqueConstraint):
        """toppra's torque constraint, its parameters computed with three inverse
        dynamics calls a grid point instead of four: ``inv_dyn(q, 0, 0)`` is exactly 0
        here (the torque measured from gravity's), so toppra's ``c`` is left out; a, b
        come out bit-identical (x - 0.0 == x)."""

        def compute_constraint_params(self, path: Any, gridpoints: Array) -> Any:
            from toppra.constraint import canlinear_colloc_to_interpolate

            assert self.discretization_type == constraint.DiscretizationType.Interpolation
            n_dof = path.dof
            p = path.eval(gridpoints)
            ps = path.evald(gridpoints)
            pss = path.evaldd(gridpoints)
            a = np.array([inv_dyn(p_, zeros, ps_) for p_, ps_ in zip(p, ps, strict=True)])
            b = np.array([inv_dyn(p_, ps_, pss_) for p_, ps_, pss_ in zip(p, ps, pss, strict=True)])
            c = np.zeros_like(a)
            eye = np.eye(n_dof)
            F = np.concatenate([eye, -eye])
            g = np.concatenate([self.tau_lim[:, 1], -self.tau_lim[:, 0]])
            return canlinear_colloc_to_interpolate(
                a, b, c, F, g, None, None, gridpoints, identical=True
            )

    constraints = [
        constraint.JointVelocityConstraint(np.stack([-v, v], axis=1)),
        _TorqueConstraint(
            inv_dyn,
            np.tile([-float(torque_fraction), float(torque_fraction)], (dof, 1)),
            np.zeros(dof),
            discretization_scheme=constraint.DiscretizationType.Interpolation,
        ),
    ]
    grid = ss
    if grid_per_knot > 1:
        f = np.arange(grid_per_knot) / grid_per_knot
        grid = np.concatenate([(ss[:-1, None] + np.diff(ss)[:, None] * f).ravel(), ss[-1:]])
    instance = algo.TOPPRA(
        constraints, geometric, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    )
    traj = instance.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise PlannerlabError(
            "toppra found no time parameterisation within the velocity limits and "
            f"{torque_fraction:g} x the torque left after gravity"
        )
    data = instance.problem_data
    return Trajectory(
        float(traj.duration),
        knots,
        max_dev,
        len(grid),
        interpolant,
        bound,
        geometric,
        ss,
        np.asarray(data.gridpoints, dtype=float),
        np.asarray(data.sd_vec, dtype=float),
        to_urdf,
    )


__all__ = [
    "CORNER_M",
    "GRID_PER_KNOT",
    "INTERPOLANT",
    "PCHIP_BOUND",
    "TORQUE_FRACTION",
    "Trajectory",
    "corner_knots",
    "retime",
    "unwrap_path",
]

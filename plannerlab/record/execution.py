"""The record of one executed leg: :class:`Execution` and its :class:`ContactRecord` s.

:mod:`plannerlab.sim.execute` produces them, and
:func:`plannerlab.sim.continuum.execute_chord_arc` for a contact-permitting plan (the
continuum's); ``plannerlab execute`` and ``plannerlab continuum --execute --out`` write
them to an execution file beside the plan, and the trial store keeps them, through the
one codec (:mod:`plannerlab.record.codec`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.record.codec import read_float, to_data
from plannerlab.robots.base import Array, as_xyz


@dataclass(frozen=True)
class ContactRecord:
    """One (robot link, other) pair that was in contact during an execution.

    Attributes:
        link_name: robot link.
        other_name: obstacle name, or the other robot link when ``other_is_link``.
        other_is_link: True for self-contact.
        max_depth_m: largest penetration depth seen [m].
        first_time_s: simulated time the pair was first seen, from the leg's start [s].
        p_world_m: (3,) contact point at the largest depth, world frame [m].
        expected: the plan asked for this contact (a contact-permitting planner's
            collision point, or a guide it slides in; see
            :func:`plannerlab.sim.continuum.execute_chord_arc`, which keys its records
            by (link, other, expected), so one pair may appear once each way). False for
            every contact of an ordinary plan: any contact is a failure there.
        collision_point: index of the plan's nearest collision point on that obstacle at
            the deepest point (contact-permitting plans only; else None).
        distance_m: planar distance from ``p_world_m`` to that collision point [m]
            (None without one).
    """

    link_name: str
    other_name: str
    other_is_link: bool
    max_depth_m: float
    first_time_s: float
    p_world_m: tuple[float, float, float]
    expected: bool = False
    collision_point: int | None = None
    distance_m: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return to_data(
            {
                "link_name": self.link_name,
                "other_name": self.other_name,
                "other_is_link": self.other_is_link,
                "max_depth_m": self.max_depth_m,
                "first_time_s": self.first_time_s,
                "p_world_m": list(self.p_world_m),
                "expected": self.expected,
                "collision_point": self.collision_point,
                "distance_m": self.distance_m,
            }
        )

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ContactRecord:
        point = data.get("collision_point")
        dist = data.get("distance_m")
        return cls(
            link_name=str(data["link_name"]),
            other_name=str(data["other_name"]),
            other_is_link=bool(data["other_is_link"]),
            max_depth_m=read_float(data["max_depth_m"]),
            first_time_s=read_float(data["first_time_s"]),
            p_world_m=as_xyz(data["p_world_m"]),
            expected=bool(data.get("expected", False)),
            collision_point=None if point is None else int(point),
            distance_m=None if dist is None else float(dist),
        )


_ARRAY_FIELDS = (
    "t_s",
    "q_cmd_rad",
    "q_actual_rad",
    "track_err_rad",
    "tip_track_err_m",
    "deviation_m",
    "q_start_rad",
    "q_final_rad",
)
#: the per-waypoint log, left out of a trial store's copy
_LOG_FIELDS = (
    "t_s",
    "q_cmd_rad",
    "q_actual_rad",
    "track_err_rad",
    "tip_track_err_m",
    "deviation_m",
)
_FLOAT_FIELDS = (
    "final_pos_err_m",
    "final_angle_err_deg",
    "start_offset_rad",
    "final_track_err_rad",
    "final_tip_track_err_m",
    "duration_s",
    "spline_dev",
    "recheck_joint_step",
    "max_deviation_m",
    "reference_deviation_m",
    "max_deviation_time_s",
    "max_deviation_limit_m",
    "min_clearance_m",
    "min_clearance_time_s",
)


@dataclass(frozen=True, eq=False)
class Execution:
    """What happened when a path was executed in the simulator.

    Attributes:
        problem: problem name.
        leg: leg index, or None when the path was run without a goal.
        goal: the leg's goal name (or None).
        path_valid: the FCL re-check found no collision; None when no re-check was made
            (a contact-permitting plan, whose path touches obstacles by design: the
            planner classified its contacts, the simulator's are in ``contacts``).
        recheck_joint_step: re-check resolution [rad per joint] (NaN without a re-check).
        recheck_states: interpolated states the re-check looked at.
        recheck_first_invalid_edge: first path edge with a collision (or None).
        recheck_pairs: colliding (link, other) names at the first invalid state.
        waypoint_step: densification of the commanded path, or the spline's knot
            spacing for ``"toppra"`` [rad per joint].
        steps_per_waypoint: physics steps per commanded waypoint (``"waypoints"``
            timing) or per logged sample (``"toppra"``).
        settle_steps: physics steps holding the last waypoint.
        dt_s: physics step [s].
        contact_tol_m: penetration depth above which a contact counted [m].
        gravity_mps2: gravity of the world, world frame [m/s²].
        t_s: (M,) simulated time at which each waypoint's state was logged, from the
            leg's start [s].
        q_cmd_rad: (M, dof) commanded (densified) waypoints.
        q_actual_rad: (M, dof) state reached at the end of each waypoint's steps
            (PyBullet's raw, unwrapped joint values).
        track_err_rad: (M,) max over joints of the wrapped |q_cmd − q_actual| [rad];
            for ``"toppra"``, also the max over every physics step since the previous
            logged sample.
        tip_track_err_m: (M,) distance between commanded and actual tip [m].
        contacts: every (link, other) pair in contact, see :class:`ContactRecord`.
        q_start_rad: (dof,) the state the execution started from.
        carried_over: True when the start state was where the previous leg really
            ended (:func:`execute_legs`), not a reset to the path's first waypoint.
        start_offset_rad: max wrapped |q_start − path[0]| over joints [rad].
        q_final_rad: (dof,) state after settling.
        final_track_err_rad, final_tip_track_err_m: tracking errors after settling.
        final_pos_err_m, final_angle_err_deg: final tip errors against the leg's goal
            [m, deg] (NaN without a leg).
        goal_reached: final state inside the goal region (None without a leg).
        sim_time_s: simulated time of this execution (physics steps × dt) [s].
        wall_time_s: wall-clock time of this execution, re-check included [s].
        reason: why it succeeded or failed, in words.
        track_err_limit_rad: the problem's ``[simulation] max_track_err_rad`` [rad]: the
            verdict's joint tracking limit in records made before ``max_deviation_m``
            (see :attr:`followed`); recorded, not judged, since.
        timing: ``"toppra"`` (retimed trajectory, position+velocity targets every physics
            step) or ``"waypoints"`` (densified waypoints, position targets held for
            ``steps_per_waypoint`` steps each).
        duration_s: the commanded motion's duration, settling excluded [s].
        trajectory_valid: the FCL re-check of the retimed trajectory's commanded states
            (None for ``"waypoints"``, whose commands are the densified path itself).
        spline_dev: largest distance between the retimed spline and the path's
            polyline at the knot-interval midpoints [rad or m] (NaN for ``"waypoints"``).
        deviation_m: (M,) per logged sample, the largest deviation of the robot's
            collision geometry from the plan since the previous sample [m]
            (settling excluded; empty in records made before it existed).
        max_deviation_m: largest displacement of any point of the robot's collision
            geometry (every link's capsule) between the commanded and the simulated
            state over the whole execution, settling included [m]; see
            :mod:`plannerlab.sim.measure` for the bound and the states measured (NaN in
            records made before it existed).
            Since the reference is interpolated (``"toppra"``), the commanded state
            it is measured against is the *plan's*: the planned polyline's state at
            the reference's path parameter, so it bounds how far the simulated
            geometry was from the plan (the reference's own distance from the plan,
            ``reference_deviation_m``, included).
        reference_deviation_m: largest displacement of any point of the collision
            geometry between the retimed reference and the plan's state at the same
            path parameter, over every physics step [m] (0 for ``"waypoints"``, whose
            commands are the plan; NaN in older records); a-priori at most
            :data:`~plannerlab.sim.retime.PCHIP_BOUND` × ``CORNER_M`` (see
            :mod:`plannerlab.sim.retime`).
        max_deviation_time_s: when it was met, from the leg's start [s].
        max_deviation_limit_m: the problem's ``[simulation] max_deviation_m`` that the
            verdict applied [m] (NaN in older records, judged by the joint tracking
            limit ``track_err_limit_rad`` instead).
        min_clearance_m: smallest simulated clearance (PyBullet's closest points) of the
            robot to the scene and between its non-excluded links over the execution,
            sampled as :mod:`plannerlab.sim.measure` says [m]; negative: penetration
            (NaN when not measured: older records, and contact-permitting plans, which
            touch by design; their closest approaches are in ``extra``).
        min_clearance_time_s: when it was met [s].
        min_clearance_pair: (robot link, obstacle or other link) of that clearance.
        clearance_samples: states whose clearance was queried.
        solver: PyBullet's constraint solver ("pgs", "dantzig"; "" when not recorded).
    """

    problem: str
    leg: int | None
    goal: str | None
    path_valid: bool | None
    recheck_joint_step: float
    recheck_states: int
    recheck_first_invalid_edge: int | None
    recheck_pairs: tuple[tuple[str, str], ...]
    waypoint_step: float
    steps_per_waypoint: int
    settle_steps: int
    dt_s: float
    contact_tol_m: float
    gravity_mps2: tuple[float, float, float]
    t_s: Array
    q_cmd_rad: Array
    q_actual_rad: Array
    track_err_rad: Array
    tip_track_err_m: Array
    contacts: tuple[ContactRecord, ...]
    q_start_rad: Array
    carried_over: bool
    start_offset_rad: float
    q_final_rad: Array
    final_track_err_rad: float
    final_tip_track_err_m: float
    final_pos_err_m: float
    final_angle_err_deg: float
    goal_reached: bool | None
    sim_time_s: float
    wall_time_s: float
    reason: str
    track_err_limit_rad: float = 0.05
    timing: str = "waypoints"
    duration_s: float = math.nan
    trajectory_valid: bool | None = None
    spline_dev: float = math.nan
    deviation_m: Array = field(default_factory=lambda: np.zeros(0))
    max_deviation_m: float = math.nan
    reference_deviation_m: float = math.nan
    max_deviation_time_s: float = math.nan
    max_deviation_limit_m: float = math.nan
    min_clearance_m: float = math.nan
    min_clearance_time_s: float = math.nan
    min_clearance_pair: tuple[str, str] | None = None
    clearance_samples: int = 0
    solver: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in _ARRAY_FIELDS:
            a = np.array(getattr(self, name), dtype=float)
            if name in ("q_cmd_rad", "q_actual_rad"):
                a = a.reshape(len(a), -1) if a.size else a.reshape(0, len(self.q_final_rad))
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        for name in _FLOAT_FIELDS:
            object.__setattr__(self, name, read_float(getattr(self, name)))
        object.__setattr__(self, "gravity_mps2", tuple(float(g) for g in self.gravity_mps2))
        object.__setattr__(self, "extra", dict(self.extra))
        if self.min_clearance_pair is not None:
            link, other = self.min_clearance_pair
            object.__setattr__(self, "min_clearance_pair", (str(link), str(other)))
        object.__setattr__(self, "clearance_samples", int(self.clearance_samples))
        object.__setattr__(
            self, "recheck_pairs", tuple((str(a), str(b)) for a, b in self.recheck_pairs)
        )
        object.__setattr__(
            self,
            "contacts",
            tuple(
                c if isinstance(c, ContactRecord) else ContactRecord.from_dict(c)
                for c in self.contacts
            ),
        )

    @property
    def tracked(self) -> bool:
        """The maximum joint tracking error stayed within ``track_err_limit_rad`` (the
        verdict of records made before ``max_deviation_m``; informational since)."""
        return self.max_track_err_rad <= self.track_err_limit_rad

    @property
    def followed(self) -> bool:
        """The robot followed the commanded motion: ``max_deviation_m`` within
        ``max_deviation_limit_m``; a record made before the deviation was measured is
        judged by its joint tracking limit (:attr:`tracked`), as it was then."""
        if math.isnan(self.max_deviation_limit_m):
            return self.tracked
        return self.max_deviation_m <= self.max_deviation_limit_m

    @property
    def clear(self) -> bool:
        """The simulated clearance never fell below 0 (True when it was not measured)."""
        return not self.min_clearance_m < 0

    @property
    def expected_contacts(self) -> tuple[ContactRecord, ...]:
        """The contacts the plan asked for (none for an ordinary plan)."""
        return tuple(c for c in self.contacts if c.expected)

    @property
    def unexpected_contacts(self) -> tuple[ContactRecord, ...]:
        """Every other contact: each one makes the execution a failure."""
        return tuple(c for c in self.contacts if not c.expected)

    @property
    def success(self) -> bool:
        """Executed cleanly: re-check not failed, no unexpected contact, smallest
        simulated clearance >= 0, largest deviation within the limit (:attr:`followed`)
        and (with a leg) the final state in the goal."""
        return (
            self.path_valid is not False
            and self.trajectory_valid is not False
            and not self.unexpected_contacts
            and self.clear
            and self.followed
            and self.goal_reached is not False
        )

    @property
    def failures(self) -> tuple[str, ...]:
        """Why :attr:`success` is False, one short phrase per failed test (none when it
        succeeded): the re-check's colliding pair, the first unexpected contact, a
        negative clearance with its pair, the deviation over its limit, the goal missed."""
        out: list[str] = []
        if self.path_valid is False:
            pair = " x ".join(self.recheck_pairs[0]) if self.recheck_pairs else "a pair"
            out.append(f"re-check: {pair} collide")
        if self.trajectory_valid is False:
            out.append("retimed trajectory collides")
        bad = self.unexpected_contacts
        if bad:
            more = f" (+{len(bad) - 1} more)" if len(bad) > 1 else ""
            out.append(f"contact {bad[0].link_name} x {bad[0].other_name}{more}")
        if not self.clear:
            pair = f" ({' x '.join(self.min_clearance_pair)})" if self.min_clearance_pair else ""
            out.append(f"clearance {1e3 * self.min_clearance_m:.3g} mm{pair}")
        if not self.followed:
            if math.isnan(self.max_deviation_limit_m):
                out.append(
                    f"tracking {self.max_track_err_rad:.3g} > {self.track_err_limit_rad:.3g} rad"
                )
            else:
                out.append(
                    f"deviation {1e3 * self.max_deviation_m:.3g} > "
                    f"{1e3 * self.max_deviation_limit_m:.3g} mm"
                )
        if self.goal_reached is False:
            out.append(
                f"tip outside the goal ({self.final_pos_err_m:.3g} m, "
                f"{self.final_angle_err_deg:.3g}°)"
            )
        return tuple(out)

    @property
    def max_track_err_rad(self) -> float:
        """Largest per-waypoint tracking error [rad] (0 for an empty log)."""
        return float(np.max(self.track_err_rad, initial=0.0))

    @property
    def max_tip_track_err_m(self) -> float:
        """Largest per-waypoint tip tracking error [m] (0 for an empty log)."""
        return float(np.max(self.tip_track_err_m, initial=0.0))

    @property
    def max_contact_depth_m(self) -> float:
        """Deepest contact of the execution [m] (0 without contacts)."""
        return max((c.max_depth_m for c in self.contacts), default=0.0)

    def to_dict(self, *, include_log: bool = True) -> dict[str, Any]:
        """Plain JSON-able data (the codec's convention); :meth:`from_dict` reads it back.

        Args:
            include_log: False leaves out the per-waypoint log (``t_s``, ``q_cmd_rad``,
                ``q_actual_rad``, ``track_err_rad``, ``tip_track_err_m``,
                ``deviation_m``: a trial store keeps hundreds of legs) and writes
                ``log_points``, ``success``, ``max_track_err_rad`` and
                ``max_tip_track_err_m`` instead.
        """
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["contacts"] = [c.to_dict() for c in self.contacts]
        if not include_log:
            for name in _LOG_FIELDS:
                del out[name]
            out["log_points"] = len(self.t_s)
            out["success"] = self.success
            out["max_track_err_rad"] = self.max_track_err_rad
            out["max_tip_track_err_m"] = self.max_tip_track_err_m
        return to_data(out)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Execution:
        """Rebuild an execution from :meth:`to_dict` output.

        Raises:
            PlannerlabError: ``data`` is not an execution record.
        """
        fields = dataclasses.fields(cls)
        try:
            values = {
                f.name: data[f.name]
                for f in fields
                if f.name in data
                or (f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
            }
            for k in ("sim_time_s", "wall_time_s", "dt_s", "contact_tol_m"):
                values[k] = read_float(values[k])
            return cls(**values)
        except (KeyError, TypeError, ValueError) as exc:
            raise PlannerlabError(f"not an execution record: {exc!r}") from None

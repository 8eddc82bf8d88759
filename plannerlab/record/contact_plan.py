"""The record a contact-permitting plan carries from planner to executor and figures.

The continuum robot's ``chord_arc`` planner plans *through* contact: its curve passes the
problem's collision points (obstacle corners) and the chain bears on them. What the
executor must know to tell an expected contact from a collision, what the figures draw
and what the CLI prints is one typed record, :class:`ContactPlan`, stored on the leg
(:attr:`plannerlab.record.leg.PlanResult.contact_plan`) and written with it to plan files
and trial stores. Nothing downstream re-plans or reads untyped keys:

* :func:`plannerlab.sim.continuum.execute_chord_arc` reads the chosen solution's collision
  points and their obstacles, the contact tolerance and the guide obstacles;
* :mod:`plannerlab.plot.continuum` draws the plane's obstacles (as cut by the robot's
  plane, and as grown by the link radius when the planner planned the robot's axis), the
  collision points, the port, the target, every solution's arcs, the dropped ones and the
  points where a zero-thickness curve would cut an obstacle;
* ``plannerlab continuum`` prints its table from it.

Every field is plain data (numbers, strings, tuples): the record depends on no planner.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from typing import Any

from plannerlab.errors import PlanFileError
from plannerlab.record.codec import to_data

Point = tuple[float, float]


def _pt(value: Any) -> Point:
    x, y = value
    return (float(x), float(y))


def _pts(values: Any) -> tuple[Point, ...]:
    return tuple(_pt(v) for v in values)


@dataclass(frozen=True)
class PlanarArc:
    """One constant-curvature arc of a solution in the robot's plane (world x-y, metres).

    Attributes:
        start_xy_m: where the arc starts.
        start_tangent: unit direction of the curve there.
        theta_rad: bend angle (positive bends clockwise seen from +z).
        length_m: arc length.
    """

    start_xy_m: Point
    start_tangent: Point
    theta_rad: float
    length_m: float

    @property
    def curvature_per_m(self) -> float:
        return self.theta_rad / self.length_m

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PlanarArc:
        return cls(
            _pt(d["start_xy_m"]),
            _pt(d["start_tangent"]),
            float(d["theta_rad"]),
            float(d["length_m"]),
        )


@dataclass(frozen=True)
class PlanarShape:
    """An obstacle as the robot's plane cuts it: a disc (``radius_m`` about ``center_m``)
    or a convex polygon (``vertices_m``, counter-clockwise)."""

    name: str
    center_m: Point | None = None
    radius_m: float | None = None
    vertices_m: tuple[Point, ...] = ()

    @property
    def is_disc(self) -> bool:
        return self.radius_m is not None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PlanarShape:
        center = d.get("center_m")
        radius = d.get("radius_m")
        return cls(
            str(d["name"]),
            None if center is None else _pt(center),
            None if radius is None else float(radius),
            _pts(d.get("vertices_m", ())),
        )


@dataclass(frozen=True)
class PlannedContact:
    """A (link, obstacle) pair of the chain that touches along a solution's path.

    Attributes:
        link: the chain's link.
        obstacle: the obstacle's name.
        first_state: the path state where it first touches (for an unexpected pair: where
            it first touches away from the solution's collision points).
        collision_point: the nearest of the solution's collision points on that obstacle
            (index into the problem's list), or None.
        distance_m: the link axis's distance to that collision point [m], or None.
    """

    link: str
    obstacle: str
    first_state: int
    collision_point: int | None
    distance_m: float | None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PlannedContact:
        cp, dist = d.get("collision_point"), d.get("distance_m")
        return cls(
            str(d["link"]),
            str(d["obstacle"]),
            int(d["first_state"]),
            None if cp is None else int(cp),
            None if dist is None else float(dist),
        )


@dataclass(frozen=True)
class ContactSolution:
    """One chord-arc solution: the arcs from the port through collision points to the
    target, and what the planner found about it.

    Attributes:
        contact_indices: the collision points it passes, in order (indices into
            :attr:`ContactPlan.collision_points_m`).
        contact_points_m: those collision points (the obstacle corners).
        axis_points_m: where the robot's axis passes them (moved out of the obstacle by
            the link radius when the planner planned the axis).
        arcs: the curve, arc by arc.
        total_length_m: the arcs' length; ``leftover_m``: the robot's length left behind
            the port.
        contact_obstacles, contact_types, contact_sides: per collision point, its
            obstacle, how the robot bears on it (the search's contact-type check) and on which
            side of the robot it is (+1: right, -1: left).
        motion: the motion sequence as (kind, description) steps.
        path_waypoints: states of its joint path (0 if it was dropped before one was made).
        expected_contacts: the chain's contacts at its collision points along that path.
        reason, stage: why it was dropped and by which check (``contact_type``: the
            search's motion check; ``chain``: joint bounds or the chain's thickness); empty
            for a kept solution.
        unexpected_contacts: the contacts away from the collision points that dropped it.
        cuts_xy_m: for a zero-thickness solution, points where a robot of the link's
            radius following it would cut an obstacle away from its collision points.
    """

    contact_indices: tuple[int, ...]
    contact_points_m: tuple[Point, ...]
    axis_points_m: tuple[Point, ...]
    arcs: tuple[PlanarArc, ...]
    total_length_m: float
    leftover_m: float
    contact_obstacles: tuple[str, ...] = ()
    contact_types: tuple[str, ...] = ()
    contact_sides: tuple[int, ...] = ()
    motion: tuple[tuple[str, str], ...] = ()
    path_waypoints: int = 0
    expected_contacts: tuple[PlannedContact, ...] = ()
    reason: str = ""
    stage: str = ""
    unexpected_contacts: tuple[PlannedContact, ...] = ()
    cuts_xy_m: tuple[Point, ...] = ()

    @property
    def bend_angles_rad(self) -> tuple[float, ...]:
        return tuple(a.theta_rad for a in self.arcs)

    @property
    def arc_lengths_m(self) -> tuple[float, ...]:
        return tuple(a.length_m for a in self.arcs)

    @property
    def curvatures_per_m(self) -> tuple[float, ...]:
        return tuple(a.curvature_per_m for a in self.arcs)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> ContactSolution:
        return cls(
            contact_indices=tuple(int(i) for i in d["contact_indices"]),
            contact_points_m=_pts(d["contact_points_m"]),
            axis_points_m=_pts(d["axis_points_m"]),
            arcs=tuple(PlanarArc.from_dict(a) for a in d["arcs"]),
            total_length_m=float(d["total_length_m"]),
            leftover_m=float(d["leftover_m"]),
            contact_obstacles=tuple(str(s) for s in d.get("contact_obstacles", ())),
            contact_types=tuple(str(s) for s in d.get("contact_types", ())),
            contact_sides=tuple(int(s) for s in d.get("contact_sides", ())),
            motion=tuple((str(k), str(t)) for k, t in d.get("motion", ())),
            path_waypoints=int(d.get("path_waypoints", 0)),
            expected_contacts=tuple(
                PlannedContact.from_dict(c) for c in d.get("expected_contacts", ())
            ),
            reason=str(d.get("reason", "")),
            stage=str(d.get("stage", "")),
            unexpected_contacts=tuple(
                PlannedContact.from_dict(c) for c in d.get("unexpected_contacts", ())
            ),
            cuts_xy_m=_pts(d.get("cuts_xy_m", ())),
        )


@dataclass(frozen=True)
class ContactPlan:
    """What a contact-permitting planner decided for one leg (see the module docstring).

    Attributes:
        base_xy_m, base_tangent: the port and the direction the robot leaves it.
        target_xy_m: the target in the robot's plane.
        obstacles: the scene cut by the robot's plane.
        planning_obstacles: what the planned curve avoids (``obstacles`` grown by
            ``inflated_by_m`` when the planner planned the robot's axis).
        collision_points_m: the problem's collision points.
        link_radius_m: the chain's link radius.
        inflated_by_m: how far obstacles were grown for planning (0: the paper's
            zero-thickness curve).
        contact_tolerance_m: a contact within this distance of one of the chosen
            solution's collision points on its obstacle is expected.
        guide_obstacles: obstacles the robot slides in (their contacts are expected).
        solutions: the kept solutions; ``dropped``: the others, each with its reason.
        chosen: index of the executed solution in ``solutions``, or None.
        search: the search's counters (time, expansions, arcs built / checked / rejected,
            depth, geometric solutions).
        motion_step_of_waypoint: per path state, the chosen solution's motion step.
    """

    base_xy_m: Point
    base_tangent: Point
    target_xy_m: Point
    obstacles: tuple[PlanarShape, ...]
    planning_obstacles: tuple[PlanarShape, ...]
    collision_points_m: tuple[Point, ...]
    link_radius_m: float
    inflated_by_m: float
    contact_tolerance_m: float
    guide_obstacles: tuple[str, ...] = ()
    solutions: tuple[ContactSolution, ...] = ()
    dropped: tuple[ContactSolution, ...] = ()
    chosen: int | None = None
    search: Mapping[str, Any] = field(default_factory=dict)
    motion_step_of_waypoint: tuple[int, ...] = ()

    @property
    def chosen_solution(self) -> ContactSolution | None:
        return None if self.chosen is None else self.solutions[self.chosen]

    @property
    def searched(self) -> tuple[ContactSolution, ...]:
        """The solutions the search's motion check passed: the kept ones and those the
        chain's check dropped (joint bounds, thickness)."""
        return self.solutions + tuple(d for d in self.dropped if d.stage == "chain")

    @property
    def expected_contacts(self) -> tuple[PlannedContact, ...]:
        """The chosen solution's expected contacts (none without a choice)."""
        sol = self.chosen_solution
        return () if sol is None else sol.expected_contacts

    def to_dict(self) -> dict[str, Any]:
        return to_data({f.name: _plain(getattr(self, f.name)) for f in fields(self)})

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> ContactPlan:
        """Read back what :meth:`to_dict` wrote.

        Raises:
            PlanFileError: ``d`` is not a contact plan.
        """
        try:
            chosen = d.get("chosen")
            plan = cls(
                base_xy_m=_pt(d["base_xy_m"]),
                base_tangent=_pt(d["base_tangent"]),
                target_xy_m=_pt(d["target_xy_m"]),
                obstacles=tuple(PlanarShape.from_dict(o) for o in d["obstacles"]),
                planning_obstacles=tuple(PlanarShape.from_dict(o) for o in d["planning_obstacles"]),
                collision_points_m=_pts(d["collision_points_m"]),
                link_radius_m=float(d["link_radius_m"]),
                inflated_by_m=float(d["inflated_by_m"]),
                contact_tolerance_m=float(d["contact_tolerance_m"]),
                guide_obstacles=tuple(str(n) for n in d.get("guide_obstacles", ())),
                solutions=tuple(ContactSolution.from_dict(s) for s in d.get("solutions", ())),
                dropped=tuple(ContactSolution.from_dict(s) for s in d.get("dropped", ())),
                chosen=None if chosen is None else int(chosen),
                search=dict(d.get("search", {})),
                motion_step_of_waypoint=tuple(int(i) for i in d.get("motion_step_of_waypoint", ())),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise PlanFileError(f"not a contact plan: {type(exc).__name__}: {exc}") from None
        if plan.chosen is not None and not 0 <= plan.chosen < len(plan.solutions):
            raise PlanFileError(
                f"not a contact plan: chosen = {plan.chosen} but there are "
                f"{len(plan.solutions)} solutions"
            )
        if not (math.isfinite(plan.contact_tolerance_m) and plan.contact_tolerance_m >= 0):
            raise PlanFileError(
                f"not a contact plan: contact_tolerance_m = {plan.contact_tolerance_m}"
            )
        return plan


def _plain(value: Any) -> Any:
    """Records inside a contact plan as dicts (their own fields), the rest unchanged."""
    if hasattr(value, "__dataclass_fields__"):
        return {f.name: _plain(getattr(value, f.name)) for f in fields(value)}
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value


def as_contact_plan(plan: Any) -> ContactPlan | None:
    """``plan`` as a :class:`ContactPlan` (a record, or its dict form), or None."""
    if plan is None or isinstance(plan, ContactPlan):
        return plan
    if isinstance(plan, Mapping):
        return ContactPlan.from_dict(plan)
    raise PlanFileError(f"not a contact plan: {type(plan).__name__}")


__all__: Sequence[str] = [
    "ContactPlan",
    "ContactSolution",
    "PlanarArc",
    "PlanarShape",
    "PlannedContact",
    "as_contact_plan",
]

"""Settings of the ``chord_arc`` planner: its search, motion check and joint path."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

from plannerlab.planners.chord_arc.geometry import ChordArcInputError

CHOICES: tuple[str, ...] = ("shortest", "fewest_contacts", "first")


@dataclass(frozen=True)
class ChordArcSettings:
    """Settings of the ``chord_arc`` planner: its search, motion check and joint path.

    The search functions of this module read the first group; the planner
    (:mod:`plannerlab.planners.chord_arc`) reads the second.

    Search and motion check:
        max_depth: most arcs in a solution (contacts + 1); 0 = collision points + 1.
        max_expansions: most bases expanded (the port counts as one).
        arc_step_m: largest spacing of the samples along an arc [m].
        inside_tol_m: a sample counts as inside an obstacle only deeper than this [m].
        boundary_tol_m: how far a collision point may lie from a boundary [m].
        max_bend_rad: largest |θ| of one arc [rad].
        push_length_m: initial push l at each contact [m] (capped at half the next arc).
        rebend_steps: intermediate curvatures checked while re-bending the pushed part.
        min_kappa_change_per_m: |κ_out − κ_in| below this carries no load [1/m].
        coarse_factor: a first pass samples arcs this many times more sparsely to drop
            blocked arcs early (1 = off).
        chunk_samples: arc samples per numpy batch (bounds memory).

    Planner:
        inflate_by_radius: plan the robot's axis among obstacles grown by the link
            radius, through collision points moved out of their obstacle by the radius, so
            that the chain's capsules touch the corners instead of cutting them (default);
            False: the paper's zero-thickness curve.
        choose: which surviving solution to execute: "shortest" (least arc length),
            "fewest_contacts" (ties: shorter), "first" (breadth-first order).
        path_step_m: largest change of inserted length and of the last arc's length
            between path waypoints [m].
        path_joint_step_rad: largest change of any bend joint between waypoints [rad].
        check_contacts: check every state of every surviving solution's path for the
            chain's capsules touching obstacles away from its collision points, and drop
            such solutions.
        contact_slack_m: a contact is expected within 2·link radius + this of one of
            the solution's collision points [m] (the contact tolerance's slack; named
            ``contact_margin_m`` before issue 36: not the problem's safety margin).
    """

    max_depth: int = 0
    max_expansions: int = 100_000
    arc_step_m: float = 1e-3
    inside_tol_m: float = 1e-6
    boundary_tol_m: float = 1e-6
    max_bend_rad: float = math.pi
    push_length_m: float = 0.005
    rebend_steps: int = 8
    min_kappa_change_per_m: float = 1e-9
    coarse_factor: int = 8
    chunk_samples: int = 65536
    inflate_by_radius: bool = True
    choose: str = "shortest"
    path_step_m: float = 0.002
    path_joint_step_rad: float = 0.02
    check_contacts: bool = True
    contact_slack_m: float = 0.01

    #: settings renamed (old key -> new): still read for one release, with a warning
    RENAMED_KEYS: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"contact_margin_m": "contact_slack_m"}
    )

    def __post_init__(self) -> None:
        if self.max_depth < 0:
            raise ChordArcInputError(f"max_depth must be >= 0 (0: no limit), got {self.max_depth}")
        for name in ("max_expansions", "rebend_steps", "coarse_factor", "chunk_samples"):
            if getattr(self, name) < 1:
                raise ChordArcInputError(f"{name} must be >= 1, got {getattr(self, name)}")
        for name in (
            "arc_step_m",
            "max_bend_rad",
            "push_length_m",
            "path_step_m",
            "path_joint_step_rad",
        ):
            if not getattr(self, name) > 0:
                raise ChordArcInputError(f"{name} must be > 0, got {getattr(self, name)}")
        for name in ("inside_tol_m", "boundary_tol_m", "contact_slack_m"):
            if not getattr(self, name) >= 0:
                raise ChordArcInputError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.choose not in CHOICES:
            raise ChordArcInputError(
                f"choose must be one of {', '.join(CHOICES)}, got {self.choose!r}"
            )

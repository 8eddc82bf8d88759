"""The planner registry: planners are looked up by name and imported on first use.

An entry maps a name to ``"module:factory"``; the factory is called as
``factory(name, overrides, **entry.options)`` and returns a planner with frozen settings.
OMPL planners are all served by :mod:`plannerlab.planners.ompl` (the only module importing
``ompl``). Planners that run another planner (the hybrids' RRT-Connect escape) get its
factory through their entry's options: no planner module looks anything up here.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from plannerlab.errors import UnknownNameError
from plannerlab.planners.base import Planner, PlanResult, Status, Stepper


@dataclass(frozen=True)
class PlannerEntry:
    """One registered planner.

    Attributes:
        name: registry name (``gradient``, ``ompl.rrtconnect``, …).
        target: ``"module:factory"``, imported lazily.
        summary: one line for ``plannerlab planners``.
        needs_stepper: the planner runs a simulator in its loop (closed-loop modes).
        robots: robot kinds it applies to (None: every joint-vector robot).
        uses_rng: the planner draws from its generator (False: deterministic methods that
            ignore it; the contract checks that seeds do not change their path).
        options: keyword arguments the factory gets besides the name and the overrides
            (the OMPL class of an ``ompl.*`` planner, the escape planner's factory of a
            hybrid), so that no planner module has to look anything up in this registry.
    """

    name: str
    target: str
    summary: str
    needs_stepper: bool = False
    robots: tuple[str, ...] | None = None
    uses_rng: bool = True
    options: Mapping[str, Any] = field(default_factory=dict)


#: OMPL geometric planners shipped in the ``ompl`` wheel: registry suffix -> OMPL class.
#: Left out (README, "Planners left out"): SORRTstar, which does not honour its budget
#: (its ordered informed sampler runs for long stretches without polling the termination
#: condition: 42 s past a 5 s limit on irb6_case1), and AORRTC, which stops with "Invalid
#: goal" ("Zero-length path found") on problems RRT-Connect solves.
OMPL_PLANNERS: Mapping[str, str] = MappingProxyType(
    {
        "rrtconnect": "RRTConnect",
        "rrt": "RRT",
        "rrtstar": "RRTstar",
        "informedrrtstar": "InformedRRTstar",
        "kpiece1": "KPIECE1",
        "bkpiece1": "BKPIECE1",
        "lbkpiece1": "LBKPIECE1",
        "prm": "PRM",
        "prmstar": "PRMstar",
        "bitstar": "BITstar",
        "fmt": "FMT",
        "bfmt": "BFMT",
    }
)


#: sampling planners compiled end to end (``plannerlab.planners.native``): algorithm -> summary
NATIVE_PLANNERS: Mapping[str, str] = MappingProxyType(
    {
        "rrtconnect": "RRT-Connect compiled end to end (numba): sampling, nearest neighbours, "
        "edges on the re-check's grid and shortcuts in compiled code",
        "rrtstar": "RRT* compiled end to end (numba): k-nearest rewiring, goal-biased, "
        "shortens its best path until the budget is spent",
        "kpiece": "KPIECE compiled end to end (numba): a tree grown from the frontier of a "
        "grid over a random projection, for long chains where RRT-Connect fails",
    }
)


def _rrtconnect(overrides: Mapping[str, Any]) -> Planner:
    """OMPL's RRT-Connect (``ompl.rrtconnect``): the hybrids' escape planner, handed to
    their factories as ``escape_planner``; ``ompl`` is imported on first use."""
    from plannerlab.planners.ompl import make

    return make("ompl.rrtconnect", overrides, ompl_class=OMPL_PLANNERS["rrtconnect"])


#: options of the planners that escape with RRT-Connect
_ESCAPE_RRTCONNECT: Mapping[str, Any] = MappingProxyType({"escape_planner": _rrtconnect})


def _entries() -> dict[str, PlannerEntry]:
    entries = [
        PlannerEntry(
            "gradient",
            "plannerlab.planners.gradient:make",
            "the Arm-Z paper's gradient method, faithful (finite differences, kinematic steps)",
            uses_rng=False,
        ),
        PlannerEntry(
            "gradient.closed_loop",
            "plannerlab.planners.gradient:make",
            "the paper's gradient method with PyBullet in the loop (100 steps of "
            "1/240 s per iteration)",
            needs_stepper=True,
            uses_rng=False,
        ),
        PlannerEntry(
            "gradient.analytic",
            "plannerlab.planners.gradient:make",
            "faster variant: the same descent with the analytic Jacobian gradient "
            "instead of dof + 1 objective evaluations",
            uses_rng=False,
        ),
    ]
    entries.append(
        PlannerEntry(
            "gradient+rrtconnect",
            "plannerlab.planners.hybrid:make",
            "gradient descent; at a local minimum RRT-Connect plans from the stall to the goal",
            options=_ESCAPE_RRTCONNECT,
        )
    )
    entries.append(
        PlannerEntry(
            "gradient.multistart",
            "plannerlab.planners.hybrid:make",
            "gradient descent restarted from random collision-free states near each stall",
            options=_ESCAPE_RRTCONNECT,
        )
    )
    for name, summary, uses_rng in (
        (
            "gradient.clearance",
            "the paper's objective (the joint distance towards a goal state) plus a smooth "
            "clearance term (link distances to the scene and each other): the descent "
            "slides along walls; no escape",
            False,
        ),
        (
            "gradient.clearance+detour",
            "gradient.clearance; at a stall, sub-goals near the stall (the goal's approach "
            "point, then the tip drawn back along its own body), the descent resumes",
            False,
        ),
        (
            "gradient.clearance+random_detour",
            "gradient.clearance+detour with its sub-goals drawn from the seed (random "
            "retract depths, points jittered round the body), drawn again if none works",
            True,
        ),
        (
            "gradient.clearance+rrtconnect",
            "gradient.clearance; at a stall, RRT-Connect from the stall to a goal state "
            "found by the clearance descent from the stall, or drawn by IK when it finds none",
            True,
        ),
    ):
        entries.append(
            PlannerEntry(
                name,
                "plannerlab.planners.clearance.descent:make",
                summary,
                uses_rng=uses_rng,
                options=_ESCAPE_RRTCONNECT,
            )
        )
    for name, summary, uses_rng in (
        (
            "gradient.follow_leader",
            "follow-the-leader: a shortest path for the tip through free workspace (voxel "
            "grid of the scene's distance, into the goal along its normal), tracked by the "
            "clearance descent so the body follows the tip",
            False,
        ),
        (
            "gradient.follow_leader+detour",
            "gradient.follow_leader; if the descent stalls after the leader's path, the "
            "clearance descent's detour",
            False,
        ),
        (
            "gradient.follow_leader+random",
            "gradient.follow_leader with the grid shifted and the centring weight scaled by "
            "the seed, a new leader path drawn from a stall",
            True,
        ),
    ):
        entries.append(
            PlannerEntry(
                name,
                "plannerlab.planners.follow_leader.planner:make",
                summary,
                uses_rng=uses_rng,
                options=_ESCAPE_RRTCONNECT,
            )
        )
    entries.append(
        PlannerEntry(
            "chord_arc",
            "plannerlab.planners.chord_arc.planner:make",
            "continuum robot's chord-arc tree search with obstacle wrapping (contact at the "
            "problem's collision points)",
            robots=("continuum_chain",),
            uses_rng=False,
        )
    )
    for algorithm, summary in NATIVE_PLANNERS.items():
        entries.append(
            PlannerEntry(
                f"native.{algorithm}",
                "plannerlab.planners.native:make",
                summary,
                options=MappingProxyType({"algorithm": algorithm}),
            )
        )
    entries.append(
        PlannerEntry(
            "native.rrtconnect+leader",
            "plannerlab.planners.native.leader:make",
            "native.rrtconnect helped by follow-the-leader: its body states from the start "
            "and from goal states into the start's tip seed both trees and bias the samples",
        )
    )
    for suffix, cls in OMPL_PLANNERS.items():
        entries.append(
            PlannerEntry(
                f"ompl.{suffix}",
                "plannerlab.planners.ompl:make",
                f"OMPL {cls} (geometric)",
                options=MappingProxyType({"ompl_class": cls}),
            )
        )
    return {e.name: e for e in entries}


#: every planner by name (read-only)
REGISTRY: Mapping[str, PlannerEntry] = MappingProxyType(_entries())


def planner_names() -> tuple[str, ...]:
    return tuple(REGISTRY)


def get_entry(name: str) -> PlannerEntry:
    """The registry entry for ``name``; an unknown name lists the close matches."""
    try:
        return REGISTRY[name]
    except KeyError:
        raise UnknownNameError("planner", name, REGISTRY) from None


def make_planner(name: str, overrides: Mapping[str, Any] | None = None) -> Planner:
    """A planner by registry name, with some settings overridden."""
    entry = get_entry(name)
    module_name, factory = entry.target.split(":")
    factory_fn = getattr(importlib.import_module(module_name), factory)
    return factory_fn(name, dict(overrides or {}), **entry.options)


__all__ = [
    "NATIVE_PLANNERS",
    "OMPL_PLANNERS",
    "REGISTRY",
    "PlanResult",
    "Planner",
    "PlannerEntry",
    "Status",
    "Stepper",
    "get_entry",
    "make_planner",
    "planner_names",
]

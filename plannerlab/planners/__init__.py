"""The planner registry: planners are looked up by name and imported on first use.

An entry maps a name to a *factory*, a function called as ``factory(name, overrides,
**entry.options)`` that returns a planner with frozen settings. The factories below are
entry points: each imports its planner's module inside its body (``from
plannerlab.planners.gradient import make``), so that ``import plannerlab.planners`` loads no
planner, and the architecture test (``tests/house/test_architecture.py``) sees every import
a registry makes, as it sees any other (no ``"module:function"`` strings). OMPL planners
are all served by :mod:`plannerlab.planners.ompl` (the only module importing ``ompl``).
Planners that run another planner (the hybrids' RRT-Connect escape) get its factory
through their entry's options: no planner module looks anything up here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
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
        factory: the entry point, ``factory(name, overrides, **options) -> Planner``: a
            function that imports its planner's module when called (see the module
            docstring; a ``"module:function"`` string is refused).
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
    factory: Callable[..., Planner]
    summary: str
    needs_stepper: bool = False
    robots: tuple[str, ...] | None = None
    uses_rng: bool = True
    options: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not callable(self.factory):
            raise TypeError(
                f"planner {self.name!r}: the factory must be a function that imports its "
                f"module when called (an entry point), got {self.factory!r}; write "
                "def _mine(name, overrides, **options): from plannerlab.planners.mine "
                "import make; return make(name, overrides, **options)"
            )


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


#: trajectory optimisers over whole paths (``plannerlab.planners.trajopt``): name -> summary
TRAJOPT_PLANNERS: Mapping[str, str] = MappingProxyType(
    {
        "trajopt.line": "trajectory optimisation of the whole path (squared accelerations "
        "under a collision hinge, Gauss-Newton on the banded structure) from the straight "
        "line to each goal state, random restarts",
        "trajopt.gradient": "trajectory optimisation seeded by the paper's gradient descent",
        "trajopt.rrtconnect": "trajectory optimisation seeded by native.rrtconnect's path",
        "trajopt.leader": "trajectory optimisation seeded by native.rrtconnect+leader's path",
        "trajopt.line+rrtconnect": "trajopt.line, then native.rrtconnect's path as the "
        "seed when no line seed gives a path",
    }
)


# ---------------------------------------------------------------- entry points
def _gradient(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.gradient import make

    return make(name, dict(overrides), **options)


def _hybrid(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.hybrid import make

    return make(name, dict(overrides), **options)


def _clearance(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.clearance.descent import make

    return make(name, dict(overrides), **options)


def _follow_leader(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.follow_leader.planner import make

    return make(name, dict(overrides), **options)


def _chord_arc(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.chord_arc.planner import make

    return make(name, dict(overrides), **options)


def _native(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.native.planner import make

    return make(name, dict(overrides), **options)


def _native_leader(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.native.leader import make

    return make(name, dict(overrides), **options)


def _ompl(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.ompl.planner import make

    return make(name, dict(overrides), **options)


def _trajopt(name: str, overrides: Mapping[str, Any], **options: Any) -> Planner:
    from plannerlab.planners.trajopt.planner import make

    return make(name, dict(overrides), **options)


def _rrtconnect(overrides: Mapping[str, Any]) -> Planner:
    """OMPL's RRT-Connect (``ompl.rrtconnect``): the hybrids' escape planner, handed to
    their factories as ``escape_planner``; ``ompl`` is imported on first use."""
    return _ompl("ompl.rrtconnect", overrides, ompl_class=OMPL_PLANNERS["rrtconnect"])


#: options of the planners that escape with RRT-Connect
_ESCAPE_RRTCONNECT: Mapping[str, Any] = MappingProxyType({"escape_planner": _rrtconnect})


def _leader(overrides: Mapping[str, Any]) -> Planner:
    """Follow-the-leader (``gradient.follow_leader``): the clearance detours' route
    escape, handed to their factory as ``route_planner``."""
    return _follow_leader("gradient.follow_leader", overrides)


#: options of the clearance descents: RRT-Connect's escape, the detours' route escape
_CLEARANCE_ESCAPES: Mapping[str, Any] = MappingProxyType(
    {"escape_planner": _rrtconnect, "route_planner": _leader}
)


def _entries() -> dict[str, PlannerEntry]:
    entries = [
        PlannerEntry(
            "gradient",
            _gradient,
            "the Arm-Z paper's gradient method, faithful (finite differences, kinematic steps)",
            uses_rng=False,
        ),
        PlannerEntry(
            "gradient.closed_loop",
            _gradient,
            "the paper's gradient method with PyBullet in the loop (100 steps of "
            "1/240 s per iteration)",
            needs_stepper=True,
            uses_rng=False,
        ),
        PlannerEntry(
            "gradient.analytic",
            _gradient,
            "faster variant: the same descent with the analytic Jacobian gradient "
            "instead of dof + 1 objective evaluations",
            uses_rng=False,
        ),
    ]
    entries.append(
        PlannerEntry(
            "gradient+rrtconnect",
            _hybrid,
            "gradient descent; at a local minimum RRT-Connect plans from the stall to the goal",
            options=_ESCAPE_RRTCONNECT,
        )
    )
    entries.append(
        PlannerEntry(
            "gradient.multistart",
            _hybrid,
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
            "point, then the tip drawn back along its own body), the descent resumes; when "
            "none leads in, the tip's route through free workspace (follow-the-leader)",
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
                _clearance,
                summary,
                uses_rng=uses_rng,
                options=_CLEARANCE_ESCAPES,
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
                _follow_leader,
                summary,
                uses_rng=uses_rng,
                options=_ESCAPE_RRTCONNECT,
            )
        )
    entries.append(
        PlannerEntry(
            "chord_arc",
            _chord_arc,
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
                _native,
                summary,
                options=MappingProxyType({"algorithm": algorithm}),
            )
        )
    entries.append(
        PlannerEntry(
            "native.rrtconnect+leader",
            _native_leader,
            "native.rrtconnect helped by follow-the-leader: its body states from the start "
            "and from goal states into the start's tip seed both trees and bias the samples",
        )
    )
    for name, summary in TRAJOPT_PLANNERS.items():
        entries.append(PlannerEntry(name, _trajopt, summary))
    for suffix, cls in OMPL_PLANNERS.items():
        entries.append(
            PlannerEntry(
                f"ompl.{suffix}",
                _ompl,
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
    return entry.factory(name, dict(overrides or {}), **entry.options)


__all__ = [
    "NATIVE_PLANNERS",
    "OMPL_PLANNERS",
    "REGISTRY",
    "TRAJOPT_PLANNERS",
    "PlanResult",
    "Planner",
    "PlannerEntry",
    "Status",
    "Stepper",
    "get_entry",
    "make_planner",
    "planner_names",
]

"""What ``plannerlab planners`` shows: every registered planner with the robots it
suits, and one planner's settings (name, unit, default, what it does)."""

from __future__ import annotations

from typing import Any


def planner_catalog() -> list[dict[str, Any]]:
    """One JSON-able row per registered planner: ``name``, ``summary``,
    ``needs_simulator``, ``uses_rng``, ``robots`` (robot kinds, or ``"any"``)."""
    from plannerlab.planners import REGISTRY

    return [
        {
            "name": e.name,
            "summary": e.summary,
            "needs_simulator": e.needs_stepper,
            "uses_rng": e.uses_rng,
            "robots": list(e.robots) if e.robots else "any",
        }
        for e in REGISTRY.values()
    ]

"""What a trial's process imports, all at once: a comparison's fork server imports this
module before it forks one process per trial (``plannerlab.comparison.local``), so that
each trial starts with plannerlab's planners, checker, simulator and records loaded
(numpy, python-fcl, PyBullet and OMPL's Python modules with them; no OMPL object is
created). A module of ``run/`` because ``run/`` may import every room a trial walks
through; the comparison names only this module.

:func:`warm` loads the compiled kernels (numba's cache) a part of the house needs, and
compiles them when the cache is empty: on a fresh clone that is about 90 s of CPU for the
collision core, then about 50 s each for the clearance descent and the compiled samplers
(measured on this 2-core machine's EPYC; ``./do main`` runs the core first, then the
other two side by side, before its comparison, so that its trials do not compile the same
kernels twice at once)."""

from __future__ import annotations

from typing import Any

import plannerlab.collision.fcl_checker
import plannerlab.planners
import plannerlab.planners.gradient
import plannerlab.planners.hybrid
import plannerlab.planners.ompl
import plannerlab.problem.catalog
import plannerlab.record.files
import plannerlab.run.pipeline
import plannerlab.sim.execute

#: the modules loaded (for a reader; importing this module is the point)
MODULES = (
    plannerlab.collision.fcl_checker,
    plannerlab.problem.catalog,
    plannerlab.planners,
    plannerlab.planners.ompl,
    plannerlab.planners.gradient,
    plannerlab.planners.hybrid,
    plannerlab.run.pipeline,
    plannerlab.sim.execute,
    plannerlab.record.files,
)

#: what :func:`warm` can load, in the order the kernels depend on each other
WARM_PARTS = ("core", "clearance", "native")


def warm(part: str) -> None:
    """Load (or, on an empty cache, compile) one part's compiled kernels in this process:
    ``"core"`` (the collision core, the compiled model and its vector lanes, for Arm-Z and
    for serial chains), ``"clearance"`` (the clearance descent's field and step) or
    ``"native"`` (the compiled samplers). ``"clearance"`` and ``"native"`` reuse the
    core's kernels from the cache: warm the core first.

    Raises:
        ValueError: an unknown part.
    """
    if part == "core":
        _warm_core()
    elif part == "clearance":
        from plannerlab.planners.clearance.compiled import warm_up

        warm_up()
    elif part == "native":
        from plannerlab.planners.native.warm import warm_up as warm_native

        warm_native()
    else:
        raise ValueError(f"part: one of {', '.join(WARM_PARTS)}, got {part!r}")


def _warm_core() -> None:
    """A checker of a short Arm-Z and of a two-link chain beside a sphere, each asked a
    state, an edge and its compiled model: every kernel of the core runs once."""
    import numpy as np

    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Scene, Sphere
    from plannerlab.robots.armz.model import ArmZ
    from plannerlab.robots.base import trans
    from plannerlab.robots.continuum.model import ContinuumChain

    scene = Scene((Sphere("far", trans(5.0, 0.0, 0.0), 0.1),))
    armz, chain = ArmZ(n_modules=4), ContinuumChain(n_links=3)
    # free states: Arm-Z's straight column, the chain pushed out straight
    robots: tuple[tuple[Any, np.ndarray], ...] = (
        (armz, np.full(armz.dof, np.pi)),
        (chain, np.r_[0.2, np.zeros(3)]),
    )
    for robot, q in robots:
        checker = CollisionChecker(robot, scene, margin_m=0.01)
        checker.is_valid(q)
        checker.check_path(np.array([q, q + 0.01]), 0.05)
        _ = checker.model


__all__ = ["MODULES", "WARM_PARTS", "warm"]

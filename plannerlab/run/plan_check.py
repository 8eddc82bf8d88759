"""Reading a plan file a user hands to ``execute`` or ``plot``, and checking it fits its
problem before any work starts: every error names the file, the key and what was expected.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlanFileError


def read_plan(path: str | Path) -> Any:
    """:meth:`Plan.load` with the errors a user can cause turned into ``PlanFileError`` s."""
    from plannerlab.record.plan import Plan

    path = Path(path)
    if path.is_dir():
        raise PlanFileError(f"{path}: [<file>] a plan file (.json), got a directory")
    try:
        path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise PlanFileError(f"{path}: [<file>] no such plan file") from None
    except OSError as exc:
        raise PlanFileError(f"{path}: [<file>] a readable plan file: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise PlanFileError(f"{path}: [<encoding>] UTF-8 JSON text (a plan file)") from None
    try:
        plan = Plan.load(path)
    except PlanFileError:
        raise
    except (TypeError, ValueError, AttributeError) as exc:
        raise PlanFileError(f"{path}: [legs] a list of plan results ({exc})") from None
    if not plan.legs:
        raise PlanFileError(f"{path}: [legs] at least one leg, got none")
    return plan


def check_plan(plan: Any, problem: Any, path: str | Path) -> None:
    """Every leg's path is (m >= 1, dof) finite joint values of ``problem``'s robot, and its
    leg index exists in the problem."""
    dof = problem.robot.dof
    for i, r in enumerate(plan.legs):
        key = f"legs[{i}]"
        if not 0 <= r.leg < problem.legs:
            raise PlanFileError(
                f"{path}: [{key}.leg] a leg of {problem.name} (0..{problem.legs - 1}), got {r.leg}"
            )
        q = np.asarray(r.path)
        if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] != dof:
            raise PlanFileError(
                f"{path}: [{key}.path] waypoints of {dof} joint values each (the "
                f"{problem.robot.kind} robot of {problem.source}), got shape {list(q.shape)}"
            )
        if not np.all(np.isfinite(q)):
            row = int(np.flatnonzero(~np.all(np.isfinite(q), axis=1))[0])
            raise PlanFileError(f"{path}: [{key}.path[{row}]] finite joint values, got NaN or inf")


def read_checked_plan(path: str | Path) -> tuple[Any, Any]:
    """A user's plan file and its problem, ready to draw or animate: :func:`read_plan`,
    the problem it was planned on (:meth:`Plan.load_problem`), :func:`check_plan`.

    Raises:
        PlanFileError: a plan file that cannot be read or does not fit its problem.
    """
    plan = read_plan(path)
    problem = plan.load_problem()
    check_plan(plan, problem, path)
    return plan, problem

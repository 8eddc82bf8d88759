"""Which planner escaped which local minimum, read from a comparison's trial records.

The Arm-Z paper's gradient method stalls in local minima; the rest of plannerlab exists
to get past them. :func:`local_minima` reads that story out of the records, with nothing
hard-coded: a *baseline* planner (the paper's ``gradient``, or the first planner of the
comparison) stalls on some legs of a problem (its leg ends ``local_minimum``); for each
such leg, every other planner's trials say whether they solved that leg (escaped the
minimum the baseline stalled in), failed it (with the status), or never reached it (a
trial stops at its first failed leg). Besides, each planner's own records count the local
minima it met and escaped on the way (``local_minima``, ``escapes`` of a leg: the
clearance family's detours, the hybrids' RRT-Connect escapes).

The records are read by a handful of fields (``problem``, ``planner``, ``seed``,
``legs_run`` and, per leg, ``leg``, ``goal``, ``status``, ``reason``, ``pos_err_m``,
``iterations``, ``local_minima``, ``escapes``), as mappings or as objects with those
attributes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

#: a leg's status when its planner stalled in a local minimum
LOCAL_MINIMUM = "local_minimum"
SOLVED = "solved"


def _get(rec: Any, name: str, default: Any = None) -> Any:
    if isinstance(rec, Mapping):
        return rec.get(name, default)
    return getattr(rec, name, default)


def _status(leg: Any) -> str:
    status = _get(leg, "status")
    return str(getattr(status, "value", status))


@dataclass(frozen=True)
class Stall:
    """A leg on which the baseline planner stalled.

    Attributes:
        problem, leg, goal: where (the leg's index and its goal's name).
        seeds: the baseline's trials that stalled there.
        reason: the stall's reason (of the first such trial).
        pos_err_m: how far its tip stayed from the goal [m].
        iterations: its iterations at the stall.
        escaped: other planners whose trials solved that leg: (planner, trials solved,
            trials that reached the leg).
        not_escaped: other planners none of whose trials solved it: (planner, trials that
            reached the leg, their statuses joined; "never reached" when none did).
    """

    problem: str
    leg: int
    goal: str
    seeds: tuple[int, ...]
    reason: str
    pos_err_m: float
    iterations: int
    escaped: tuple[tuple[str, int, int], ...]
    not_escaped: tuple[tuple[str, int, str], ...]


@dataclass(frozen=True)
class OwnEscapes:
    """The local minima a planner met and escaped on its way, summed over its trials.

    Attributes:
        problem, planner: where and who.
        legs: per leg goal with any: (goal, minima met, minima escaped).
        trials: the planner's trials on the problem.
    """

    problem: str
    planner: str
    legs: tuple[tuple[str, int, int], ...]
    trials: int


def _legs(rec: Any) -> list[Any]:
    return list(_get(rec, "legs_run") or [])


def local_minima(
    records: Iterable[Any], baseline: str | None = None
) -> tuple[list[Stall], list[OwnEscapes]]:
    """The baseline's stalls with who escaped each, and every planner's own escapes.

    Args:
        records: trial records of one comparison (the store's, in any order).
        baseline: the planner whose stalls are the local minima asked about (default: the
            paper's ``gradient`` when it ran, else the first planner of the records).

    Returns:
        The stalls (by problem, then leg) and the planners' own minima met and escaped
        (only planners that met any).
    """
    recs = [r for r in records if _get(r, "planner")]
    planners = list(dict.fromkeys(str(_get(r, "planner")) for r in recs))
    if not planners:
        return [], []
    if baseline is None:
        baseline = "gradient" if "gradient" in planners else planners[0]
    stalls: list[Stall] = []
    own: list[OwnEscapes] = []
    for problem in dict.fromkeys(str(_get(r, "problem")) for r in recs):
        mine = [r for r in recs if _get(r, "problem") == problem]
        stalls += _stalls(problem, mine, baseline, planners)
        own += _own(problem, mine, planners)
    return stalls, own


def _stalls(problem: str, recs: list[Any], baseline: str, planners: Sequence[str]) -> list[Stall]:
    by_leg: dict[int, list[tuple[int, Any]]] = {}
    for r in recs:
        if _get(r, "planner") != baseline:
            continue
        for leg in _legs(r):
            if _status(leg) == LOCAL_MINIMUM:
                by_leg.setdefault(int(_get(leg, "leg")), []).append((int(_get(r, "seed")), leg))
    out = []
    for index in sorted(by_leg):
        stalled = by_leg[index]
        first = stalled[0][1]
        escaped, not_escaped = [], []
        for planner in planners:
            if planner == baseline:
                continue
            reached = [
                leg
                for r in recs
                if _get(r, "planner") == planner
                for leg in _legs(r)
                if int(_get(leg, "leg")) == index
            ]
            solved = sum(_status(leg) == SOLVED for leg in reached)
            if solved:
                escaped.append((planner, solved, len(reached)))
            else:
                statuses = ", ".join(dict.fromkeys(_status(leg) for leg in reached))
                not_escaped.append((planner, len(reached), statuses or "never reached"))
        out.append(
            Stall(
                problem=problem,
                leg=index,
                goal=str(_get(first, "goal")),
                seeds=tuple(sorted(seed for seed, _ in stalled)),
                reason=str(_get(first, "reason") or ""),
                pos_err_m=float(_get(first, "pos_err_m") or float("nan")),
                iterations=int(_get(first, "iterations") or 0),
                escaped=tuple(escaped),
                not_escaped=tuple(not_escaped),
            )
        )
    return out


def _own(problem: str, recs: list[Any], planners: Sequence[str]) -> list[OwnEscapes]:
    out = []
    for planner in planners:
        trials = [r for r in recs if _get(r, "planner") == planner]
        per_goal: dict[str, list[int]] = {}
        for r in trials:
            for leg in _legs(r):
                met = int(_get(leg, "local_minima") or 0)
                if met:
                    counts = per_goal.setdefault(str(_get(leg, "goal")), [0, 0])
                    counts[0] += met
                    counts[1] += int(_get(leg, "escapes") or 0)
        if per_goal:
            legs = tuple((goal, met, esc) for goal, (met, esc) in per_goal.items())
            out.append(OwnEscapes(problem, planner, legs, len(trials)))
    return out


def describe(stalls: Sequence[Stall], own: Sequence[OwnEscapes], baseline: str) -> list[str]:
    """The summary as lines of text (``plannerlab compare --minima`` prints them); the
    baseline's own stalls are the stalls, not repeated among the planners' own."""
    lines = []
    if not stalls:
        lines.append(f"{baseline} stalled in no local minimum in these trials")
    for s in stalls:
        seeds = ", ".join(map(str, s.seeds))
        lines.append(
            f"{s.problem}, leg {s.goal}: {baseline} stalls in a local minimum (seed {seeds}: "
            f"its tip stays {s.pos_err_m:.2f} m from the goal after {s.iterations} iterations)"
        )
        got = ", ".join(f"{p} {k}/{n}" for p, k, n in s.escaped)
        lines.append(f"  escaped by (solved the leg, trials): {got or 'none'}")
        if s.not_escaped:
            missed = ", ".join(
                f"{p} ({why})" if n == 0 else f"{p} 0/{n} ({why})" for p, n, why in s.not_escaped
            )
            lines.append(f"  not escaped by: {missed}")
    others = [o for o in own if o.planner != baseline]
    if others:
        lines.append("local minima the planners met on their own way (escaped of met, per leg):")
    for o in others:
        legs = ", ".join(f"{goal} {esc} of {met}" for goal, met, esc in o.legs)
        lines.append(f"  {o.problem}, {o.planner} ({o.trials} trial(s)): {legs}")
    return lines


__all__ = ["LOCAL_MINIMUM", "OwnEscapes", "Stall", "describe", "local_minima"]

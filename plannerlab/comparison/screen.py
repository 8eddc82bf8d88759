"""A screen, then the best: which member of each planner family a study runs at full size.

A study that compares planner *families* (the paper's gradient, the clearance descent,
OMPL's planners, ...) runs each family at its best settings. Which member is best is
measured, not chosen: a **screen** runs every member on every problem once (the first
seed), and :func:`best_members` picks per family the member that executed cleanly on the
most problems, ties broken by the fewest collision checks summed over its screen trials,
then by name. The study then runs only those members on the remaining seeds; the screen's
trials are part of it (the first seed's).

The rule is the same for any set of problems and families; nothing in it knows a problem.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import TrialRecord


def executed_cleanly(r: TrialRecord) -> bool:
    """Planned (every leg) and executed cleanly (every leg, the executor's verdict)."""
    return bool(r.success) and bool(r.exec_success)


@dataclass(frozen=True)
class Screened:
    """One member's screen: problems executed cleanly, problems run, checks summed."""

    planner: str
    clean: int
    problems: int
    checks: int

    def rank(self) -> tuple[int, int, str]:
        """Sort key, best first."""
        return (-self.clean, self.checks, self.planner)


def screen_table(records: Iterable[TrialRecord], seed: int) -> dict[str, Screened]:
    """Per planner, its trials of ``seed`` summed (the last record of a problem wins)."""
    by: dict[tuple[str, str], TrialRecord] = {}
    for r in records:
        if r.seed == seed:
            by[(r.planner, r.problem)] = r
    out: dict[str, list[TrialRecord]] = {}
    for (planner, _), r in by.items():
        out.setdefault(planner, []).append(r)
    return {
        p: Screened(
            p,
            sum(executed_cleanly(r) for r in rs),
            len(rs),
            sum(int(r.collision_checks) for r in rs),
        )
        for p, rs in out.items()
    }


def best_members(
    records: Iterable[TrialRecord],
    families: Mapping[str, Sequence[str]],
    seed: int,
    problems: Sequence[str],
) -> dict[str, str]:
    """Each family's best member on the screen (the trials of ``seed``): most problems
    executed cleanly, then fewest checks, then name. A family without members is left out.

    Raises:
        PlannerlabError: a member has not run every problem of the screen (the screen is
            incomplete: run it first).
    """
    recs = [r for r in records if r.problem in set(problems)]
    table = screen_table(recs, seed)
    out: dict[str, str] = {}
    for family, members in families.items():
        if not members:
            continue
        missing = [m for m in members if m not in table or table[m].problems < len(set(problems))]
        if missing:
            raise PlannerlabError(
                f"the screen (seed {seed}) is incomplete for {family!r}: "
                f"{', '.join(missing)} ha{'s' if len(missing) == 1 else 've'} not run every "
                f"problem of {', '.join(problems)}"
            )
        out[family] = min((table[m] for m in members), key=Screened.rank).planner
    return out


__all__ = ["Screened", "best_members", "executed_cleanly", "screen_table"]

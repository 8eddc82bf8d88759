"""What a report says about its comparison besides the records: :class:`ReportMeta` (the
mapping ``plannerlab compare`` writes to ``meta.json``, typed) and :func:`machine_info`."""

from __future__ import annotations

import dataclasses
import os
import platform
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from plannerlab.problem.load import Budget


# ---------------------------------------------------------------------- metadata
@dataclass(frozen=True)
class ReportMeta:
    """What a report says about its comparison besides the records (``meta.json``).

    Build it with :meth:`of` from the mapping ``plannerlab compare`` writes (any subset of
    these keys; others are kept in ``meta.json`` and not read here).

    Attributes:
        name, command: the comparison's name and the command that reproduces it.
        problems, planners, seeds: what was compared; ``seeds_spec`` as given.
        budget: the budget overrides; ``budgets_used``: per problem, the budget its
            trials ran with (a :class:`~plannerlab.problem.load.Budget`).
        settings: per planner, the settings overrides; ``legs``: the legs asked for.
        execute, jobs: executed in PyBullet; trials run at once.
        trials, ran, skipped, errors: trials asked for, run now, reused from the store,
            and those that did not run to their end.
        started_at, wall_s, store: this invocation's start, wall time [s] and the store.
        versions, machine: package versions and the machine (:func:`machine_info`).
    """

    name: str = ""
    command: str = ""
    problems: tuple[str, ...] = ()
    planners: tuple[str, ...] = ()
    seeds: tuple[int, ...] = ()
    seeds_spec: str = ""
    budget: Mapping[str, Any] = field(default_factory=dict)
    budgets_used: Mapping[str, Budget] = field(default_factory=dict)
    settings: Mapping[str, Any] = field(default_factory=dict)
    legs: str | None = None
    execute: bool = False
    jobs: int | str = ""
    trials: int | None = None
    ran: int | str = "?"
    skipped: int | str = "?"
    errors: int = 0
    started_at: str = ""
    wall_s: float | None = None
    store: str = ""
    versions: Mapping[str, str] = field(default_factory=dict)
    machine: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def of(cls, meta: Mapping[str, Any] | ReportMeta) -> ReportMeta:
        """The metadata from a mapping (its keys among the fields)."""
        if isinstance(meta, ReportMeta):
            return meta
        known = {f.name for f in dataclasses.fields(cls)}
        values = {k: v for k, v in meta.items() if k in known and v is not None}
        for k in ("problems", "planners", "seeds"):
            if k in values:
                values[k] = tuple(values[k])
        budgets = values.pop("budgets_used", {})
        values["budgets_used"] = {
            p: b if isinstance(b, Budget) else Budget().replace(**b) for p, b in budgets.items()
        }
        return cls(**values)


def machine_info() -> dict[str, Any]:
    """Where the numbers were measured: host, OS, CPU model and count, memory."""
    info: dict[str, Any] = {
        "hostname": platform.node() or "unknown",
        "platform": platform.platform(),
        "machine": platform.machine(),
        "cpu_count": os.cpu_count(),
        "cpu_model": platform.processor() or "unknown",
    }
    try:
        info["cpu_affinity"] = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        pass
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                info["cpu_model"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                info["memory_gb"] = round(int(line.split()[1]) / 1024**2, 1)
                break
    except (OSError, ValueError, IndexError):
        pass
    return info


__all__ = ["ReportMeta", "machine_info"]

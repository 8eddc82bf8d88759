"""One comparison, specified and checked before any trial starts: :class:`ComparisonSpec`.

``plannerlab compare`` and :func:`plannerlab.compare` build the same specification from
their arguments, so both run the same grid with the same checks: the planners exist and
accept their settings, every planner works on every problem's robot kind, no two problem
files share a name, the legs exist, the budget, jobs and time limits are positive, the
backend is known. A mistake is reported before the first process starts, never as a grid
of failed trials.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from plannerlab.comparison.trial import Scalar, Trial
from plannerlab.errors import PlannerlabError
from plannerlab.problem.load import Budget, Problem
from plannerlab.record.trial import TrialRecord
from plannerlab.run.pipeline import legs_from_spec

#: the backends a comparison runs on, by name
BACKENDS = ("local", "ray")
#: wall-clock allowance per leg when the budget has no time limit [s]
LEG_ALLOWANCE_S = 600.0
#: wall-clock allowance per executed leg [s]
EXECUTE_ALLOWANCE_S = 120.0
#: start-up allowance per trial [s]
STARTUP_ALLOWANCE_S = 60.0
#: the budget keys a comparison may override
BUDGET_KEYS = ("max_iterations", "max_collision_checks", "time_limit_s")


def default_trial_timeout_s(time_limit_s: float | None, n_legs: int, execute: bool) -> float:
    """A trial's wall-clock limit derived from its budget: per leg twice the time limit
    plus 30 s (or :data:`LEG_ALLOWANCE_S` when only checks or iterations are budgeted, which
    have no clock), plus :data:`EXECUTE_ALLOWANCE_S` per executed leg, plus
    :data:`STARTUP_ALLOWANCE_S`."""
    per_leg = 2.0 * float(time_limit_s) + 30.0 if time_limit_s else LEG_ALLOWANCE_S
    if execute:
        per_leg += EXECUTE_ALLOWANCE_S
    return STARTUP_ALLOWANCE_S + max(1, int(n_legs)) * per_leg


@dataclass(frozen=True)
class ComparisonSpec:
    """Problems × planners × seeds, with everything each trial needs (see :meth:`build`).

    Attributes:
        problems: the loaded problems; ``problem_files``: their files (absolute).
        planners: registry names, in order, each once.
        seeds: one trial per seed.
        budget: budget overrides for every trial (keys of :data:`BUDGET_KEYS`).
        settings: per planner, settings overrides.
        legs_spec: the legs as given (None: every leg); ``legs``: per problem name, the
            leg indices (None: every leg).
        execute: execute each trial's solved legs in PyBullet.
        jobs: trial processes alive at once.
        backend: ``local`` or ``ray``; ``address``: a Ray cluster's address.
        trial_timeout_s: one wall-clock limit for every trial, or None to derive one from
            each trial's budget (:func:`default_trial_timeout_s`).
        retry_errors: rerun trials stored as ``error`` or ``timeout``.
        built: each planner built with its settings (to check them), which every trial
            of it takes (its process builds none).
    """

    problems: tuple[Problem, ...]
    problem_files: tuple[Path, ...]
    planners: tuple[str, ...]
    seeds: tuple[int, ...]
    budget: Mapping[str, Scalar] = field(default_factory=dict)
    settings: Mapping[str, Mapping[str, Scalar]] = field(default_factory=dict)
    legs_spec: str | None = None
    legs: Mapping[str, list[int] | None] = field(default_factory=dict)
    execute: bool = False
    jobs: int = 1
    backend: str = "local"
    address: str | None = None
    trial_timeout_s: float | None = None
    retry_errors: bool = False
    built: Mapping[str, Any] = field(default_factory=dict, repr=False)

    @classmethod
    def build(
        cls,
        problems: Sequence[str | Path],
        planners: Sequence[str],
        seeds: Iterable[int],
        *,
        budget: Mapping[str, Scalar] | None = None,
        settings: Mapping[str, Mapping[str, Scalar]] | None = None,
        legs: str | None = None,
        execute: bool = False,
        jobs: int = 1,
        backend: str = "local",
        address: str | None = None,
        trial_timeout_s: float | None = None,
        retry_errors: bool = False,
    ) -> ComparisonSpec:
        """Check everything and load the problems.

        Args:
            problems: bundled problem names or problem file paths (each once).
            planners: registry names (each once).
            seeds: the seeds.
            budget: overrides of ``max_iterations``, ``max_collision_checks``,
                ``time_limit_s`` (None values are dropped).
            settings: per planner, settings overrides.
            legs: indices or goal names, comma-separated (None or ``all``: every leg).
            execute, jobs, backend, address, trial_timeout_s, retry_errors: see the class.

        Raises:
            PlannerlabError: anything that would make a trial fail for a reason other
                than its planner (the message names the argument and what was expected).
        """
        from plannerlab.planners import get_entry, make_planner
        from plannerlab.problem.catalog import load_problem, resolve_problem_path

        if jobs < 1:
            raise PlannerlabError(f"--jobs: expected >= 1, got {jobs}")
        if trial_timeout_s is not None and not (
            math.isfinite(trial_timeout_s) and trial_timeout_s > 0
        ):
            raise PlannerlabError(f"--trial-timeout: expected a number > 0, got {trial_timeout_s}")
        if backend not in BACKENDS:
            raise PlannerlabError(
                f"backend: expected one of {', '.join(BACKENDS)}, got {backend!r}"
            )
        if address is not None and backend != "ray":
            raise PlannerlabError("--address is for --backend ray")
        budget = {k: v for k, v in (budget or {}).items() if v is not None}
        unknown = sorted(set(budget) - set(BUDGET_KEYS))
        if unknown:
            raise PlannerlabError(
                f"budget: unknown key(s) {', '.join(unknown)}; expected {', '.join(BUDGET_KEYS)}"
            )
        for key, v in budget.items():
            if isinstance(v, bool) or not isinstance(v, int | float) or not v > 0:
                raise PlannerlabError(f"budget {key}: expected a number > 0, got {v!r}")
        seeds = tuple(int(s) for s in seeds)
        if not seeds:
            raise PlannerlabError("seeds: give at least one seed")
        planners = tuple(dict.fromkeys(planners))
        if not planners:
            raise PlannerlabError("--planners: give at least one planner name")
        entries = {name: get_entry(name) for name in planners}  # unknown: "did you mean"
        settings = {k: dict(v) for k, v in (settings or {}).items() if v}
        stray = sorted(set(settings) - set(planners))
        if stray:
            raise PlannerlabError(
                f"settings for {', '.join(stray)}, which is not among the planners compared"
            )
        # unknown setting or bad value: raises now; each trial takes its planner from here
        built = {name: make_planner(name, settings.get(name)) for name in planners}
        loaded = [
            (load_problem(spec), resolve_problem_path(spec).resolve())
            for spec in dict.fromkeys(problems)
        ]
        if not loaded:
            raise PlannerlabError("give at least one problem")
        names = [p.name for p, _ in loaded]
        if len(set(names)) != len(names):
            raise PlannerlabError(f"two problem files have the same problem name: {names}")
        for problem, _ in loaded:
            for name, entry in entries.items():
                if entry.robots is not None and problem.robot.kind not in entry.robots:
                    raise PlannerlabError(
                        f"planner {name} works on {', '.join(entry.robots)} robots; "
                        f"{problem.name} has a {problem.robot.kind}"
                    )
        return cls(
            problems=tuple(p for p, _ in loaded),
            problem_files=tuple(path for _, path in loaded),
            planners=planners,
            seeds=seeds,
            budget=budget,
            settings=settings,
            legs_spec=legs,
            legs={p.name: legs_from_spec(p, legs) for p, _ in loaded},
            execute=bool(execute),
            jobs=int(jobs),
            backend=backend,
            address=address,
            trial_timeout_s=trial_timeout_s,
            retry_errors=bool(retry_errors),
            built=built,
        )

    @property
    def problem_names(self) -> list[str]:
        return [p.name for p in self.problems]

    @property
    def trials(self) -> list[Trial]:
        """Every trial, seeds outermost within a problem (an interrupted run stays balanced
        over the planners)."""
        return [
            Trial.make(
                problem.name,
                path,
                planner,
                seed,
                budget=self.budget,
                settings=self.settings.get(planner),
                legs=self.legs.get(problem.name),
                execute=self.execute,
                loaded=problem,  # parsed once, here: the trial's process does not parse it
                planner_obj=self.built.get(planner),  # built once, here
            )
            for problem, path in zip(self.problems, self.problem_files, strict=True)
            for seed in self.seeds
            for planner in self.planners
        ]

    def budget_used(self, problem: Problem) -> Budget:
        """The budget a problem's trials run with (its own, with the overrides)."""
        return problem.budget.replace(**self.budget)

    def trial_timeout(self, trial: Trial) -> float:
        """The wall-clock limit of one trial [s]."""
        if self.trial_timeout_s is not None:
            return float(self.trial_timeout_s)
        problem = next(p for p in self.problems if p.name == trial.problem)
        legs = self.legs.get(problem.name)
        n_legs = len(legs) if legs is not None else problem.legs
        return default_trial_timeout_s(
            self.budget_used(problem).time_limit_s, n_legs, trial.execute
        )

    def sort_key(self, rec: TrialRecord) -> tuple[int, int, int]:
        """Records in the specification's order: problem, planner, seed."""
        order_p = {n: i for i, n in enumerate(self.problem_names)}
        order_pl = {n: i for i, n in enumerate(self.planners)}
        return (order_p.get(rec.problem, 1 << 30), order_pl.get(rec.planner, 1 << 30), rec.seed)

    def to_dict(self) -> dict[str, Any]:
        """The specification as data (a report's metadata)."""
        return {
            "problems": self.problem_names,
            "problem_files": [str(p) for p in self.problem_files],
            "planners": list(self.planners),
            "seeds": list(self.seeds),
            "budget": dict(self.budget),
            "budgets_used": {p.name: self.budget_used(p).to_dict() for p in self.problems},
            "settings": {k: dict(v) for k, v in self.settings.items()},
            "legs": self.legs_spec,
            "execute": self.execute,
            "jobs": self.jobs,
            "backend": self.backend,
            "trial_timeout_s": self.trial_timeout_s,
            "trials": len(self.trials),
        }


__all__ = [
    "BACKENDS",
    "BUDGET_KEYS",
    "ComparisonSpec",
    "default_trial_timeout_s",
]

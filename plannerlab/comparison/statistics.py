"""Statistics of trial records: one row per (problem, planner).

Decisions:

* **Statistics** (:func:`summarise`): success = every leg SOLVED; a trial with status
  ``error``, ``timeout`` or ``died`` counts in ``n`` as a failure and in ``errors``.
  Times (sum over legs of ``time_s``) and collision checks are over every trial that ran;
  path quality (length, roughness, clearance along the path) and the final tip errors
  over successful trials only, the tip errors beside the last leg's tolerances (a failed
  trial's last state is no result); 95 % Wilson score interval for the success rate.
* **Deterministic planners.** Seeds mean something only if they change the trial. A row
  is ``deterministic`` when it has two or more trials and all of them are the same trial:
  the same :func:`trial_fingerprint` (every leg's status, path hash, counts and tip
  errors, and the execution's verdict; clocks left out). Its seeds are one run repeated,
  so it gets no interval (``ci95_low``/``ci95_high`` NaN) and the tables say
  "deterministic" where the interval would be. This is detected from what the trials did,
  not read from the registry's ``uses_rng``: a planner that draws from its generator only
  at a stall (``gradient.clearance+rrtconnect``) runs one trial on every seed of a
  problem where it never stalls, and its interval would mean as little there.
  ``distinct_trials`` counts the different trials of a row.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.record.codec import dumps, to_data
from plannerlab.record.trial import TrialRecord


# ---------------------------------------------------------------------- statistics
def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (95 % by default), from
    ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``.

    ``(nan, nan)`` for ``n == 0``. 0/20 gives (0, 0.161); 20/20 gives (0.839, 1).
    """
    if n <= 0:
        return (math.nan, math.nan)
    if not 0 <= successes <= n:
        raise ValueError(f"successes must be in [0, {n}], got {successes}")
    from scipy.stats import binomtest  # here: scipy.stats takes a while to import

    ci = binomtest(int(successes), int(n)).proportion_ci(
        confidence_level=confidence, method="wilson"
    )
    return (float(ci.low), float(ci.high))


def trial_fingerprint(rec: TrialRecord) -> str:
    """What a trial did, as a string: two trials with the same fingerprint are the same
    trial (seeds that changed nothing). Its status and error, every leg's status, path
    digest, counts and tip errors, and the execution's verdict; clocks are left out."""
    return dumps(
        {
            "status": rec.status,
            "error": rec.error,
            "legs": [
                (
                    leg.leg,
                    leg.status,
                    leg.path_points,
                    leg.path_sha256,
                    leg.iterations,
                    leg.collision_checks,
                    leg.fk_calls,
                    leg.local_minima,
                    leg.escapes,
                    leg.pos_err_m,
                    leg.angle_err_deg,
                )
                for leg in rec.legs_run
            ],
            "execution": (rec.exec_success, rec.exec_max_track_err_rad, rec.exec_contacts),
        }
    )


def _vals(xs: Iterable[Any]) -> np.ndarray:
    return np.array([float(x) for x in xs if x is not None and math.isfinite(float(x))])


def _pct(xs: np.ndarray, q: float) -> float:
    return float(np.percentile(xs, q)) if xs.size else math.nan


@dataclass(frozen=True)
class SummaryRow:
    """One (problem, planner) of a comparison (NaN where there is nothing to measure).

    Attributes:
        n, successes, errors: trials, those whose every leg solved, those that did not
            run to their end (raised, timed out, died).
        success_rate, ci95_low, ci95_high: the rate and its 95 % Wilson interval (NaN for
            a ``deterministic`` row: its ``distinct_trials`` is 1, its seeds one run).
        time_median_s, time_p75_s, time_p95_s: planning time summed over legs, over the
            trials that ran [s]; ``checks_median``, ``iterations_median`` likewise.
        path_length_median: joint-space length summed over legs, median over successes.
        smoothness_median_rad2: roughness summed over legs (lower is smoother), median over
            successes [rad²].
        path_clearance_min_m: smallest clearance along the whole path, over successes [m];
            ``path_clearance_median_m`` the median over them of each trial's smallest.
        pos_err_median_m, angle_err_median_deg: the last leg's tip errors, median over
            successes; ``pos_tol_m``, ``angle_tol_deg`` that leg's tolerances (NaN when
            none solved or not recorded).
        local_minima, escapes: totals over the trials that ran.
        executed, exec_successes, exec_success_rate: executions in PyBullet and the clean
            ones; ``exec_track_err_median_rad``, ``exec_deviation_median_m`` medians,
            ``exec_clearance_min_m`` the smallest, ``exec_contacts`` the total of
            unexpected contacts.
    """

    problem: str
    planner: str
    n: int
    successes: int
    errors: int
    success_rate: float
    ci95_low: float
    ci95_high: float
    deterministic: bool
    distinct_trials: int
    time_median_s: float
    time_p75_s: float
    time_p95_s: float
    path_length_median: float
    smoothness_median_rad2: float
    path_clearance_min_m: float
    path_clearance_median_m: float
    pos_err_median_m: float
    pos_tol_m: float
    angle_err_median_deg: float
    angle_tol_deg: float
    checks_median: float
    iterations_median: float
    local_minima: int
    escapes: int
    executed: int
    exec_successes: int
    exec_success_rate: float
    exec_track_err_median_rad: float
    exec_deviation_median_m: float
    exec_clearance_min_m: float
    exec_contacts: int

    def to_dict(self) -> dict[str, Any]:
        """The row as plain data (non-finite numbers None, the codec's convention)."""
        out: dict[str, Any] = to_data(dataclasses.asdict(self))
        return out


#: the columns of a summary row, in order
SUMMARY_COLUMNS = tuple(f.name for f in dataclasses.fields(SummaryRow))


def _tolerance(ok: list[TrialRecord], attr: str) -> float:
    """The last leg's tolerance of the successful trials (the same leg for all: they
    solved every leg asked for); NaN when none solved or none recorded it."""
    vals = _vals(getattr(r.last_leg, attr) for r in ok if r.last_leg is not None)
    return float(vals.max()) if vals.size else math.nan


def _row(problem: str, planner: str, recs: list[TrialRecord]) -> SummaryRow:
    n = len(recs)
    ok = [r for r in recs if r.success]
    ran = [r for r in recs if r.ran]
    distinct = len({trial_fingerprint(r) for r in recs})
    deterministic = n >= 2 and distinct == 1
    # the seeds of a deterministic row are one trial: no interval over copies of it
    lo, hi = (math.nan, math.nan) if deterministic else wilson_interval(len(ok), n)
    t = _vals(r.time_s for r in ran)
    last_ok = [r.last_leg for r in ok if r.last_leg is not None]
    clear = _vals(r.path_clearance_m for r in ok)
    ex = [r for r in recs if r.executions is not None]
    exec_ok = sum(1 for r in ex if r.exec_success)
    return SummaryRow(
        problem=problem,
        planner=planner,
        n=n,
        successes=len(ok),
        errors=n - len(ran),
        success_rate=len(ok) / n if n else math.nan,
        ci95_low=lo,
        ci95_high=hi,
        deterministic=deterministic,
        distinct_trials=distinct,
        time_median_s=_pct(t, 50),
        time_p75_s=_pct(t, 75),
        time_p95_s=_pct(t, 95),
        path_length_median=_pct(_vals(r.path_length for r in ok), 50),
        smoothness_median_rad2=_pct(_vals(r.roughness_rad2 for r in ok), 50),
        path_clearance_min_m=_pct(clear, 0),
        path_clearance_median_m=_pct(clear, 50),
        pos_err_median_m=_pct(_vals(x.pos_err_m for x in last_ok), 50),
        pos_tol_m=_tolerance(ok, "pos_tol_m"),
        angle_err_median_deg=_pct(_vals(x.angle_err_deg for x in last_ok), 50),
        angle_tol_deg=_tolerance(ok, "angle_tol_deg"),
        checks_median=_pct(_vals(r.collision_checks for r in ran), 50),
        iterations_median=_pct(_vals(r.iterations for r in ran), 50),
        local_minima=sum(r.local_minima for r in ran),
        escapes=sum(r.escapes for r in ran),
        executed=len(ex),
        exec_successes=exec_ok,
        exec_success_rate=exec_ok / len(ex) if ex else math.nan,
        exec_track_err_median_rad=_pct(_vals(r.exec_max_track_err_rad for r in ex), 50),
        exec_deviation_median_m=_pct(_vals(r.exec_max_deviation_m for r in ex), 50),
        exec_clearance_min_m=_pct(_vals(r.exec_min_clearance_m for r in ex), 0),
        exec_contacts=sum(r.exec_contacts or 0 for r in ex),
    )


def summarise(records: Iterable[TrialRecord]) -> list[SummaryRow]:
    """One row per (problem, planner), in order of first appearance (see
    :class:`SummaryRow`)."""
    groups: dict[tuple[str, str], list[TrialRecord]] = {}
    for r in records:
        groups.setdefault((r.problem, r.planner), []).append(r)
    return [_row(problem, planner, recs) for (problem, planner), recs in groups.items()]


__all__ = [
    "SUMMARY_COLUMNS",
    "SummaryRow",
    "summarise",
    "trial_fingerprint",
    "wilson_interval",
]

"""Statistics of trial records: one row per (problem, planner).

Decisions:

* **Statistics** (:func:`summarise`): success = every leg SOLVED; a trial with status
  ``error`` or ``timeout`` counts in ``n`` as a failure and in ``errors``. Times (sum
  over legs of ``time_s``) and final tip errors are over every trial that did not error
  or time out; path length over successful trials only; 95 % Wilson score interval for
  the success rate.
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

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from plannerlab.comparison.trial import ERROR_STATUS, TIMEOUT_STATUS
from plannerlab.record.codec import dumps


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


#: per-leg fields of a trial record that say what the leg did (no clocks)
_FINGERPRINT_LEG_KEYS = (
    "leg",
    "status",
    "path_points",
    "path_sha256",
    "iterations",
    "collision_checks",
    "fk_calls",
    "local_minima",
    "escapes",
    "pos_err_m",
    "angle_err_deg",
)


def trial_fingerprint(rec: Mapping[str, Any]) -> str:
    """What a trial did, as a string: two trials with the same fingerprint are the same
    trial (seeds that changed nothing). Its status and error, every leg's
    :data:`_FINGERPRINT_LEG_KEYS` and the execution's verdict; clocks are left out."""
    ex = rec.get("execution") or {}
    return dumps(
        {
            "status": rec.get("status"),
            "error": rec.get("error"),
            "legs": [
                {k: leg.get(k) for k in _FINGERPRINT_LEG_KEYS} for leg in rec.get("legs_run") or []
            ],
            "execution": {k: ex.get(k) for k in ("success", "max_track_err_rad", "contacts")},
        }
    )


def _vals(xs: Iterable[Any]) -> np.ndarray:
    return np.array([float(x) for x in xs if x is not None and math.isfinite(float(x))])


def _pct(xs: np.ndarray, q: float) -> float:
    return float(np.percentile(xs, q)) if xs.size else math.nan


#: the columns of a summary row, in order
SUMMARY_COLUMNS = (
    "problem",
    "planner",
    "n",
    "successes",
    "errors",
    "success_rate",
    "ci95_low",
    "ci95_high",
    "deterministic",
    "distinct_trials",
    "time_median_s",
    "time_p75_s",
    "time_p95_s",
    "path_length_median",
    "pos_err_median_m",
    "angle_err_median_deg",
    "checks_median",
    "iterations_median",
    "local_minima",
    "escapes",
    "executed",
    "exec_successes",
    "exec_success_rate",
    "exec_track_err_median_rad",
    "exec_deviation_median_m",
    "exec_clearance_min_m",
    "exec_contacts",
)


def summarise(records: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One row per (problem, planner), in order of first appearance; keys
    :data:`SUMMARY_COLUMNS` (NaN where there is nothing to measure)."""
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for r in records:
        groups.setdefault((str(r["problem"]), str(r["planner"])), []).append(r)
    rows = []
    for (problem, planner), recs in groups.items():
        n = len(recs)
        ok = [r for r in recs if r.get("success")]
        ran = [r for r in recs if r.get("status") not in (ERROR_STATUS, TIMEOUT_STATUS)]
        distinct = len({trial_fingerprint(r) for r in recs})
        deterministic = n >= 2 and distinct == 1
        # the seeds of a deterministic row are one trial: no interval over copies of it
        lo, hi = (math.nan, math.nan) if deterministic else wilson_interval(len(ok), n)
        t = _vals(r["totals"].get("time_s") for r in ran)
        ex = [r["execution"] for r in recs if r.get("execution")]
        rows.append(
            {
                "problem": problem,
                "planner": planner,
                "n": n,
                "successes": len(ok),
                "errors": n - len(ran),
                "success_rate": len(ok) / n if n else math.nan,
                "ci95_low": lo,
                "ci95_high": hi,
                "deterministic": deterministic,
                "distinct_trials": distinct,
                "time_median_s": _pct(t, 50),
                "time_p75_s": _pct(t, 75),
                "time_p95_s": _pct(t, 95),
                "path_length_median": _pct(_vals(r["totals"].get("path_length") for r in ok), 50),
                "pos_err_median_m": _pct(_vals(r.get("final_pos_err_m") for r in ran), 50),
                "angle_err_median_deg": _pct(_vals(r.get("final_angle_err_deg") for r in ran), 50),
                "checks_median": _pct(_vals(r["totals"].get("collision_checks") for r in ran), 50),
                "iterations_median": _pct(_vals(r["totals"].get("iterations") for r in ran), 50),
                "local_minima": int(sum(r["totals"].get("local_minima") or 0 for r in ran)),
                "escapes": int(sum(r["totals"].get("escapes") or 0 for r in ran)),
                "executed": len(ex),
                "exec_successes": sum(1 for e in ex if e.get("success")),
                "exec_success_rate": (
                    sum(1 for e in ex if e.get("success")) / len(ex) if ex else math.nan
                ),
                "exec_track_err_median_rad": _pct(
                    _vals(e.get("max_track_err_rad") for e in ex), 50
                ),
                "exec_deviation_median_m": _pct(_vals(e.get("max_deviation_m") for e in ex), 50),
                "exec_clearance_min_m": _pct(_vals(e.get("min_clearance_m") for e in ex), 0),
                "exec_contacts": int(sum(e.get("contacts") or 0 for e in ex)),
            }
        )
    return rows


__all__ = [
    "SUMMARY_COLUMNS",
    "summarise",
    "trial_fingerprint",
    "wilson_interval",
]

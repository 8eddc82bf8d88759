"""The records of a trial store: :class:`TrialRecord` (one trial), :class:`LegRecord` (one
planned leg: a :class:`~plannerlab.record.leg.PlanResult`'s record, :meth:`LegRecord.of`)
and :class:`ExecutionRecord` (one executed leg: an
:class:`~plannerlab.record.execution.Execution`'s record, :meth:`ExecutionRecord.of`),
typed end to end.

They are msgspec ``Struct`` s (``bench/records_bench.py`` measured them against
dataclasses with the same fields on the stores under ``results/``: the same JSON, read and
written several times faster, and every field's type checked on reading). A store line is
``msgspec.json.encode(record)``; :func:`decode_trial` reads one back, checking every type.

Conventions:

* A number that was not measured, or was not finite, is ``None`` (JSON ``null``: the
  codec's convention, :mod:`plannerlab.record.codec`); the tables print "-" for it.
* A record's ``format`` is its schema version, :data:`TRIAL_FORMAT`. Lines of the previous
  version (:data:`OLD_TRIAL_FORMATS`: every store committed under ``results/``) are read
  and converted (:func:`trial_from_v1`); a line of any other version is refused by name
  (:class:`StoreFormatError`: the file, the line, the version found, the version expected
  and what to do).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import msgspec
import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.record.codec import to_data
from plannerlab.record.execution import ContactRecord, Execution
from plannerlab.record.leg import PlanResult, Status
from plannerlab.robots.paths import path_length

#: the schema version written in every trial record's ``format``
TRIAL_FORMAT = "plannerlab.trial/2"
#: versions read and converted (the stores committed under ``results/`` are all of it)
OLD_TRIAL_FORMATS = ("plannerlab.trial/1",)

#: statuses of a trial besides the planner's (:class:`Status`): the trial raised
ERROR_STATUS = "error"
#: killed for running past its wall-clock limit
TIMEOUT_STATUS = "timeout"
#: its process died before reporting (a crash in native code, a kill): retried by the
#: next run of the same comparison
DIED_STATUS = "died"

#: a float field: None when it was not measured or was not finite
Num = float | None
#: most progress rows a leg record keeps (evenly picked, the first and last always)
MAX_PROGRESS_ROWS = 200


def thinned(rows: Any, most: int = MAX_PROGRESS_ROWS) -> np.ndarray:
    """At most ``most`` rows of a (k, 4) progress table, evenly picked, first and last kept."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    if len(rows) <= most:
        return rows
    return rows[np.unique(np.linspace(0, len(rows) - 1, most).round().astype(int))]


def _finite(d: Any) -> Any:
    """Plain data with every non-finite float None (the codec's convention; a record
    compares equal to itself read back)."""
    if isinstance(d, float):
        return d if math.isfinite(d) else None
    if isinstance(d, dict):
        return {k: _finite(v) for k, v in d.items()}
    if isinstance(d, list | tuple):
        return [_finite(v) for v in d]
    return d


def num(x: Any) -> float | None:
    """A number for a record's float field: None for None, NaN and ±inf."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def nan(x: float | None) -> float:
    """A record's float field as a float (NaN for None)."""
    return math.nan if x is None else float(x)


def reached_best(status: Status | str, path_points: int) -> bool:
    """A leg's last state is the best it reached, so its tip errors describe a result: a
    solved leg, or one that ended as close as it got (approximate) or stalled there (a
    local minimum) after moving. A leg that planned nothing (its path is its start), gave
    up or failed has no such state: its errors are those of wherever it stopped."""
    status = Status(status)
    return status is Status.SOLVED or (
        status in (Status.APPROXIMATE, Status.LOCAL_MINIMUM) and path_points > 1
    )


class LegRecord(msgspec.Struct, frozen=True, kw_only=True):
    """One planned leg as a trial store keeps it: its
    :class:`~plannerlab.record.leg.PlanResult` without the path and trace (identified by
    ``path_points`` and ``path_sha256``), with the path's quality measured.

    Attributes (beside :class:`~plannerlab.record.leg.PlanResult`'s, which they mirror):
        pos_tol_m, angle_tol_deg: the leg's goal tolerances, which ``pos_err_m`` and
            ``angle_err_deg`` are judged against.
        path_points: states of the path (its waypoints); ``path_sha256`` its digest.
        path_length: joint-space length of the path [rad; m for prismatic joints].
        path_clearance_m: smallest clearance along the whole path [m]: every state of the
            final re-check's grid (``joint_step / 4``), the robot's true capsules (no
            margin) against the scene and between its checked link pairs; measured after
            the solve, outside the planner's clock (None: not measured, e.g. a leg that
            did not solve, or a contact-permitting planner's).
        roughness_rad2: the path's roughness [rad²]
            (:func:`~plannerlab.robots.paths.roughness`: the sum of squared turning angles
            of the path resampled at 200 states of equal arc length; lower is smoother).
        progress: the thinned progress rows ``(time_s, collision_checks, best_goal_dist,
            best_cost)``.
    """

    planner: str
    problem: str
    leg: int
    goal: str
    status: Status
    reason: str = ""
    time_s: float = 0.0
    iterations: int = 0
    collision_checks: int = 0
    fk_calls: int = 0
    pos_err_m: Num = None
    angle_err_deg: Num = None
    pos_tol_m: Num = None
    angle_tol_deg: Num = None
    min_clearance_m: Num = None
    path_clearance_m: Num = None
    roughness_rad2: Num = None
    path_length: Num = None
    path_points: int = 0
    path_sha256: str = ""
    progress: tuple[tuple[Num, ...], ...] = ()
    local_minima: int = 0
    escapes: int = 0
    seed: int | None = None
    settings: dict[str, Any] = {}
    extra: dict[str, Any] = {}
    contact_plan: dict[str, Any] | None = None

    @classmethod
    def of(
        cls, r: PlanResult, continuous: np.ndarray, progress_rows: int = MAX_PROGRESS_ROWS
    ) -> LegRecord:
        """The record of a planned leg (its path's length on ``continuous`` joints; at most
        ``progress_rows`` progress rows, evenly picked, the first and last kept)."""
        d = r.to_dict(include_path=False)
        d["path_length"] = path_length(r.path, continuous)
        d["progress"] = to_data(thinned(r.progress, progress_rows))
        return msgspec.convert(_finite(d), cls)

    @property
    def solved(self) -> bool:
        return self.status is Status.SOLVED

    @property
    def reached_best(self) -> bool:
        """The leg's last state is the best it reached: its tip errors mean something
        (:func:`reached_best`)."""
        return reached_best(self.status, self.path_points)


class ExecutionRecord(msgspec.Struct, frozen=True, kw_only=True):
    """One executed leg as a trial store keeps it: its
    :class:`~plannerlab.record.execution.Execution` without the per-waypoint log (the
    fields mean what they mean there), with the verdicts the log gave (``success``,
    ``max_track_err_rad``, ``max_tip_track_err_m``; ``log_points``: its length) and the
    count of unexpected contacts (``contact_count``; the contacts themselves in
    ``contacts``)."""

    problem: str
    leg: int | None
    goal: str | None
    success: bool
    path_valid: bool | None
    reason: str = ""
    failures: tuple[str, ...] = ()
    contact_count: int = 0
    contacts: tuple[ContactRecord, ...] = ()
    max_deviation_m: Num = None
    max_deviation_limit_m: Num = None
    reference_deviation_m: Num = None
    max_deviation_time_s: Num = None
    min_clearance_m: Num = None
    min_clearance_time_s: Num = None
    min_clearance_pair: tuple[str, str] | None = None
    clearance_samples: int = 0
    max_track_err_rad: Num = None
    max_tip_track_err_m: Num = None
    track_err_limit_rad: Num = None
    final_pos_err_m: Num = None
    final_angle_err_deg: Num = None
    final_track_err_rad: Num = None
    final_tip_track_err_m: Num = None
    goal_reached: bool | None = None
    recheck_joint_step: Num = None
    recheck_states: int = 0
    recheck_first_invalid_edge: int | None = None
    recheck_pairs: tuple[tuple[str, str], ...] = ()
    trajectory_valid: bool | None = None
    waypoint_step: Num = None
    steps_per_waypoint: int = 0
    settle_steps: int = 0
    dt_s: Num = None
    contact_tol_m: Num = None
    gravity_mps2: tuple[float, float, float] = (0.0, 0.0, 0.0)
    timing: str = "waypoints"
    duration_s: Num = None
    spline_dev: Num = None
    q_start_rad: tuple[float, ...] = ()
    carried_over: bool = False
    start_offset_rad: Num = None
    q_final_rad: tuple[float, ...] = ()
    sim_time_s: Num = None
    wall_time_s: Num = None
    solver: str = ""
    log_points: int = 0
    extra: dict[str, Any] = {}
    geometry: dict[str, str] = {}

    @classmethod
    def of(cls, e: Execution) -> ExecutionRecord:
        """The record of an executed leg: its log left out, the log's verdicts kept."""
        d = e.to_dict(include_log=False)
        d["contact_count"] = len(e.unexpected_contacts)
        d["failures"] = list(e.failures)
        d["max_tip_track_err_m"] = e.max_tip_track_err_m
        return msgspec.convert(_finite(d), cls)


def _min(xs: Sequence[float | None]) -> float | None:
    vals = [x for x in xs if x is not None]
    return min(vals) if vals else None


def _max(xs: Sequence[float | None]) -> float | None:
    vals = [x for x in xs if x is not None]
    return max(vals) if vals else None


class TrialRecord(msgspec.Struct, frozen=True, kw_only=True):
    """One trial (problem, planner, seed, settings) as a trial store keeps it.

    Attributes:
        format: the schema version (:data:`TRIAL_FORMAT`).
        key: the trial's key (``problem/planner/s<seed>/<hash of the config>``).
        problem, problem_file, planner, seed: what ran.
        budget, settings: the trial's overrides; ``legs``: the leg indices asked for
            (None: all); ``execute``: executed in PyBullet.
        status: the first leg's status that is not SOLVED (a :class:`Status` value), or
            ``solved``, or :data:`ERROR_STATUS`, :data:`TIMEOUT_STATUS`,
            :data:`DIED_STATUS`; ``success``: every leg solved.
        error: why a trial raised, timed out or died, in words (None otherwise).
        exit_code, signal: how a trial that died ended (its exit code, or the signal that
            killed it, by name); ``output``: the end of what its process wrote (stdout and
            stderr).
        legs_run: the legs planned, in order (the trial stops at its first unsolved leg).
        executions: the executed legs (the solved ones up to the first that is not), or
            None when nothing was executed; ``executed_legs`` their number.
        budget_used, settings_used: the budget and the planner's settings in effect.
        ompl_seeded, versions, pid, wall_s, cpu_s (the trial process's CPU time), startup_s,
            finished_at: where and how it ran.
    """

    key: str
    problem: str
    problem_file: str
    planner: str
    seed: int
    status: str
    format: str = TRIAL_FORMAT
    budget: dict[str, Any] = {}
    settings: dict[str, Any] = {}
    legs: tuple[int, ...] | None = None
    execute: bool = False
    success: bool = False
    error: str | None = None
    exit_code: int | None = None
    signal: str | None = None
    output: str = ""
    legs_run: tuple[LegRecord, ...] = ()
    executions: tuple[ExecutionRecord, ...] | None = None
    executed_legs: int = 0
    budget_used: dict[str, Any] | None = None
    settings_used: dict[str, Any] = {}
    ompl_seeded: bool = False
    versions: dict[str, str] = {}
    pid: int | None = None
    wall_s: Num = None
    cpu_s: Num = None
    startup_s: Num = None
    finished_at: str = ""

    # ---------------------------------------------------------------- what it did
    @property
    def ran(self) -> bool:
        """The trial ran to its end (it did not raise, time out or die)."""
        return self.status not in (ERROR_STATUS, TIMEOUT_STATUS, DIED_STATUS)

    @property
    def legs_solved(self) -> int:
        return sum(1 for x in self.legs_run if x.solved)

    @property
    def last_leg(self) -> LegRecord | None:
        return self.legs_run[-1] if self.legs_run else None

    @property
    def time_s(self) -> float:
        """Planning time summed over the legs [s]."""
        return float(sum(x.time_s for x in self.legs_run))

    @property
    def iterations(self) -> int:
        return sum(x.iterations for x in self.legs_run)

    @property
    def collision_checks(self) -> int:
        return sum(x.collision_checks for x in self.legs_run)

    @property
    def fk_calls(self) -> int:
        return sum(x.fk_calls for x in self.legs_run)

    @property
    def local_minima(self) -> int:
        return sum(x.local_minima for x in self.legs_run)

    @property
    def escapes(self) -> int:
        return sum(x.escapes for x in self.legs_run)

    @property
    def path_length(self) -> float | None:
        """Joint-space length summed over the legs (None: a leg's is unknown)."""
        lengths = [x.path_length for x in self.legs_run]
        known = [v for v in lengths if v is not None]
        return float(sum(known)) if len(known) == len(lengths) else None

    @property
    def path_clearance_m(self) -> float | None:
        """Smallest clearance along the whole path over the legs [m] (None: none
        measured)."""
        return _min([x.path_clearance_m for x in self.legs_run])

    @property
    def roughness_rad2(self) -> float | None:
        """Roughness summed over the legs [rad²] (None: a leg's is unknown)."""
        r = [x.roughness_rad2 for x in self.legs_run]
        known = [v for v in r if v is not None]
        return float(sum(known)) if r and len(known) == len(r) else None

    # ---------------------------------------------------------------- executed
    @property
    def executed(self) -> bool:
        return self.executions is not None

    @property
    def exec_success(self) -> bool | None:
        """Every executed leg ran cleanly (None: not executed)."""
        if self.executions is None:
            return None
        return bool(self.executions) and all(e.success for e in self.executions)

    @property
    def exec_path_valid(self) -> bool | None:
        if self.executions is None:
            return None
        return all(e.path_valid is not False for e in self.executions)

    @property
    def exec_max_track_err_rad(self) -> float | None:
        return (
            None
            if self.executions is None
            else _max([e.max_track_err_rad for e in self.executions])
        )

    @property
    def exec_max_deviation_m(self) -> float | None:
        if self.executions is None:
            return None
        devs = [e.max_deviation_m for e in self.executions]
        return None if any(d is None for d in devs) else _max(devs)

    @property
    def exec_min_clearance_m(self) -> float | None:
        return (
            None if self.executions is None else _min([e.min_clearance_m for e in self.executions])
        )

    @property
    def exec_contacts(self) -> int | None:
        """Unexpected contacts over the executed legs (None: not executed)."""
        return None if self.executions is None else sum(e.contact_count for e in self.executions)

    @property
    def exec_last(self) -> ExecutionRecord | None:
        return self.executions[-1] if self.executions else None

    def replace(self, **changes: Any) -> TrialRecord:
        return msgspec.structs.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The record as plain JSON-able data (what a store line holds)."""
        out: dict[str, Any] = msgspec.json.decode(msgspec.json.encode(self))
        return out


# ---------------------------------------------------------------------- reading
class StoreFormatError(PlannerlabError):
    """A store line of a schema version this plannerlab does not read."""


class NotJSONError(PlannerlabError):
    """A store line that is not JSON (a line half-written by a kill, say)."""


_DECODER = msgspec.json.Decoder(TrialRecord)
_ENCODER = msgspec.json.Encoder()


def encode_trial(rec: TrialRecord) -> bytes:
    """One store line (without its newline)."""
    return _ENCODER.encode(rec)


def decode_trial(line: bytes | str, where: str = "<record>") -> TrialRecord:
    """Read one store line (this version, or an old one converted).

    Raises:
        StoreFormatError: a line of another schema version, naming ``where`` (the file and
            line), the version found, the version expected and what to do.
        PlannerlabError: a line that is not a trial record (the field and what was
            expected).
    """
    first: Exception | None = None
    try:
        rec = _DECODER.decode(line)
        if rec.format == TRIAL_FORMAT:
            return rec
    except msgspec.ValidationError as exc:  # another version, or not a trial record
        first = exc
    except msgspec.DecodeError as exc:
        raise NotJSONError(f"{where}: not JSON ({exc})") from None
    try:
        data = msgspec.json.decode(line)
    except msgspec.DecodeError as exc:
        raise NotJSONError(f"{where}: not JSON ({exc})") from None
    if not isinstance(data, dict):
        raise PlannerlabError(f"{where}: a trial record (a JSON object), got {type(data).__name__}")
    found = data.get("format")
    if found in OLD_TRIAL_FORMATS:
        return trial_from_v1(data, where)
    if found != TRIAL_FORMAT:
        raise StoreFormatError(
            f"{where}: trial record of version {found!r}; this plannerlab reads "
            f"{TRIAL_FORMAT!r} (and converts {', '.join(map(repr, OLD_TRIAL_FORMATS))}). "
            "Read it with the plannerlab that wrote it (its 'versions' say which), or "
            "run the comparison again into a new --name."
        )
    raise PlannerlabError(f"{where}: not a {TRIAL_FORMAT} record: {first}") from None


def _v1_leg(x: Mapping[str, Any], trial: Mapping[str, Any]) -> dict[str, Any]:
    leg = dict(x)
    for k in ("path", "trace"):
        leg.pop(k, None)
    for k in ("planner", "problem", "seed"):  # the first stores named them per trial only
        leg.setdefault(k, trial.get(k))
    if "extra_lengths" in leg:  # the first stores kept only the lengths of ``extra``
        leg["extra"] = {**leg.pop("extra_lengths"), **leg.get("extra", {})}
    return leg


def _v1_execution(x: Mapping[str, Any], trial: Mapping[str, Any]) -> dict[str, Any]:
    e = dict(x)
    e.setdefault("problem", trial.get("problem"))  # the first stores: per trial only
    e.setdefault("goal", None)
    contacts = e.get("contacts")
    if isinstance(contacts, int):  # stores written before legs were Execution records
        e["contact_count"] = contacts
        e["contacts"] = []
    else:
        e["contact_count"] = sum(1 for c in contacts or [] if not c.get("expected", False))
    e.setdefault("success", False)
    e.setdefault("path_valid", None)
    return e


def trial_from_v1(data: Mapping[str, Any], where: str = "<record>") -> TrialRecord:
    """A ``plannerlab.trial/1`` record (a dict) as a :class:`TrialRecord`: the legs and the
    executions typed, the totals (sums over the legs) dropped, the execution's verdict
    over the legs kept per leg; a died trial (an ``error`` whose reason says its process
    died) gets :data:`DIED_STATUS`.

    Raises:
        PlannerlabError: the record does not fit (the field and what was expected).
    """
    d = {k: v for k, v in data.items() if k not in ("totals", "execution")}
    d["format"] = TRIAL_FORMAT
    d["legs_run"] = [_v1_leg(x, data) for x in data.get("legs_run") or []]
    ex = data.get("execution")
    d["executions"] = None if ex is None else [_v1_execution(x, data) for x in ex.get("legs", [])]
    if d.get("status") == ERROR_STATUS and str(d.get("error") or "").startswith(
        "trial process died"
    ):
        d["status"] = DIED_STATUS
    d.pop("final_pos_err_m", None)
    d.pop("final_angle_err_deg", None)
    d["output"] = d.get("output") or ""
    for k in ("wall_s", "startup_s"):
        d[k] = num(d.get(k))
    try:
        return msgspec.convert(d, TrialRecord, strict=False)
    except msgspec.ValidationError as exc:
        raise PlannerlabError(
            f"{where}: a {OLD_TRIAL_FORMATS[0]} record that does not fit: {exc}"
        ) from None


__all__ = [
    "DIED_STATUS",
    "ERROR_STATUS",
    "OLD_TRIAL_FORMATS",
    "TIMEOUT_STATUS",
    "TRIAL_FORMAT",
    "ExecutionRecord",
    "LegRecord",
    "NotJSONError",
    "StoreFormatError",
    "TrialRecord",
    "decode_trial",
    "encode_trial",
    "nan",
    "num",
    "reached_best",
    "trial_from_v1",
]

"""The trial store's typed records: every store committed under ``results/`` reads (the
previous schema version converted), a record survives the store unchanged, another
version is refused by name, and the tables tell a solved leg's error beside its tolerance
and print none for a leg that has no best state."""

from __future__ import annotations

import json
from pathlib import Path

import msgspec
import pytest

from plannerlab.comparison.report import leg_rows, markdown, summary_cells, trial_rows
from plannerlab.comparison.statistics import summarise
from plannerlab.comparison.store import TrialStore
from plannerlab.errors import PlannerlabError
from plannerlab.record.cells import err_of_tol
from plannerlab.record.leg import Status
from plannerlab.record.trial import (
    TRIAL_FORMAT,
    LegRecord,
    StoreFormatError,
    TrialRecord,
    decode_trial,
    encode_trial,
)

ROOT = Path(__file__).resolve().parents[2]
STORES = sorted(ROOT.glob("results/**/*.jsonl"))


def test_every_committed_store_reads_as_typed_records() -> None:
    assert len(STORES) >= 20
    total = 0
    for path in STORES:
        lines = [x for x in path.read_text(encoding="utf-8").splitlines() if x.strip()]
        recs = TrialStore(path).load()
        assert recs, path
        assert len(recs) == len({json.loads(x)["key"] for x in lines}), path
        for key, rec in recs.items():
            assert isinstance(rec, TrialRecord) and rec.key == key
            assert rec.format == TRIAL_FORMAT  # converted on reading
            assert all(isinstance(x, LegRecord) for x in rec.legs_run)
            # the converted record is a record of this version: it survives the store
            assert decode_trial(encode_trial(rec)) == rec
        total += len(recs)
    assert total > 1000


def _a_record() -> TrialRecord:
    path = ROOT / "results" / "compare" / "irb6" / "trials.jsonl"
    return next(iter(TrialStore(path).load().values()))


def test_a_record_survives_the_store_unchanged(tmp_path: Path) -> None:
    rec = _a_record()
    store = TrialStore(tmp_path / "trials.jsonl")
    with store.writer() as append:
        append(rec)
    assert store.load() == {rec.key: rec}
    line = json.loads(store.path.read_text(encoding="utf-8"))
    assert line["format"] == TRIAL_FORMAT and line["key"] == rec.key


def test_another_schema_version_is_refused_by_name(tmp_path: Path) -> None:
    line = json.loads(encode_trial(_a_record()))
    line["format"] = "plannerlab.trial/99"
    store = tmp_path / "trials.jsonl"
    store.write_text(json.dumps(line) + "\n", encoding="utf-8")
    with pytest.raises(StoreFormatError) as info:
        TrialStore(store).load()
    msg = str(info.value)
    for part in (str(store), "line 1", "'plannerlab.trial/99'", repr(TRIAL_FORMAT), "--name"):
        assert part in msg, (part, msg)


def test_a_field_of_the_wrong_type_is_refused_naming_it(tmp_path: Path) -> None:
    line = json.loads(encode_trial(_a_record()))
    line["legs_run"][0]["iterations"] = "many"
    with pytest.raises(PlannerlabError, match=r"store: line 3: .*\$\.legs_run\[0\]\.iterations"):
        decode_trial(json.dumps(line), "store: line 3")


def _leg(status: Status, points: int, pos: float, ang: float, **kw) -> LegRecord:
    return LegRecord(
        planner="x",
        problem="p",
        leg=kw.pop("leg", 0),
        goal="g",
        status=status,
        reason=kw.pop("reason", ""),
        pos_err_m=pos,
        angle_err_deg=ang,
        pos_tol_m=0.1,
        angle_tol_deg=10.0,
        path_points=points,
        path_length=1.0,
        **kw,
    )


def _trial(seed: int, *legs: LegRecord) -> TrialRecord:
    ok = all(x.solved for x in legs)
    status = "solved" if ok else next(x.status.value for x in legs if not x.solved)
    return TrialRecord(
        key=f"p/x/s{seed}/0",
        problem="p",
        problem_file="p.toml",
        planner="x",
        seed=seed,
        status=status,
        success=ok,
        legs_run=legs,
    )


def test_tables_put_the_tolerance_beside_the_error_and_no_error_on_a_failed_leg() -> None:
    solved = _leg(Status.SOLVED, 9, 0.0976, 9.54, roughness_rad2=0.5, path_clearance_m=0.0126)
    gave_up = _leg(Status.BUDGET_EXHAUSTED, 1, 1.23, 180.0, reason="out of checks")
    stalled = _leg(Status.LOCAL_MINIMUM, 40, 0.4, 30.0, reason="stalled")
    recs = [_trial(0, solved), _trial(1, gave_up), _trial(2, stalled)]
    (row,) = summarise(recs)
    # the errors are the solved trial's, beside the tolerance; the failures' are no result
    assert (row.pos_err_median_m, row.pos_tol_m) == (0.0976, 0.1)
    assert (row.angle_err_median_deg, row.angle_tol_deg) == (9.54, 10.0)
    cells = summary_cells(row, executed=False)
    assert "0.0976 / 0.1" in cells and "9.54 / 10" in cells
    assert "1.23" not in " ".join(cells) and "180" not in " ".join(cells)
    # smoothness and the path's clearance [mm] beside the length
    assert "0.5" in cells and "12.6" in cells
    assert "smoothness" in markdown([row], recs, {"name": "t"})
    # per leg: a leg that gave up at its start has no tip error; a stall has its best state
    legs = {r["seed"]: r for r in leg_rows(recs)}
    assert (legs[1]["pos_err_m"], legs[1]["tip_state"], legs[1]["reason"]) == (
        None,
        "none",
        "out of checks",
    )
    assert (legs[2]["pos_err_m"], legs[2]["tip_state"]) == (0.4, "best reached")
    assert (legs[0]["pos_err_m"], legs[0]["pos_tol_m"], legs[0]["tip_state"]) == (
        0.0976,
        0.1,
        "goal",
    )
    # per trial: a failed trial's final error is blank (its last state is no result)
    trials = {r["seed"]: r for r in trial_rows(recs)}
    assert trials[1]["final_pos_err_m"] is None and trials[0]["final_pos_tol_m"] == 0.1
    # with nothing solved the tables print "-", not a number that looks like a result
    (none,) = summarise(recs[1:])
    assert err_of_tol(none.pos_err_median_m, none.pos_tol_m) == "-"


def test_a_records_fields_are_typed() -> None:
    rec = _a_record()
    assert isinstance(rec.legs_run[0].status, Status)
    with pytest.raises(AttributeError):
        rec.key = "other"  # type: ignore[misc]
    assert msgspec.structs.replace(rec, seed=7).seed == 7

"""The trial store's records as msgspec Structs (what plannerlab uses) against the same
records as dataclasses with the json module (the baseline), on the stores under
``results/``: bytes per store, and the time to write and to read every record back.

    .venv/bin/python bench/records_bench.py [--repeat 5]

Both sides hold the same fields (the dataclasses are made from the Structs' fields) and
write the same JSON; reading builds the nested records (legs, executions, contacts) on
both sides, the Structs' reader checks every field's type too. Ratios are dataclasses'
time over msgspec's, measured in one run (best of ``--repeat``), with the machine's load.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

import msgspec

from plannerlab.record.codec import to_data
from plannerlab.record.execution import ContactRecord
from plannerlab.record.leg import Status
from plannerlab.record.trial import (
    ExecutionRecord,
    LegRecord,
    TrialRecord,
    decode_trial,
    encode_trial,
)

ROOT = Path(__file__).resolve().parent.parent


def _mirror(struct: type) -> type:
    """A frozen dataclass with the Struct's fields and defaults."""
    fields = []
    for f in msgspec.structs.fields(struct):
        if f.default is not msgspec.NODEFAULT:
            default = f.default
            if isinstance(default, dict | list):
                fields.append((f.name, Any, dataclasses.field(default_factory=type(default))))
            else:
                fields.append((f.name, Any, dataclasses.field(default=default)))
        else:
            fields.append((f.name, Any))
    required = [x for x in fields if len(x) == 2]
    optional = [x for x in fields if len(x) == 3]
    return dataclasses.make_dataclass(f"{struct.__name__}DC", required + optional, frozen=True)


LegDC = _mirror(LegRecord)
ExecutionDC = _mirror(ExecutionRecord)
TrialDC = _mirror(TrialRecord)


def to_dataclass(rec: TrialRecord) -> Any:
    """The same record as the mirror dataclasses (nested)."""
    d = {f: getattr(rec, f) for f in rec.__struct_fields__}
    d["legs_run"] = tuple(
        LegDC(**{f: getattr(x, f) for f in x.__struct_fields__}) for x in rec.legs_run
    )
    if rec.executions is not None:
        d["executions"] = tuple(
            ExecutionDC(**{f: getattr(e, f) for f in e.__struct_fields__}) for e in rec.executions
        )
    return TrialDC(**d)


def dc_encode(rec: Any) -> str:
    return json.dumps(to_data(dataclasses.asdict(rec)), separators=(",", ":"), allow_nan=False)


def dc_decode(line: str) -> Any:
    """json.loads and the nested records built by hand (a dataclass's from_dict)."""
    d = json.loads(line)
    legs = []
    for x in d["legs_run"]:
        x["status"] = Status(x["status"])
        x["progress"] = tuple(tuple(row) for row in x["progress"])
        legs.append(LegDC(**x))
    d["legs_run"] = tuple(legs)
    if d.get("executions") is not None:
        exs = []
        for e in d["executions"]:
            e["contacts"] = tuple(ContactRecord.from_dict(c) for c in e["contacts"])
            e["recheck_pairs"] = tuple(tuple(p) for p in e["recheck_pairs"])
            e["gravity_mps2"] = tuple(e["gravity_mps2"])
            for k in ("failures", "q_start_rad", "q_final_rad"):
                e[k] = tuple(e[k])
            if e["min_clearance_pair"] is not None:
                e["min_clearance_pair"] = tuple(e["min_clearance_pair"])
            exs.append(ExecutionDC(**e))
        d["executions"] = tuple(exs)
    if d.get("legs") is not None:
        d["legs"] = tuple(d["legs"])
    return TrialDC(**d)


def records() -> list[TrialRecord]:
    out = []
    for f in sorted(ROOT.glob("results/**/*.jsonl")):
        for i, line in enumerate(f.read_bytes().splitlines()):
            if line.strip():
                out.append(decode_trial(line, f"{f}:{i + 1}"))
    return out


def best(fn: Any, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    recs = records()
    dcs = [to_dataclass(r) for r in recs]
    ms_lines = [encode_trial(r) for r in recs]
    dc_lines = [dc_encode(r) for r in dcs]
    # the same records either way
    assert all(decode_trial(b) == r for b, r in zip(ms_lines, recs, strict=True))
    assert all(dc_decode(s) == d for s, d in zip(dc_lines, dcs, strict=True))
    ms_bytes = sum(len(b) + 1 for b in ms_lines)
    dc_bytes = sum(len(s.encode()) + 1 for s in dc_lines)
    t_ms_w = best(lambda: [encode_trial(r) for r in recs], args.repeat)
    t_dc_w = best(lambda: [dc_encode(r) for r in dcs], args.repeat)
    t_ms_r = best(lambda: [decode_trial(b) for b in ms_lines], args.repeat)
    t_dc_r = best(lambda: [dc_decode(s) for s in dc_lines], args.repeat)
    load = os.getloadavg()
    py = sys.version.split()[0]
    print(f"{len(recs)} trial records from the stores under results/ (python {py})")
    print(f"machine load (1, 5, 15 min): {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}", end="")
    print(f" on {os.cpu_count()} CPUs")
    rows = [
        ("store size [kB]", ms_bytes / 1e3, dc_bytes / 1e3),
        ("write all [ms]", 1e3 * t_ms_w, 1e3 * t_dc_w),
        ("read all [ms]", 1e3 * t_ms_r, 1e3 * t_dc_r),
    ]
    print(f"{'':24}{'msgspec':>12}{'dataclasses':>14}{'ratio dc/ms':>13}")
    for name, ms, dc in rows:
        print(f"{name:24}{ms:12.1f}{dc:14.1f}{dc / ms:13.2f}")


if __name__ == "__main__":
    main()

"""Which planner escaped which local minimum (issue 36, item 5): read from the trial
records, nothing hard-coded: the baseline's stalls, who solved those legs, and the minima
each planner met and escaped itself."""

from __future__ import annotations

import json
from types import SimpleNamespace

import plannerlab as pl
import plannerlab.extras as px
from plannerlab.cli.main import main


def _leg(leg, goal, status, **kw):
    return {"leg": leg, "goal": goal, "status": status, "reason": kw.pop("reason", ""), **kw}


def _trial(planner, seed, *legs, problem="p"):
    return {"problem": problem, "planner": planner, "seed": seed, "legs_run": list(legs)}


RECORDS = [
    _trial("gradient", 0, _leg(0, "a", "solved"), _leg(1, "b", "local_minimum", pos_err_m=2.5,
                                                        iterations=40, reason="stalled")),
    _trial("gradient", 1, _leg(0, "a", "local_minimum", pos_err_m=1.0, iterations=9)),
    _trial("hybrid", 0, _leg(0, "a", "solved"), _leg(1, "b", "solved", local_minima=2, escapes=1)),
    _trial("hybrid", 1, _leg(0, "a", "solved"), _leg(1, "b", "failed")),
    _trial("sampler", 0, _leg(0, "a", "budget_exhausted")),
    _trial("sampler", 1, _leg(0, "a", "budget_exhausted")),
]  # fmt: skip


def test_the_baselines_stalls_and_who_escaped_them():
    stalls, own = pl.local_minima(RECORDS)  # the paper's gradient is the baseline
    assert [(s.goal, s.seeds) for s in stalls] == [("a", (1,)), ("b", (0,))]
    a, b = stalls
    assert a.pos_err_m == 1.0 and a.iterations == 9
    assert a.escaped == (("hybrid", 2, 2),)
    assert a.not_escaped == (("sampler", 2, "budget_exhausted"),)
    assert b.escaped == (("hybrid", 1, 2),)  # one of the two trials solved it
    assert b.not_escaped == (("sampler", 0, "never reached"),)  # stopped at leg a
    assert [(o.planner, o.legs, o.trials) for o in own] == [("hybrid", (("b", 2, 1),), 2)]


def test_another_baseline_and_records_as_objects():
    objects = [
        SimpleNamespace(**{**r, "legs_run": [SimpleNamespace(**g) for g in r["legs_run"]]})
        for r in RECORDS
    ]
    stalls, _ = pl.local_minima(objects, baseline="sampler")
    assert stalls == []  # the sampler never stalled in a local minimum
    lines = px.describe_minima(stalls, [], "sampler")
    assert lines == ["sampler stalled in no local minimum in these trials"]
    stalls, own = pl.local_minima(objects)
    text = "\n".join(px.describe_minima(stalls, own, "gradient"))
    assert "p, leg b: gradient stalls in a local minimum (seed 0: its tip stays 2.50 m" in text
    assert "escaped by (solved the leg, trials): hybrid 1/2" in text
    assert "not escaped by: sampler (never reached)" in text
    assert "p, hybrid (2 trial(s)): b 1 of 2" in text


def test_compare_ends_with_the_local_minima(capsys, tmp_path):
    """The paper's gradient stalls on armz_pocket; OMPL's RRT-Connect solves the leg."""
    code = main(
        [
            "compare",
            "armz_pocket",
            "--planners",
            "gradient,ompl.rrtconnect",
            "--seeds",
            "0",
            "--max-checks",
            "20000",
            "--out",
            str(tmp_path),
            "--name",
            "m",
            "--minima",
        ]
    )
    out = " ".join(capsys.readouterr().out.split())
    assert code == 0
    assert "Local minima (from the trial records)" in out
    assert "armz_pocket, leg pocket: gradient stalls in a local minimum (seed 0" in out
    assert "escaped by (solved the leg, trials): ompl.rrtconnect 1/1" in out
    records = [json.loads(x) for x in (tmp_path / "m" / "trials.jsonl").read_text().splitlines()]
    stalls, _ = pl.local_minima(records)
    assert [(s.problem, s.goal) for s in stalls] == [("armz_pocket", "pocket")]

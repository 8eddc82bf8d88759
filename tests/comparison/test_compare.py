"""``plannerlab compare``: one process per trial, resumable store, reports, OMPL log.

Budgets are collision-check budgets (never clocks). One comparison is run once per module
(``armz_pocket``, gradient planners and OMPL RRT-Connect when the adapter imports, seeds
0-2, two jobs); the resume tests work on copies of its store.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from plannerlab.cli.main import main
from plannerlab.comparison.runner import run_comparison
from plannerlab.comparison.statistics import summarise, wilson_interval
from plannerlab.comparison.store import TrialStore
from plannerlab.comparison.trial import ERROR_STATUS, Trial, parse_seeds, run_trial
from plannerlab.errors import PlannerlabError
from plannerlab.problem.catalog import resolve_problem_path
from plannerlab.record.trial import DIED_STATUS, TrialRecord

try:
    import plannerlab.planners.ompl  # noqa: F401

    HAVE_OMPL = True
except ImportError:  # pragma: no cover - the adapter is optional while being written
    HAVE_OMPL = False

PROBLEM = "armz_pocket"
#: a trial on it lasts many seconds (seven legs of the clearance descent)
SLOW_PROBLEM = "armz_inspection"
PLANNERS = ["gradient", "gradient.analytic"] + (["ompl.rrtconnect"] if HAVE_OMPL else [])
SEEDS = [0, 1, 2]
#: RRT-Connect solves armz_pocket in ~130 000 checks with the 1-cm margin and edges in metres
MAX_CHECKS = 200_000
NAME = "t"
BIN = Path(sys.executable).parent


def _trials() -> list[Trial]:
    """The module comparison's trials, as the CLI builds them (same keys)."""
    path = resolve_problem_path(PROBLEM).resolve()
    return [
        Trial.make(PROBLEM, path, pl, s, budget={"max_collision_checks": MAX_CHECKS})
        for s in SEEDS
        for pl in PLANNERS
    ]


def _lines(path: Path) -> list[dict]:
    return [json.loads(x) for x in path.read_text().splitlines() if x.strip()]


def _deterministic(rec: dict | TrialRecord) -> list[dict]:
    """A record's per-leg results without the clocks (progress rows without their time)."""
    if isinstance(rec, TrialRecord):
        rec = rec.to_dict()
    return [
        {
            **{k: v for k, v in leg.items() if k not in ("time_s", "progress")},
            "progress": [row[1:] for row in leg.get("progress", [])],
        }
        for leg in rec["legs_run"]
    ]


@pytest.fixture(scope="module")
def comparison(tmp_path_factory: pytest.TempPathFactory) -> dict:
    out = tmp_path_factory.mktemp("compare")
    argv = [
        "compare",
        PROBLEM,
        "--planners",
        ",".join(PLANNERS),
        "--seeds",
        "0-2",
        "--max-checks",
        str(MAX_CHECKS),
        "--jobs",
        "2",
        "--out",
        str(out),
        "--name",
        NAME,
        "--json",
    ]
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(argv)
    assert code == 0
    summary = json.loads(buf.getvalue())
    return {
        "argv": argv,
        "out": out,
        "folder": out / NAME,
        "summary": summary,
        "store": out / NAME / "trials.jsonl",
    }


def _copy_store(comparison: dict, tmp_path: Path) -> Path:
    dst = tmp_path / "trials.jsonl"
    shutil.copy(comparison["store"], dst)
    return dst


# ---------------------------------------------------------------------- the store
def test_store_has_one_record_per_trial(comparison: dict) -> None:
    s = comparison["summary"]
    n = len(PLANNERS) * len(SEEDS)
    assert (s["trials"], s["ran"], s["skipped"], s["errors"]) == (n, n, 0, 0)
    recs = _lines(comparison["store"])
    assert len(recs) == n
    assert {r["key"] for r in recs} == {t.key for t in _trials()}
    assert len({r["pid"] for r in recs}) == n  # every trial had its own process
    for r in recs:
        assert r["status"] != ERROR_STATUS, r.get("error")
        assert r["budget_used"]["max_collision_checks"] == MAX_CHECKS
        assert r["legs_run"] and r["legs_run"][0]["path_length"] is not None


def test_rerun_skips_every_finished_trial(comparison: dict, capsys) -> None:
    before = comparison["store"].read_bytes()
    assert main(comparison["argv"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert (s["ran"], s["skipped"]) == (0, len(PLANNERS) * len(SEEDS))
    assert comparison["store"].read_bytes() == before  # no new record, no new process


def test_deleted_line_reruns_only_that_trial(comparison: dict, tmp_path: Path) -> None:
    store = _copy_store(comparison, tmp_path)
    lines = store.read_text().splitlines(keepends=True)
    gone = json.loads(lines.pop(1))
    store.write_text("".join(lines))
    fresh: list[str] = []
    run = run_comparison(
        _trials(),
        store,
        jobs=2,
        on_done=lambda r, skipped: None if skipped else fresh.append(r.key),
    )
    assert (run.ran, run.skipped) == (1, len(_trials()) - 1)
    assert fresh == [gone["key"]]
    recs = _lines(store)
    assert len(recs) == len(_trials())
    again = next(r for r in recs if r["key"] == gone["key"])
    assert again["pid"] != gone["pid"]
    assert _deterministic(again) == _deterministic(gone)


def test_truncated_last_line_is_ignored_and_rerun(comparison: dict, tmp_path: Path) -> None:
    store = _copy_store(comparison, tmp_path)
    data = store.read_bytes()
    last_start = data.rstrip(b"\n").rfind(b"\n") + 1
    cut = json.loads(data[last_start:])
    store.write_bytes(data[: last_start + (len(data) - last_start) // 2])  # killed mid-write
    assert cut["key"] not in TrialStore(store).load()
    assert len(TrialStore(store).load()) == len(_trials()) - 1
    run = run_comparison(_trials(), store, jobs=1)
    assert (run.ran, run.skipped) == (1, len(_trials()) - 1)
    recs = _lines(store)  # every line parses: the half line was cut, not glued onto
    assert len(recs) == len(_trials())
    assert {r["key"] for r in recs} == {t.key for t in _trials()}


# ---------------------------------------------------------------------- reports
def test_csv_and_markdown_name_every_planner(comparison: dict) -> None:
    folder = comparison["folder"]
    for f in ("summary.csv", "trials.csv", "legs.csv", "report.md", "meta.json"):
        assert (folder / f).is_file(), f
    summary = (folder / "summary.csv").read_text().splitlines()
    assert len(summary) == 1 + len(PLANNERS)
    assert len((folder / "trials.csv").read_text().splitlines()) == 1 + len(_trials())
    md = (folder / "report.md").read_text()
    for pl in PLANNERS:
        assert any(line.startswith(f"{PROBLEM},{pl},") for line in summary[1:])
        assert f"| {pl} |" in md
    assert "plannerlab compare armz_pocket" in md and f"--max-checks {MAX_CHECKS}" in md
    assert "ompl" in md and "## Machine" in md
    assert "may add at most 1 % to the checks and to the time" in md  # the budget footnote
    meta = json.loads((folder / "meta.json").read_text())
    assert meta["seeds"] == SEEDS and meta["budget"] == {"max_collision_checks": MAX_CHECKS}


def test_ompl_log_loads_into_sqlite(comparison: dict, tmp_path: Path) -> None:
    log = comparison["folder"] / f"{NAME}.log"
    db = tmp_path / "bench.db"
    script = BIN / "ompl_benchmark_statistics"
    if not script.exists():
        found = shutil.which("ompl_benchmark_statistics")
        if found is None:
            pytest.skip("ompl_benchmark_statistics is not installed")
        script = Path(found)
    proc = subprocess.run(
        [str(script), str(log), "-d", str(db)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    con = sqlite3.connect(db)
    try:
        rows = dict(
            (name, (n, solved))
            for name, n, solved in con.execute(
                "SELECT p.name, COUNT(*), SUM(r.solved) FROM runs r "
                "JOIN plannerConfigs p ON p.id = r.plannerid GROUP BY p.name"
            )
        )
        exps = con.execute("SELECT name, runcount FROM experiments").fetchall()
        seeds = sorted(s for (s,) in con.execute("SELECT DISTINCT seed FROM runs"))
        enum = dict(con.execute("SELECT description, value FROM enums WHERE name='status'"))
        statuses = con.execute(
            "SELECT COUNT(*) FROM runs WHERE status = ?", (enum["solved"],)
        ).fetchone()[0]
    finally:
        con.close()
    expected = {r["planner"]: r["successes"] for r in comparison["summary"]["summary"]}
    assert exps == [(PROBLEM, len(SEEDS))]
    assert seeds == SEEDS
    assert rows == {pl: (len(SEEDS), expected[pl]) for pl in PLANNERS}
    assert statuses == sum(expected.values())


def test_planner_arena_shows_progress(comparison: dict, tmp_path: Path) -> None:
    """The OMPL log's progress properties reach Planner Arena's progress table: per run,
    times increasing from 0 and the best goal distance never growing, and 0 at the end of
    every solved run."""
    database = pytest.importorskip("plannerarena.database")
    script = BIN / "ompl_benchmark_statistics"
    if not script.exists():
        pytest.skip("ompl_benchmark_statistics is not installed")
    db = tmp_path / "arena.db"
    log = comparison["folder"] / f"{NAME}.log"
    proc = subprocess.run(
        [str(script), str(log), "-d", str(db)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    data = database.load_database(db)
    progress = data["progress"]
    assert not progress.is_empty()
    # Planner Arena shows the SQL columns with spaces again
    assert {"time", "best goal distance", "best cost", "collision checks", "leg"} <= set(
        progress.columns
    )
    con = sqlite3.connect(db)
    try:
        runs = con.execute(
            "SELECT r.id, p.name, r.solved, r.collision_checks FROM runs r "
            "JOIN plannerConfigs p ON p.id = r.plannerid"
        ).fetchall()
        for run_id, planner, solved, checks in runs:
            rows = con.execute(
                "SELECT time, best_goal_distance, collision_checks FROM progress "
                "WHERE runid = ? ORDER BY time",
                (run_id,),
            ).fetchall()
            assert rows, (planner, run_id)
            times = [t for t, _, _ in rows]
            dists = [d for _, d, _ in rows]
            assert times[0] >= 0 and all(b > a for a, b in zip(times, times[1:], strict=False))
            assert all(b <= a for a, b in zip(dists, dists[1:], strict=False)), planner
            assert 0 < rows[-1][2] <= checks  # the run's checks, counted from its start
            if solved:
                assert dists[-1] == 0.0, planner
    finally:
        con.close()


# ---------------------------------------------------------------------- determinism
def test_same_seed_same_results_in_fresh_processes(comparison: dict, tmp_path: Path) -> None:
    first = {r["key"]: r for r in _lines(comparison["store"])}
    pick = [t for t in _trials() if t.seed == 1]
    run = run_comparison(pick, tmp_path / "again.jsonl", jobs=2)
    assert run.ran == len(pick)
    for rec in run.records:
        old = first[rec.key]
        assert rec.pid != old["pid"]
        assert _deterministic(rec) == _deterministic(old), rec.key


def test_same_seeds_same_table_whatever_jobs(comparison: dict, tmp_path: Path) -> None:
    """The module comparison ran with --jobs 2 in children forked from the fork server;
    one job at a time gives the same per-trial results and the same table, and OMPL's
    seed took effect in every child (different seeds, different paths)."""
    first = TrialStore(comparison["store"]).load()
    run = run_comparison(_trials(), tmp_path / "one.jsonl", jobs=1)
    assert run.ran == len(first)
    for rec in run.records:
        assert _deterministic(rec) == _deterministic(first[rec.key]), rec.key
        assert rec.startup_s is not None and rec.startup_s >= 0.0

    def table(records: list[TrialRecord]) -> list[dict]:
        return [
            {k: v for k, v in row.to_dict().items() if not k.startswith("time_")}
            for row in summarise(records)
        ]

    assert table(run.records) == table([first[r.key] for r in run.records])
    if HAVE_OMPL:
        hashes = {
            r.seed: r.legs_run[0].path_sha256 for r in run.records if r.planner == "ompl.rrtconnect"
        }
        assert len(set(hashes.values())) == len(SEEDS), hashes


def test_a_planner_whose_seeds_are_one_trial_is_marked_and_gets_no_interval(
    comparison: dict,
) -> None:
    """The gradient methods ignore their generator: their three seeds are one trial, so
    the row says deterministic and has no interval; RRT-Connect's seeds differ."""
    import msgspec

    records = list(TrialStore(comparison["store"]).load().values())
    rows = {r.planner: r for r in summarise(records)}
    for name in ("gradient", "gradient.analytic"):
        row = rows[name]
        assert row.deterministic is True and row.distinct_trials == 1, name
        assert math.isnan(row.ci95_low) and math.isnan(row.ci95_high)
    if HAVE_OMPL:
        row = rows["ompl.rrtconnect"]
        assert row.deterministic is False and row.distinct_trials == len(SEEDS)
        assert (row.ci95_low, row.ci95_high) == wilson_interval(row.successes, row.n)
    report = (comparison["folder"] / "report.md").read_text(encoding="utf-8")
    assert report.count(f"[deterministic: {len(SEEDS)} seeds, one trial]") == 2
    # a trial that did something else (another path) is another trial: the interval is back
    grad = [r for r in records if r.planner == "gradient"]
    leg0 = msgspec.structs.replace(grad[0].legs_run[0], path_sha256="0" * 16)
    (row,) = summarise([grad[0].replace(legs_run=(leg0,)), *grad[1:]])
    assert row.deterministic is False and row.distinct_trials == 2
    assert (row.ci95_low, row.ci95_high) == wilson_interval(row.successes, row.n)
    # one trial alone is not called deterministic (nothing to compare it with)
    (row,) = summarise(grad[:1])
    assert row.deterministic is False and row.distinct_trials == 1


def test_fork_server_children_match_spawned_interpreters(comparison: dict, tmp_path: Path) -> None:
    """A child forked from the warm fork server gives what a fresh interpreter gives."""
    from plannerlab.comparison.local import LocalBackend

    first = {r["key"]: r for r in _lines(comparison["store"])}
    pick = [t for t in _trials() if t.seed == 2]
    backend = LocalBackend(tmp_path / "running", run_trial, start_method="spawn")
    try:
        run = run_comparison(pick, tmp_path / "spawned.jsonl", jobs=2, backend=backend)
    finally:
        backend.close()
    assert run.ran == len(pick)
    for rec in run.records:
        assert _deterministic(rec) == _deterministic(first[rec.key]), rec.key


def test_a_trial_past_its_time_limit_is_killed_and_recorded(tmp_path: Path) -> None:
    """A planner that overruns the per-trial limit is killed, recorded as timeout, and the
    comparison goes on with the next trial."""
    from plannerlab.comparison.trial import TIMEOUT_STATUS

    path = resolve_problem_path(PROBLEM).resolve()
    slow = Trial.make(PROBLEM, path, "gradient", 0)  # default budget: seconds
    quick = Trial.make(PROBLEM, path, "gradient.analytic", 0, budget={"max_collision_checks": 100})
    t0 = time.monotonic()
    run = run_comparison(
        [slow, quick],
        tmp_path / "s.jsonl",
        jobs=1,
        poll_s=0.05,
        trial_timeout_s=lambda t: 0.2 if t.key == slow.key else None,
    )
    assert time.monotonic() - t0 < 60
    recs = {r.key: r for r in run.records}
    assert recs[slow.key].status == TIMEOUT_STATUS and not recs[slow.key].success
    assert "per-trial limit of 0.2 s" in str(recs[slow.key].error)
    assert recs[quick.key].status not in (TIMEOUT_STATUS, ERROR_STATUS)
    rows = {r.planner: r for r in summarise(run.records)}
    assert rows["gradient"].errors == 1 and rows["gradient"].successes == 0
    # a timeout is finished for resuming
    again = run_comparison([slow, quick], tmp_path / "s.jsonl", jobs=1)
    assert again.ran == 0 and again.skipped == 2


def test_cli_trial_timeout_records_timeouts(tmp_path: Path) -> None:
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(
            [
                "compare",
                SLOW_PROBLEM,  # the numpy clearance descent plans for many seconds here
                "--planners",
                "gradient.clearance",
                "--set",
                "gradient.clearance:backend=numpy",
                "--seeds",
                "0",
                "--trial-timeout",
                "0.2",
                "--out",
                str(tmp_path),
                "--name",
                "to",
                "--json",
            ]
        )
    assert code == 0
    (rec,) = _lines(tmp_path / "to" / "trials.jsonl")
    assert rec["status"] == "timeout"
    assert json.loads(buf.getvalue())["errors"] == 1


RAY_PLANNERS = PLANNERS[1:]  # a gradient planner and, with the adapter, RRT-Connect


def test_ray_backend_gives_the_same_records(comparison: dict, tmp_path: Path) -> None:
    """--backend ray on a small local Ray instance started here: each trial a Ray task in
    a fresh worker (max_calls=1), the same store and reports, the same results."""
    ray = pytest.importorskip("ray")
    import contextlib
    import io

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = main(
                [
                    "compare",
                    PROBLEM,
                    "--planners",
                    ",".join(RAY_PLANNERS),
                    "--seeds",
                    "1",
                    "--max-checks",
                    str(MAX_CHECKS),
                    "--jobs",
                    "2",
                    "--backend",
                    "ray",
                    "--out",
                    str(tmp_path),
                    "--name",
                    NAME,
                    "--json",
                ]
            )
        assert code == 0
        assert ray.is_initialized()  # joined the running instance, left it running
    finally:
        ray.shutdown()
    summary = json.loads(buf.getvalue())
    assert summary["ran"] == len(RAY_PLANNERS)
    first = {r["key"]: r for r in _lines(comparison["store"])}
    recs = _lines(tmp_path / NAME / "trials.jsonl")
    assert len({r["pid"] for r in recs}) == len(recs)  # a fresh worker per trial
    for rec in recs:
        assert _deterministic(rec) == _deterministic(first[rec["key"]]), rec["key"]
    meta = json.loads((tmp_path / NAME / "meta.json").read_text())
    assert meta["backend"] == "ray"
    summary_csv = (tmp_path / NAME / "summary.csv").read_text()
    assert all(p in summary_csv for p in RAY_PLANNERS)


# ---------------------------------------------------------------------- failures
def test_a_raising_trial_is_recorded_and_execution_summarised(tmp_path: Path) -> None:
    path = resolve_problem_path(PROBLEM).resolve()
    bad = Trial.make(PROBLEM, tmp_path / "missing.toml", "gradient", 0)
    ok = Trial.make(
        PROBLEM, path, "ompl.rrtconnect", 0, budget={"max_collision_checks": 400_000}, execute=True
    )
    stalled = Trial.make(
        PROBLEM, path, "gradient.analytic", 0, budget={"max_collision_checks": 100}, execute=True
    )
    run = run_comparison([bad, ok, stalled], tmp_path / "s.jsonl", jobs=2)
    recs = {r.key: r for r in run.records}
    assert recs[bad.key].status == ERROR_STATUS
    assert "missing.toml" in str(recs[bad.key].error)
    good = recs[ok.key]
    assert good.success, good.legs_run
    assert good.executions is not None and good.exec_success is not None
    # the verdict's numbers in metres, per trial and per leg
    assert 0.0 <= good.exec_max_deviation_m <= 0.01 and good.exec_min_clearance_m > 0.0
    assert all(e.max_deviation_limit_m == 0.01 for e in good.executions)
    assert len(good.executions) == len(good.legs_run) == good.executed_legs
    # the path's quality, measured densely after the solve, and the goal's tolerances
    (leg,) = good.legs_run
    # every state of the re-check's grid: no point moves more than the 1-cm margin between
    # two of them, so the planner's own states (its min_clearance_m) are at most that far
    # from one (twice for a pair of links)
    assert leg.path_clearance_m is not None and leg.min_clearance_m is not None
    assert 0.0 < leg.path_clearance_m <= leg.min_clearance_m + 2 * 0.01
    assert leg.roughness_rad2 is not None and leg.roughness_rad2 >= 0.0
    assert leg.pos_tol_m is not None and leg.pos_err_m <= leg.pos_tol_m
    # a plan that did not solve its leg is not executed
    assert recs[stalled.key].executions is None and recs[stalled.key].executed_legs == 0
    rows = {r.planner: r for r in summarise(run.records)}
    assert rows["gradient"].errors == 1 and rows["ompl.rrtconnect"].errors == 0
    assert rows["ompl.rrtconnect"].executed == 1
    assert math.isfinite(rows["ompl.rrtconnect"].exec_track_err_median_rad)
    assert 0.0 <= rows["ompl.rrtconnect"].exec_deviation_median_m <= 0.01
    assert rows["ompl.rrtconnect"].exec_clearance_min_m > 0.0
    assert rows["gradient.analytic"].executed == 0


def test_a_trial_whose_process_dies_is_recorded(tmp_path: Path) -> None:
    """A hard crash (here SIGKILL) of one trial's process is that trial's ``died`` record,
    with the signal; the trial beside it is unaffected."""
    import multiprocessing
    import threading

    path = resolve_problem_path(PROBLEM).resolve()
    slow_path = resolve_problem_path(SLOW_PROBLEM).resolve()
    # the numpy clearance descent over the paper's seven legs: many seconds, whatever the
    # machine (the compiled one plans them in well under a second)
    victim = Trial.make(
        SLOW_PROBLEM, slow_path, "gradient.clearance", 0, settings={"backend": "numpy"}
    )
    other = Trial.make(PROBLEM, path, "gradient.analytic", 0, budget={"max_collision_checks": 100})
    killed: list[int] = []

    def killer() -> None:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not killed:
            for child in multiprocessing.active_children():
                if child.name == f"trial {victim.key}" and child.pid:
                    time.sleep(0.5)
                    os.kill(child.pid, signal.SIGKILL)
                    killed.append(child.pid)
                    break
            time.sleep(0.02)

    th = threading.Thread(target=killer, daemon=True)
    th.start()
    run = run_comparison([victim, other], tmp_path / "s.jsonl", jobs=2)
    th.join(timeout=5)
    recs = {r.key: r for r in run.records}
    assert killed
    assert recs[victim.key].status == DIED_STATUS
    assert recs[victim.key].signal == "SIGKILL" and recs[victim.key].exit_code is None
    assert "died (killed by SIGKILL)" in str(recs[victim.key].error)
    assert recs[other.key].status not in (ERROR_STATUS, DIED_STATUS)


def _dies_loudly(trial: Trial) -> TrialRecord:
    """A trial's process that writes to stderr and exits (code 3) without reporting."""
    for i in range(30):
        print(f"line {i} of a dying trial", file=sys.stderr)
    sys.stderr.flush()
    os._exit(3)


def test_a_died_trial_says_why_and_is_run_again_next_time(tmp_path: Path) -> None:
    """A trial whose process really exits without reporting (code 3, after writing to
    stderr) is recorded as died, with the exit code and the last lines of its output; the
    next run of the same comparison runs it again (no --retry-errors needed), and its
    new record replaces the old one."""
    from plannerlab.comparison.local import OUTPUT_TAIL_LINES, LocalBackend

    path = resolve_problem_path(PROBLEM).resolve()
    trial = Trial.make(PROBLEM, path, "gradient.analytic", 0, budget={"max_collision_checks": 100})
    store = tmp_path / "s.jsonl"
    dying = LocalBackend(tmp_path / "running", _dies_loudly, start_method="spawn")
    try:
        run = run_comparison([trial], store, backend=dying)
    finally:
        dying.close()
    (rec,) = run.records
    assert (rec.status, rec.exit_code, rec.signal) == (DIED_STATUS, 3, None)
    assert "died (exit code 3)" in str(rec.error) and "line 29 of a dying trial" in str(rec.error)
    lines = rec.output.splitlines()
    assert len(lines) == OUTPUT_TAIL_LINES and lines[-1] == "line 29 of a dying trial"
    assert TrialStore(store).load()[trial.key].status == DIED_STATUS  # in the store
    again = run_comparison([trial], store)
    assert (again.ran, again.skipped) == (1, 0)
    (rec,) = again.records
    assert rec.status != DIED_STATUS and rec.error is None
    assert TrialStore(store).load()[trial.key] == rec
    assert run_comparison([trial], store).skipped == 1  # finished now


def test_interrupted_compare_resumes(tmp_path: Path) -> None:
    argv = [
        str(BIN / "plannerlab"),
        "compare",
        PROBLEM,
        "--planners",
        "gradient",
        "--seeds",
        "0-3",
        "--jobs",
        "1",
        "--out",
        str(tmp_path),
        "--name",
        "irq",
    ]
    store = tmp_path / "irq" / "trials.jsonl"
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    # Interrupt as soon as the first trial is stored: with --jobs 1 the three others run
    # one after another, each the faithful gradient's finite-difference descent to the
    # pocket's stall (61 iterations of 24 objective evaluations: seconds, where a poll
    # is 20 ms), so the signal always lands with trials left to resume.
    deadline = time.monotonic() + 300
    while not (store.exists() and store.read_text().strip()):
        assert time.monotonic() < deadline and proc.poll() is None, "no trial finished"
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    done = _lines(store)
    assert proc.returncode == 130, out
    assert "resume" in out
    assert 1 <= len(done) < 4
    res = subprocess.run([*argv, "--json"], capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    s = json.loads(res.stdout)
    assert (s["skipped"], s["ran"]) == (len(done), 4 - len(done))
    assert len(_lines(store)) == 4
    assert not (tmp_path / "irq" / ".running").exists() or not any(
        (tmp_path / "irq" / ".running").iterdir()
    )


# ---------------------------------------------------------------------- units
def test_wilson_interval_known_values() -> None:
    lo, hi = wilson_interval(0, 20)
    assert lo == 0.0 and hi == pytest.approx(0.1611, abs=5e-4)
    lo, hi = wilson_interval(20, 20)
    assert hi == 1.0 and lo == pytest.approx(0.8389, abs=5e-4)
    lo, hi = wilson_interval(10, 20)
    assert (lo, hi) == pytest.approx((0.2993, 0.7007), abs=5e-4)
    assert all(math.isnan(x) for x in wilson_interval(0, 0))


def test_parse_seeds() -> None:
    assert parse_seeds("0-19") == list(range(20))
    assert parse_seeds("0,3,5-7") == [0, 3, 5, 6, 7]
    assert parse_seeds("4") == [4]
    for bad in ("a", "5-2", "-1", ""):
        with pytest.raises(PlannerlabError):
            parse_seeds(bad)


def test_unknown_planner_and_setting_fail_up_front(tmp_path: Path, capsys) -> None:
    base = ["compare", PROBLEM, "--seeds", "0", "--out", str(tmp_path)]
    assert main([*base, "--planners", "gradient,gradiant.analytic"]) == 2
    err = capsys.readouterr().err
    assert "did you mean" in err and "gradient.analytic" in err
    assert main([*base, "--planners", "gradient", "--set", "gradient:no_such_key=1"]) == 2
    assert "no_such_key" in capsys.readouterr().err
    assert main([*base, "--planners", "gradient", "--set", "rrt:range=1"]) == 2
    assert main([*base, "--planners", "gradient", "--seeds", "3-1"]) == 2
    assert not any(tmp_path.iterdir())  # nothing ran, nothing written


def test_cli_parses_the_issue_example() -> None:
    from plannerlab.cli.main import build_parser

    a = build_parser().parse_args(
        [
            "compare",
            "p1",
            "p2",
            "--planners",
            "a,b,c",
            "--seeds",
            "0-19",
            "--time-limit",
            "2",
            "--execute",
            "--jobs",
            "4",
        ]
    )
    assert a.problems == ["p1", "p2"] and a.planners == "a,b,c" and a.jobs == 4
    assert a.time_limit == 2.0 and a.execute and a.max_checks is None


@pytest.mark.skipif(os.name != "posix", reason="the store lock uses fcntl")
def test_store_is_locked_while_written(tmp_path: Path) -> None:
    store = TrialStore(tmp_path / "s.jsonl")
    rec = TrialRecord(
        key="k", problem="p", problem_file="p.toml", planner="x", seed=0, status="solved"
    )
    with store.writer() as append:
        append(rec)
        with pytest.raises(PlannerlabError, match="in use"), store.writer():
            pass
    assert TrialStore(tmp_path / "s.jsonl").load() == {"k": rec}


def test_the_api_checks_a_comparison_as_the_cli_does(tmp_path: Path) -> None:
    """``plannerlab.compare`` builds the same ComparisonSpec as ``plannerlab compare``: a
    planner on the wrong robot kind, an unknown leg or a bad budget fail before any trial
    runs (no store is written)."""
    import plannerlab as pl

    store = tmp_path / "s.jsonl"
    with pytest.raises(PlannerlabError, match="works on continuum_chain robots"):
        pl.compare(["armz_pocket"], ["chord_arc"], [0], store)
    with pytest.raises(PlannerlabError, match="unknown leg 'nowhere'"):
        pl.compare(["armz_pocket"], ["gradient"], [0], store, legs="nowhere")
    with pytest.raises(PlannerlabError, match="max_collision_checks: expected a number > 0"):
        pl.compare(["armz_pocket"], ["gradient"], [0], store, budget={"max_collision_checks": 0})
    with pytest.raises(PlannerlabError, match="backend: expected one of local, ray"):
        pl.compare(["armz_pocket"], ["gradient"], [0], store, backend="slurm")
    with pytest.raises(PlannerlabError, match="budget: unknown key.s. max_checks"):
        pl.compare(["armz_pocket"], ["gradient"], [0], store, budget={"max_checks": 10})
    with pytest.raises(PlannerlabError, match="settings for ompl.rrt, which is not among"):
        pl.compare(["armz_pocket"], ["gradient"], [0], store, settings={"ompl.rrt": {"a": 1}})
    with pytest.raises(PlannerlabError, match="seeds: give at least one seed"):
        pl.compare(["armz_pocket"], ["gradient"], [], store)
    assert not store.exists()

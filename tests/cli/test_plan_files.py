"""Plan files work from anywhere (issue 27, item 6): the problem is found relative to the
plan's own folder or at its recorded absolute path, its hash checked; ``plannerlab
problems`` lists every problem there is; ``execute`` says why a leg is not ok."""

from __future__ import annotations

import dataclasses
import json
import shutil

from conftest import PROBLEMS, plannerlab
from rich.console import Console

from plannerlab.cli.execute import print_execution_tables
from plannerlab.cli.main import main
from plannerlab.record.execution import Execution
from plannerlab.record.plan import Plan, file_sha256


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _plan_in(folder, capsys, monkeypatch) -> tuple:
    """``solve pocket.toml`` run inside ``folder`` (a relative problem path), the plan in
    ``folder/plans``."""
    folder.mkdir()
    shutil.copy(PROBLEMS / "armz_pocket.toml", folder / "pocket.toml")
    monkeypatch.chdir(folder)
    argv = ("solve", "pocket.toml", "--planner", "gradient.analytic", "--max-iterations", "5")
    code, out, err = run(capsys, *argv, "--out", "plans/plan.json", "--json")
    assert code == 0, err
    return folder / "plans" / "plan.json", json.loads(out)


def test_a_plan_records_its_problem_by_absolute_and_relative_path(capsys, tmp_path, monkeypatch):
    plan_file, doc = _plan_in(tmp_path / "work", capsys, monkeypatch)
    assert doc == json.loads(plan_file.read_text())  # --json prints the file's content
    assert doc["problem_file"] == str(tmp_path / "work" / "pocket.toml")
    assert doc["problem_file_from_plan"] == "../pocket.toml"
    assert doc["problem_sha256"] == file_sha256(tmp_path / "work" / "pocket.toml")


def test_execute_and_plot_from_another_folder(capsys, tmp_path, monkeypatch):
    plan_file, _ = _plan_in(tmp_path / "work", capsys, monkeypatch)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    code, out, err = run(capsys, "execute", str(plan_file), "--json")
    assert code == 0, err
    assert json.loads(out)["executions"][0]["problem"] == "armz_pocket"
    code, out, err = run(capsys, "plot", str(plan_file), "--out", "fig", "--json")
    assert code == 0, err
    assert all((elsewhere / "fig").joinpath(f.split("/")[-1]).is_file() for f in json.loads(out))


def test_a_moved_folder_finds_its_problem_beside_the_plan(capsys, tmp_path, monkeypatch):
    """The recorded absolute path is gone; the path from the plan's folder still holds."""
    plan_file, _ = _plan_in(tmp_path / "work", capsys, monkeypatch)
    monkeypatch.chdir(tmp_path)
    shutil.move(tmp_path / "work", tmp_path / "moved")
    moved = tmp_path / "moved" / "plans" / "plan.json"
    assert Plan.load(moved).problem_path() == tmp_path / "moved" / "pocket.toml"
    code, out, err = run(capsys, "execute", str(moved), "--json")
    assert code == 0, err
    # a changed problem: the clear error, and --allow-changed-problem executes anyway
    problem = tmp_path / "moved" / "pocket.toml"
    problem.write_text(problem.read_text() + "\n# edited after planning\n")
    code, _, err = run(capsys, "execute", str(moved))
    assert code == 2 and "changed since planning" in " ".join(err.split())
    code, out, err = run(capsys, "execute", str(moved), "--allow-changed-problem")
    assert code == 0, err
    assert "changed since planning" in " ".join(out.split())
    # a problem that is gone: said so, with where it was looked for, and no offer to go on
    problem.unlink()
    code, _, err = run(capsys, "execute", str(moved), "--allow-changed-problem")
    err = " ".join(err.split())
    assert code == 2 and "no longer exists" in err and "--allow-changed-problem" not in err


def test_an_older_plan_with_a_relative_path_finds_its_problem_from_its_folder(
    capsys, tmp_path, monkeypatch
):
    """Plans written before this change recorded the path as given to ``solve``."""
    plan_file, doc = _plan_in(tmp_path / "work", capsys, monkeypatch)
    doc["problem_file"] = "pocket.toml"
    del doc["problem_file_from_plan"]
    old = tmp_path / "work" / "old.json"
    old.write_text(json.dumps(doc))
    monkeypatch.chdir(tmp_path)
    plan = Plan.load(old)
    assert plan.problem_changed() is None
    assert plan.problem_path() == tmp_path / "work" / "pocket.toml"
    assert plan.load_problem().name == "armz_pocket"


def test_a_lost_copy_of_a_bundled_problem_is_found_by_name_and_hash(capsys, tmp_path, monkeypatch):
    plan_file, _ = _plan_in(tmp_path / "work", capsys, monkeypatch)
    doc = json.loads(plan_file.read_text())
    doc["problem_file"] = str(tmp_path / "gone" / "armz_pocket.toml")
    doc["problem_file_from_plan"] = "../gone/armz_pocket.toml"
    plan_file.write_text(json.dumps(doc))
    plan = Plan.load(plan_file)
    assert plan.problem_path() == PROBLEMS / "armz_pocket.toml"
    assert plan.problem_changed() is None
    # a different hash: not taken for the same problem
    doc["problem_sha256"] = "0" * 64
    plan_file.write_text(json.dumps(doc))
    assert Plan.load(plan_file).problem_path() is None
    assert "no longer exists" in Plan.load(plan_file).problem_changed()


def test_problems_lists_every_bundled_problem_grouped(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "problems", "--json")
    rows = json.loads(out)
    on_disk = sorted(p.resolve() for p in PROBLEMS.rglob("*.toml"))
    assert code == 0 and sorted(p["file"] for p in rows) == sorted(map(str, on_disk))
    groups = {r["name"]: r["group"] for r in rows}
    assert groups["armz_pocket"] == "" and groups["bookshelf_small_0001"] == "urdf/panda"
    assert groups["armz_inspection_v07"] == "variants"
    assert all(r["from"] == "bundled" and "error" not in r for r in rows)
    code, out, _ = run(capsys, "problems")
    assert "problems in urdf/panda/" in out and "problems in variants/" in out
    # a grouped problem resolves by its name
    code, out, err = run(
        capsys,
        "solve",
        "armz_inspection_v07",
        "--planner",
        "gradient",
        "--max-iterations",
        "1",
        "--legs",
        "0",
        "--out",
        "p.json",
        "--json",
    )
    assert code == 0, err
    assert json.loads(out)["problem_file"] == str(
        PROBLEMS / "variants" / "armz_inspection_v07.toml"
    )


def test_execute_says_why_a_leg_is_not_ok(capsys, tmp_path, monkeypatch):
    plan_file, _ = _plan_in(tmp_path / "work", capsys, monkeypatch)
    code, out, err = run(capsys, "execute", str(plan_file), "--json")
    (e,) = [Execution.from_dict(x) for x in json.loads(out)["executions"]]
    # five iterations from rest: the tip is far from the goal, nothing else is wrong
    assert e.path_valid is True and not e.unexpected_contacts and e.clear and e.followed
    assert e.goal_reached is False and e.failures == (
        f"tip outside the goal ({e.final_pos_err_m:.3g} m, {e.final_angle_err_deg:.3g}°)",
    )
    plan = Plan.load(plan_file)
    worse = dataclasses.replace(
        e,
        min_clearance_m=-0.0041,
        min_clearance_pair=("link_7", "boulder"),
        max_deviation_m=0.012,
        max_deviation_limit_m=0.005,
    )
    assert worse.failures[:2] == ("clearance -4.1 mm (link_7 x boulder)", "deviation 12 > 5 mm")
    for width in (80, 200):  # beside the numbers, or in a table of its own when narrow
        console = Console(width=width, record=True)
        print_execution_tables(console, plan.legs, [worse])
        text = " ".join(console.export_text().split())
        assert "why not" in text and "clearance -4.1 mm (link_7 x boulder)" in text
        assert "deviation 12 > 5 mm" in text
    assert e.final_pos_err_m > 1.0  # the case above is a real miss, not a rounding


def test_pybullet_build_time_stays_off_the_terminal_unless_verbose(tmp_path):
    shutil.copy(PROBLEMS / "armz_pocket.toml", tmp_path / "pocket.toml")
    plan = tmp_path / "plan.json"
    argv = ("--planner", "gradient.analytic", "--max-iterations", "3", "--out", str(plan))
    assert plannerlab("solve", str(tmp_path / "pocket.toml"), *argv).returncode == 0
    quiet = plannerlab("execute", str(plan), cwd=tmp_path)
    assert quiet.returncode == 0, quiet.stderr
    for text in (quiet.stdout, quiet.stderr):
        assert "build time" not in text and "argv[0]" not in text
    loud = plannerlab("-v", "execute", str(plan), cwd=tmp_path)
    assert loud.returncode == 0, loud.stderr
    assert "build time" not in loud.stdout and "pybullet build time" in loud.stderr

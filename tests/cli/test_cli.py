"""The plannerlab command end to end: list, solve, execute, plot, errors."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pytest
from conftest import PROBLEMS

from plannerlab.cli.main import main


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_problems_and_planners_list_as_json(capsys):
    code, out, _ = run(capsys, "problems", "--json")
    names = {p["name"] for p in json.loads(out)}
    assert code == 0 and {"armz_inspection", "armz_pocket"} <= names
    code, out, _ = run(capsys, "planners", "--json")
    planners = {p["name"]: p for p in json.loads(out)}
    assert {
        "gradient",
        "gradient.closed_loop",
        "gradient.analytic",
        "gradient.clearance+random_detour",
        "ompl.rrtconnect",
        "ompl.kpiece1",
    } <= set(planners)
    # which planners draw from their seed
    assert not planners["gradient.clearance+detour"]["uses_rng"]
    assert planners["gradient.clearance+random_detour"]["uses_rng"]


def test_problems_lists_the_local_folder_first(capsys, tmp_path, monkeypatch):
    """A name resolves from ./problems first: the listing shows those files (a broken one
    with its error), then the bundled problems they do not shadow."""
    (tmp_path / "problems").mkdir()
    shutil.copy(PROBLEMS / "armz_pocket.toml", tmp_path / "problems" / "my_pocket.toml")
    shutil.copy(PROBLEMS / "armz_window.toml", tmp_path / "problems" / "armz_window.toml")
    (tmp_path / "problems" / "broken.toml").write_text("[robot\n")
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "problems", "--json")
    rows = json.loads(out)
    by_name = {r["name"]: r for r in rows}
    assert code == 0
    assert [r["name"] for r in rows[:3]] == ["armz_window", "broken", "my_pocket"]
    assert by_name["my_pocket"]["from"] == "./problems" and by_name["my_pocket"]["dof"] == 23
    assert "broken.toml" in by_name["broken"]["error"]
    assert by_name["armz_window"]["file"] == str(tmp_path / "problems" / "armz_window.toml")
    assert by_name["armz_pocket"]["from"] == "bundled"
    assert sum(r["name"] == "armz_window" for r in rows) == 1  # shadowed, listed once


def test_solve_execute_plot_round_trip(capsys, tmp_path):
    plan_path = tmp_path / "plan.json"
    code, out, _ = run(
        capsys,
        "solve",
        "armz_pocket",
        "--planner",
        "gradient.analytic",
        "--seed",
        "3",
        "--out",
        str(plan_path),
        "--json",
    )
    assert code == 0
    plan = json.loads(out)
    assert plan == json.loads(plan_path.read_text())
    leg = plan["legs"][0]
    assert leg["status"] == "local_minimum" and leg["seed"] == 3
    assert plan["versions"]["pybullet"] and plan["versions"]["python-fcl"]
    # --strict turns the stall into a failing exit code
    assert (
        run(
            capsys,
            "solve",
            "armz_pocket",
            "--planner",
            "gradient.analytic",
            "--out",
            str(tmp_path / "p2.json"),
            "--strict",
        )[0]
        == 1
    )

    plan_bytes = plan_path.read_bytes()
    umask = os.umask(0o022)
    os.umask(umask)
    # an ordinary file (0644 under the usual umask), not mkstemp's 0600
    assert plan_path.stat().st_mode & 0o777 == 0o666 & ~umask
    code, out, _ = run(capsys, "execute", str(plan_path), "--json")
    assert code == 0
    executed = json.loads(out)
    ex = executed["executions"][0]
    assert ex["path_valid"] is True and ex["leg"] == 0
    assert ex["final_pos_err_m"] == pytest.approx(leg["pos_err_m"], abs=0.05)
    assert len(ex["q_actual_rad"]) > 1
    # the execution goes beside the plan; the plan itself is never rewritten
    assert plan_path.read_bytes() == plan_bytes
    assert json.loads((tmp_path / "plan.exec.json").read_text()) == executed
    code, out, _ = run(capsys, "execute", str(plan_path), "--out", str(tmp_path / "x.json"))
    assert code == 0 and json.loads((tmp_path / "x.json").read_text())["executions"]

    # --out an existing folder: the file of its default name goes into it (it used to
    # fail only at saving, "Is a directory", the plan computed and lost)
    folder = tmp_path / "plans"
    folder.mkdir()
    code, out, _ = run(
        capsys,
        "solve",
        "armz_pocket",
        "--planner",
        "gradient.analytic",
        "--seed",
        "3",
        "--out",
        str(folder),
        "--json",
    )
    assert code == 0 and json.loads(out)["legs"][0]["status"] == "local_minimum"
    saved = folder / "armz_pocket__gradient.analytic__seed3.json"
    assert json.loads(saved.read_text())["legs"][0]["path"] == leg["path"]
    code, out, _ = run(capsys, "execute", str(plan_path), "--out", str(folder))
    assert code == 0 and json.loads((folder / "plan.exec.json").read_text())["executions"]

    code, out, _ = run(capsys, "plot", str(plan_path), "--out", str(tmp_path / "fig"), "--json")
    files = json.loads(out)
    assert code == 0 and any(f.endswith("stall.png") for f in files)
    assert all((tmp_path / "fig" / f.split("/")[-1]).stat().st_size > 10_000 for f in files)


def test_execute_refuses_a_plan_whose_problem_changed(capsys, tmp_path):
    problem = tmp_path / "pocket.toml"
    shutil.copy(PROBLEMS / "armz_pocket.toml", problem)
    plan_path = tmp_path / "plan.json"
    argv = ("solve", str(problem), "--planner", "gradient.analytic", "--max-iterations", "5")
    assert run(capsys, *argv, "--out", str(plan_path))[0] == 0
    plan = json.loads(plan_path.read_text())
    assert len(plan["problem_sha256"]) == 64
    problem.write_text(problem.read_text() + "\n# edited after planning\n")
    code, _, err = run(capsys, "execute", str(plan_path))
    assert code == 2 and "changed since planning" in " ".join(err.split())
    assert not (tmp_path / "plan.exec.json").exists()
    code, out, _ = run(capsys, "execute", str(plan_path), "--allow-changed-problem")
    assert code == 0 and "changed since planning" in out
    assert (tmp_path / "plan.exec.json").exists()


def test_table_output_names_every_leg(capsys, tmp_path):
    code, out, _ = run(
        capsys,
        "solve",
        "armz_inspection",
        "--planner",
        "gradient.analytic",
        "--legs",
        "enter",
        "--max-iterations",
        "20",
        "--out",
        str(tmp_path / "p.json"),
    )
    assert code == 0
    assert "enter" in out and "budget_exhausted" in out and "iteration budget of 20" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (("solve", "armz_pocket", "--planner", "ompl.rrtconect"), "did you mean 'ompl.rrtconnect'"),
        (("solve", "armz_pockt", "--planner", "gradient"), "did you mean 'armz_pocket'"),
        (
            ("solve", "armz_pocket", "--planner", "gradient", "--set", "gama=1"),
            "did you mean 'gamma'",
        ),
        (
            ("solve", "armz_pocket", "--planner", "gradient", "--legs", "nowhere"),
            "unknown leg 'nowhere'",
        ),
        (("execute", "missing_plan.json"), "no such plan file"),
        (("plot", str(PROBLEMS / "armz_pocket.toml")), "not JSON"),
    ],
)
def test_bad_input_exits_2_with_a_clear_message(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert message in " ".join((out + err).split())


def test_a_plan_file_of_another_format_is_refused(capsys, tmp_path):
    bad = tmp_path / "plan.json"
    bad.write_text(json.dumps({"format": "something/9", "legs": []}))
    code, out, err = run(capsys, "plot", str(bad))
    assert code == 2 and "[format] expected 'plannerlab.plan/2'" in " ".join(err.split())
    bad.write_text(json.dumps({"format": "plannerlab.plan/1", "problem": "x"}))
    code, out, err = run(capsys, "execute", str(bad))
    assert code == 2 and "is missing" in err


def test_a_bad_problem_file_shows_its_key_in_brackets(capsys, tmp_path):
    src = tmp_path / "p.toml"
    text = (PROBLEMS / "armz_pocket.toml").read_text(encoding="utf-8")
    src.write_text(text.replace("n = [0.0059, 0.2202, 0.9754]", "n = [0.0, 0.0, 0.0]"))
    code, out, err = run(capsys, "solve", str(src), "--planner", "gradient")
    assert code == 2 and "[goals[0].n] a non-zero normal vector" in " ".join(err.split())


def test_console_script_is_installed():
    exe = shutil.which("plannerlab") or str(
        __import__("pathlib").Path(sys.executable).parent / "plannerlab"
    )
    done = subprocess.run([exe, "planners"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "gradient" in done.stdout

"""What a newcomer tripped on (issue 36, item 7), each tried as a new user would: problem
names as ``plannerlab problems`` shows them, user text printed literally, help without
markup or internal names, ``solve`` by leg name, ``execute`` refusing another problem's
plan, the README's way to ``plannerlab`` and Jupyter."""

from __future__ import annotations

import ast
import json
import re
import shutil
from pathlib import Path

import pytest
from conftest import PROBLEMS

import plannerlab as pl
from plannerlab.cli.main import build_parser, main
from plannerlab.errors import PlanFileError, PlannerlabError, UnknownNameError

ROOT = Path(__file__).resolve().parents[2]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------------- problem names
def test_every_listed_problem_loads_by_the_name_it_shows(capsys, monkeypatch, tmp_path):
    """Bundled ``table`` twice (iiwa_mesh/, panda_mesh/) was listed as ``table`` twice and
    refused; a local ./problems folder shadows only the bundled file at its own place."""
    (tmp_path / "problems").mkdir()
    shutil.copy(PROBLEMS / "armz_pocket.toml", tmp_path / "problems" / "armz_pocket.toml")
    shutil.copy(PROBLEMS / "armz_window.toml", tmp_path / "problems" / "table.toml")
    for cwd in (ROOT, tmp_path):
        monkeypatch.chdir(cwd)
        code, out, _ = run(capsys, "problems", "--json")
        rows = json.loads(out)
        names = [r["name"] for r in rows]
        assert code == 0 and len(names) == len(set(names))  # each name once
        for r in rows:
            loaded = pl.load_problem(r["name"])
            assert Path(loaded.source).resolve() == Path(r["file"]).resolve(), r["name"]
        assert {"urdf/iiwa_mesh/table", "urdf/panda_mesh/table"} <= set(names)
        assert "bookshelf_small_0001" in names  # a stem no other problem has stays short
    by_name = {r["name"]: r for r in rows}
    assert by_name["table"]["from"] == "./problems"  # the local one is "table" now
    assert by_name["armz_pocket"]["from"] == "./problems"
    assert sum(r["name"].endswith("armz_pocket") for r in rows) == 1  # shadowed: listed once


def test_a_shared_name_and_a_near_miss_say_what_to_type(monkeypatch):
    monkeypatch.chdir(ROOT)
    with pytest.raises(PlannerlabError) as err:
        pl.load_problem("table")
    assert "'urdf/iiwa_mesh/table' and 'urdf/panda_mesh/table'" in str(err.value)
    with pytest.raises(UnknownNameError) as unknown:
        pl.load_problem("panda_mesh_table")
    assert "did you mean 'urdf/panda_mesh/table'" in str(unknown.value)


# ---------------------------------------------------------------------- user text literally
TINY = """\
[problem]
name = "tiny"
description = "a [simulation] table named in brackets"

[robot]
type = "armz"
n_modules = 6

[start]
fill_deg = 180.0

[[obstacles]]
name = "wall"
type = "box"
center_m = [3.0, 0.0, 2.0]
size_m = [0.4, 4.0, 4.0]

[[goals]]
name = "toward_wall"
p_m = [1.83, -0.33, 3.26]
n = [0.81, 0.28, 0.52]
pos_tol_m = 0.1
angle_tol_deg = 10.0

[simulation]
gravity_mps2 = [0.0, 0.0, 0.0]
"""


def test_terminal_output_prints_user_text_literally(capsys, tmp_path):
    """Brackets in paths, descriptions and messages were read as rich markup and eaten
    (``simulation: gravity [0.0, 0.0, 0.0] m/s² from`` stopped there)."""
    folder = tmp_path / "[simulation] runs"
    folder.mkdir()
    problem = folder / "tiny.toml"
    problem.write_text(TINY, encoding="utf-8")
    plan = folder / "[red]plan[/red].json"
    code, out, _ = run(
        capsys, "solve", str(problem), "--planner", "gradient.clearance", "--out", str(plan)
    )
    assert code == 0, out
    assert f"from {problem}" in " ".join(out.split())  # the path, brackets and all
    assert f"plan written to {plan}" in " ".join(out.split())
    code, out, _ = run(capsys, "execute", str(plan), "--out", str(folder / "e.json"))
    assert "simulation: gravity [0.0, 0.0, 0.0] m/s² from [simulation]" in out
    code, _, err = run(capsys, "solve", str(folder / "[missing].toml"), "--planner", "gradient")
    assert code == 2 and "[missing].toml" in err


def test_a_long_path_is_printed_whole_on_a_narrow_terminal(capsys, tmp_path, monkeypatch):
    """On a 40-column terminal an error and the problem's source line still carry the
    path as one run of characters, to copy and paste (rich used to break it with a line
    break at the console's width: ``.../plan.jso`` + newline + ``n``)."""
    monkeypatch.setenv("COLUMNS", "40")
    folder = tmp_path / ("a_folder_name_longer_than_the_terminal_is_wide" * 2)
    folder.mkdir()
    problem = folder / "tiny.toml"
    problem.write_text(TINY, encoding="utf-8")
    code, out, _ = run(capsys, "solve", str(problem), "--planner", "gradient.clearance",
                       "--out", str(folder / "plan.json"))  # fmt: skip
    assert code == 0 and f"from {problem}" in out
    plan = folder / "plan.json"
    problem.write_text(TINY + "\n# changed\n", encoding="utf-8")
    code, out, _ = run(capsys, "execute", str(plan), "--allow-changed-problem",
                       "--out", str(folder / "e.json"))  # fmt: skip
    assert code == 0
    assert f"the problem file {problem} changed since planning" in out
    assert f"execution written to {folder / 'e.json'} (plan: {plan})" in out
    (folder / "bad.json").write_text("{", encoding="utf-8")
    code, _, err = run(capsys, "execute", str(folder / "bad.json"))
    assert code == 2 and str(folder / "bad.json") in err


# ---------------------------------------------------------------------- help texts
def _help_texts(capsys) -> dict[str, str]:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    texts = {"plannerlab --help": parser.format_help()}
    for name, p in sub.choices.items():
        texts[f"plannerlab {name} --help"] = p.format_help()
    for name in pl.planner_names():
        code, out, _ = run(capsys, "planners", name)
        assert code == 0
        texts[f"plannerlab planners {name}"] = out
    return texts


def _internal_class_names() -> set[str]:
    """Every class defined in the package but the ones the public API exports."""
    public = {n for n in pl.__all__ if n[:1].isupper()}
    names = set()
    for path in (ROOT / "plannerlab").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                names.add(node.name)
    return names - public


def test_help_texts_print_no_markup_and_name_no_internals(capsys):
    internal = _internal_class_names()
    assert {"OMPLSettings", "ComparisonSpec", "ClearanceDescent"} <= internal
    offenders = []
    for where, text in _help_texts(capsys).items():
        flat = " ".join(text.split())
        for pattern in (r":[a-z]+:`", "``", r"\bplannerlab\.[a-z_]+\.[a-z_]+"):
            offenders += [f"{where}: {m}" for m in re.findall(pattern, flat)]
        offenders += [
            f"{where}: {w}" for w in sorted(set(re.findall(r"\b[A-Z]\w+\b", flat)) & internal)
        ]
    assert offenders == []


# ---------------------------------------------------------------------- solve and execute
@pytest.fixture(scope="module")
def pocket_plan():
    problem = pl.load_problem("armz_pocket")
    budget = problem.budget.replace(max_collision_checks=500)
    return problem, pl.solve(problem, "gradient", seed=0, budget=budget)


def test_solve_takes_leg_names_as_the_command_line_does():
    problem = pl.load_problem("armz_inspection")
    budget = problem.budget.replace(max_collision_checks=50)
    names = [g.name for g in problem.goals]
    for legs, want in (
        (names[-1], [len(names) - 1]),
        ([names[2], 0], [2, 0]),
        (f"{names[1]},{names[3]}", [1, 3]),
        (4, [4]),
    ):
        plan = pl.solve(problem, "gradient", seed=0, budget=budget, legs=legs)
        assert [r.leg for r in plan.legs] == want
        assert [r.goal for r in plan.legs] == [names[i] for i in want]
    with pytest.raises(PlannerlabError, match=r"unknown leg 'home'.*enter"):
        pl.solve(problem, "gradient", seed=0, budget=budget, legs="home")


def test_execute_refuses_a_plan_of_another_problem(pocket_plan):
    _, plan = pocket_plan
    window = pl.load_problem("armz_window")
    with pytest.raises(PlanFileError) as err:
        pl.execute(plan, window)
    assert "'armz_pocket'" in str(err.value) and "'armz_window'" in str(err.value)


# ---------------------------------------------------------------------- after set-up
def test_the_readme_says_how_to_reach_plannerlab_and_jupyter():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    do = (ROOT / "do").read_text(encoding="utf-8")
    assert "source .venv/bin/activate" in readme
    assert "./do jupyter" in readme
    assert re.search(r"^\s+jupyter\)", do, flags=re.M)  # the job exists
    assert "jupyterlab" in do  # and installs Jupyter into .venv

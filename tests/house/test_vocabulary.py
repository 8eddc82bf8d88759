"""One vocabulary for distances (issue 36, item 2): docs/distances.md names every distance
setting, and a renamed setting, problem-file key or flag still works for one release
with a warning that names its new name."""

from __future__ import annotations

import dataclasses
import re
import warnings
from pathlib import Path

import pytest

import plannerlab as pl
from plannerlab.cli.main import build_parser, main
from plannerlab.errors import ProblemError, RenamedWarning
from plannerlab.problem.reader import RENAMED_KEYS

ROOT = Path(__file__).resolve().parents[2]
GLOSSARY = (ROOT / "docs" / "distances.md").read_text(encoding="utf-8")

TINY = """\
[problem]
name = "tiny"

[robot]
type = "armz"
n_modules = 6

[start]
fill_deg = 180.0

[[goals]]
name = "up"
p_m = [0.5, 0.0, 3.0]
n = [0.0, 0.0, 1.0]
pos_tol_m = 0.1
angle_tol_deg = 10.0
"""


def _distance_settings() -> dict[str, set[str]]:
    """Every planner setting measured in m, rad or deg: key -> the planners having it."""
    out: dict[str, set[str]] = {}
    for name in pl.planner_names():
        for s in pl.planner_info(name)["settings"]:
            key = s["key"].split(".")[-1]
            if s["unit"] in ("m", "rad", "deg") or key.endswith(("_m", "_rad", "_deg")):
                out.setdefault(key, set()).add(name)
    return out


def _settings_classes() -> list[type]:
    """The settings classes of every planner, nested ones included."""
    seen: dict[str, type] = {}

    def visit(settings: object) -> None:
        seen.setdefault(type(settings).__qualname__, type(settings))
        for f in dataclasses.fields(settings):  # type: ignore[arg-type]
            value = getattr(settings, f.name)
            if dataclasses.is_dataclass(value) and not isinstance(value, type):
                visit(value)

    for name in pl.planner_names():
        visit(pl.make_planner(name).settings)
    # follow-the-leader's descent settings (descent.<key>)
    visit(pl.make_planner("gradient.follow_leader").descent_settings)  # type: ignore[attr-defined]
    return list(seen.values())


def _renamed_settings() -> list[tuple[type, str, str]]:
    return [
        (cls, old, new)
        for cls in _settings_classes()
        for old, new in getattr(cls, "RENAMED_KEYS", {}).items()
    ]


def test_the_glossary_names_every_distance_setting():
    missing = sorted(k for k in _distance_settings() if f"`{k}`" not in GLOSSARY)
    assert missing == []


def test_no_setting_is_named_margin_but_the_safety_margin():
    """Six settings read "margin" (issue 36); the one margin left is the problem's."""
    assert [k for k in _distance_settings() if "margin" in k] == []
    assert [k for k in _distance_settings() if k == "min_clearance_m"] == []


def test_the_glossary_lists_every_rename_and_the_code_renames_what_it_lists():
    renames = {(old, new) for _, old, new in _renamed_settings()}
    renames |= {(old, new) for table in RENAMED_KEYS.values() for old, new in table.items()}
    listed = set(re.findall(r"^\| [^|]+ \| `([\w-]+)` \| `([\w-]+)` \|", GLOSSARY, flags=re.M))
    flags = {(o, n) for o, n in listed if o.startswith("--")}
    assert listed - flags == renames
    assert flags == {("--min-clearance", "--clearance-floor"), ("--margin-m", "--safety-margin-m")}


def _settings_of(planner: object, prefix: str) -> object:
    """A planner's settings, or (``descent.``) its descent's (follow-the-leader)."""
    return planner.descent_settings if prefix else planner.settings  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "planner,prefix",
    [("gradient.clearance", ""), ("gradient.follow_leader", "descent."), ("chord_arc", "")],
)
def test_a_renamed_setting_is_read_with_a_warning_naming_its_new_name(planner, prefix):
    renamed = type(_settings_of(pl.make_planner(planner), prefix)).RENAMED_KEYS  # type: ignore[attr-defined]
    assert renamed
    for old, new in renamed.items():
        with pytest.warns(RenamedWarning, match=rf"'{old}' is renamed '{new}'"):
            made = pl.make_planner(planner, {prefix + old: "0.123"})
        assert getattr(_settings_of(made, prefix), new) == 0.123
        with pytest.raises(pl.PlannerlabError, match=f"give '{new}' only"):
            pl.make_planner(planner, {prefix + old: "0.1", prefix + new: "0.2"})


def test_a_renamed_problem_file_key_is_read_with_a_warning(tmp_path):
    path = tmp_path / "tiny.toml"
    witness = "\n[witness]\ngoal_states_rad = [[3.14159, 3.14159, 3.14159, 3.14159, 3.14159]]\n"
    assert RENAMED_KEYS["witness"] == {"min_clearance_m": "clearance_floor_m"}
    goal_free = TINY.replace("p_m = [0.5, 0.0, 3.0]", "p_m = [0.0, -0.34, 3.6]")
    goal_free = goal_free.replace("pos_tol_m = 0.1", "pos_tol_m = 1.0")
    goal_free = goal_free.replace("angle_tol_deg = 10.0", "angle_tol_deg = 180.0")
    path.write_text(goal_free + witness + "min_clearance_m = 0.04\n", encoding="utf-8")
    with pytest.warns(RenamedWarning, match=r"\[witness\].*'min_clearance_m' is renamed"):
        problem = pl.parse_problem(path)
    assert problem.extras["witness"]["clearance_floor_m"] == 0.04
    assert "min_clearance_m" not in problem.extras["witness"]
    path.write_text(goal_free + witness + "clearance_floor_m = 0.04\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new key: no warning
        pl.parse_problem(path)
    both = "min_clearance_m = 0.04\nclearance_floor_m = 0.04\n"
    path.write_text(goal_free + witness + both, encoding="utf-8")
    with pytest.raises(ProblemError, match="clearance_floor_m' only"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pl.parse_problem(path)


def test_a_renamed_flag_is_read_with_a_warning_on_the_command_line(capsys):
    parser = build_parser()
    with pytest.warns(RenamedWarning, match="'--min-clearance' is renamed '--clearance-floor'"):
        args = parser.parse_args(["variants", "armz_inspection", "--min-clearance", "0.05"])
    assert args.clearance_floor == 0.05
    with pytest.warns(RenamedWarning, match="'--margin-m' is renamed '--safety-margin-m'"):
        args = parser.parse_args(["import", "mbm", "x", "--margin-m", "0.02"])
    assert args.safety_margin_m == 0.02
    assert "--min-clearance" not in parser.format_help()
    # the command line shows it as one line on stderr, not a Python traceback of a warning
    code = main(["planners", "gradient.clearance", "--json"])
    assert code == 0
    capsys.readouterr()


def test_the_command_line_prints_a_renamed_setting_as_one_warning_line(capsys, tmp_path):
    (tmp_path / "p.toml").write_text(TINY, encoding="utf-8")
    code = main(
        [
            "solve",
            str(tmp_path / "p.toml"),
            "--planner",
            "gradient.clearance",
            "--set",
            "margin_m=0.2",
            "--max-checks",
            "50",
            "--out",
            str(tmp_path / "plan.json"),
        ]
    )
    _, err = capsys.readouterr()
    assert code in (0, 1)
    lines = [line for line in err.splitlines() if "renamed" in line]
    assert len(lines) == 1 and lines[0].startswith("warning: settings of gradient.clearance:")
    assert "'influence_m'" in lines[0]

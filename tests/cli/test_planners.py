"""``plannerlab planners``: what each planner suits, and one planner's settings with
units, defaults and what each does, read from its settings dataclass and docstrings."""

from __future__ import annotations

import dataclasses
import json

import pytest

import plannerlab as pl
from plannerlab.cli.main import main
from plannerlab.run.planner_info import docstring_entries


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_the_list_says_what_each_planner_suits(capsys):
    code, out, _ = run(capsys, "planners", "--json")
    rows = {r["name"]: r for r in json.loads(out)}
    assert code == 0 and set(rows) == set(pl.planner_names())
    assert all(r["suits"] for r in rows.values())
    assert "7-joint" in rows["ompl.rrtconnect"]["suits"]
    assert "hyper-redundant" in rows["gradient.follow_leader"]["suits"]
    assert "continuum" in rows["chord_arc"]["suits"]
    assert rows["chord_arc"]["robots"] == ["continuum_chain"]
    code, out, _ = run(capsys, "planners")
    assert "continuum_chain" in out and "plannerlab planners NAME" in out


def test_one_planner_shows_its_settings_as_one_json_document(capsys):
    code, out, _ = run(capsys, "planners", "gradient.clearance+detour", "--json")
    info = json.loads(out)  # raises on anything around the document
    settings = {s["key"]: s for s in info["settings"]}
    assert code == 0 and info["name"] == "gradient.clearance+detour"
    assert info["settings_class"].endswith("ClearanceSettings")
    # the defaults of this planner (its registry entry sets the escape)
    assert settings["escape"]["default"] == "detour"
    # derived from the robot's size when the leg is planned; the doc gives Arm-Z's value
    assert (
        settings["influence_m"]["default"] == "derived" and settings["influence_m"]["unit"] == "m"
    )
    assert "0.3 on Arm-Z" in settings["influence_m"]["doc"]
    assert "distance of influence" in settings["influence_m"]["doc"]
    assert settings["max_step_rad"]["unit"] == "rad"
    assert "tip position" in settings["r1"]["doc"] and "tip normal" in settings["r2"]["doc"]


def test_every_setting_of_every_planner_is_listed(capsys):
    for name in pl.planner_names():
        info = pl.planner_info(name)
        settings = pl.make_planner(name).settings
        assert [s["key"] for s in info["settings"]] == [
            f.name for f in dataclasses.fields(settings)
        ], name


@pytest.mark.parametrize("name", ["gradient.follow_leader", "ompl.rrtconnect", "chord_arc"])
def test_documented_settings_show_their_meaning_and_unit(capsys, name):
    code, out, _ = run(capsys, "planners", name)
    info = pl.planner_info(name)
    assert code == 0 and all(s["doc"] for s in info["settings"]), name
    text = " ".join(out.split())
    assert "what it does" in text and "--set key=value" in text
    for s in info["settings"]:
        assert s["key"] in text
        if s["key"].endswith("_m") and not s["key"].endswith("_per_m"):
            assert s["unit"] == "m", s
        if s["key"].endswith("_per_m"):
            assert s["unit"] == "1/m", s


def test_an_unknown_planner_is_a_clear_error(capsys):
    code, _, err = run(capsys, "planners", "ompl.rrtconect")
    assert code == 2 and "did you mean 'ompl.rrtconnect'" in " ".join(err.split())


def test_the_docstring_reader_takes_each_form():
    doc = """Settings.

    Attributes:
        a_m: the first [m].
        b, c_rad: two at once,
            continued here [rad].
        d: see ``e``.

    Search:
        f: in another section.

    Prose: ``g``: inline in a sentence. After it.
    """
    entries = docstring_entries(doc)
    assert entries["a_m"] == "the first [m]."
    assert entries["b"] == entries["c_rad"] == "two at once, continued here [rad]."
    assert entries["d"] == "see ``e``."
    assert entries["f"] == "in another section."
    assert entries["g"] == "inline in a sentence."
    assert "Prose" not in entries and "Settings." not in entries

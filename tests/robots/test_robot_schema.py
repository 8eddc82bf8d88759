"""The ``[robot]`` tables: each family declares its keys beside its model
(``robots/<family>/schema.py``), the loader parses them all with one function, and
``docs/problem-format.md`` lists exactly the declared keys with their units and defaults."""

from __future__ import annotations

import dataclasses
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from plannerlab.errors import ProblemError, UnknownNameError
from plannerlab.problem.reader import TableReader
from plannerlab.problem.robot_table import build_robot, parse_robot_table
from plannerlab.robots.registry import FAMILIES, robot_table
from plannerlab.robots.schema import Key, RobotTable, TableValueError

DOC = Path(__file__).resolve().parents[2] / "docs" / "problem-format.md"


def _doc_rows(kind: str) -> dict[str, tuple[str, str, str]]:
    """key -> (unit, default, meaning) from the table under ``### `type = "KIND"```."""
    text = DOC.read_text(encoding="utf-8")
    head = f'### `type = "{kind}"`'
    assert text.count(head) == 1, f"{DOC.name} has no single section {head}"
    section = text.split(head, 1)[1].split("\n## ", 1)[0].split("\n### ", 1)[0]
    rows: dict[str, tuple[str, str, str]] = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|") or len(cells) != 4 or not cells[0].startswith("`"):
            continue
        names = re.findall(r"`([^`]+)`", cells[0])
        assert len(names) == 1, f"one key per row, got {cells[0]!r} (section {kind})"
        assert names[0] not in rows, f"{names[0]} listed twice (section {kind})"
        rows[names[0]] = (cells[1], cells[2], cells[3])
    return rows


def _doc_value(cell: str) -> object:
    """A default as the doc writes it: a TOML value, with typographic minus signs."""
    return tomllib.loads("v = " + cell.replace("−", "-"))["v"]


@pytest.mark.parametrize("kind", sorted(FAMILIES))
def test_the_doc_lists_every_declared_key_with_its_unit_and_default(kind):
    table = robot_table(kind)
    rows = _doc_rows(kind)
    assert sorted(rows) == sorted(table.names), f"{DOC.name}, type = {kind!r}"
    for key in table.keys:
        unit, default, meaning = rows[key.name]
        assert unit == key.unit, (kind, key.name)
        if key.required:
            assert default == "required", (kind, key.name, default)
            continue
        value = _doc_value(default)
        if key.kind == "pairs":
            assert value == [list(p) for p in key.default], (kind, key.name)  # type: ignore[union-attr]
        elif key.kind == "vector":
            assert isinstance(value, list), (kind, key.name, default)
            assert np.allclose(value, key.default, rtol=0, atol=1e-12), (kind, key.name)
        elif key.kind in ("string", "path"):
            assert value == key.default, (kind, key.name)
        else:
            assert isinstance(value, int | float) and abs(value - key.default) < 1e-12, (
                kind,
                key.name,
                default,
            )
        if key.kind == "integer" and key.minimum is not None and key.maximum is not None:
            assert f"{key.minimum:g} … {key.maximum:g}" in meaning, (kind, key.name)


def test_the_doc_check_reads_a_table_as_written():
    """The parser behind the doc test finds rows, units, defaults (TOML values)."""
    rows = _doc_rows("irb6")
    assert rows["theta1_range_deg"][:2] == ("deg", "[−170, 170]")
    assert _doc_value(rows["theta1_range_deg"][1]) == [-170, 170]
    assert _doc_value(rows["dead_wedge_side"][1]) == "-z"


@pytest.mark.parametrize("kind", sorted(FAMILIES))
def test_a_table_with_only_the_type_builds_the_models_defaults(kind):
    """The declared defaults are the model's own: nothing drifts between the two."""
    table = robot_table(kind)
    assert table.type == kind
    required = [k.name for k in table.keys if k.required]
    if required:  # a URDF robot has no defaults to build: the table names what is missing
        with pytest.raises(ProblemError, match=rf"mem\.toml.*robot\.{required[0]}\] is missing"):
            build_robot(TableReader("mem.toml", "robot", {"type": kind}))
        return
    robot = build_robot(TableReader("mem.toml", "robot", {"type": kind}))
    default = type(robot)()
    for f in dataclasses.fields(robot):
        if f.init:
            a, b = getattr(robot, f.name), getattr(default, f.name)
            assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, f.name


def test_an_unknown_robot_type_names_the_known_ones():
    with pytest.raises(UnknownNameError, match="did you mean 'irb6'"):
        robot_table("irb7")


# ------------------------------------------------------------ the one generic parser
def _build(values):  # a stand-in constructor: the parser's tests need no robot
    if values["count"] == 7:
        raise TableValueError("count", "an unlucky number")
    return dict(values)


TOY = RobotTable(
    type="toy",
    keys=(
        Key("count", "integer", 3, meaning="how many", minimum=1, maximum=9, why_maximum="a toy"),
        Key("length_m", "number", 0.5, "m", "how long", positive=True),
        Key("angle_deg", "number", 10.0, "deg", "how bent", minimum=-90, maximum=90),
        Key("span_m", "vector", (0.0, 1.0), "m", "where", length=2, ordered=True),
        Key("side", "string", "left", meaning="which side", choices=("left", "right")),
    ),
    build=_build,
)


def _parse(table: dict) -> dict:
    return parse_robot_table(TableReader("toy.toml", "robot", {"type": "toy", **table}), TOY)


def test_absent_keys_take_their_defaults_as_plain_values():
    v = _parse({"count": 4, "note": "free text"})
    assert v["count"] == 4 and isinstance(v["count"], int)
    assert v["length_m"] == 0.5 and isinstance(v["length_m"], float)
    assert isinstance(v["span_m"], np.ndarray) and v["span_m"].tolist() == [0.0, 1.0]
    assert v["side"] == "left" and set(v) == set(TOY.names)


BAD_VALUES = {
    # name: (table, key named, expectation in the message)
    "unknown_key": ({"lenght_m": 1.0}, "robot.lenght_m", "did you mean 'length_m'"),
    "integer_as_float": ({"count": 2.0}, "robot.count", "an integer, got 2.0"),
    "integer_too_small": ({"count": 0}, "robot.count", "an integer >= 1, got 0"),
    "integer_too_big": ({"count": 10}, "robot.count", "an integer <= 9, got 10 (a toy)"),
    "number_as_string": ({"length_m": "1"}, "robot.length_m", "a number, got '1'"),
    "number_as_bool": ({"length_m": True}, "robot.length_m", "a number, got True"),
    "number_not_positive": ({"length_m": 0}, "robot.length_m", "a positive number"),
    "number_nan": ({"length_m": float("nan")}, "robot.length_m", "a finite number"),
    "number_below_minimum": ({"angle_deg": -91}, "robot.angle_deg", "a number >= -90"),
    "number_above_maximum": ({"angle_deg": 95}, "robot.angle_deg", "a number <= 90, got 95"),
    "vector_wrong_length": ({"span_m": [1.0]}, "robot.span_m", "a list of 2 numbers"),
    "vector_not_ordered": ({"span_m": [2, 1]}, "robot.span_m", "lower <= upper [m]"),
    "string_not_a_choice": ({"side": "up"}, "robot.side", '"left" (the default) or "right"'),
}


@pytest.mark.parametrize("case", sorted(BAD_VALUES))
def test_a_bad_value_names_the_file_the_key_and_the_expectation(case):
    table, key, expected = BAD_VALUES[case]
    with pytest.raises(ProblemError) as err:
        _parse(table)
    assert err.value.source == "toy.toml" and err.value.key == key
    assert expected in err.value.expected, err.value.expected


def test_a_combination_the_constructor_refuses_names_its_key(monkeypatch):
    from plannerlab.robots import registry

    monkeypatch.setitem(registry.FAMILIES, "toy", registry.RobotFamily("toy", lambda: TOY))
    reader = TableReader("toy.toml", "robot", {"type": "toy", "count": 7})
    with pytest.raises(ProblemError) as err:
        build_robot(reader)
    assert err.value.key == "robot.count" and err.value.expected == "an unlucky number"


def test_a_continuum_base_out_of_the_plane_is_refused_on_its_key():
    reader = TableReader("c.toml", "robot", {"type": "continuum_chain", "base_rpy_deg": [5, 0, 0]})
    with pytest.raises(ProblemError) as err:
        build_robot(reader)
    assert err.value.key == "robot.base_rpy_deg" and "planar" in err.value.expected


def test_an_irb6_range_the_model_refuses_is_blamed_on_its_key():
    reader = TableReader("i.toml", "robot", {"type": "irb6", "theta1_range_deg": [-200, 200]})
    with pytest.raises(ProblemError) as err:
        build_robot(reader)
    assert err.value.key == "robot.theta1_range_deg" and "360" in err.value.expected


@pytest.mark.parametrize(
    "kwargs",
    [
        {"kind": "vectr", "default": 1.0},
        {"kind": "vector", "default": (0.0, 0.0)},  # no length
        {"kind": "vector", "default": (0.0,), "length": 1, "ordered": True},
        {"kind": "number", "default": 1.0, "choices": ("a",)},
        {"kind": "string", "default": "a", "positive": True},
        {"kind": "integer", "default": 1, "why_maximum": "no maximum given"},
    ],
    ids=["kind", "vector_length", "ordered", "choices", "positive_string", "why_maximum"],
)
def test_a_malformed_declaration_is_refused_when_declared(kwargs):
    with pytest.raises(ValueError, match="robot table key 'x'"):
        Key("x", **kwargs)


def test_type_and_note_are_not_declared_by_a_family():
    with pytest.raises(ValueError, match="common to every robot table"):
        Key("note", "string", "")


def test_a_family_plugs_in_with_one_registry_entry(monkeypatch, tmp_path):
    """A new robot family needs its entry in robots/registry.py and nothing in problem/:
    a problem file naming it loads through the registered table, and its own reach bound
    and goal sampler are the ones used."""
    from plannerlab.problem.goals import GoalRegion, unreachable_reason
    from plannerlab.problem.load import parse_problem
    from plannerlab.robots import registry
    from plannerlab.robots.registry import goal_sampler

    entry = registry.RobotFamily(
        "armz_alias",
        lambda: ALIAS_TABLE,
        reach=_tiny_reach,
        goal_sampler=_no_goal,
    )
    monkeypatch.setitem(registry.FAMILIES, "armz_alias", entry)
    path = tmp_path / "p.toml"
    path.write_text(
        '[problem]\nname = "alias"\n[robot]\ntype = "armz_alias"\nn_modules = 6\n'
        '[start]\nfill_deg = 180.0\n[[goals]]\nname = "g"\n'
        "p_m = [1.0, 0.0, 1.0]\nn = [0.0, 0.0, 1.0]\npos_tol_m = 0.1\nangle_tol_deg = 10.0\n",
        encoding="utf-8",
    )
    problem = parse_problem(path)
    assert problem.robot.dof == 5  # the Arm-Z table built it
    goal = GoalRegion("g", np.array([1.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), 0.1, 10.0)
    assert "tiny reach" in unreachable_reason(problem.robot, goal)
    assert goal_sampler("armz_alias") is _no_goal


def _alias_build(values):
    from plannerlab.robots.armz.schema import TABLE

    robot = TABLE.build(values)
    object.__setattr__(robot, "kind", "armz_alias")  # a family's robots carry its kind
    return robot


def _alias_table():
    import dataclasses

    from plannerlab.robots.armz.schema import TABLE

    return dataclasses.replace(TABLE, type="armz_alias", build=_alias_build)


ALIAS_TABLE = _alias_table()


def _tiny_reach(robot, p_world_m):
    return float(np.linalg.norm(p_world_m)), 0.01, "tiny reach"


def _no_goal(robot, goal, rng, seeds=()):
    return None

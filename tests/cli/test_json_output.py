"""``--json`` output is exactly one JSON document on stdout, whatever the engines print
(PyBullet writes ``argv[0]=`` and its banner to file descriptor 1, OMPL logs there).

Runs the real command in a subprocess (file-descriptor-level output is what matters),
for each kind of planner: gradient, gradient.closed_loop (PyBullet in the loop), ompl.*.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import PROBLEMS, plannerlab

POCKET = str(PROBLEMS / "armz_pocket.toml")


def one_json_document(stdout: str):
    return json.loads(stdout)  # raises on anything before or after the document


BUDGETS = {
    "gradient": ["--max-iterations", "3"],
    "gradient.closed_loop": ["--max-iterations", "3"],
    "ompl.rrtconnect": ["--max-checks", "300"],
}


@pytest.fixture(scope="module")
def plans(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("plans")
    paths = {}
    for planner, budget in BUDGETS.items():
        path = out / f"{planner}.json"
        proc = plannerlab(
            "solve", POCKET, "--planner", planner, "--out", str(path), "--json", *budget
        )
        assert proc.returncode == 0, proc.stderr
        plan = one_json_document(proc.stdout)
        assert plan["planner"] == planner and len(plan["legs"]) == 1
        paths[planner] = path
    return paths


@pytest.mark.parametrize("planner", sorted(BUDGETS))
def test_solve_json_is_one_document(plans, planner):
    assert json.loads(plans[planner].read_text())["planner"] == planner


@pytest.mark.parametrize("planner", ["gradient", "ompl.rrtconnect"])
def test_execute_json_is_one_document(plans, tmp_path, planner):
    proc = plannerlab("execute", str(plans[planner]), "--json")
    assert proc.returncode == 0, proc.stderr
    doc = one_json_document(proc.stdout)
    assert len(doc["executions"]) == 1


def test_plot_json_is_one_document(plans, tmp_path):
    proc = plannerlab("plot", str(plans["gradient"]), "--out", str(tmp_path), "--json")
    assert proc.returncode == 0, proc.stderr
    files = one_json_document(proc.stdout)
    assert files and all(Path(f).exists() for f in files)


def test_compare_json_is_one_document(tmp_path):
    proc = plannerlab(
        "compare",
        POCKET,
        "--planners",
        "gradient,ompl.rrtconnect",
        "--seeds",
        "0",
        "--max-checks",
        "300",
        "--max-iterations",
        "3",
        "--out",
        str(tmp_path),
        "--json",
    )
    assert proc.returncode == 0, proc.stderr
    one_json_document(proc.stdout)


def test_pybullet_banner_stays_off_a_normal_terminal_unless_verbose(plans):
    quiet = plannerlab("execute", str(plans["gradient"]))
    assert quiet.returncode == 0, quiet.stderr
    assert "argv[0]" not in quiet.stdout and "argv[0]" not in quiet.stderr
    loud = plannerlab("-v", "execute", str(plans["gradient"]))
    assert loud.returncode == 0, loud.stderr
    assert "argv[0]" not in loud.stdout and "argv[0]" in loud.stderr


def test_robot_command_reports_covers_pairs_and_writes_the_srdf(tmp_path):
    """``plannerlab robot URDF --json``: one document with the joints, every mesh's cover
    (primitives within the budget, its worst excess), the pairs never checked with their
    reasons, the load time; the SRDF it wrote reads back as the same pairs."""
    from plannerlab.robots.urdf.model import read_srdf_disabled

    data = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"
    srdf = tmp_path / "arm.srdf"
    proc = plannerlab(
        "robot",
        str(data / "mesh_arm.urdf"),
        "--mesh-path",
        str(data / "pkgroot"),
        "--max-primitives",
        "4",
        "--excess-mm",
        "20",
        "--states",
        "100",
        "--srdf",
        str(srdf),
        "--no-cache",
        "--json",
    )
    assert proc.returncode == 0, proc.stderr
    doc = one_json_document(proc.stdout)
    assert doc["tip_link"] == "tool" and doc["dof"] == 3
    assert [c["link"] for c in doc["covers"]] == ["base", "upper", "fore", "tool"]
    assert all(1 <= c["primitives"] <= 4 and c["max_excess_mm"] > 0 for c in doc["covers"])
    reasons = {p["reason"] for p in doc["pairs"]}
    assert "Adjacent" in reasons and doc["load_s"] > 0
    pairs = {(p["link1"], p["link2"]) for p in doc["pairs"]}
    assert set(read_srdf_disabled(srdf)) == pairs


def test_robot_command_names_a_broken_mesh_and_exits_2(tmp_path):
    import shutil

    data = Path(__file__).resolve().parents[1] / "data" / "mesh_arm"
    d = tmp_path / "arm"
    shutil.copytree(data, d)
    (d / "meshes" / "upper.obj").write_text("not a mesh")
    proc = plannerlab("robot", str(d / "mesh_arm.urdf"), "--mesh-path", str(d / "pkgroot"))
    assert proc.returncode == 2
    err = proc.stderr.replace("\n", "")  # the terminal's lines wrap the message
    assert "upper.obj" in err and "link upper" in err

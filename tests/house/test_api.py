"""The public API: light to import, and docs/api.md's example runs as written."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat

import plannerlab

ROOT = Path(__file__).resolve().parents[2]


def test_every_export_resolves_and_nothing_else_does():
    for name in plannerlab.__all__:
        assert getattr(plannerlab, name) is not None
    assert set(plannerlab.__all__) <= set(dir(plannerlab))
    try:
        plannerlab.not_a_name  # noqa: B018
    except AttributeError as exc:
        assert "not_a_name" in str(exc)
    else:
        raise AssertionError("an unknown attribute resolved")


def test_import_plannerlab_loads_no_engine_and_no_submodule():
    code = (
        "import json, sys\n"
        "import plannerlab\n"
        "heavy = ('numpy', 'fcl', 'ompl', 'pybullet', 'matplotlib')\n"
        "print(json.dumps(sorted(m for m in sys.modules\n"
        "                        if m.split('.')[0] in heavy or m.startswith('plannerlab.'))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout) == []


def test_the_api_pages_checker_example_runs(tmp_path):
    """docs/api.md's ``pl.checker`` example, as a user copies it."""
    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    (example,) = [
        b for b in re.findall(r"```python\n(.*?)```", page, flags=re.S) if "checker(" in b
    ]
    out = subprocess.run(
        [sys.executable, "-c", example + "\nprint(check.valid(q), int(ok.sum()))\n"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=600,
        env={**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)},
    )
    assert out.returncode == 0, out.stderr[-2000:]
    first, count = out.stdout.split()[-2:]
    assert first == "True" and 0 < int(count) < 100_000


def test_the_api_page_example_runs_as_a_script(tmp_path):
    """docs/api.md's example (the README links it), pasted into a file and run as a script,
    with no ``if __name__ == "__main__":``: the comparison's trial processes must not run
    the script again (they did, and every trial died in its bootstrapping, issue 36)."""
    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    example = re.findall(r"```python\n(.*?)```", page, flags=re.S)[0]
    assert len(example.strip().splitlines()) <= 14
    assert "__main__" not in example
    script = tmp_path / "example.py"
    script.write_text(example, encoding="utf-8")
    out = subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=600,
        env={**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)},
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert "ompl.rrtconnect" in out.stdout  # the comparison's table
    records = [json.loads(line) for line in (tmp_path / "trials.jsonl").read_text().splitlines()]
    assert sorted((r["planner"], r["seed"]) for r in records) == [
        ("gradient", 0),
        ("gradient", 1),
        ("ompl.rrtconnect", 0),
        ("ompl.rrtconnect", 1),
    ]
    assert [r["error"] for r in records] == [None] * 4  # every trial ran, none died
    assert all(r["legs_run"] for r in records)


def _api_tables() -> tuple[list[str], list[str]]:
    """The names docs/api.md lists: its table of ``plannerlab`` and its table of
    ``plannerlab.extras`` (the first column's backticked name of each row)."""
    page = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    top, extras = page.split("## What only the command line needs")
    top = top.split("## Every name of `plannerlab`")[1]

    def names(text: str) -> list[str]:
        return re.findall(r"^\| `(\w+)` \|", text, flags=re.M)

    return names(top), names(extras)


def test_the_api_page_lists_every_public_name_and_no_other():
    import plannerlab.extras

    top, extras = _api_tables()
    assert len(top) == len(set(top)) and len(extras) == len(set(extras))
    assert sorted(top) == sorted(plannerlab.__all__)
    assert sorted(extras) == sorted(plannerlab.extras.__all__)
    assert set(top).isdisjoint(extras)


def test_the_extras_resolve_and_import_nothing_until_used():
    import plannerlab.extras

    for name in plannerlab.extras.__all__:
        assert getattr(plannerlab.extras, name) is not None
    assert plannerlab.extras.__all__ == sorted(plannerlab.extras._EXPORTS)
    code = (
        "import json, sys\n"
        "import plannerlab.extras\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.startswith('plannerlab.')\n"
        "                        and m != 'plannerlab.extras')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout) == []


def test_the_notebook_uses_only_the_public_api():
    nb = nbformat.read(ROOT / "notebooks" / "compare.ipynb", as_version=4)
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    assert "import plannerlab as pl" in code
    assert re.findall(r"(?:from|import) plannerlab\.\w+", code) == []


def test_the_export_table_and_all_agree():
    """``__all__`` is the lazy export table plus the functions written in the module itself
    (``view``, which puts the viewer's parts together)."""
    own = sorted(set(plannerlab.__all__) - set(plannerlab._EXPORTS))
    assert own == ["view"]
    assert all(getattr(plannerlab, n).__module__ == "plannerlab" for n in own)
    assert sorted(set(plannerlab.__all__) - set(own)) == sorted(plannerlab._EXPORTS)
    assert len(plannerlab.__all__) == len(set(plannerlab.__all__))

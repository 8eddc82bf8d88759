"""The notebook runs headless, top to bottom, with the quick switch on."""

from __future__ import annotations

from pathlib import Path

import nbformat
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[2] / "notebooks" / "compare.ipynb"


def test_compare_notebook_runs_headless(tmp_path, monkeypatch):
    monkeypatch.setenv("PLANNERLAB_QUICK", "1")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(
        nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    ).execute()
    outputs = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    )
    assert "local_minimum" in outputs  # the paper's method stalls on the pocket
    assert "gradient+rrtconnect" in outputs
    images = [o for c in nb.cells for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert len(images) >= 2  # the arm snapshot and the progress plot
    gifs = [o for c in nb.cells for o in c.get("outputs", []) if "image/gif" in o.get("data", {})]
    assert len(gifs) == 2  # the motions, planned and executed, inline: Arm-Z's and the Panda's
    # the interactive 3-D views (viser), Arm-Z's and the Panda's, inline as live pages
    frames = [
        o["data"]["text/html"]
        for c in nb.cells
        for o in c.get("outputs", [])
        if "<iframe" in o.get("data", {}).get("text/html", "")
    ]
    assert len(frames) == 2 and all('src="http://127.0.0.1:' in f for f in frames)
    # the Panda on the bookshelf, from the files in problems/urdf/panda (no network)
    panda = outputs.split("bookshelf_small_0001 - MotionBenchMaker")[1]
    assert panda.startswith(" bookshelf_small_panda/scene0001")
    assert "solved - RRTConnect: Exact solution" in panda
    assert "without contact" in panda
    assert "certified free: True" in panda  # pl.checker on the Panda's plan

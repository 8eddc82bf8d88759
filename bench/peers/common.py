"""What both peer runners share (standard library and numpy only: they run in the peers'
own virtual environments, where plannerlab is not installed).

A runner is called as ``python <runner> QUERY.json OUT.json``; ``QUERY.json`` is written by
``bench/peers_mesh.py`` (its docstring has the format), ``OUT.json`` gets one JSON object:
``peer``, ``version``, ``solved``, ``status``, ``setup_s`` (URDF and scene loaded),
``plan_s`` (the search and the path's simplification), ``start_valid`` / ``goal_valid``
(in the peer's own collision model), ``path`` (rows of joint values in the query's
``joint_names`` order; empty when not solved), ``notes``.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any


def write_atomic(path: Path, doc: dict[str, Any]) -> None:
    """``doc`` as JSON at ``path``, written to a temporary file first and renamed."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(doc, fh)
    os.replace(tmp, path)


def reorder(names_from: list[str], names_to: list[str]) -> list[int]:
    """Indices ``k`` so that ``row[k]`` (a row in ``names_from`` order) is in
    ``names_to`` order; refuses two different sets of joints, naming both."""
    if sorted(names_from) != sorted(names_to):
        raise SystemExit(f"the peer's joints {names_from} are not the query's {names_to}")
    return [names_from.index(n) for n in names_to]


def main(peer: str, solve: Callable[[dict[str, Any]], dict[str, Any]]) -> int:
    """Read the query (argv[1]), run ``solve``, write its answer (argv[2]); an exception
    is an answer too (``status`` = its text), so the bench records why a peer failed."""
    if len(sys.argv) != 3:
        print(f"usage: {Path(sys.argv[0]).name} QUERY.json OUT.json", file=sys.stderr)
        return 2
    query = json.loads(Path(sys.argv[1]).read_text())
    try:
        out = solve(query)
    except Exception as exc:  # the peer refused the URDF, the scene or the query
        out = {
            "solved": False,
            "status": f"error: {type(exc).__name__}: {exc}"[:600],
            "traceback": traceback.format_exc()[-3000:],
            "path": [],
        }
    out["peer"] = peer
    write_atomic(Path(sys.argv[2]), out)
    return 0

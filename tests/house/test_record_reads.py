"""Records are read by attribute (issue 36): the string-key reads left in ``comparison/``
and ``plot/``, counted from the code.

A string-key read is ``x["name"]`` (loaded, not stored) or ``x.get("name", …)``. Run it
to see the count and every read left:

    .venv/bin/python tests/house/test_record_reads.py
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "plannerlab"
ROOMS = ("comparison", "plot")
#: the most string-key reads ``comparison/`` and ``plot/`` may hold (the issue's target)
MOST = 20


def string_key_reads(path: Path) -> list[tuple[int, str]]:
    """(line, source) of every string-key read in one module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Subscript)
            and isinstance(node.ctx, ast.Load)
            and isinstance(node.slice, ast.Constant)
            and isinstance(node.slice.value, str)
        ) or (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "get"
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
        ):
            out.append((node.lineno, ast.unparse(node)))
    return sorted(out)


def all_reads() -> dict[str, list[tuple[int, str]]]:
    return {
        str(p.relative_to(PACKAGE.parent)): reads
        for room in ROOMS
        for p in sorted((PACKAGE / room).glob("*.py"))
        if (reads := string_key_reads(p))
    }


def test_records_are_read_by_attribute() -> None:
    reads = all_reads()
    total = sum(len(v) for v in reads.values())
    assert total <= MOST, "\n".join(f"{f}:{n}: {s}" for f, v in reads.items() for n, s in v)


if __name__ == "__main__":
    found = all_reads()
    for f, v in found.items():
        for n, s in v:
            print(f"{f}:{n}: {s}")
    print(f"{sum(len(v) for v in found.values())} string-key reads in {', '.join(ROOMS)}")
    sys.exit(0)

"""Tooling that CI runs through this test: the code is ruff-formatted and mypy finds no
error in ``plannerlab/`` (configuration in pyproject.toml)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _run(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=600)


def test_ruff_format_is_clean():
    out = _run(sys.executable, "-m", "ruff", "format", "--check", "plannerlab", "tests", "bench")
    assert out.returncode == 0, out.stdout + out.stderr


def test_mypy_finds_no_error():
    out = _run(sys.executable, "-m", "mypy", "plannerlab")
    assert out.returncode == 0, out.stdout[-5000:] + out.stderr[-2000:]

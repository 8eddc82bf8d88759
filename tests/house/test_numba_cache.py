"""numba's cache goes to a folder named by a digest of the package's compiled code
(``plannerlab._numba_cache_dir``), so that a cached kernel never runs against a callee
changed by an update, whether numba is imported before plannerlab or not; a
``NUMBA_CACHE_DIR`` the user sets wins."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def _cache_dir(code: str, tmp_path: Path, **env: str) -> str:
    run_env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    run_env |= {"XDG_CACHE_HOME": str(tmp_path), **env}
    out = subprocess.run(
        [sys.executable, "-c", code + "\nprint(numba.core.config.CACHE_DIR)"],
        env=run_env,
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    return out.stdout.strip().splitlines()[-1]


def test_the_digest_folder_is_used_whether_numba_comes_first_or_not(tmp_path: Path) -> None:
    after = _cache_dir("import plannerlab\nimport numba", tmp_path)
    first = _cache_dir("import numba\nimport plannerlab", tmp_path)
    folder = Path(after)
    assert folder.parent == tmp_path / "plannerlab" / "numba"
    assert len(folder.name) == 16 and folder.is_dir()
    assert first == after  # numba imported first no longer falls back to __pycache__


def test_a_cache_dir_set_by_the_user_wins(tmp_path: Path) -> None:
    mine = str(tmp_path / "mine")
    assert _cache_dir("import numba\nimport plannerlab", tmp_path, NUMBA_CACHE_DIR=mine) == mine
    assert _cache_dir("import plannerlab\nimport numba", tmp_path, NUMBA_CACHE_DIR=mine) == mine


def test_old_folders_go_but_one_in_use_by_another_checkout_stays(tmp_path: Path) -> None:
    """Folders of other code versions: beyond the three most recently used, one unused for
    longer than ``CACHE_IN_USE_S`` is removed; one used recently (another checkout's
    running process may write to it) stays, however many there are."""
    import time

    import plannerlab

    base = tmp_path / "plannerlab" / "numba"
    now = time.time()
    ages_days = {"recent1": 0.01, "recent2": 1, "recent3": 2, "recent4": 3, "old1": 30, "old2": 60}
    for name, age in ages_days.items():
        (base / name).mkdir(parents=True)
        (base / name / "stamp").touch()
        os.utime(base / name / "stamp", (now - age * 86400, now - age * 86400))
    (base / "unstamped").mkdir()
    mine = base / "mine"
    mine.mkdir()
    plannerlab._prune_numba_caches(mine)
    left = sorted(p.name for p in base.iterdir())
    assert left == ["mine", "recent1", "recent2", "recent3", "recent4"]

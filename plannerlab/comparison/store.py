"""The trial store: one JSON line per finished trial (a
:class:`~plannerlab.record.trial.TrialRecord` with its schema version), appended by one
writer, read back to resume an interrupted comparison."""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from plannerlab.errors import PlannerlabError
from plannerlab.record.trial import NotJSONError, TrialRecord, decode_trial, encode_trial

LOGGER = logging.getLogger(__name__)


# ---------------------------------------------------------------------- the store
class TrialStore:
    """Append-only JSON-lines file of finished trial records (one line per trial).

    Every line is flushed and fsynced when written. On reading, a line that is not valid
    JSON is ignored: the last one may be half-written by a kill (it is cut off before the
    next append, so new lines never glue onto it); any other is logged. A key that occurs
    twice keeps its last record. Lines of the previous schema version are read and
    converted; a line of another version is refused, naming the file and line
    (:class:`~plannerlab.record.trial.StoreFormatError`).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)

    def load(self) -> dict[str, TrialRecord]:
        """Records by trial key.

        Raises:
            StoreFormatError: a line of a schema version this plannerlab does not read.
            PlannerlabError: a JSON line that is not a trial record.
        """
        out: dict[str, TrialRecord] = {}
        if not self.path.exists():
            return out
        lines = self.path.read_bytes().split(b"\n")
        for i, line in enumerate(lines):
            if not line.strip():
                continue
            try:
                line.decode("utf-8")
                rec = decode_trial(line, f"{self.path}: line {i + 1}")
            except (UnicodeDecodeError, NotJSONError):
                if i < len(lines) - 1:
                    LOGGER.warning("%s: line %d is not JSON; ignored", self.path, i + 1)
                continue
            out[rec.key] = rec
        return out

    def _cut_partial_tail(self) -> None:
        """Drop a last line without its newline (a write interrupted by a kill)."""
        if not self.path.exists():
            return
        with open(self.path, "r+b") as fh:
            size = fh.seek(0, os.SEEK_END)
            if size == 0:
                return
            fh.seek(size - 1)
            if fh.read(1) == b"\n":
                return
            data = self.path.read_bytes()
            cut = data.rfind(b"\n") + 1
            LOGGER.info("%s: dropping a half-written last line (%d bytes)", self.path, size - cut)
            fh.truncate(cut)
            fh.flush()
            os.fsync(fh.fileno())

    @contextlib.contextmanager
    def writer(self) -> Iterator[Callable[[TrialRecord], None]]:
        """Exclusive appender: ``with store.writer() as append: append(record)``.

        Raises:
            PlannerlabError: another process holds the store (a comparison already running
                into the same folder).
        """
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        lock_path = self.path.with_name(self.path.name + ".lock")
        with open(lock_path, "a") as lock:
            try:
                fcntl.flock(lock.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise PlannerlabError(
                    f"{self.path} is in use by another comparison (lock {lock_path})"
                ) from None
            self._cut_partial_tail()
            with open(self.path, "a", encoding="utf-8") as fh:

                def append(rec: TrialRecord) -> None:
                    fh.write(encode_trial(rec).decode("utf-8") + "\n")
                    fh.flush()
                    os.fsync(fh.fileno())

                yield append


def store_path(out_dir: str | Path, name: str) -> Path:
    """``<out_dir>/<name>/trials.jsonl``."""
    return Path(out_dir) / name / "trials.jsonl"


def default_name(problems: Sequence[str], planners: Sequence[str]) -> str:
    """A folder name from the problems and planners (filesystem-safe, at most ~80 chars)."""
    import re

    raw = "__".join(["+".join(problems), "+".join(planners)])
    safe = re.sub(r"[^A-Za-z0-9._+-]", "_", raw)
    if len(safe) <= 80:
        return safe
    h = hashlib.sha256(raw.encode()).hexdigest()[:8]
    return f"{safe[:70]}-{h}"

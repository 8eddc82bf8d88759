"""The bridge to OMPL's process-global state: its seed and its log output.

OMPL's seed takes effect only before its first generator exists (the first solve of a
process); OMPL's ``OutputHandler`` cannot be subclassed from Python, so during a solve OMPL
writes to a temporary file whose messages are re-emitted on the ``plannerlab.ompl``
logger, at their levels (see the package docstring).
"""

from __future__ import annotations

import logging
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import ompl.util as ou

LOGGER = logging.getLogger("plannerlab.ompl")

#: OMPL seeds must be in [1, 2**31 - 1] (0 means "random" to OMPL)
SEED_MAX = 2**31 - 1


def seed_ompl(seed: int) -> None:
    """Seed OMPL's process-global RNG. Call before any OMPL object exists (fresh process).

    Args:
        seed: any integer; mapped into OMPL's valid range [1, 2**31 - 1].
    """
    ou.RNG.setSeed(int(seed) % (SEED_MAX - 1) + 1)


_OMPL_PREFIXES = (
    ("Debug:", logging.DEBUG),
    ("Info:", logging.INFO),
    ("Warning:", logging.WARNING),
    ("Error:", logging.ERROR),
)


def _ompl_level(logger: logging.Logger) -> Any:
    level = logger.getEffectiveLevel()
    if level <= logging.DEBUG:
        return ou.LOG_DEBUG
    if level <= logging.INFO:
        return ou.LOG_INFO
    if level <= logging.WARNING:
        return ou.LOG_WARN
    if level <= logging.ERROR:
        return ou.LOG_ERROR
    return ou.LOG_NONE


def _forward_log(text: str, logger: logging.Logger) -> None:
    """Re-emit the lines an ``OutputHandlerFile`` wrote, one record per OMPL message."""
    messages: list[tuple[int, str]] = []
    for line in text.splitlines():
        for prefix, level in _OMPL_PREFIXES:
            if line.startswith(prefix):
                messages.append((level, line[len(prefix) :].strip()))
                break
        else:
            if messages and line.strip():
                lvl, msg = messages[-1]
                messages[-1] = (lvl, f"{msg} ({line.strip()})")
    for level, msg in messages:
        if "Random number generation already started" in msg:
            level = logging.DEBUG  # expected for every solve after the first in a process
        logger.log(level, "OMPL: %s", msg)


@contextmanager
def ompl_logging(logger: logging.Logger) -> Iterator[None]:
    """Route OMPL's output into ``logger`` for the duration of the block."""
    fd, filename = tempfile.mkstemp(prefix="plannerlab_ompl_", suffix=".log")
    os.close(fd)
    previous_level = ou.getLogLevel()
    handler = ou.OutputHandlerFile(filename)
    ou.useOutputHandler(handler)
    ou.setLogLevel(_ompl_level(logger))
    try:
        yield
    finally:
        ou.restorePreviousOutputHandler()
        ou.setLogLevel(previous_level)
        del handler  # closes the file
        try:
            with open(filename, encoding="utf-8", errors="replace") as f:
                _forward_log(f.read(), logger)
        finally:
            os.unlink(filename)

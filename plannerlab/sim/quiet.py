"""PyBullet's C code writes to the process's file descriptors (its build time on import,
``argv[0]=`` on connect, a GUI's OpenGL report), past Python's ``sys.stdout``: around
those calls the descriptors go to a temporary file, C's buffers are flushed before they
come back, and what was written is logged at INFO (shown with ``plannerlab -v``)."""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import sys
import tempfile
from collections.abc import Iterator

LOGGER = logging.getLogger(__name__)


def _flush_c_stdio() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C library to ask: nothing buffered
        pass


@contextlib.contextmanager
def engine_output_logged(what: str) -> Iterator[None]:
    """Run the block with file descriptors 1 and 2 sent to a temporary file; log what
    landed there as ``what: text`` at INFO. Does nothing when the descriptors cannot be
    duplicated."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    _flush_c_stdio()
    try:
        saved = (os.dup(1), os.dup(2))
    except OSError:
        yield
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            _flush_c_stdio()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            tmp.seek(0)
            text = tmp.read(65536).decode("utf-8", errors="replace").strip()
            if text:
                LOGGER.info("%s: %s", what, text)

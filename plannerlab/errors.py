"""The project's exceptions. Every error a user can cause is a `PlannerlabError`."""

from __future__ import annotations

import difflib
import warnings
from collections.abc import Iterable


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """`` did you mean 'x'?`` for the closest known names, or ``""``."""
    close = difflib.get_close_matches(name, sorted(known), n=3, cutoff=0.5)
    return f" did you mean {', '.join(repr(c) for c in close)}?" if close else ""


class PlannerlabError(Exception):
    """Base class of every error plannerlab raises on purpose."""


class ProblemError(PlannerlabError):
    """A problem file or problem definition is invalid.

    The message names the file, the key and what was expected.
    """

    def __init__(self, source: str, key: str, expected: str) -> None:
        self.source = source
        self.key = key
        self.expected = expected
        super().__init__(f"{source}: [{key}] {expected}")


class UnknownNameError(PlannerlabError, KeyError):
    """A name (planner, problem, robot type, obstacle type) that does not exist."""

    def __init__(self, kind: str, name: str, known: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        self.known = sorted(known)
        hint = did_you_mean(name, self.known)
        listing = ", ".join(self.known)
        msg = f"unknown {kind} {name!r};{hint} known: {listing}"
        super().__init__(msg)

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class PlanFileError(PlannerlabError):
    """A saved plan (JSON) cannot be read back."""


class RenamedWarning(FutureWarning):
    """A setting, problem-file key or flag was given by a name it no longer has: it still
    works for one release, read as its new name, which the message names
    (``docs/distances.md`` lists the renamed ones). A ``FutureWarning``: shown by default."""


def warn_renamed(where: str, old: str, new: str) -> None:
    """Warn that ``old`` (in ``where``: a file and table, a planner's settings, a command)
    is read as ``new``, its name now."""
    warnings.warn(
        f"{where}: {old!r} is renamed {new!r}; the old name is read as {new!r} for one more "
        f"release: write {new!r}",
        RenamedWarning,
        stacklevel=3,
    )

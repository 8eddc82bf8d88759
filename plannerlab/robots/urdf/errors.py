"""The URDF family's error (``UrdfError``: the ``[robot]`` key to blame and what was
expected) and its "did you mean" hint."""

from __future__ import annotations

import difflib

from plannerlab.errors import PlannerlabError


class UrdfError(PlannerlabError):
    """A URDF, SRDF or link name the family cannot use; ``key`` is the ``[robot]`` key
    to blame (``urdf``, ``tip_link``, ``srdf``, ``allowed_collisions``)."""

    def __init__(self, key: str, expected: str) -> None:
        self.key = key
        self.expected = expected
        super().__init__(f"[robot.{key}] {expected}")


def hint(name: str, names: list[str]) -> str:
    close = difflib.get_close_matches(name, names, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


__all__ = ["UrdfError", "hint"]

"""The ``[robot]`` table of a problem file, as each robot family declares it.

A family declares its table beside its model (``robots/<family>/schema.py``) as a
:class:`RobotTable`: the keys, each a :class:`Key` (name, kind, default, unit, limits,
one-line meaning), and a constructor ``build(values)`` that takes the validated plain
values (a number as ``float``, an integer as ``int``, a vector as a float array, a string
as ``str``; every key present, defaults filled in) and returns the robot. Nothing here
reads TOML: the problem loader parses every family's table with one function
(:func:`plannerlab.problem.robot_table.parse_robot_table`), so every key is checked, and named in
errors, the same way. ``docs/problem-format.md`` lists the same keys, units and defaults
(``tests/robots/test_robot_schema.py`` compares them).

A constructor rejects a combination of values that each passed their key's checks by
raising :class:`TableValueError` with the key to blame; the loader turns it into an error
naming the file and ``robot.<key>``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, pose_matrix

#: the kinds of value a key may hold: a ``path`` is a string naming a file relative to the
#: problem file (resolved and checked to exist by the loader; "" when absent), ``pairs`` a
#: list of ``[name, name]`` string pairs
KINDS = ("number", "integer", "vector", "string", "path", "pairs")

#: keys every ``[robot]`` table may have besides its family's: the type and a free note
COMMON_KEYS = ("type", "note")


@dataclass(frozen=True)
class Key:
    """One key of a ``[robot]`` table.

    Attributes:
        name: the key as written in the file (units in the name: ``length_m``).
        kind: ``"number"`` (finite float), ``"integer"``, ``"vector"`` (finite floats) or
            ``"string"``.
        default: the value when the key is absent (a tuple for a vector).
        unit: the unit of the value as written in the file (``"m"``, ``"deg"``), ``""`` if
            none.
        meaning: one line saying what the key sets.
        positive: a number must be > 0.
        minimum, maximum: inclusive limits of a number or an integer.
        why_maximum: why the maximum is there (shown when it is exceeded).
        length: how many numbers a vector holds.
        ordered: a vector is ``[lower, upper]`` with lower <= upper.
        choices: the values a string may take.
        required: the key must be given (its default is never used).
    """

    name: str
    kind: str
    default: float | int | str | tuple[float, ...]
    unit: str = ""
    meaning: str = ""
    positive: bool = False
    minimum: float | None = None
    maximum: float | None = None
    why_maximum: str = ""
    length: int | None = None
    ordered: bool = False
    choices: tuple[str, ...] = ()
    required: bool = False

    def __post_init__(self) -> None:
        def wrong(what: str) -> ValueError:
            return ValueError(f"robot table key {self.name!r}: {what}")

        if self.kind not in KINDS:
            raise wrong(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.name in COMMON_KEYS:
            raise wrong(f"{', '.join(COMMON_KEYS)} are common to every robot table")
        if self.kind == "vector":
            if not isinstance(self.default, tuple) or len(self.default) != self.length:
                raise wrong("a vector needs a length and a default of that many numbers")
            if self.ordered and self.length != 2:
                raise wrong("an ordered vector is [lower, upper]")
        elif self.length is not None or self.ordered:
            raise wrong("length and ordered apply to vectors only")
        if self.choices and self.kind != "string":
            raise wrong("choices apply to strings only")
        if self.kind in ("vector", "string", "path", "pairs") and (
            self.positive or self.minimum is not None or self.maximum is not None
        ):
            raise wrong("positive, minimum and maximum apply to numbers and integers only")
        if self.why_maximum and self.maximum is None:
            raise wrong("why_maximum without a maximum")


class TableValueError(PlannerlabError):
    """A robot's constructor rejects the value of ``key`` (alone or with the others)."""

    def __init__(self, key: str, expected: str) -> None:
        self.key = key
        self.expected = expected
        super().__init__(f"[robot.{key}] {expected}")


@dataclass(frozen=True)
class RobotTable:
    """The ``[robot]`` table of one robot type: its keys and its constructor.

    Attributes:
        type: the ``type = "..."`` value that selects this table.
        keys: the keys besides ``type`` and ``note``, in the order the documentation lists
            them.
        build: ``build(values) -> Robot`` from every key's validated value (typed ``Any``:
            the models are frozen dataclasses, which mypy does not match to the
            :class:`~plannerlab.robots.base.Robot` protocol's plain attributes).
    """

    type: str
    keys: tuple[Key, ...]
    build: Callable[[Mapping[str, Any]], Any]

    def __post_init__(self) -> None:
        names = [k.name for k in self.keys]
        if len(set(names)) != len(names):
            raise ValueError(f"robot table {self.type!r} declares a key twice: {names}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(k.name for k in self.keys)

    def key(self, name: str) -> Key:
        for k in self.keys:
            if k.name == name:
                return k
        raise KeyError(name)


def base_pose_keys(frame: str) -> tuple[Key, Key]:
    """``base_xyz_m`` and ``base_rpy_deg``: the pose of ``frame`` in the world (either may
    be left out: zero)."""
    return (
        Key("base_xyz_m", "vector", (0.0, 0.0, 0.0), "m", f"{frame} position, world", length=3),
        Key(
            "base_rpy_deg",
            "vector",
            (0.0, 0.0, 0.0),
            "deg",
            f"{frame} orientation, world: roll, pitch, yaw (URDF)",
            length=3,
        ),
    )


def base_pose(values: Mapping[str, Any]) -> Array:
    """T (4, 4) of the base in the world from ``base_xyz_m`` [m] and ``base_rpy_deg``
    [deg]."""
    return pose_matrix(values["base_xyz_m"], np.deg2rad(np.asarray(values["base_rpy_deg"])))


__all__ = [
    "COMMON_KEYS",
    "KINDS",
    "Key",
    "RobotTable",
    "TableValueError",
    "base_pose",
    "base_pose_keys",
]

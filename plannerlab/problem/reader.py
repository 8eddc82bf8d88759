"""Typed access to one table of a problem file, with errors that name the file and the key.

Every table reader of the loader (:mod:`plannerlab.problem.load` and the ``*_table`` modules
beside it) reads its values through a :class:`TableReader`: a value of the wrong kind, out of
its limits or missing raises :class:`~plannerlab.errors.ProblemError` naming the file, the key
(``goals[1].pos_tol_m``) and what was expected.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError, did_you_mean, warn_renamed
from plannerlab.robots.base import Array, pose_matrix

#: problem-file keys renamed (table -> {old key: new key}): a file with the old key is
#: read as if it had the new one for one release, with a warning naming the new key
#: (``docs/distances.md``: each distance setting has one name and one meaning)
RENAMED_KEYS: Mapping[str, Mapping[str, str]] = MappingProxyType(
    {"witness": MappingProxyType({"min_clearance_m": "clearance_floor_m"})}
)


def _renamed(source: str, prefix: str, table: dict[str, Any]) -> dict[str, Any]:
    """``table`` with its renamed keys (:data:`RENAMED_KEYS`) under their new names."""
    renamed = RENAMED_KEYS.get(re.sub(r"\[\d+\]$", "", prefix), {})
    if not any(old in table for old in renamed):
        return table
    out = dict(table)
    for old, new in renamed.items():
        if old in out:
            if new in out:
                raise ProblemError(
                    source, f"{prefix}.{old}", f"{new!r} only ({old!r} is its old name)"
                )
            warn_renamed(f"{source}: [{prefix}]", old, new)
            out[new] = out.pop(old)
    return out


class TableReader:
    """Typed access to one TOML table with errors that name the file and the key. A key
    the file format renamed (:data:`RENAMED_KEYS`) is read under its new name."""

    def __init__(self, source: str, prefix: str, table: Any) -> None:
        if not isinstance(table, dict):
            raise ProblemError(source, prefix, f"a table, got {type(table).__name__}")
        self.source = source
        self.prefix = prefix
        self.table: dict[str, Any] = _renamed(source, prefix, table)

    def key(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def fail(self, name: str, expected: str) -> ProblemError:
        return ProblemError(self.source, self.key(name), expected)

    def has(self, name: str) -> bool:
        return name in self.table

    def raw(self, name: str, default: Any = ...) -> Any:
        if name not in self.table:
            if default is ...:
                raise self.fail(name, "is missing")
            return default
        return self.table[name]

    def string(self, name: str, default: Any = ...) -> str:
        v = self.raw(name, default)
        if not isinstance(v, str):
            raise self.fail(name, f"a string, got {v!r}")
        return v

    def number(
        self,
        name: str,
        default: Any = ...,
        *,
        positive: bool = False,
        nonnegative: bool = False,
        minimum: float | None = None,
        maximum: float | None = None,
        why_maximum: str = "",
    ) -> float:
        v = self.raw(name, default)
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise self.fail(name, f"a number, got {v!r}")
        v = float(v)
        if not math.isfinite(v):
            raise self.fail(name, f"a finite number, got {v}")
        if positive and v <= 0:
            raise self.fail(name, f"a positive number, got {v}")
        if nonnegative and v < 0:
            raise self.fail(name, f"a number >= 0, got {v}")
        if minimum is not None and v < minimum:
            raise self.fail(name, f"a number >= {minimum:g}, got {v:g}")
        if maximum is not None and v > maximum:
            raise self.fail(
                name,
                f"a number <= {maximum:g}, got {v:g}"
                + (f" ({why_maximum})" if why_maximum else ""),
            )
        return v

    def integer(
        self,
        name: str,
        default: Any = ...,
        *,
        minimum: int | None = None,
        maximum: int | None = None,
        why_maximum: str = "",
    ) -> int:
        v = self.raw(name, default)
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(name, f"an integer, got {v!r}")
        if minimum is not None and v < minimum:
            raise self.fail(name, f"an integer >= {minimum}, got {v}")
        if maximum is not None and v > maximum:
            raise self.fail(
                name,
                f"an integer <= {maximum}, got {v}" + (f" ({why_maximum})" if why_maximum else ""),
            )
        return v

    def optional_integer(self, name: str, *, minimum: int | None = None) -> int | None:
        return self.integer(name, minimum=minimum) if self.has(name) else None

    def optional_number(self, name: str, *, positive: bool = False) -> float | None:
        return self.number(name, positive=positive) if self.has(name) else None

    def vector(self, name: str, length: int | None = None, default: Any = ...) -> Array:
        v = self.raw(name, default)
        if not isinstance(v, list | tuple) or any(
            isinstance(x, bool) or not isinstance(x, int | float) for x in v
        ):
            want = f"a list of {length} numbers" if length else "a list of numbers"
            raise self.fail(name, f"{want}, got {v!r}")
        if length is not None and len(v) != length:
            raise self.fail(name, f"a list of {length} numbers, got {len(v)}")
        a = np.array(v, dtype=float)
        if not np.all(np.isfinite(a)):
            raise self.fail(name, f"finite numbers, got {v!r} (NaN or inf)")
        return a

    def pose(self, xyz_name: str, rpy_name: str) -> Array:
        """A pose from a position [m] and roll, pitch, yaw [deg]; either may be left out
        (zero)."""
        xyz = self.vector(xyz_name, 3, default=[0.0, 0.0, 0.0])
        rpy_deg = self.vector(rpy_name, 3, default=[0.0, 0.0, 0.0])
        return pose_matrix(xyz, np.deg2rad(rpy_deg))

    def unknown_keys(self, allowed: tuple[str, ...]) -> None:
        extra = sorted(set(self.table) - set(allowed))
        if extra:
            raise self.fail(
                extra[0],
                f"is not a known key here;{did_you_mean(extra[0], allowed)} "
                f"allowed: {', '.join(allowed)}",
            )

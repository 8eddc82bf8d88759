"""A record's numbers as table cells: the one formatting of the terminal tables and the
Markdown reports (3 significant digits, "-" for a missing number)."""

from __future__ import annotations

import math
from typing import Any


def mm(x: Any) -> Any:
    """Metres to millimetres for a table cell (None and NaN pass through)."""
    return None if x is None else 1e3 * float(x)


def fmt(x: Any, digits: int = 3) -> str:
    """A number for a table: 3 significant digits, "-" for missing/NaN."""
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, float):
        if not math.isfinite(x):
            return "-"
        return f"{x:.{digits}g}" if abs(x) < 1e3 else f"{x:.0f}"
    return str(x)


def err_of_tol(err: Any, tol: Any, digits: int = 3) -> str:
    """A tip error beside its tolerance, ``"0.0976 / 0.1"`` ("-" without an error; the
    error alone when the tolerance is unknown)."""
    if err is None or (isinstance(err, float) and not math.isfinite(err)):
        return "-"
    if tol is None or (isinstance(tol, float) and not math.isfinite(tol)):
        return fmt(float(err), digits)
    return f"{fmt(float(err), digits)} / {fmt(float(tol), digits)}"


#: roughness below this is float noise of a straight path (a turn of 3e-5 rad) [rad²]
ROUGHNESS_RESOLUTION_RAD2 = 1e-9


def rough(x: Any) -> str:
    """A roughness [rad²] for a table: 3 significant digits, 0 below
    :data:`ROUGHNESS_RESOLUTION_RAD2` (a straight path's float noise), "-" when missing."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return fmt(0.0 if abs(float(x)) < ROUGHNESS_RESOLUTION_RAD2 else float(x))

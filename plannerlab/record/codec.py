"""The one JSON codec of plannerlab's records: plan files, execution files, trial stores.

Convention (the only one): a non-finite float (NaN, ±inf) is written as JSON ``null``;
records read it back as NaN in their float fields (:func:`read_float`). The output is
strict JSON (``allow_nan=False``), so any JSON reader can parse it. numpy arrays become
nested lists, numpy scalars plain numbers, enums their value, mappings dicts with string
keys, tuples lists.
"""

from __future__ import annotations

import enum
import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np


def to_data(value: Any) -> Any:
    """``value`` as plain JSON-able data (see the module doc for the convention)."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
            return to_data(value.tolist())
        return value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool | int | str) or value is None:
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, enum.Enum):
        return to_data(value.value)
    if isinstance(value, Mapping):
        return {str(k): to_data(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_data(v) for v in value]
    return value


def read_float(value: Any) -> float:
    """A float field read back: ``null`` (a non-finite number) is NaN.

    Plan files written before this codec stored infinities as the strings ``"inf"`` and
    ``"-inf"``; ``float`` reads those too.
    """
    return math.nan if value is None else float(value)


def dumps(data: Any, *, indent: int | None = None) -> str:
    """``data`` as strict JSON text (records are converted by :func:`to_data` first)."""
    separators = None if indent is not None else (",", ":")
    return json.dumps(to_data(data), indent=indent, separators=separators, allow_nan=False)


def loads(text: str) -> Any:
    """Parse JSON text written by :func:`dumps`."""
    return json.loads(text)

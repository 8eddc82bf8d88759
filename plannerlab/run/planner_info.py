"""What ``plannerlab planners`` shows: every registered planner with the robots it
suits, and one planner's settings (name, unit, default, what it does).

A planner's settings are its frozen settings dataclass (:func:`make_planner`'s
``settings``): the fields and their defaults come from there, what each does from the
docstrings of the class and its bases, read leniently: an ``Attributes:`` section (or any
section) of ``name: text`` entries, ``a, b: text`` for several, continuation lines
indented deeper, or a ``name``: text sentence in prose. A unit is the first ``[unit]`` of
the text, else the name's suffix (``_m``, ``_rad``, ``_deg``, ``_s``).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from typing import Any

#: what each family of planners suits (robot kinds of the registry entry say which robots
#: it runs on at all), by registry-name prefix, the longest prefix first
SUITS: tuple[tuple[str, str], ...] = (
    (
        "gradient.follow_leader",
        "hyper-redundant chains (Arm-Z): the body follows the tip through windows and into rooms",
    ),
    (
        "gradient.clearance",
        "hyper-redundant chains (Arm-Z, 20-32 modules): the descent slides along walls; "
        "tip or joint goals",
    ),
    ("gradient+rrtconnect", "redundant chains with tip goals; RRT-Connect from each stall"),
    ("gradient.multistart", "redundant chains with tip goals; random restarts"),
    ("gradient", "the Arm-Z paper's method: redundant chains with tip goals, free space"),
    ("chord_arc", "planar continuum robots (contact with the scene by design)"),
    (
        "native.",
        "any robot with a compiled model (serial chains: 6-7-joint arms, hyper-redundant "
        "chains): sampling compiled end to end; tip or joint goals",
    ),
    (
        "trajopt.",
        "any chain with a compiled model and a tip (6-7-joint arms, hyper-redundant "
        "chains): smooth whole paths, optimised from seeds; tip or joint goals",
    ),
    (
        "ompl.",
        "any joint-space robot: 6-7-joint arms (Panda, IRb-6 on its track), "
        "hyper-redundant chains; tip or joint goals",
    ),
)

#: unit of a setting by its name's suffix (when its text names none)
_SUFFIX_UNITS = (
    ("_mm", "mm"),
    ("_m", "m"),
    ("_rad", "rad"),
    ("_deg", "deg"),
    ("_s", "s"),
    ("_hz", "Hz"),
)

_ENTRY = re.compile(r"^(\s*)([A-Za-z_][\w.]*(?:\s*,\s*[A-Za-z_][\w.]*)*)\s*:\s*(.*)$")
_INLINE = re.compile(r"``([A-Za-z_]\w*)``\s*:\s*(.+?\.)(?=\s|$)", re.S)
_UNIT = re.compile(r"\[([^\[\]]{1,40})\]")


def suits(name: str) -> str:
    """What the planner ``name`` suits, in a few words (:data:`SUITS`)."""
    for prefix, text in SUITS:
        if name == prefix or name.startswith(prefix):
            return text
    return ""


def docstring_entries(doc: str | None) -> dict[str, str]:
    """``name -> text`` of every ``name: text`` entry of a Google-style docstring (any
    section; ``a, b: text`` gives both names the text; continuation lines are those
    indented deeper than the entry) and of every ````name````: text sentence in prose."""
    if not doc:
        return {}
    lines = inspect.cleandoc(doc).splitlines()
    out: dict[str, str] = {}
    current: list[str] = []
    indent = -1
    text: list[str] = []

    def close() -> None:
        if current:
            joined = " ".join(" ".join(text).split())
            for n in current:
                out.setdefault(n, joined)

    for line in lines:
        m = _ENTRY.match(line)
        depth = len(line) - len(line.lstrip())
        if m and m.group(3) and depth > 0 and (indent < 0 or depth <= indent):
            close()
            indent = depth
            current = [n.strip() for n in m.group(2).split(",")]
            text = [m.group(3)]
        elif current and line.strip() and depth > indent:
            text.append(line.strip())
        else:
            close()
            current, text, indent = [], [], -1
    close()
    for m in _INLINE.finditer(" ".join(doc.split())):
        out.setdefault(m.group(1), m.group(2).strip())
    return out


def _unit(key: str, text: str) -> str:
    for m in _UNIT.finditer(text):
        unit = m.group(1).split(",")[0].strip()
        if re.match(r"^(?:[A-Za-z°µ%]|1/)", unit):
            return unit
    for suffix, unit in _SUFFIX_UNITS:
        if key.endswith(suffix):
            return unit
    return ""


#: a reStructuredText role (``:func:`~a.b.name```): its target's last part is kept
_ROLE = re.compile(r":[a-z]+:`~?(?:[\w.]*\.)?([^`.]+)`")


def plain_text(text: str) -> str:
    """Documentation text as a terminal shows it: no reStructuredText markup (a role
    keeps the last part of its target's name; ````x```` is ``x``)."""
    return _ROLE.sub(r"\1", text).replace("``", "")


def _docs_of(cls: type) -> dict[str, str]:
    out: dict[str, str] = {}
    for klass in cls.__mro__:
        if klass is object:
            continue
        for k, v in docstring_entries(klass.__doc__).items():
            out.setdefault(k, v)
    return out


def _settings_rows(settings: Any, prefix: str = "") -> list[dict[str, Any]]:
    docs = _docs_of(type(settings))
    rows: list[dict[str, Any]] = []
    for f in dataclasses.fields(settings):
        value = getattr(settings, f.name)
        key = prefix + f.name
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            rows += _settings_rows(value, key + ".")
            continue
        doc = docs.get(f.name, "")
        derived = value is None and "derived" in doc  # set from the robot's size at plan time
        rows.append(
            {
                "key": key,
                "default": "derived"
                if derived
                else value
                if isinstance(value, int | float | str | bool)
                else repr(value),
                "type": "float" if derived else type(value).__name__,
                "unit": _unit(f.name, doc),
                "doc": plain_text(doc),
            }
        )
    return rows


def planner_catalog() -> list[dict[str, Any]]:
    """One JSON-able row per registered planner: ``name``, ``summary``,
    ``needs_simulator``, ``uses_rng``, ``robots`` (robot kinds, or ``"any"``), ``suits``
    (in a few words)."""
    from plannerlab.planners import REGISTRY

    return [
        {
            "name": e.name,
            "summary": e.summary,
            "needs_simulator": e.needs_stepper,
            "uses_rng": e.uses_rng,
            "robots": list(e.robots) if e.robots else "any",
            "suits": suits(e.name),
        }
        for e in REGISTRY.values()
    ]


def planner_info(name: str) -> dict[str, Any]:
    """One planner: its catalogue row (:func:`planner_catalog`), its settings class and
    one row per setting (``key``, ``default``, ``type``, ``unit``, ``doc``), the
    overridable keys of ``--set key=value`` (a nested settings object's keys as
    ``outer.key``).

    Raises:
        UnknownNameError: no planner has that name (the message lists close ones).
    """
    from plannerlab.planners import get_entry, make_planner

    entry = get_entry(name)
    (row,) = [r for r in planner_catalog() if r["name"] == entry.name]
    settings = make_planner(name).settings
    return {
        **row,
        "settings_class": f"{type(settings).__module__}.{type(settings).__qualname__}",
        "settings": _settings_rows(settings),
    }

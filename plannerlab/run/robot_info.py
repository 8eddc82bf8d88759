"""What plannerlab makes of a URDF (``plannerlab robot URDF``): its joints and links, the
cover of each collision mesh (primitives, worst excess), the self-collision pairs it
computes (:func:`plannerlab.run.srdf.disabled_pairs`) and the SRDF it writes, and how
long loading took.

The tip link, when not given, is the end of the arm (:func:`default_tip_link`, from
:mod:`plannerlab.robots.urdf.tip`): the tool centre frame where the URDF names one, else
the hand where the chain of movable joints ends or branches (a gripper's fingers), never a
single moving jaw.
"""

from __future__ import annotations

import tempfile
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.robots.urdf.model import UrdfChain
from plannerlab.robots.urdf.tip import default_tip_link
from plannerlab.run.srdf import DisabledPair, disabled_pairs, write_srdf


@dataclass(frozen=True)
class RobotReport:
    """A URDF as plannerlab plans with it.

    Attributes:
        urdf: the file; tip_link: the chain's end; robot: the loaded chain.
        joints: per movable joint of the chain: name, type, lower and upper limit.
        links: the URDF links that carry collision geometry, in file order.
        covers: per collision mesh: link, file, primitives, capsules, worst excess [m],
            excess aimed at [m], the solid the excess is measured from, read from cache.
        primitives_by_link: every link's primitive count (meshes and URDF primitives).
        pairs: the self-collision pairs never checked, with their reason.
        load_s: seconds to load the chain (covers included; cached covers load fast).
        srdf: where the SRDF was written, or None.
        notes: the loader's warnings (links without geometry, ...).
    """

    urdf: Path
    tip_link: str
    robot: UrdfChain
    joints: tuple[tuple[str, str, float, float], ...]
    links: tuple[str, ...]
    covers: tuple[Any, ...]
    primitives_by_link: dict[str, int]
    pairs: tuple[DisabledPair, ...]
    load_s: float
    srdf: Path | None
    notes: tuple[str, ...]


def robot_report(
    urdf: str | Path,
    tip_link: str | None = None,
    *,
    srdf_out: str | Path | None = None,
    n_states: int = 1000,
    seed: int = 0,
    **chain_args: Any,
) -> RobotReport:
    """Load a URDF as ``[robot] type = "urdf"`` would (``chain_args``: ``mesh_paths``,
    ``cover_excess_m``, ``cover_max_primitives``, ...), compute its self-collision pairs
    from ``n_states`` seeded states and, with ``srdf_out``, write them as an SRDF.

    Raises:
        PlannerlabError: the URDF, a mesh or the tip link cannot be used (the error says
            which file, link and key).
    """
    path = Path(urdf)
    tip = tip_link or default_tip_link(path, tuple(chain_args.get("mesh_paths", ())))
    with tempfile.TemporaryDirectory() as tmp:
        if chain_args.get("cover_cache") is False:
            # the pairs rebuild the chain: its covers from a cache of this call only
            chain_args = {**chain_args, "cover_cache": True, "cover_cache_dir": Path(tmp)}
        start = time.perf_counter()
        robot = UrdfChain(path, tip, **chain_args)
        load_s = time.perf_counter() - start
        pairs = disabled_pairs(robot, np.random.default_rng(seed), n_states=n_states)
    out = None
    if srdf_out is not None:
        out = Path(srdf_out)
        write_srdf(pairs, out, ET.parse(path).getroot().get("name", "robot"))
    kinds = [
        "prismatic" if p else "continuous" if c else "revolute"
        for p, c in zip(robot.chain_data()[3], robot.continuous, strict=True)
    ]
    joints = tuple(
        (name, kind, float(lo), float(hi))
        for name, kind, lo, hi in zip(
            robot.joint_names, kinds, robot.lower, robot.upper, strict=True
        )
    )
    counts: dict[str, int] = {}
    for n in robot.link_urdf_names:
        counts[n] = counts.get(n, 0) + 1
    return RobotReport(
        path,
        tip,
        robot,
        joints,
        tuple(counts),
        tuple(robot.mesh_covers),
        counts,
        tuple(pairs),
        load_s,
        out,
        tuple(robot.notes),
    )


__all__ = ["RobotReport", "default_tip_link", "robot_report"]

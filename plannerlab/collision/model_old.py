"""The robot's chain packed alone (the previous compiled model's packing,
:mod:`plannerlab.collision.chain_pack`): what the sphere field
(:mod:`plannerlab.collision.spheres`) reads when no checker's model is at hand.

A :class:`ChainModel` is a named tuple of arrays: ``P``, ``M``, ``idat`` (the chain, its
capsules, no pairs, no scene), the joint bounds, and ``perm`` (capsule ``perm[k]`` of the
robot is the ``k``-th packed one). A robot without a chain (``chain_data()``) gets a
:class:`ModelError` naming its kind.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from plannerlab.collision.chain_pack import _pack
from plannerlab.errors import PlannerlabError


class ModelError(PlannerlabError):
    """A compiled consumer asked for the model of a robot that cannot give one."""


class ChainModel(NamedTuple):
    """One robot in one scene with a margin, as arrays (see the module docstring)."""

    P: np.ndarray
    M: np.ndarray
    idat: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    continuous: np.ndarray
    edge_weights: np.ndarray
    margin_m: float
    perm: np.ndarray


def has_chain(robot: Any) -> bool:
    """True when the robot gives its serial chain (``chain_data()``) to compile."""
    return callable(getattr(robot, "chain_data", None))


def chain_model(robot: Any) -> ChainModel:
    """The model of a robot's chain alone (no scene, no margin, no checked pairs): its
    kinematics and capsules packed as :func:`model_of_core` packs them, for a consumer
    that needs only those (the clearance field's spheres,
    :mod:`plannerlab.collision.spheres`) when no checker's model is at hand.

    Raises:
        ModelError: the robot gives no serial chain (``chain_data()``).
    """
    if not has_chain(robot):
        raise ModelError(
            f"robot type {getattr(robot, 'kind', type(robot).__name__)!r} gives no serial "
            "chain (chain_data()): its kinematics cannot be compiled"
        )
    L = len(np.asarray(robot.link_radii_m))
    zeros = np.zeros(L)
    P, M, idat, perm = _pack(
        robot,
        zeros,
        zeros,
        np.ones(L, dtype=bool),
        np.zeros((L, L), dtype=bool),
        np.zeros(0, dtype=np.int64),
        np.zeros((0, 3, 3)),
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        None,
    )
    dof = int(robot.dof)
    return ChainModel(
        P=P,
        M=M,
        idat=idat,
        lower=np.array(robot.lower, dtype=np.float64, order="C", copy=True),
        upper=np.array(robot.upper, dtype=np.float64, order="C", copy=True),
        continuous=np.array(robot.continuous, dtype=np.bool_, order="C", copy=True),
        edge_weights=np.zeros(dof),
        margin_m=0.0,
        perm=np.array(perm, dtype=np.int64, order="C", copy=True),
    )

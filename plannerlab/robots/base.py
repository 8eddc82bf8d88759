"""What every robot model offers the rest of plannerlab.

A robot is a joint-vector robot: a state is ``q`` of shape ``(dof,)`` and every batched
function also takes ``(k, dof)``. Collision geometry is a set of capsules ("links"), each a
segment between two world points with a radius; the checker in
:mod:`plannerlab.collision.fcl_checker` turns them into FCL objects. Frames are 4x4 homogeneous
transforms ``T_world_frame``.

Only numpy/scipy are used here (see ``docs/architecture.md``).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


@runtime_checkable
class Robot(Protocol):
    """The contract between a robot model and the planners, checker and simulator."""

    #: registry name of the robot family ("armz", "irb6", "continuum_chain")
    kind: str
    #: number of joints
    dof: int
    #: one name per joint, also the URDF joint names
    joint_names: tuple[str, ...]
    #: (dof,) joint lower/upper bounds [rad or m]; continuous joints wrap at them
    lower: Array
    upper: Array
    #: (dof,) True where the joint is continuous (wraps around)
    continuous: NDArray[np.bool_]
    #: (L,) capsule radius per link [m]
    link_radii_m: Array
    #: one name per link, also the URDF link names
    link_names: tuple[str, ...]
    #: links that never move (a fixed base): never checked against the scene
    fixed_links: frozenset[int]
    #: link pairs (i < j) never counted as self-collision (always touching neighbours)
    excluded_pairs: frozenset[tuple[int, int]]
    #: (4, 4) pose of the robot's base frame in the world
    T_world_base: Array

    def fk(self, q: Array) -> Array:
        """Frames ``T_world_frame``: (F, 4, 4) for q (dof,), (k, F, 4, 4) for (k, dof)."""
        ...

    def tip(self, q: Array) -> tuple[Array, Array]:
        """Tip position ``p_world`` [m] and unit normal ``n_world``: (3,) each, or (k, 3)."""
        ...

    def tip_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Analytic Jacobians ``dp/dq`` (3, dof) and ``dn/dq`` (3, dof) at one q."""
        ...

    def link_segments(self, q: Array) -> Array:
        """Capsule axes in the world: (L, 2, 3) for one q, (k, L, 2, 3) for a batch."""
        ...

    def urdf(self) -> str:
        """URDF text of the robot in its base frame (load it at ``T_world_base``).

        Movable joints are named ``joint_names`` and appear in q order; URDF link
        ``link_frame_names[i]`` has the frame ``fk(q)[i]``.
        """
        ...

    @property
    def link_frame_names(self) -> tuple[str, ...]:
        """URDF link names whose frames equal ``fk(q)`` frames, in order."""
        ...


def wrap_to_pi(q: Array, continuous: NDArray[np.bool_]) -> Array:
    """Wrap the continuous joints of q (..., dof) into [-pi, pi)."""
    q = np.array(q, dtype=float, copy=True)
    wrapped = (q + np.pi) % (2.0 * np.pi) - np.pi
    return np.where(continuous, wrapped, q)


def joint_difference(q_to: Array, q_from: Array, continuous: NDArray[np.bool_]) -> Array:
    """Shortest joint-space difference q_to - q_from, wrapping continuous joints."""
    d = np.asarray(q_to, dtype=float) - np.asarray(q_from, dtype=float)
    return np.where(continuous, (d + np.pi) % (2.0 * np.pi) - np.pi, d)


def rot_x(a: ArrayLike) -> Array:
    """Rotations about x for angles a (...,) -> (..., 4, 4)."""
    a = np.asarray(a, dtype=float)
    c, s = np.cos(a), np.sin(a)
    T = np.zeros(a.shape + (4, 4))
    T[..., 0, 0] = 1.0
    T[..., 1, 1] = c
    T[..., 1, 2] = -s
    T[..., 2, 1] = s
    T[..., 2, 2] = c
    T[..., 3, 3] = 1.0
    return T


def rot_y(a: ArrayLike) -> Array:
    """Rotations about y for angles a (...,) -> (..., 4, 4)."""
    a = np.asarray(a, dtype=float)
    c, s = np.cos(a), np.sin(a)
    T = np.zeros(a.shape + (4, 4))
    T[..., 0, 0] = c
    T[..., 0, 2] = s
    T[..., 1, 1] = 1.0
    T[..., 2, 0] = -s
    T[..., 2, 2] = c
    T[..., 3, 3] = 1.0
    return T


def rot_z(a: ArrayLike) -> Array:
    """Rotations about z for angles a (...,) -> (..., 4, 4)."""
    a = np.asarray(a, dtype=float)
    c, s = np.cos(a), np.sin(a)
    T = np.zeros(a.shape + (4, 4))
    T[..., 0, 0] = c
    T[..., 0, 1] = -s
    T[..., 1, 0] = s
    T[..., 1, 1] = c
    T[..., 2, 2] = 1.0
    T[..., 3, 3] = 1.0
    return T


def as_xyz(v: ArrayLike) -> tuple[float, float, float]:
    """A 3-vector as a tuple of three floats (for records)."""
    x, y, z = (float(c) for c in np.asarray(v, dtype=float).reshape(3))
    return (x, y, z)


def trans(x: float, y: float, z: float) -> Array:
    """Pure translation (4, 4)."""
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def rpy_to_matrix(rpy_rad: ArrayLike) -> Array:
    """Fixed-axis roll, pitch, yaw (URDF convention: R = Rz(yaw) Ry(pitch) Rx(roll)) -> (3, 3)."""
    r, p, y = (float(v) for v in np.asarray(rpy_rad, dtype=float).reshape(3))
    return (rot_z(y) @ rot_y(p) @ rot_x(r))[:3, :3]


def matrix_to_rpy(R: Array) -> Array:
    """Inverse of :func:`rpy_to_matrix` (URDF roll, pitch, yaw) [rad]."""
    R = np.asarray(R, dtype=float)
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    if np.isclose(np.cos(pitch), 0.0, atol=1e-9):
        roll = 0.0
        yaw = np.arctan2(-R[0, 1], R[1, 1])
    else:
        roll = np.arctan2(R[2, 1], R[2, 2])
        yaw = np.arctan2(R[1, 0], R[0, 0])
    return np.array([roll, pitch, yaw])


def pose_matrix(xyz_m: ArrayLike, rpy_rad: ArrayLike) -> Array:
    """T (4, 4) from a position [m] and URDF roll-pitch-yaw [rad]."""
    T = np.eye(4)
    T[:3, :3] = rpy_to_matrix(rpy_rad)
    T[:3, 3] = np.asarray(xyz_m, dtype=float)
    return T


def urdf_origin(T: Array) -> str:
    """``<origin xyz=.. rpy=..>`` for a transform, in full precision."""
    xyz = " ".join(repr(float(v)) for v in T[:3, 3])
    rpy = " ".join(repr(float(v)) for v in matrix_to_rpy(T[:3, :3]))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'

"""Joint-space path utilities shared by planners, the checker and execution."""

from __future__ import annotations

import math

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, joint_difference


def edge_steps(q_a: Array, q_b: Array, joint_step: float, continuous: np.ndarray) -> int:
    """Number of intervals so that no joint moves more than ``joint_step`` per interval."""
    d = np.abs(joint_difference(q_b, q_a, continuous))
    return max(1, int(np.ceil(float(np.max(d, initial=0.0)) / joint_step - 1e-12)))


#: most states one edge may be densified into: a bound on memory and time per check
#: (at 100 000 states a 23-joint edge takes 18 MB and about a minute of checking)
MAX_EDGE_STATES = 100_000


def require_joint_step(joint_step: float) -> None:
    """Raise unless ``joint_step`` is a positive finite number."""
    if not (joint_step > 0.0 and math.isfinite(joint_step)):
        raise PlannerlabError(f"joint_step must be a positive finite number, got {joint_step!r}")


def edge_too_long(span_rad: float, joint_step: float, n: int) -> PlannerlabError:
    """The error for an edge that needs more than :data:`MAX_EDGE_STATES` states."""
    return PlannerlabError(
        f"an edge of {span_rad:.3g} rad checked every joint_step = {joint_step:.3g} rad needs "
        f"{n} states, more than the limit of {MAX_EDGE_STATES}: use a larger "
        "[checking] joint_step"
    )


def interpolate_edge(q_a: Array, q_b: Array, joint_step: float, continuous: np.ndarray) -> Array:
    """States from q_a to q_b inclusive, at most ``joint_step`` apart per joint: (m, dof).

    Continuous joints go the short way round and are not wrapped here (callers that
    need [-pi, pi) wrap themselves; kinematics do not care).

    Raises:
        PlannerlabError: the edge would need more than :data:`MAX_EDGE_STATES` states.
    """
    require_joint_step(joint_step)
    n = edge_steps(q_a, q_b, joint_step, continuous)
    if n > MAX_EDGE_STATES:
        span = float(np.max(np.abs(joint_difference(q_b, q_a, continuous))))
        raise edge_too_long(span, joint_step, n)
    d = joint_difference(q_b, q_a, continuous)
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    return np.asarray(q_a, dtype=float)[None, :] + t * d[None, :]


def edge_counts(
    path: Array,
    joint_step: float,
    continuous: np.ndarray,
    edge_weights: Array | None = None,
) -> tuple[Array, np.ndarray]:
    """Per edge of a path (m >= 2 states): its joint change (m - 1, dof) and the number of
    steps :func:`densify` cuts it into (m - 1,) int: at most ``joint_step`` per joint and,
    with ``edge_weights``, at least ``ceil(Σ |Δq_i| · edge_weights_i)``.

    Raises:
        PlannerlabError: an edge would need more than :data:`MAX_EDGE_STATES` states.
    """
    require_joint_step(joint_step)
    d = joint_difference(path[1:], path[:-1], continuous)  # (m - 1, dof)
    span = np.max(np.abs(d), axis=1, initial=0.0)
    n_f = np.maximum(1.0, np.ceil(span / joint_step - 1e-12))  # steps per edge
    if edge_weights is not None:
        n_f = np.maximum(n_f, np.ceil(np.abs(d) @ np.asarray(edge_weights) - 1e-12))
    worst = int(np.argmax(n_f))
    if n_f[worst] > MAX_EDGE_STATES:
        raise edge_too_long(float(span[worst]), joint_step, int(min(n_f[worst], 2**62)))
    n: np.ndarray = n_f.astype(np.int64)
    return d, n


def densify(
    path: Array,
    joint_step: float,
    continuous: np.ndarray,
    edge_weights: Array | None = None,
) -> tuple[Array, Array]:
    """A path (m, dof) densified edge by edge, in one vectorised pass (no loop per edge).

    Edge ``i`` contributes the states of :func:`interpolate_edge` after its first, bit for
    bit (``t = j * (1 / n)`` as :func:`numpy.linspace` computes it, the last ``t`` exactly 1).
    With ``edge_weights`` (dof,), an edge ``Δq`` is also cut into at least
    ``ceil(Σ |Δq_i| · edge_weights_i)`` steps (the collision checker's edges in metres:
    weights = reach per joint / margin).

    Returns:
        states (M, dof) and, for each, the index of the waypoint edge it belongs to.

    Raises:
        PlannerlabError: an edge would need more than :data:`MAX_EDGE_STATES` states.
    """
    path = np.atleast_2d(np.asarray(path, dtype=float))
    if len(path) == 1:
        return path.copy(), np.zeros(1, dtype=int)
    d, n = edge_counts(path, joint_step, continuous, edge_weights)
    owners = np.repeat(np.arange(len(d)), n)
    j = np.arange(len(owners)) - np.repeat(np.cumsum(n) - n, n) + 1  # 1 .. n_i
    n_of = n[owners]
    t = np.where(j == n_of, 1.0, j * (1.0 / n_of))
    states = path[:-1][owners] + t[:, None] * d[owners]
    return (
        np.concatenate([path[:1], states]),
        np.concatenate([np.zeros(1, dtype=int), owners]),
    )


def path_length(path: Array, continuous: np.ndarray) -> float:
    """Sum of joint-space Euclidean edge lengths (wrapping continuous joints)."""
    path = np.atleast_2d(np.asarray(path, dtype=float))
    if len(path) < 2:
        return 0.0
    d = joint_difference(path[1:], path[:-1], continuous)
    return float(np.sum(np.linalg.norm(d, axis=1)))


#: states of the resampled path on which :func:`roughness` measures turning
ROUGHNESS_SAMPLES = 200


def roughness(path: Array, continuous: np.ndarray, n_samples: int = ROUGHNESS_SAMPLES) -> float:
    """How much a joint-space path turns [rad²]: the sum of the squared turning angles of
    the path resampled at ``n_samples`` states of equal joint-space arc length (the first
    and last state included; continuous joints the short way round). A straight path has
    0; a path that doubles back on itself adds π² at the turn. It does not depend on how
    many waypoints a planner returns or how it spaces them, only on the path's shape, so
    planners are compared on it (the ``smoothness`` of ``docs/comparison.md``: lower is
    smoother). A path with fewer than two distinct states has 0.

    Args:
        path: (m, dof) states [rad or m].
        continuous: (dof,) bool, joints that wrap.
        n_samples: states of the resampled path (at least 3).
    """
    if n_samples < 3:
        raise ValueError(f"roughness needs at least 3 samples, got {n_samples}")
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if len(P) < 2:
        return 0.0
    steps = joint_difference(P[1:], P[:-1], continuous)  # (m - 1, dof), unwrapped
    seg = np.linalg.norm(steps, axis=1)
    keep = seg > 1e-12  # repeated states carry no direction
    steps, seg = steps[keep], seg[keep]
    if len(seg) == 0:
        return 0.0
    s = np.concatenate([[0.0], np.cumsum(seg)])
    U = P[0] + np.concatenate([np.zeros((1, P.shape[1])), np.cumsum(steps, axis=0)])
    t = np.linspace(0.0, s[-1], n_samples)
    R = np.column_stack([np.interp(t, s, U[:, j]) for j in range(U.shape[1])])
    d = np.diff(R, axis=0)
    n = np.linalg.norm(d, axis=1)
    a, b, na, nb = d[:-1], d[1:], n[:-1], n[1:]
    ok = (na > 0.0) & (nb > 0.0)
    cos = np.einsum("ij,ij->i", a[ok], b[ok]) / (na[ok] * nb[ok])
    turn = np.arccos(np.clip(cos, -1.0, 1.0))
    return float(np.sum(turn**2))


def _on_segment(a: Array, b: Array, inner: Array, tol_rad: float) -> Array:
    """For each row of ``inner`` (k, dof): within ``tol_rad`` of segment a–b, between a and b."""
    ab = b - a
    den = float(ab @ ab)
    if den == 0.0:
        return np.linalg.norm(inner - a, axis=1) <= tol_rad
    t = (inner - a) @ ab / den
    off = np.linalg.norm(inner - a - t[:, None] * ab[None, :], axis=1)
    return (off <= tol_rad) & (t >= 0.0) & (t <= 1.0)


def waypoints(path: Array, tol_rad: float = 1e-9) -> Array:
    """The path's waypoints: states that lie inside a straight joint-space segment are left
    out (an interpolated path comes back as the corners it was interpolated between).

    A state is dropped only when it lies within ``tol_rad`` (Euclidean, joint space) of the
    segment between the kept states around it, and between them. The first and last
    states are always kept. Differences are taken as stored (a continuous joint's wrap at
    ±pi is a corner).

    The result is a fixed point (``waypoints(waypoints(p))`` equals ``waypoints(p)`` bit
    for bit): a pass that drops states is repeated on what it kept until none drops. It is
    the canonical form of a planned path: what a plan file holds and what every execution
    runs (:func:`plannerlab.run.pipeline.execute_results`), so a saved plan executes exactly
    as the plan in memory did.

    Args:
        path: (m, dof) joint path.
        tol_rad: distance from the segment below which a state counts as on it.

    Returns:
        (k, dof) with k <= m, the kept states in order (copies).
    """
    kept = _waypoints_once(np.atleast_2d(np.asarray(path, dtype=float)), tol_rad)
    while True:
        again = _waypoints_once(kept, tol_rad)
        if len(again) == len(kept):  # nothing dropped: the same states
            return kept
        kept = again


def _waypoints_once(path: Array, tol_rad: float) -> Array:
    """One pass of :func:`waypoints`."""
    m = len(path)
    if m <= 2:
        return path.copy()
    # candidates: interior states on the segment between their two neighbours
    prev, mid, nxt = path[:-2], path[1:-1], path[2:]
    d = nxt - prev
    den = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", mid - prev, d) / np.where(den > 0, den, 1.0)
    off = np.linalg.norm(mid - prev - t[:, None] * d, axis=1)
    droppable = (off <= tol_rad) & (t >= 0.0) & (t <= 1.0)
    corners = [0, *(np.flatnonzero(~droppable) + 1).tolist(), m - 1]
    # every dropped state must lie on the segment between the corners around it
    keep = [0]
    for a, b in zip(corners[:-1], corners[1:], strict=True):
        if b - a > 1 and not bool(np.all(_on_segment(path[a], path[b], path[a + 1 : b], tol_rad))):
            keep.extend(range(a + 1, b))  # a slow curve: keep its states as they are
        keep.append(b)
    return path[keep].copy()

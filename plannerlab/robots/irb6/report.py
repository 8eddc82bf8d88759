"""One IRb-6 pose solved by the analytic IK and every solution checked by the forward
kinematics: what ``plannerlab ik irb6`` prints and ``plannerlab.irb6_ik`` returns."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError


def _finite3(values: Any, what: str) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        shown = ", ".join(str(x) for x in np.ravel(values))
        raise PlannerlabError(f"{what} expects three finite numbers, got ({shown})")
    return v


def _finite(value: float | None, what: str) -> float | None:
    if value is not None and not math.isfinite(value):
        raise PlannerlabError(f"{what} expects a finite angle in degrees, got {value}")
    return value


def _rotation_error_rad(R_a: np.ndarray, R_b: np.ndarray) -> float:
    """Angle of the rotation R_a^T R_b [rad], accurate for small angles too."""
    R = R_a.T @ R_b
    skew = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return float(math.atan2(float(np.linalg.norm(skew)), 0.5 * (float(np.trace(R)) - 1.0)))


def ik_report(
    robot: Any,
    p_station_m: np.ndarray,
    c_station: np.ndarray,
    roll_rad: float,
    previous_theta5_rad: float | None,
) -> dict[str, Any]:
    """Solve one pose (station frame) and check every solution with the forward kinematics.

    Returns:
        A JSON-able dict: ``case``, ``lambda0_intervals_m``, ``R_wew_m``, ``R_zew_m``,
        ``solutions`` (each with ``q``, ``lambda0_m``, ``theta_deg``, ``pos_err_m``,
        ``rot_err_deg``, ``approach_err_deg``), ``reachable``, ``reason_code``, ``reason``.
    """
    from plannerlab.robots.irb6.ik import pose_from_approach, solve_ik

    T_target = pose_from_approach(p_station_m, c_station, roll_rad)
    answer = solve_ik(robot, T_target, previous_theta5_rad)
    solutions = []
    for q in answer.solutions:
        T_fk = robot.fk_station(q)[5]
        pos_err = float(np.linalg.norm(T_fk[:3, 3] - T_target[:3, 3]))
        cos_c = float(np.clip(T_fk[:3, 2] @ T_target[:3, 2], -1.0, 1.0))
        solutions.append(
            {
                "q": [float(v) for v in q],
                "lambda0_m": float(q[0]),
                "theta_deg": [math.degrees(float(v)) for v in q[1:]],
                "pos_err_m": pos_err,
                "rot_err_deg": math.degrees(_rotation_error_rad(T_target[:3, :3], T_fk[:3, :3])),
                "approach_err_deg": math.degrees(math.acos(cos_c)),
            }
        )
    return {
        "case": answer.case,
        "lambda0_intervals_m": [[float(lo), float(hi)] for lo, hi in answer.lambda0_intervals_m],
        "R_wew_m": answer.inner_radius_m,
        "R_zew_m": answer.outer_radius_m,
        "reachable": answer.ok,
        "reason_code": answer.reason_code,
        "reason": answer.reason,
        "solutions": solutions,
    }


def irb6_ik(
    position_m: Any,
    approach: Any,
    roll_deg: float | None = 0.0,
    previous_theta5_deg: float | None = None,
    *,
    robot: Any = None,
    frame: str = "station",
) -> dict[str, Any]:
    """The IRb-6's analytic IK of one flange pose, every solution checked by the forward
    kinematics.

    Args:
        position_m: flange position (3,) [m] in ``frame``.
        approach: approach vector c (3,), normalised here, in ``frame``.
        roll_deg: roll of the flange about c [deg] (None: 0).
        previous_theta5_deg: θ5 of the previous pose [deg], or None.
        robot: an :class:`~plannerlab.robots.irb6.model.IRb6` (a problem's ``robot``), or
            None for the model's defaults.
        frame: ``"station"`` or ``"world"`` (the robot's world: ``T_world_base``).

    Returns:
        ``frame``, ``position_station_m``, ``approach_station``, ``roll_deg``,
        ``previous_theta5_deg`` and :func:`ik_report`'s keys.

    Raises:
        PlannerlabError: a non-finite or zero input, an unknown frame.
    """
    from plannerlab.robots.irb6.model import IRb6

    if frame not in ("station", "world"):
        raise PlannerlabError(f"frame: 'station' or 'world', got {frame!r}")
    p_in = _finite3(position_m, "--position")
    c_in = _finite3(approach, "--approach")
    norm = float(np.linalg.norm(c_in))
    if norm < 1e-12:
        raise PlannerlabError(
            "--approach must be a non-zero direction vector (c = 0, 0, 0 has no direction)"
        )
    c_in = c_in / norm
    roll = float(_finite(roll_deg, "--roll") or 0.0)
    prev = _finite(previous_theta5_deg, "--previous-theta5")
    robot = IRb6() if robot is None else robot
    if not isinstance(robot, IRb6):
        raise PlannerlabError(f'robot: an IRb-6 (type = "irb6"), got {robot.kind!r}')
    if frame == "world":
        T_base_world = np.linalg.inv(robot.T_world_base)
        p_s = T_base_world[:3, :3] @ p_in + T_base_world[:3, 3]
        c_s = T_base_world[:3, :3] @ c_in
    else:
        p_s, c_s = p_in, c_in
    report = ik_report(
        robot, p_s, c_s, math.radians(roll), None if prev is None else math.radians(prev)
    )
    return {
        "frame": frame,
        "position_station_m": [float(v) for v in p_s],
        "approach_station": [float(v) for v in c_s],
        "roll_deg": roll,
        "previous_theta5_deg": prev,
        **report,
    }

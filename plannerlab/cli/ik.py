"""``plannerlab ik``: the IRb-6 analytic inverse kinematics from the command line.

    plannerlab ik irb6 --position X Y Z --approach CX CY CZ [--roll DEG]
                       [--previous-theta5 DEG] [--problem FILE-or-name] [--frame station|world]
                       [--json]

Prints the case of the pose (unambiguous, ambiguous 1 or 2, ``docs/papers.md`` §2), the
paper's R_wew and R_zew, the feasible λ0 intervals and every solution with its
forward-kinematics check, or the reason the pose is unreachable. Units: the position in
metres and the approach vector in the station frame (x_s horizontal, y_s up, z_s along
the track; ``--frame world`` reads them in the world frame of ``--problem``'s robot),
angles in degrees. Exit status: 0 when a solution exists, 1 when the pose is unreachable,
2 on bad input (the message says which flag and what was expected).
"""

# Argument parsing and printing only; the solver is plannerlab.extras.irb6_ik
# (plannerlab/robots/irb6/ik.py). The docstring above is the command's help.

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.table import Table
from rich.text import Text

from plannerlab import extras as px
from plannerlab.errors import PlannerlabError

#: robots the ``ik`` command knows (those with an analytic IK)
IK_ROBOTS = ("irb6",)


def add_ik_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``ik`` subcommand on the ``plannerlab`` parser's subparsers."""
    p = subparsers.add_parser(
        "ik",
        help="analytic inverse kinematics of the IRb-6 on LP-1: case, λ0 intervals, solutions",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("robot", choices=IK_ROBOTS, help="robot with an analytic IK")
    p.add_argument(
        "--position",
        nargs=3,
        type=float,
        required=True,
        metavar=("X", "Y", "Z"),
        help="flange position [m] (station frame unless --frame world)",
    )
    p.add_argument(
        "--approach",
        nargs=3,
        type=float,
        required=True,
        metavar=("CX", "CY", "CZ"),
        help="approach vector c (normalised here; station frame unless --frame world)",
    )
    p.add_argument(
        "--roll",
        type=float,
        default=0.0,
        metavar="DEG",
        help="roll of the flange about c [deg] (θ5 for a non-vertical approach; default 0)",
    )
    p.add_argument(
        "--previous-theta5",
        type=float,
        default=None,
        metavar="DEG",
        help="θ5 of the previous pose [deg]: at the ends of the θ5 range keep the closer value",
    )
    p.add_argument(
        "--problem",
        default=None,
        metavar="FILE",
        help="take the robot's parameters from this problem's [robot] table (name or .toml)",
    )
    p.add_argument(
        "--frame",
        choices=("station", "world"),
        default="station",
        help="frame of --position/--approach (world = the problem's world; default station)",
    )
    p.add_argument("--json", action="store_true", help="machine-readable output on stdout")
    p.set_defaults(func=cmd_ik)
    return p


# ---------------------------------------------------------------------- command
def _robot(args: argparse.Namespace) -> tuple[Any, str | None]:
    """The IRb-6 model (None: the defaults, or a problem's [robot] table) and the
    problem's name."""
    import plannerlab as pl

    if args.problem is None:
        if args.frame == "world":
            raise PlannerlabError("--frame world needs --problem (the world of which problem?)")
        return None, None
    problem = pl.load_problem(args.problem)
    if problem.robot.kind != "irb6":
        raise PlannerlabError(
            f"--problem {args.problem}: its robot is {problem.robot.kind!r}; "
            f"'plannerlab ik irb6' needs a problem with [robot] type = \"irb6\""
        )
    return problem.robot, problem.name


def cmd_ik(args: argparse.Namespace, console: Console) -> int:
    """Run ``plannerlab ik``: 0 with solutions, 1 when unreachable (bad input raises)."""

    robot, problem_name = _robot(args)
    report = px.irb6_ik(
        args.position,
        args.approach,
        args.roll,
        args.previous_theta5,
        robot=robot,
        frame=args.frame,
    )
    out = {"robot": args.robot, "problem": problem_name, **report}
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        _print(console, out)
    return 0 if report["reachable"] else 1


def _print(console: Console, out: dict[str, Any]) -> None:
    def vec(v: list[float]) -> str:
        return "(" + ", ".join(f"{x:.4f}" for x in v) + ")"

    t = Table(title="IRb-6 on LP-1: analytic IK", show_header=False)
    t.add_column("", style="bold")
    t.add_column("")

    def row(label: str, value: str | Text) -> None:
        t.add_row(label, value)

    source = f"problem {out['problem']}" if out["problem"] else "model defaults"
    row("robot", f"{out['robot']} ({source})")
    row("flange position (station) [m]", vec(out["position_station_m"]))
    row("approach c (station)", vec(out["approach_station"]))
    row("roll [°]", f"{out['roll_deg']:.3f}")
    row("case", out["case"])
    if out["R_wew_m"] is not None and out["R_zew_m"] is not None:
        row("R_wew, R_zew [m]", f"{out['R_wew_m']:.4f}, {out['R_zew_m']:.4f}")
    spans = " ∪ ".join(f"[{lo:.4f}, {hi:.4f}]" for lo, hi in out["lambda0_intervals_m"])
    if out["case"] == "unambiguous" and out["lambda0_intervals_m"]:
        spans = f"{out['lambda0_intervals_m'][0][0]:.4f} (one value: d_z − d_x·c_z/c_x)"
    row("λ0 intervals [m]", spans or "none")
    if not out["reachable"]:
        row(
            "unreachable",
            Text.assemble((str(out["reason_code"]), "red"), f": {out['reason'] or ''}"),
        )
    console.print(t)
    if not out["solutions"]:
        return
    s = Table(title=f"{len(out['solutions'])} solution(s), checked by forward kinematics")
    for col in ("#", "λ0 m", "θ1 °", "θ2 °", "θ3 °", "θ4 °", "θ5 °", "pos err m", "rot err °"):
        s.add_column(col, justify="right")
    for i, sol in enumerate(out["solutions"], start=1):
        s.add_row(
            str(i),
            f"{sol['lambda0_m']:.4f}",
            *(f"{v:.3f}" for v in sol["theta_deg"]),
            f"{sol['pos_err_m']:.2e}",
            f"{sol['rot_err_deg']:.2e}",
        )
    console.print(s)


__all__ = ["IK_ROBOTS", "add_ik_parser", "cmd_ik"]

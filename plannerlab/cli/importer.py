"""`plannerlab import mbm`: MotionBenchMaker problems (MoveIt scene + request YAML) as
plannerlab problem files (:mod:`plannerlab.problem.mbm`); `plannerlab import
kinematic-chain`: OMPL's KinematicChain benchmark (:mod:`plannerlab.problem.kinematic_chain`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from rich.console import Console

from plannerlab import extras as px
from plannerlab.cli.common import add_renamed_flag


def cmd_import_mbm(args: argparse.Namespace, console: Console) -> int:
    from plannerlab.errors import PlannerlabError

    mbm = px.mbm

    urdf, srdf = args.urdf, args.srdf
    robot = mbm.mbm_robot(args.robot)
    tip_link = args.tip_link or robot.tip_link
    sources: list[Path] = list(args.source)
    if args.fetch:
        got = mbm.fetch_vamp(robot.name, args.cache)
        console.print(
            f"vamp-planner 0.6.4 (Apache-2.0, licence {got.licence}): "
            f"{robot.name} URDF {got.urdf}, SRDF {got.srdf}, "
            f"problems in {got.problems}",
            highlight=False,
        )
        urdf = urdf or got.urdf
        srdf = srdf or got.srdf
        if not sources:
            sources = got.scenario_folders()
    if not sources:
        if args.fetch:
            return 0
        raise PlannerlabError(
            "import mbm: give scenario folders or scene+request files, or --fetch"
        )
    if urdf is None:
        raise PlannerlabError("import mbm: --urdf is needed (or --fetch for the robot's)")
    pairs: list[tuple[Path, Path, str]] = []
    files = [s for s in sources if not s.is_dir()]
    if files:
        if len(files) != 2 or len(sources) != 2:
            raise PlannerlabError(
                "import mbm: give scenario folders, or one scene file and one request file"
            )
        scene, request = files
        pairs.append((scene, request, args.name or scene.stem))
    for folder in (s for s in sources if s.is_dir()):
        found = mbm.problem_pairs(folder)
        if not found:
            raise PlannerlabError(f"{folder}: no sceneNNNN.yaml + requestNNNN.yaml pairs")
        scenario = folder.name.removesuffix(f"_{robot.name}")
        for scene, request in found[: args.limit]:
            pairs.append((scene, request, f"{scenario}_{scene.stem.removeprefix('scene')}"))
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise PlannerlabError(f"--out {out}: a folder (problem files are written into it)")
    out.mkdir(parents=True, exist_ok=True)
    for scene, request, name in pairs:
        target = out / f"{name}.toml"
        text = mbm.problem_toml(
            scene,
            request,
            out_path=target,
            urdf=Path(urdf),
            srdf=Path(srdf) if srdf else None,
            tip_link=tip_link,
            name=name,
            safety_margin_m=args.safety_margin_m,
            joint_step_rad=args.joint_step,
        )
        target.write_text(text, encoding="utf-8")
    console.print(f"{len(pairs)} problem files written to {out}", highlight=False, soft_wrap=True)
    return 0


def cmd_import_kinematic_chain(args: argparse.Namespace, console: Console) -> int:
    from plannerlab.errors import PlannerlabError

    kc = px.kinematic_chain
    # every N checked before any file is written: "--links 10 1" writes nothing
    bad = [n for n in args.links if not kc.MIN_LINKS <= n <= kc.MAX_LINKS]
    if bad:
        raise PlannerlabError(
            f"--links: each N must be in {kc.MIN_LINKS} … {kc.MAX_LINKS} links, got "
            f"{', '.join(map(str, bad))}"
        )
    for n in args.links:
        target = kc.write_problem(
            n,
            args.out,
            link_radius_m=args.link_radius_m,
            wall_thickness_m=args.wall_thickness_m,
            safety_margin_m=args.margin_m,
            joint_step_rad=args.joint_step,
            time_limit_s=args.time_limit,
        )
        console.print(f"{target} (and its URDF)", highlight=False, soft_wrap=True)
    return 0


def _add_kinematic_chain(kinds: Any) -> None:
    k = kinds.add_parser(
        "kinematic-chain",
        help="OMPL's KinematicChain benchmark (the horn, N links) -> problem files",
        description=(
            "OMPL's KinematicChain benchmark (demos/KinematicChain.h): a planar chain of N "
            "links, each 1/N m, every joint a full turn, from inside the horn out to the "
            "left. Writes kinematic_chain_N.urdf (links as thin capsules) and "
            "kinematic_chain_N.toml (the horn's walls as thin boxes, the demo's start and "
            "goal) per N into --out."
        ),
    )
    k.add_argument("--links", type=int, nargs="+", default=[10, 20, 30], help="N (each)")
    k.add_argument("--out", type=Path, default=Path("problems/kinematic_chain"))
    k.add_argument("--link-radius-m", type=float, default=1e-3, help="the links' radius [m]")
    k.add_argument("--wall-thickness-m", type=float, default=2e-3, help="the walls' [m]")
    k.add_argument(
        "--margin-m", type=float, default=0.0, help="[planning] safety_margin_m of the files"
    )
    k.add_argument(
        "--joint-step",
        type=float,
        default=0.05,
        help="[checking] joint_step [rad] (paths re-checked at a quarter of it)",
    )
    k.add_argument("--time-limit", type=float, default=10.0, help="[budget] time_limit_s [s]")
    k.set_defaults(func=cmd_import_kinematic_chain)


def mbm_default_joint_step() -> float:

    return px.mbm.DEFAULT_JOINT_STEP_RAD


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "import",
        help="turn other benchmarks' problems into plannerlab problem files",
    )
    kinds = p.add_subparsers(dest="import_kind", required=True, metavar="KIND")
    m = kinds.add_parser(
        "mbm",
        help="MotionBenchMaker (MoveIt scene + request YAML) -> problem files",
        description=(
            "MotionBenchMaker problems (MoveIt scene + request YAML, joint goals) -> plannerlab "
            "problem files for a URDF robot. SOURCE: scenario folders of sceneNNNN.yaml + "
            "requestNNNN.yaml pairs, or one scene file and one request file. --fetch gets "
            "the --robot's set (panda, ur5, fetch), URDF and SRDF from the vamp-planner "
            "0.6.4 source distribution "
            "(pip download) into a cache and says where."
        ),
    )
    m.add_argument("source", nargs="*", type=Path, help="scenario folders, or scene + request")
    m.add_argument("--out", type=Path, default=Path("problems/mbm"), help="folder to write to")
    m.add_argument("--urdf", type=Path, default=None, help="the robot's URDF")
    m.add_argument("--srdf", type=Path, default=None, help="the robot's SRDF (optional)")
    m.add_argument(
        "--robot",
        default="panda",
        help="the MotionBenchMaker robot: panda, ur5 or fetch (what --fetch gets; the "
        "default tip link; the suffix taken off scenario folder names)",
    )
    m.add_argument(
        "--tip-link", default=None, help="URDF link carrying the tip (default: the robot's)"
    )
    m.add_argument("--name", default=None, help="problem name (one scene + request)")
    m.add_argument("--limit", type=int, default=None, help="at most N problems per folder")
    m.add_argument(
        "--safety-margin-m",
        type=float,
        default=0.0,
        help="[planning] safety_margin_m of the files (MotionBenchMaker's states are valid "
        "with no margin)",
    )
    add_renamed_flag(m, "--margin-m", "--safety-margin-m", type=float)
    m.add_argument(
        "--joint-step",
        type=float,
        default=mbm_default_joint_step(),
        help="[checking] joint_step of the files [rad]",
    )
    m.add_argument(
        "--fetch",
        action="store_true",
        help="download the --robot's set (vamp-planner 0.6.4 sdist, pip) into --cache first",
    )
    m.add_argument(
        "--cache",
        type=Path,
        default=None,
        help="cache folder for --fetch (default $PLANNERLAB_CACHE/mbm or ~/.cache/plannerlab/mbm)",
    )
    m.set_defaults(func=cmd_import_mbm)
    _add_kinematic_chain(kinds)

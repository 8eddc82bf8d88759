"""Every serial arm of ``example-robot-data`` and ``pybullet_data`` loaded with plannerlab's
defaults (issue 35): per robot the load time with an empty cover cache (cold) and again
(cached), its primitives and its worst cover excess; per link with ``--links``.

``example-robot-data`` is data, not a dependency: fetch it once into a scratch folder,

    pip download --no-deps example-robot-data==6.0.0 -d /tmp/erd
    unzip -q /tmp/erd/example_robot_data-6.0.0-0-py3-none-any.whl -d /tmp/erd/whl
    python bench/robots_load_bench.py \
        --erd /tmp/erd/whl/cmeel.prefix/share/example-robot-data/robots

``pybullet_data`` ships with pybullet. The tip link is :func:`plannerlab.run.robot_info.
default_tip_link` (where the joint chain ends or branches). Each robot loads in a fresh
process (a cold start is a new user's: imports, reading, covering); the machine's load
average is printed with the table, wall times are not measures under load.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

#: the serial arms (fixed base, one chain to the tool) of example-robot-data 6.0.0; left
#: out: legged robots, humanoids (their lone arm ``talos_left_arm`` is in), hands, mobile
#: bases, Baxter (two arms), ``ur3.urdf`` (an empty xacro output: no links)
ERD_ARMS = (
    "kinova_description/robots/kinova.urdf",
    "panda_description/urdf/panda.urdf",
    "panda_description/urdf/panda_collision.urdf",
    "so_arm_description/urdf/so100.urdf",
    "so_arm_description/urdf/so101.urdf",
    "ur_description/urdf/ur3_robot.urdf",
    "ur_description/urdf/ur3_joint_limited_robot.urdf",
    "ur_description/urdf/ur3_gripper.urdf",
    "ur_description/urdf/ur5_robot.urdf",
    "ur_description/urdf/ur5_joint_limited_robot.urdf",
    "ur_description/urdf/ur5_gripper.urdf",
    "ur_description/urdf/ur10_robot.urdf",
    "ur_description/urdf/ur10_joint_limited_robot.urdf",
    "xarm_description/urdf/xarm7.urdf",
    "z1_description/urdf/z1.urdf",
    "talos_data/robots/talos_left_arm.urdf",
    "finger_edu_description/robots/finger_edu.urdf",
    "double_pendulum_description/urdf/double_pendulum.urdf",
    "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
    "double_pendulum_description/urdf/double_pendulum_simple.urdf",
    "asr_twodof_description/urdf/TwoDofs.urdf",
)
#: the arms of pybullet_data
PYBULLET_ARMS = (
    "franka_panda/panda.urdf",
    "kuka_iiwa/model.urdf",
    "kuka_iiwa/model_for_sdf.urdf",
    "kuka_iiwa/model_free_base.urdf",
    "kuka_iiwa/model_vr_limits.urdf",
    "xarm/xarm6_robot.urdf",
    "xarm/xarm6_robot_white.urdf",
    "xarm/xarm6_with_gripper.urdf",
)

_CHILD = r"""
import json, sys, time
from pathlib import Path
t0 = time.perf_counter()
from plannerlab.robots.urdf.model import UrdfChain
from plannerlab.run.robot_info import default_tip_link
urdf, cache = Path(sys.argv[1]), Path(sys.argv[2])
tip = default_tip_link(urdf)
t1 = time.perf_counter()
r = UrdfChain(urdf, tip, cover_cache_dir=cache)
t2 = time.perf_counter()
print(json.dumps({
    "tip": tip, "dof": r.dof, "primitives": len(r.link_names),
    "capsules": sum(c.capsules for c in r.mesh_covers),
    "meshes": len(r.mesh_covers),
    "worst_excess_mm": max((c.max_excess_m * 1e3 for c in r.mesh_covers), default=0.0),
    "load_s": t2 - t1, "with_imports_s": t2 - t0,
    "links": [
        [c.link, c.primitives, c.capsules, c.max_excess_m * 1e3, c.solid]
        for c in r.mesh_covers
    ],
}))
"""


def _load(urdf: Path, cache: Path) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(urdf), str(cache)],
        capture_output=True,
        text=True,
        check=False,
    )
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--erd", type=Path, help="example-robot-data's robots/ folder")
    ap.add_argument("--links", action="store_true", help="also print every link's cover")
    ap.add_argument("--json", type=Path, help="write the rows to this file")
    ap.add_argument("--only", help="only robots whose path contains this text")
    args = ap.parse_args()
    import pybullet_data

    robots = [("pybullet_data", Path(pybullet_data.getDataPath()) / p) for p in PYBULLET_ARMS]
    if args.erd is not None:
        robots = [("example-robot-data", args.erd / p) for p in ERD_ARMS] + robots
    if args.only:
        robots = [(s, p) for s, p in robots if args.only in str(p)]
    print(f"load average at start: {os.getloadavg()}", flush=True)
    rows = []
    print(
        "| source | URDF | tip link | dof | meshes | primitives (capsules) | worst excess mm "
        "| cold load s | cached load s |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for source, urdf in robots:
        with tempfile.TemporaryDirectory() as cache:
            cold = _load(urdf, Path(cache))
            warm = _load(urdf, Path(cache)) if "error" not in cold else cold
        row = {"source": source, "urdf": str(urdf), "cold": cold, "cached": warm}
        rows.append(row)
        name = (
            "/".join(urdf.parts[-3:])
            if source == "example-robot-data"
            else "/".join(urdf.parts[-2:])
        )
        if "error" in cold:
            print(f"| {source} | {name} | | | | | | error: {cold['error'][:120]} | |", flush=True)
            continue
        print(
            f"| {source} | {name} | {cold['tip']} | {cold['dof']} | {cold['meshes']} "
            f"| {cold['primitives']} ({cold['capsules']}) | {cold['worst_excess_mm']:.1f} "
            f"| {cold['load_s']:.1f} | {warm['load_s']:.2f} |",
            flush=True,
        )
        if args.links:
            for link, n, caps, exc, solid in cold["links"]:
                print(f"|  | | {link} | | | {n} ({caps}) | {exc:.1f} ({solid}) | | |")
    print(f"load average at end: {os.getloadavg()}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0 if all("error" not in r["cold"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())

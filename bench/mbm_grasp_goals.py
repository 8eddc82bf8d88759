"""MotionBenchMaker's grasp goals on a mesh robot, before and after declared contacts
(issue 35 item 4): counts only, no timing.

Each problem of a scenario is imported (``plannerlab.problem.mbm.problem_toml``) with a
URDF of the user's choosing (default: PyBullet's mesh Panda, ``problems/urdf/panda_mesh``,
its shipped covers), so the importer measures the goal's contacts on that robot's
collision model; the written file is loaded and its goal state checked by the compiled
core and by FCL, then the same file with every ``touch_links`` line removed (what the
importer wrote before). Printed per problem: the objects declared and the links that
touched them; then the counts of valid goals.

    PYTHONPATH=. .venv/bin/python bench/mbm_grasp_goals.py --scenario box --n 8
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from plannerlab.collision.fcl_checker import CollisionChecker, problem_checker  # noqa: E402
from plannerlab.problem.load import parse_problem  # noqa: E402
from plannerlab.problem.mbm import fetch_vamp, problem_pairs, problem_toml  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="box")
    ap.add_argument("--n", type=int, default=8)
    ap.add_argument("--urdf", default=str(ROOT / "problems/urdf/panda_mesh/panda.urdf"))
    ap.add_argument("--srdf", default=str(ROOT / "problems/urdf/panda_mesh/panda_mesh.srdf"))
    ap.add_argument("--tip-link", default="panda_hand")
    args = ap.parse_args()
    vamp = fetch_vamp("panda")
    pairs = problem_pairs(vamp.problems / f"{args.scenario}_panda")[: args.n]
    counts = {"declared_core": 0, "declared_fcl": 0, "bare_core": 0, "bare_fcl": 0}
    with tempfile.TemporaryDirectory() as tmp:
        for scene, request in pairs:
            out = Path(tmp) / f"{scene.stem}.toml"
            text = problem_toml(
                scene, request, out_path=out, urdf=Path(args.urdf), srdf=Path(args.srdf),
                tip_link=args.tip_link,
            )  # fmt: skip
            bare = "\n".join(ln for ln in text.splitlines() if not ln.startswith("touch_links"))
            notes = [ln[2:] for ln in text.splitlines() if ln.startswith("# grasped")]
            line = [scene.stem]
            for label, body in (("declared", text), ("bare", bare)):
                out.write_text(body, encoding="utf-8")
                p = parse_problem(out)
                q = np.asarray(p.goals[0].q_rad)
                core = problem_checker(p)
                fcl = CollisionChecker(p.robot, p.scene, "fcl", float(p.safety_margin_m))
                ok_core, ok_fcl = core.is_valid(q), fcl.is_valid(q)
                counts[f"{label}_core"] += ok_core
                counts[f"{label}_fcl"] += ok_fcl
                line.append(f"{label}: core {ok_core} fcl {ok_fcl}")
                if label == "bare" and not ok_core:
                    line.append(f"pairs {core.colliding_pairs(q)[:3]}")
            print(" | ".join(line), "|", "; ".join(notes) or "nothing declared")
    n = len(pairs)
    print(f"valid goals of {n}: with touch_links core {counts['declared_core']}, "
          f"FCL {counts['declared_fcl']}; without core {counts['bare_core']}, "
          f"FCL {counts['bare_fcl']}")  # fmt: skip


if __name__ == "__main__":
    main()

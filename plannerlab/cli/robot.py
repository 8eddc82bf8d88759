"""`plannerlab robot URDF`: what plannerlab makes of a URDF: its joints and links, the
cover of each collision mesh (primitives, worst excess), the self-collision pairs it
computed (written as an SRDF), the load time; ``--view`` serves a 3-D view of the model."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape

from plannerlab.cli.tables import table


def _mm(x: float) -> str:
    return f"{x * 1e3:.1f}"


def cmd_robot(args: argparse.Namespace, console: Console) -> int:
    import plannerlab.extras as px

    urdf = Path(args.urdf)
    srdf = Path(args.srdf) if args.srdf else Path(f"{urdf.stem}.srdf")
    chain_args: dict[str, Any] = {}
    if args.mesh_path:
        chain_args["mesh_paths"] = tuple(Path(p) for p in args.mesh_path)
    if args.excess_mm is not None:
        chain_args["cover_excess_m"] = args.excess_mm / 1e3
    if args.max_primitives is not None:
        chain_args["cover_max_primitives"] = args.max_primitives
    if args.no_cache:
        chain_args["cover_cache"] = False
    if not args.json:
        console.print(f"loading {escape(str(urdf))} (covers are computed once, then cached)")
    r = px.robot_report(urdf, args.tip, srdf_out=srdf, n_states=args.states, **chain_args)
    doc = {
        "urdf": str(r.urdf),
        "tip_link": r.tip_link,
        "dof": len(r.joints),
        "load_s": round(r.load_s, 3),
        "joints": [{"name": n, "type": k, "lower": lo, "upper": hi} for n, k, lo, hi in r.joints],
        "links": [{"name": n, "primitives": r.primitives_by_link[n]} for n in r.links],
        "covers": [
            {
                "link": c.link,
                "file": c.file,
                "primitives": c.primitives,
                "capsules": c.capsules,
                "max_excess_mm": round(c.max_excess_m * 1e3, 2),
                "target_excess_mm": round(c.target_excess_m * 1e3, 2),
                "solid": c.solid,
                "cached": c.cached,
            }
            for c in r.covers
        ],
        "pairs": [{"link1": p.link1, "link2": p.link2, "reason": p.reason} for p in r.pairs],
        "srdf": str(r.srdf) if r.srdf else None,
        "notes": list(r.notes),
    }
    if args.json:
        print(json.dumps(doc, indent=1))
    else:
        t = table(
            f"{urdf.name}: {len(r.joints)} joints to {r.tip_link}",
            [("joint", "name"), ("type", "name"), ("lower", "num"), ("upper", "num")],
            compact=True,
        )
        for n, k, lo, hi in r.joints:
            t.add_row(escape(n), k, f"{lo:.3f}", f"{hi:.3f}")
        console.print(t)
        t = table(
            "collision meshes as capsules (excess: how far the cover reaches outside)",
            [
                ("link", "name"),
                ("primitives", "num"),
                ("capsules", "num"),
                ("worst excess mm", "num"),
                ("aimed mm", "num"),
                ("measured from", "name"),
                ("file", "text"),
            ],
            compact=True,
        )
        for c in r.covers:
            t.add_row(
                escape(c.link),
                str(c.primitives),
                str(c.capsules),
                _mm(c.max_excess_m),
                _mm(c.target_excess_m),
                c.solid + (" (cached)" if c.cached else ""),
                escape(Path(c.file).name),
            )
        console.print(t)
        counts: dict[str, int] = {}
        for p in r.pairs:
            counts[p.reason] = counts.get(p.reason, 0) + 1
        total = sum(r.primitives_by_link.values())
        console.print(
            f"{len(r.links)} links with geometry, {total} primitives; self-collision pairs "
            f"never checked: {', '.join(f'{n} {k}' for k, n in sorted(counts.items())) or 'none'}"
        )
        console.print(f"SRDF written: {escape(str(r.srdf))}; load time {r.load_s:.1f} s")
        for note in r.notes:
            console.print(f"[yellow]note:[/] {escape(note)}")
    if args.view:
        server = px.serve_robot(r.robot, host=args.host, port=args.port)
        url = f"http://{args.host}:{server.get_port()}"
        if args.json:
            print(json.dumps({"event": "serving", "url": url}), flush=True)
        else:
            console.print(f"3-D view of the capsules at {url} (Ctrl-C to stop)")
        try:
            while True:
                time.sleep(0.2)
        except KeyboardInterrupt:
            return 0
        finally:
            server.stop()
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "robot",
        help="a URDF as plannerlab plans with it: joints, mesh covers, self-collision pairs",
        description='Load URDF as a problem\'s [robot] type = "urdf" would and show its\n'
        "joints, each collision mesh's cover (primitives, worst excess: how far the cover\n"
        "reaches outside the mesh), the self-collision pairs never checked (Adjacent,\n"
        "Default, Always, Never: seeded sampling as MoveIt's set-up assistant does) and\n"
        "the load time; writes those pairs as an SRDF ([robot] srdf reads it).",
    )
    p.add_argument("urdf", help="the URDF file")
    p.add_argument("--tip", help="the tip link (default: the tool centre frame, else the hand)")
    p.add_argument("--srdf", help="where to write the SRDF (default: ./<URDF name>.srdf)")
    p.add_argument("--states", type=int, default=1000, help="random states sampled for pairs")
    p.add_argument(
        "--mesh-path", action="append", metavar="DIR", help="a folder for package:// paths"
    )
    p.add_argument("--excess-mm", type=float, help="cover excess aimed at [mm] (default 10)")
    p.add_argument("--max-primitives", type=int, help="capsules per mesh (default 32)")
    p.add_argument("--no-cache", action="store_true", help="compute covers, do not cache")
    p.add_argument("--view", action="store_true", help="serve a 3-D view of the capsules")
    p.add_argument("--port", type=int, default=8080, help="port for --view (0: any free)")
    p.add_argument("--host", default="127.0.0.1", help="address for --view")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_robot)

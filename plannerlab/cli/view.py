"""`plannerlab view`: an interactive 3-D view of a plan and its execution in the browser."""

from __future__ import annotations

import argparse
import json
import time
import webbrowser
from typing import Any

from rich.console import Console

import plannerlab as pl


def _event(args: argparse.Namespace, console: Console, text: str, **data: Any) -> None:
    """One line for a person, or one JSON object per line with --json."""
    if args.json:
        print(json.dumps(data), flush=True)
    else:
        console.print(text, soft_wrap=True, highlight=False)


def cmd_view(args: argparse.Namespace, console: Console) -> int:
    if args.frames < 2:
        raise pl.PlannerlabError(f"--frames: expected >= 2, got {args.frames}")
    viewer = pl.view(
        args.plan,
        host=args.host,
        port=args.port,
        mesh_dirs=args.mesh_dir or (),
        max_frames=args.frames,
    )
    try:
        executed = sum(m.q_executed is not None for m in viewer.legs)
        _event(
            args,
            console,
            f"serving {args.plan} at {viewer.url} ({len(viewer.legs)} legs, {executed} "
            "executed); Ctrl-C stops",
            event="serving",
            url=viewer.url,
            legs=len(viewer.legs),
            executed_legs=executed,
            scene_nodes=viewer.scene_nodes,
            notes=viewer.notes,
        )
        for note in viewer.notes:
            if not args.json:
                console.print(f"note: {note}", soft_wrap=True, highlight=False)
        if not args.no_browser:
            webbrowser.open(viewer.url)
        clients = 0
        while True:
            now = viewer.clients
            if now != clients:
                _event(
                    args,
                    console,
                    f"{now} browser(s) connected",
                    event="clients",
                    clients=now,
                    scene_nodes=len(viewer.scene_nodes),
                )
                clients = now
            time.sleep(0.1)
    except KeyboardInterrupt:
        _event(args, console, "stopped", event="stopped")
        return 0
    finally:
        viewer.close()


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "view",
        help="interactive 3-D view of a plan and its execution in the browser",
        description="Serve an interactive 3-D view of PLAN.json (viser) until Ctrl-C:\n"
        "the scene, the robot's true capsules (or a URDF's visual meshes), the planned\n"
        "motion in blue and, when PLAN.exec.json is beside it, PyBullet's motion in orange\n"
        "(the plan a wireframe over it) on one timeline with play/pause; tip traces, goal\n"
        "regions (ball: position tolerance, cone: normal's angle tolerance), a leg selector,\n"
        "the link nearest the scene coloured by its clearance, contacts where they happened.",
    )
    p.add_argument("plan", help="PLAN.json written by solve (PLAN.exec.json beside it is shown)")
    p.add_argument("--port", type=int, default=8080, help="port to serve on (0: any free port)")
    p.add_argument("--host", default="127.0.0.1", help="address to serve on")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument("--frames", type=int, default=300, help="timeline frames per leg")
    p.add_argument(
        "--mesh-dir",
        action="append",
        metavar="DIR",
        help="another folder with a URDF robot's visual meshes (repeatable)",
    )
    p.add_argument("--json", action="store_true", help="print events as JSON lines")
    p.set_defaults(func=cmd_view)

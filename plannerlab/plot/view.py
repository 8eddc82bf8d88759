"""An interactive 3-D view of a plan and its execution, served to a browser by viser.

What the page shows (``plannerlab view PLAN.json``, :func:`plannerlab.view`):

* the scene: every obstacle of ``problem.scene`` as a solid (boxes, cylinders, spheres; a
  mesh obstacle as its triangles; any other shape as its bounding box);
* the robot with its real geometry: every link's capsule with its true radius (a sphere
  is a capsule of zero length), Arm-Z modules, the IRb-6's links and the continuum's
  segments alike (``robot.link_segments(q)``, ``robot.link_radii_m``); a URDF robot's
  visual meshes when its mesh files are found;
* the planned motion (translucent blue) and, when the plan was executed, PyBullet's motion
  (solid orange) at the same instant, on one timeline slider with play/pause;
* both tip traces; the goal regions (a ball of the position tolerance, a cone of the
  normal's angle tolerance); a leg selector;
* the link nearest the scene coloured by its clearance (red touching, green at
  :data:`CLEAR_AT_M` or more), with its distance in the side panel;
* the contacts an execution recorded, marked where they happened;
* each leg's planned path in the side panel: its length, smoothness and the smallest
  clearance along the whole path, from its record (:func:`~plannerlab.plot.view_scene.
  path_quality`).

The frames are made from records only (:func:`leg_motions`): the plan's path densified at
the problem's joint step, or, for an executed leg, each logged sample's commanded and
simulated state, then where the arm settled. Clearances come from a function the caller
passes (``plannerlab.view`` passes the collision checker's), so this module never checks
collisions itself.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.plot.view_scene import (
    CLEAR_AT_M,
    CONTACT_RGB,
    EXECUTED_RGB,
    GOAL_RGB,
    MIN_LINK_SPAN,
    MIN_MARK_M,
    PLANNED_OPACITY,
    PLANNED_RGB,
    SCENE_RGB,
    ClearanceFn,
    LegMotion,
    camera_pose,
    capsule_batch,
    clearance_rgb,
    cone_mesh,
    hex_colour,
    leg_motions,
    matrix_to_wxyz,
    motion_span,
    obstacle_mesh,
    polyline_segments,
    port_free,
    unit_cylinder,
    unit_sphere,
    urdf_cfg,
    urdf_with_meshes,
)
from plannerlab.problem.load import Problem
from plannerlab.robots.base import Array


# ------------------------------------------------------------------------ the viewer
class Viewer:
    """A running viser server showing a plan (see the module docstring).

    Args:
        problem: the problem the plan was made for.
        plan: a :class:`~plannerlab.record.plan.Plan` (or anything with ``legs``,
            ``planner``, ``problem`` and ``seed``).
        executions: the legs' :class:`~plannerlab.record.execution.Execution` records
            (none: the planned motion only).
        host, port: where to serve (port 0: any free port). A port in use raises
            :class:`~plannerlab.errors.PlannerlabError`.
        clearance: per-link clearance function (see :data:`ClearanceFn`), or None to
            leave the links uncoloured.
        mesh_dirs: more folders to look for a URDF's visual mesh files in.
        max_frames: frames per leg on the timeline.
        fps: frames per second when playing.

    Attributes:
        url: where the page is served.
        server: the :class:`viser.ViserServer`.
        legs: the :class:`LegMotion` of every leg.
        slider, leg_dropdown, play_button: the GUI handles (set ``slider.value`` to move
            the timeline from Python).
        notes: what could not be drawn as asked, in words.
    """

    def __init__(
        self,
        problem: Problem,
        plan: Any,
        executions: Sequence[Any] = (),
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        clearance: ClearanceFn | None = None,
        mesh_dirs: Sequence[str | Path] = (),
        max_frames: int = 300,
        fps: float = 20.0,
    ) -> None:
        if not 0 <= int(port) <= 65535:
            raise PlannerlabError(f"--port: expected a port number 0..65535, got {port}")
        if port and not port_free(host, int(port)):
            raise PlannerlabError(
                f"--port {port}: {host}:{port} is in use (another viewer?); give another "
                "--port, or --port 0 for any free one"
            )
        import viser

        self.problem = problem
        self.plan = plan
        self.executions = tuple(executions)
        self.legs = leg_motions(problem, plan.legs, self.executions, max_frames)
        self.clearance = clearance
        self.fps = float(fps)
        self.notes: list[str] = []
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._playing = threading.Event()
        self._cache: dict[tuple[int, int, str], tuple[Array, Sequence[str]]] = {}
        self._leg = 0
        self._nodes: dict[str, Any] = {}
        self._quiet = _QuietMimic()
        self._trace_nodes: list[Any] = []
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner
            self.server = viser.ViserServer(host=host, port=int(port), verbose=False)
        self.url = f"http://{host}:{self.server.get_port()}"
        try:
            self._build(mesh_dirs)
        except BaseException:
            self.close()
            raise
        self._player = threading.Thread(target=self._play_loop, name="plannerlab-view", daemon=True)
        self._player.start()

    # ------------------------------------------------------------------ building
    def _build(self, mesh_dirs: Sequence[str | Path]) -> None:
        s = self.server
        robot = self.problem.robot
        s.scene.set_up_direction("+z")
        # less of viser's ambient environment light: the colours stay saturated
        s.scene.configure_environment_map("warehouse", environment_intensity=0.4)
        span = motion_span(self.problem, self.legs)
        cell = 10.0 ** math.floor(math.log10(span / 4.0))
        self._add(
            "/grid", s.scene.add_grid, width=4 * span, height=4 * span, cell_size=cell, plane="xy"
        )
        for o in self.problem.scene.obstacles:
            v, f = obstacle_mesh(o)
            self._add(
                f"/scene/{_node(o.name)}",
                s.scene.add_mesh_simple,
                v,
                f,
                color=SCENE_RGB,
                opacity=0.6,  # a robot inside a guide or sleeve shows through
                side="double",
            )
        self._draw_goals()
        # the robots: capsules always (the clearance colours live there), meshes on top
        radii = np.asarray(robot.link_radii_m, dtype=float)
        thinnest = MIN_LINK_SPAN * span
        if np.any(radii < thinnest):
            self.notes.append(
                f"links thinner than {thinnest * 1000:.1f} mm (radius) are drawn that thick "
                f"to be seen (true radii from {radii.min() * 1000:.1f} mm)"
            )
        radii = np.maximum(radii, thinnest)
        self._radii = radii
        cyl = unit_cylinder()
        sph = unit_sphere()
        q0 = self.legs[0].q_planned[0]
        b = capsule_batch(robot.link_segments(q0), radii)
        self._robots: dict[str, _RobotNodes] = {}
        executed = any(m.q_executed is not None for m in self.legs)
        # with an execution beside it, the planned robot is a translucent wireframe over
        # PyBullet's solid one, so both stay visible where they agree
        kinds = [("planned", PLANNED_RGB, PLANNED_OPACITY if executed else None)]
        if executed:
            kinds.append(("executed", EXECUTED_RGB, None))
        model, why = urdf_with_meshes(robot, [Path(d) for d in mesh_dirs])
        if why:
            self.notes.append(why)
        if model is not None:
            # yourdfpy warns on every pose of a mimic joint whose joint is fixed (the
            # Panda's second finger): once per frame, so not at all while this view runs
            logging.getLogger("yourdfpy.urdf").addFilter(self._quiet)
        for kind, rgb, opacity in kinds:
            links = self._add(
                f"/{kind}/links",
                s.scene.add_batched_meshes_simple,
                cyl[0],
                cyl[1],
                batched_wxyzs=b.cyl_wxyzs,
                batched_positions=b.cyl_positions,
                batched_scales=b.cyl_scales,
                batched_colors=np.tile(np.array(rgb, dtype=np.uint8), (len(radii), 1)),
                opacity=opacity,
                wireframe=kind == "planned" and executed,
                lod="off",
            )
            caps = self._add(
                f"/{kind}/joints",
                s.scene.add_batched_meshes_simple,
                sph[0],
                sph[1],
                batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (2 * len(radii), 1)),
                batched_positions=b.cap_positions,
                batched_scales=b.cap_scales,
                batched_colors=np.tile(np.array(rgb, dtype=np.uint8), (2 * len(radii), 1)),
                opacity=opacity,
                wireframe=kind == "planned" and executed,
                lod="off",
            )
            nodes = _RobotNodes(links, caps, rgb=rgb)
            nodes.tip = self._add(
                f"/{kind}/tip",
                s.scene.add_icosphere,
                radius=MIN_MARK_M,
                color=rgb,
                position=robot.tip(q0)[0],
            )
            if model is not None:
                from viser.extras import ViserUrdf

                T = np.asarray(robot.T_world_base, dtype=float)
                self._add(
                    f"/{kind}/meshes",
                    s.scene.add_frame,
                    show_axes=False,
                    position=T[:3, 3],
                    wxyz=matrix_to_wxyz(T[:3, :3]),
                )
                alpha = 1.0 if opacity is None else opacity
                color = (rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, alpha)
                nodes.urdf = ViserUrdf(
                    s, model, root_node_name=f"/{kind}/meshes", mesh_color_override=color
                )
                nodes.model = model
            self._robots[kind] = nodes
        self._draw_gui(executed, model is not None)
        self._show_leg(0)

    def _draw_goals(self) -> None:
        s = self.server
        span = motion_span(self.problem, self.legs)
        for i, g in enumerate(self.problem.goals):
            r = max(float(g.pos_tol_m), MIN_MARK_M)
            self._add(
                f"/goals/{i}/ball",
                s.scene.add_icosphere,
                radius=r,
                color=GOAL_RGB,
                opacity=0.35,
                position=g.p_world_m,
            )
            v, f = cone_mesh(g.p_world_m, g.n_world, float(g.angle_tol_deg), 0.06 * span)
            self._add(
                f"/goals/{i}/cone",
                s.scene.add_mesh_simple,
                v,
                f,
                color=GOAL_RGB,
                opacity=0.25,
                side="double",
            )
            self._add(
                f"/goals/{i}/label", s.scene.add_label, f"goal {g.name}", position=g.p_world_m
            )

    def _draw_gui(self, executed: bool, meshes: bool) -> None:
        s = self.server
        plan = self.plan
        s.gui.configure_theme(control_width="large")
        s.gui.add_markdown(f"**{plan.planner}** on **{plan.problem}** (seed {plan.seed})")
        planned = "planned (wireframe)" if executed else "planned"
        legend = [f"<span style='color:{hex_colour(PLANNED_RGB)}'>&#9632;</span> {planned}"]
        if executed:
            legend.append(
                f"<span style='color:{hex_colour(EXECUTED_RGB)}'>&#9632;</span> "
                "executed in PyBullet"
            )
            legend.append(
                f"<span style='color:{hex_colour(CONTACT_RGB)}'>&#9679;</span> contact "
                "(where the execution recorded one)"
            )
        legend += [
            f"<span style='color:{hex_colour(GOAL_RGB)}'>&#9632;</span> goal: ball = position "
            "tolerance, cone = normal's angle tolerance",
            f"nearest link: red touching &rarr; green &ge; {CLEAR_AT_M * 1000:.0f} mm clearance",
        ]
        s.gui.add_html("<div style='font-size:0.8em'>" + "<br>".join(legend) + "</div>")
        options = tuple(_leg_label(m) for m in self.legs)
        self.leg_dropdown = s.gui.add_dropdown("leg", options, initial_value=options[0])
        self.slider = s.gui.add_slider(
            "frame", min=0, max=max(self.legs[0].frames - 1, 1), step=1, initial_value=0
        )
        self.play_button = s.gui.add_button("Play")
        self.info = s.gui.add_markdown("")
        self.checks = {
            "planned": s.gui.add_checkbox("planned robot", True),
            "traces": s.gui.add_checkbox("tip traces", True),
            "goals": s.gui.add_checkbox("goal regions", True),
            "scene": s.gui.add_checkbox("scene", True),
        }
        if executed:
            self.checks["executed"] = s.gui.add_checkbox("executed robot", True)
        if meshes:
            self.checks["meshes"] = s.gui.add_checkbox("visual meshes", True)
        for note in self.notes:
            s.gui.add_markdown(f"<small>{note}</small>")

        @self.leg_dropdown.on_update
        def _(_event: Any) -> None:
            self._show_leg(options.index(self.leg_dropdown.value))

        @self.slider.on_update
        def _(_event: Any) -> None:
            self._show_frame(int(self.slider.value))

        @self.play_button.on_click
        def _(_event: Any) -> None:
            if self._playing.is_set():
                self.pause()
            else:
                self.play()

        for check in self.checks.values():
            check.on_update(lambda _e: self._apply_visibility())

    def _apply_visibility(self) -> None:
        c = {k: v.value for k, v in self.checks.items()}
        meshes = c.get("meshes", False)
        for kind, nodes in self._robots.items():
            on = c.get(kind, True)
            nodes.links.visible = on and not meshes
            nodes.caps.visible = on and not meshes
            nodes.tip.visible = on
            if nodes.urdf is not None:
                nodes.urdf.show_visual = on and meshes
        for node in self._trace_nodes:
            node.visible = c["traces"]
        for node in self._goal_nodes():
            node.visible = c["goals"]
        for node in self._scene_nodes():
            node.visible = c["scene"]

    def _goal_nodes(self) -> list[Any]:
        return [h for n, h in self._nodes.items() if n.startswith("/goals/")]

    def _scene_nodes(self) -> list[Any]:
        return [h for n, h in self._nodes.items() if n.startswith("/scene/")]

    def _add(self, name: str, make: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """Add a scene node (replacing one of that name) and remember its handle."""
        old = self._nodes.pop(name, None)
        if old is not None:
            old.remove()
        handle = make(name, *args, **kwargs)
        self._nodes[name] = handle
        return handle

    def _remove(self, prefix: str) -> None:
        for name in sorted((n for n in self._nodes if n.startswith(prefix)), reverse=True):
            self._nodes.pop(name).remove()

    # -------------------------------------------------------------------- frames
    def _show_leg(self, i: int) -> None:
        with self._lock:
            self._leg = i
            m = self.legs[i]
            s = self.server
            self._remove("/traces/")
            traces = [("planned", m.tips_planned, PLANNED_RGB)]
            if m.tips_executed is not None:
                traces.append(("executed", m.tips_executed, EXECUTED_RGB))
            self._trace_nodes = [
                self._add(
                    f"/traces/{kind}",
                    s.scene.add_line_segments,
                    polyline_segments(tips),
                    rgb,
                    thickness=3.0,
                    thickness_units="screen",
                )
                for kind, tips, rgb in traces
            ]
            self._remove("/contacts/")
            for k, c in enumerate(m.contacts):
                r = max(float(c.max_depth_m), MIN_MARK_M)
                self._add(
                    f"/contacts/{k}",
                    s.scene.add_icosphere,
                    radius=r,
                    color=CONTACT_RGB,
                    position=c.p_world_m,
                )
                self._add(
                    f"/contacts/{k}/label",
                    s.scene.add_label,
                    f"{c.link_name} - {c.other_name}: {c.max_depth_m * 1000:.1f} mm at "
                    f"{c.first_time_s:.2f} s",
                    position=(0.0, 0.0, 0.0),
                )
            for g, h in self._nodes.items():  # the leg's goal stands out
                if g.startswith("/goals/") and g.endswith("/ball"):
                    h.opacity = 0.6 if g == f"/goals/{i}/ball" else 0.2
            if self.slider.max != max(m.frames - 1, 1):
                self.slider.max = max(m.frames - 1, 1)
            if self.leg_dropdown.value != _leg_label(m):
                self.leg_dropdown.value = _leg_label(m)  # type: ignore[misc]
            if self.slider.value != 0:
                self.slider.value = 0  # type: ignore[misc]  # calls _show_frame
            else:
                self._show_frame(0)
            self._apply_visibility()

    def _link_clearance(self, kind: str, k: int, q: Array) -> tuple[Array, Sequence[str]] | None:
        if self.clearance is None:
            return None
        key = (self._leg, k, kind)
        if key not in self._cache:
            self._cache[key] = self.clearance(q)
        return self._cache[key]

    def _show_frame(self, k: int) -> None:
        with self._lock:
            m = self.legs[self._leg]
            k = int(np.clip(k, 0, m.frames - 1))
            robot = self.problem.robot
            lines = [f"t = {m.t_s[k]:.2f} s, frame {k + 1} of {m.frames}"]
            states = {"planned": m.q_planned[k]}
            if m.q_executed is not None:
                states["executed"] = m.q_executed[k]
            with self.server.atomic():
                for kind, nodes in self._robots.items():
                    q = states.get(kind)
                    if q is None:  # this leg was not executed
                        q = m.q_planned[k]
                    b = capsule_batch(robot.link_segments(q), self._radii)
                    colors = np.tile(np.array(nodes.rgb, dtype=np.uint8), (len(self._radii), 1))
                    cl = self._link_clearance(kind, k, q) if kind in states else None
                    if cl is not None:
                        d, other = cl
                        d = np.asarray(d, dtype=float)
                        if np.any(np.isfinite(d)):
                            j = int(np.nanargmin(np.where(np.isfinite(d), d, np.inf)))
                            colors[j] = clearance_rgb(float(d[j]))
                            lines.append(
                                f"{kind}: nearest link {robot.link_names[j]} to "
                                f"{other[j]}: {d[j] * 1000:.1f} mm"
                            )
                    nodes.links.batched_positions = b.cyl_positions
                    nodes.links.batched_wxyzs = b.cyl_wxyzs
                    nodes.links.batched_scales = b.cyl_scales
                    nodes.links.batched_colors = colors
                    nodes.caps.batched_positions = b.cap_positions
                    nodes.caps.batched_colors = np.concatenate([colors, colors])
                    nodes.tip.position = robot.tip(q)[0]
                    if nodes.urdf is not None:
                        nodes.urdf.update_cfg(urdf_cfg(robot, nodes.model, q))
            if m.q_executed is not None:
                lines.append(f"leg {m.leg} '{m.goal}': {m.status}; {m.verdict}")
            else:
                lines.append(f"leg {m.leg} '{m.goal}': {m.status}; not executed")
            lines.append(m.quality)
            self.info.content = "  \n".join(lines)

    # ------------------------------------------------------------------- playing
    def play(self) -> None:
        """Play the timeline from the current frame (on to the next legs)."""
        self._playing.set()
        self.play_button.label = "Pause"

    def pause(self) -> None:
        self._playing.clear()
        self.play_button.label = "Play"

    def _play_loop(self) -> None:
        while not self._stop.is_set():
            if not self._playing.wait(timeout=0.2):
                continue
            t0 = time.monotonic()
            with self._lock:
                k = int(self.slider.value)
                m = self.legs[self._leg]
                if k + 1 < m.frames:
                    self.slider.value = k + 1  # type: ignore[misc]
                elif self._leg + 1 < len(self.legs):
                    self._show_leg(self._leg + 1)
                else:
                    self.pause()
            self._stop.wait(max(1.0 / self.fps - (time.monotonic() - t0), 0.0))

    # -------------------------------------------------------------------- status
    @property
    def scene_nodes(self) -> list[str]:
        """The names of the scene nodes the server holds (and sends every client)."""
        return sorted(self._nodes)

    @property
    def clients(self) -> int:
        """Browsers connected now."""
        return len(self.server.get_clients())

    def wait_for_client(self, timeout_s: float) -> bool:
        """Wait (at most ``timeout_s``) until a browser is connected."""
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if self.clients:
                return True
            time.sleep(0.05)
        return bool(self.clients)

    def close(self) -> None:
        """Stop playing and the server (idempotent)."""
        self._stop.set()
        self._playing.clear()
        logging.getLogger("yourdfpy.urdf").removeFilter(self._quiet)
        with contextlib.redirect_stdout(io.StringIO()):  # viser says "Server stopped"
            self.server.stop()

    def _repr_html_(self) -> str:
        """In a notebook: the live page in an iframe."""
        return (
            f'<iframe src="{self.url}" width="100%" height="520" '
            'style="border:1px solid #ddd"></iframe>'
        )

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


@dataclass
class _RobotNodes:
    """The scene nodes of one drawn robot (planned or executed): its links' cylinders and
    caps, its tip, its colour, and a URDF's visual meshes with their model (or None)."""

    links: Any
    caps: Any
    tip: Any = None
    rgb: tuple[int, int, int] = (0, 0, 0)
    urdf: Any = None
    model: Any = None


class _QuietMimic(logging.Filter):
    """Drops yourdfpy's per-pose warning about a mimic joint whose joint is not actuated."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "is supposed to mimic" not in record.getMessage()


def _node(name: str) -> str:
    """A scene-node name from an obstacle name (no slashes)."""
    return name.replace("/", "_") or "_"


def _leg_label(m: LegMotion) -> str:
    return f"{m.leg}: {m.goal} ({m.status})"


def serve(
    problem: Problem,
    plan: Any,
    executions: Sequence[Any] = (),
    **kwargs: Any,
) -> Viewer:
    """Start a :class:`Viewer` (keyword arguments as its) with the camera framing the
    motion; returns at once (the server runs in background threads)."""
    viewer = Viewer(problem, plan, executions, **kwargs)
    position, look_at = camera_pose(problem, viewer.legs)
    viewer.server.initial_camera.position = tuple(position)
    viewer.server.initial_camera.look_at = tuple(look_at)
    return viewer


def serve_robot(robot: Any, *, host: str = "127.0.0.1", port: int = 8080) -> Any:
    """Serve a 3-D view of a robot's collision model at its zero state (every joint at 0,
    clipped into its limits): each link's capsules, spheres and capsules of the mesh
    covers coloured per URDF link; returns the :class:`viser.ViserServer` (stop it with
    ``.stop()``). A port in use raises :class:`~plannerlab.errors.PlannerlabError`."""
    if port and not port_free(host, int(port)):
        raise PlannerlabError(f"--port {port}: {host}:{port} is in use; give another --port")
    import viser

    with contextlib.redirect_stdout(io.StringIO()):  # viser's banner
        server = viser.ViserServer(host=host, port=int(port), verbose=False)
    server.scene.set_up_direction("+z")
    q0 = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
    seg = np.asarray(robot.link_segments(q0), dtype=float)
    radii = np.asarray(robot.link_radii_m, dtype=float)
    names = list(getattr(robot, "link_urdf_names", robot.link_names))
    palette = np.array(
        [
            [31, 119, 180],
            [255, 127, 14],
            [44, 160, 44],
            [214, 39, 40],
            [148, 103, 189],
            [140, 86, 75],
            [227, 119, 194],
            [127, 127, 127],
            [188, 189, 34],
            [23, 190, 207],
        ],
        dtype=np.uint8,
    )
    order = {n: i for i, n in enumerate(dict.fromkeys(names))}
    colours = palette[[order[n] % len(palette) for n in names]]
    b = capsule_batch(seg, radii)
    cyl, sph = unit_cylinder(), unit_sphere()
    server.scene.add_batched_meshes_simple(
        "/robot/links",
        cyl[0],
        cyl[1],
        batched_wxyzs=b.cyl_wxyzs,
        batched_positions=b.cyl_positions,
        batched_scales=b.cyl_scales,
        batched_colors=colours,
        lod="off",
    )
    server.scene.add_batched_meshes_simple(
        "/robot/ends",
        sph[0],
        sph[1],
        batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (2 * len(radii), 1)),
        batched_positions=b.cap_positions,
        batched_scales=b.cap_scales,
        batched_colors=np.concatenate([colours, colours]),
        lod="off",
    )
    span = float(np.ptp(seg.reshape(-1, 3), axis=0).max()) + 2 * float(radii.max())
    server.initial_camera.position = tuple(seg.reshape(-1, 3).mean(axis=0) + [span, span, span])
    server.initial_camera.look_at = tuple(seg.reshape(-1, 3).mean(axis=0))
    return server


__all__ = ["Viewer", "serve", "serve_robot"]

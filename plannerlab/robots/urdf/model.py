"""Any serial chain read from a URDF: kinematics, Jacobians and collision geometry.

The URDF is read with ``yourdfpy`` (parsing only: no meshes are loaded). The chain runs
from the URDF's root link to ``tip_link``; its movable joints (revolute, continuous,
prismatic) are the robot's joints, in chain order. Fixed joints are folded into the
transforms between them. A movable joint *off* that chain (a gripper finger, say) is
frozen at 0 (clipped into its limits) and listed in :attr:`UrdfChain.frozen_joints`; the
URDF given to the simulator has it fixed there.

Bodies and frames
-----------------
Body 0 is the root link; body ``i`` (1 … dof) is the child link of the ``i``-th movable
joint, and every link hung on a body by fixed (or frozen) joints moves with it.
:meth:`UrdfChain.fk` returns the frames of the ``dof + 1`` bodies and then the tip link's
frame (``dof + 2`` frames; :attr:`UrdfChain.link_frame_names` names their URDF links).
The tip is the point ``tip_offset_m`` of the tip link's frame and its normal the unit
vector ``tip_axis`` of that frame.

Collision geometry
------------------
Every ``<collision>`` element becomes one capsule (a plannerlab "link", named
``<urdf link>`` or ``<urdf link>#k`` when the link has several):

* a sphere: a capsule of zero length (exact);
* a cylinder: the capsule along its axis with the cylinder's radius and length
  (it covers the cylinder; the rounded ends stick out by one radius);
* a box: the capsule along its longest edge, radius the half-diagonal of the other two
  (covers the box, conservative);
* a mesh (STL, OBJ, DAE; ``package://``, ``file://`` or a path relative to the URDF,
  searched as :func:`~plannerlab.robots.urdf.meshes.resolve_mesh` says): a conservative
  cover of at most ``cover_max_primitives`` capsules
  (:func:`~plannerlab.robots.urdf.meshes.mesh_cover`: every vertex and a dense surface
  sample inside, outward excess aimed at ``cover_excess_m`` (at most 3 % of the mesh's
  size) and coarser when the budget needs it, measured and reported, cached on disk; a
  ``covers/`` folder beside the URDF may ship them, read-only: ``SHIPPED_COVERS``);
  :attr:`UrdfChain.mesh_covers` reports each. The simulator is given the meshes
  themselves (:meth:`UrdfChain.urdf`): verdicts are measured on the real geometry.

A link that moves and has no ``<collision>`` is never checked; :attr:`UrdfChain.notes`
names every such link (and logs a warning).

Capsules on the root body are fixed (never checked against the scene). Self-collision
is not checked between capsules on one body, between capsules of neighbouring bodies
(parent and child of a movable joint), nor between links named in the SRDF's
``<disable_collisions>`` or in the problem's allowed-collision pairs.

Self-collision at the meshes' accuracy
--------------------------------------
A cover within the budget may reach 1-3 cm outside its mesh: fine against the scene (the
margin is of that order), too fat between links that pass within millimetres of each
other (a UR10's wrists: 2 % of random states free on its 32-capsule covers, 53 % on its
meshes). So each mesh can also get a **second, finer cover** (``self_cover_excess_m``,
default 4 mm, at most ``self_cover_max_primitives`` capsules, 128 asked; the same algorithm,
cached alike; it holds the mesh's convex hull, the solid PyBullet checks for a link's
mesh, so that a state the finer cover passes is free in execution and for the referee)
that judges self-collision only: its capsules (:attr:`UrdfChain.
self_only_links`, named ``<link>#s<k>``, after the link's first-cover capsules) are never
checked against the scene, and the first cover's capsules of that mesh (:attr:`UrdfChain.
scene_only_links`) never against other links. The finer covers are not grown by the
problem's clearance margin (which keeps the robot off the scene): links built to pass
within a centimetre of each other (a UR10's wrist 1 and wrist 3, its forearm and wrist
2, its base and upper arm) would otherwise collide in every state. Where the finer
cover is no finer (a small mesh whose first cover is already within it) the first
cover does both. Both covers
hold the mesh, so either verdict is conservative. The compiled state test reaches the
finer capsules only through its gates: a ball per body, then (a body of 33 or more
capsules of one role) a ball per group of at most 16 neighbouring capsules, then per
cluster of four (``collision/model.py``): a pair of links far apart costs one ball test,
a pair of links near each other opens only the group pairs that meet.

**It is on by default** (``self_cover_max_primitives = 128``; ``0`` asks for none: the
first cover then judges self-collision too). It used to be opt-in for three costs, each
since cut: the state test (the group level of gates: 2.5x the first covers' on the UR10,
4.3x on the Kinova), the metric edge bound (``collision/reach.py`` summed a mesh link of
128 capsules as a chain of 128 links, 83-171x the fastest point seen on the UR10; per rigid
body now, 1.0-1.3x) and the path clearance measure (``collision/kernels.
min_clearance_kernel``, a box gap for every capsule pair a state; gated per body pair
now). A robot whose links pass within millimetres of each other needs them: the UR10 (4 %
of random states free on the first covers, 25.7 % with the finer ones, 53 % on its
meshes) had no valid start state on its first covers (results/mesh_robots.md). The first
load of a robot computes them (minutes for a large arm; cached, or shipped in
``covers/``).

Only numpy (``yourdfpy`` for parsing, ``trimesh`` for meshes) is used here.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array
from plannerlab.robots.urdf.errors import UrdfError
from plannerlab.robots.urdf.meshes import CoverSettings, MeshCover
from plannerlab.robots.urdf.pairs import excluded_pairs, read_srdf_disabled
from plannerlab.robots.urdf.tree import (  # noqa: F401  (MOVABLE, axis_motion: re-exported)
    MOVABLE,
    _chain,
    _joint_axis,
    _joint_limits,
    _load_urdf,
    _origin,
    _place_links,
    _Tree,
    axis_motion,
)

#: the folder beside a URDF that may ship its meshes' covers (cache files, read-only): a
#: robot bundled with its covers loads at once on a new machine
SHIPPED_COVERS = "covers"
_LOG = logging.getLogger(__name__)


@dataclass(frozen=True)
class _Capsules:
    """Per capsule: its name, its URDF link, its body, its axis end points a, b in the
    body's frame [m] and its radius [m]."""

    names: list[str]
    link: list[str]
    body: list[int]
    a: list[Array]
    b: list[Array]
    radii: list[float]


def _report(lname: str, file: Path, sc: Any) -> MeshCover:
    return MeshCover(
        lname,
        str(file),
        sc.count,
        sc.capsules,
        sc.max_excess_m,
        sc.target_excess_m,
        sc.points_verified,
        sc.solid,
        sc.cached,
    )


@dataclass(frozen=True)
class _Tiers:
    """The second, finer cover of the meshes (self-collision only): the capsules (after
    the first cover's in the chain's list) and which capsules play one role only."""

    scene_only: frozenset[int]  # first-cover capsules of a mesh that has a finer cover
    self_only: frozenset[int]  # the finer covers' capsules
    reports: tuple[MeshCover, ...]


def _capsules(
    tree: _Tree,
    placed: dict[str, tuple[int, Array]],
    path: Path,
    cover: CoverSettings,
    self_cover: tuple[float, int] | None = None,
) -> tuple[_Capsules, list[MeshCover], dict[str, Path], _Tiers]:
    """One capsule per primitive ``<collision>`` element and a sphere cover per mesh (see
    the module docstring); the covers' reports and every collision mesh's file. With
    ``self_cover`` (excess aimed at [m], most primitives), each mesh also gets a finer
    cover for self-collision, kept where it is finer than the first (its capsules named
    ``<link>#s<k>``, listed after the link's first-cover capsules)."""
    from plannerlab.robots.urdf.meshes import MeshError, mesh_cover, resolve_mesh

    caps = _Capsules([], [], [], [], [], [])
    reports: list[MeshCover] = []
    fine_reports: list[MeshCover] = []
    mesh_files: dict[str, Path] = {}
    scene_only: list[int] = []
    self_only: list[int] = []
    fine: list[tuple[str, int, Array, Array, float]] = []  # link, body, a, b, radius
    for lname, link in tree.links.items():
        b, T_link = placed[lname]
        cols = list(link.collisions)
        pieces: list[tuple[Array, Array, float]] = []  # per capsule: a, b, radius (body)
        coarse_of_fine: list[int] = []  # pieces (indices) whose mesh has a finer cover
        for col in cols:
            T = T_link @ (np.eye(4) if col.origin is None else np.asarray(col.origin, float))
            g = col.geometry
            if g.mesh is not None:
                where = f"link {lname} of {path.name}"
                try:
                    file = resolve_mesh(str(g.mesh.filename), path, cover.mesh_paths, where)
                    scale = np.ones(3) if g.mesh.scale is None else np.asarray(g.mesh.scale, float)
                    sc = mesh_cover(
                        file,
                        scale,
                        cover.excess_m,
                        cover.max_primitives,
                        where,
                        cover.cache_dir,
                        cover.shipped_dirs,
                    )
                    fc = None
                    if self_cover is not None:
                        fc = mesh_cover(
                            file,
                            scale,
                            self_cover[0],
                            self_cover[1],
                            where,
                            cover.cache_dir,
                            cover.shipped_dirs,
                            hull=True,
                        )
                except MeshError as exc:
                    raise UrdfError("urdf", str(exc)) from None
                mesh_files[str(g.mesh.filename)] = file
                reports.append(_report(lname, file, sc))
                A = sc.a_m @ T[:3, :3].T + T[:3, 3]
                B = sc.b_m @ T[:3, :3].T + T[:3, 3]
                first = len(pieces)
                for ea, eb, r in zip(A, B, sc.radii_m, strict=True):
                    pieces.append((ea, eb, float(r)))
                if fc is not None and fc.max_excess_m < sc.max_excess_m:
                    fine_reports.append(_report(lname, file, fc))
                    coarse_of_fine.extend(range(first, len(pieces)))
                    A = fc.a_m @ T[:3, :3].T + T[:3, 3]
                    B = fc.b_m @ T[:3, :3].T + T[:3, 3]
                    for ea, eb, r in zip(A, B, fc.radii_m, strict=True):
                        fine.append((lname, b, ea, eb, float(r)))
                continue
            if g.sphere is not None:
                r, half = float(g.sphere.radius), np.zeros(3)
            elif g.cylinder is not None:
                r = float(g.cylinder.radius)
                half = np.array([0.0, 0.0, float(g.cylinder.length) / 2.0])
            elif g.box is not None:
                h = np.asarray(g.box.size, dtype=float) / 2.0
                a = int(np.argmax(h))
                others = np.delete(h, a)
                r = float(np.linalg.norm(others))
                half = np.zeros(3)
                half[a] = h[a]
            else:
                raise UrdfError(
                    "urdf",
                    f"collision geometry a sphere, cylinder, box or mesh; link {lname} of "
                    f"{path.name} has none of them in a <collision>",
                )
            mid = T[:3, 3]
            d = T[:3, :3] @ half
            pieces.append((mid - d, mid + d, r))
        for k, (end_a, end_b, rad) in enumerate(pieces):
            if k in coarse_of_fine:
                scene_only.append(len(caps.names))
            caps.names.append(lname if len(pieces) == 1 else f"{lname}#{k}")
            caps.link.append(lname)
            caps.body.append(b)
            caps.a.append(end_a)
            caps.b.append(end_b)
            caps.radii.append(rad)
        # the link's finer capsules right after its first ones: a URDF link's capsules
        # stay one run (the simulator's measures group them so)
        for k, (_, _, end_a, end_b, rad) in enumerate(fine):
            self_only.append(len(caps.names))
            caps.names.append(f"{lname}#s{k}")
            caps.link.append(lname)
            caps.body.append(b)
            caps.a.append(end_a)
            caps.b.append(end_b)
            caps.radii.append(rad)
        fine.clear()
    if not caps.names:
        raise UrdfError("urdf", f"collision elements; {path.name} has none")
    tiers = _Tiers(frozenset(scene_only), frozenset(self_only), tuple(fine_reports))
    return caps, reports, mesh_files, tiers


def _frozen_array(a: Any, dtype: Any = float) -> Any:
    out = np.array(a, dtype=dtype)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class UrdfChain:
    """A serial chain from a URDF file (implements :class:`plannerlab.robots.base.Robot`).

    Args:
        urdf_path: the URDF file.
        tip_link: the URDF link carrying the tip (the chain ends there).
        tip_axis: (3,) the tip normal in the tip link's frame (normalised here).
        tip_offset_m: (3,) the tip point in the tip link's frame [m].
        srdf_path: an SRDF whose ``disable_collisions`` pairs are not checked, or None.
        allowed_collisions: more URDF link pairs that are not checked.
        T_world_base: (4, 4) pose of the root link in the world.
        mesh_paths: folders searched for ``package://`` mesh paths (see
            :mod:`plannerlab.robots.urdf.meshes`).
        cover_excess_m: the outward excess aimed at for a mesh's cover [m] (at most 3 %
            of the mesh's size; coarser when ``cover_max_primitives`` needs it).
        cover_max_primitives: the most capsules covering one mesh.
        self_cover_excess_m, self_cover_max_primitives: the second, finer cover of each
            mesh, judging self-collision only (the first one judges the scene): the
            excess aimed at [m] and the most capsules (128, the default; 0: no second
            cover, the first judges both).
        cover_cache: keep covers on disk; ``cover_cache_dir`` (None:
            ``~/.cache/plannerlab/covers``).
        sim_urdf_path: the robot's real geometry for the simulator: a URDF with the same
            joints and links (its collision meshes, say, where ``urdf_path`` is a
            spherized copy); PyBullet loads it instead, so execution verdicts are
            measured on it. None: ``urdf_path`` itself.
    """

    urdf_path: Path
    tip_link: str
    tip_axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    tip_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    srdf_path: Path | None = None
    allowed_collisions: tuple[tuple[str, str], ...] = ()
    T_world_base: Array = field(default_factory=lambda: np.eye(4))
    mesh_paths: tuple[Path, ...] = ()
    cover_excess_m: float = 0.01
    cover_max_primitives: int = 32
    self_cover_excess_m: float = 0.004
    self_cover_max_primitives: int = 128
    cover_cache: bool = True
    cover_cache_dir: Path | None = None
    sim_urdf_path: Path | None = None

    kind: str = field(default="urdf", init=False)
    dof: int = field(init=False)
    joint_names: tuple[str, ...] = field(init=False)
    link_names: tuple[str, ...] = field(init=False)
    lower: Array = field(init=False, repr=False)
    upper: Array = field(init=False, repr=False)
    continuous: NDArray[np.bool_] = field(init=False, repr=False)
    link_radii_m: Array = field(init=False, repr=False)
    fixed_links: frozenset[int] = field(init=False, repr=False)
    excluded_pairs: frozenset[tuple[int, int]] = field(init=False, repr=False)
    #: movable joints off the chain, frozen at the value given (URDF joint name -> value)
    frozen_joints: dict[str, float] = field(init=False, repr=False)
    #: the URDF link of each capsule (the simulator's link of each plannerlab link)
    link_urdf_names: tuple[str, ...] = field(init=False, repr=False)
    #: an upper bound of the tip's distance from the root link's origin [m]
    max_reach_m: float = field(init=False, repr=False)
    #: how each collision mesh became capsules (empty for a URDF of primitives)
    mesh_covers: tuple[MeshCover, ...] = field(init=False, repr=False)
    #: the finer covers judging self-collision (one per mesh where finer than the first)
    self_covers: tuple[MeshCover, ...] = field(init=False, repr=False)
    #: capsules never checked against each other (a mesh's first cover where a finer one
    #: judges self-collision): checked against the scene only
    scene_only_links: frozenset[int] = field(init=False, repr=False)
    #: capsules never checked against the scene (the finer covers): self-collision only
    self_only_links: frozenset[int] = field(init=False, repr=False)
    #: links that move (not on the root body) and have no collision geometry
    links_without_geometry: tuple[str, ...] = field(init=False, repr=False)
    #: warnings about the model, in words (also logged)
    notes: tuple[str, ...] = field(init=False, repr=False)
    _mesh_files: dict[str, Path] = field(init=False, repr=False)
    _sim_mesh_files: dict[str, Path] = field(init=False, repr=False)
    # the chain's fixed data (see __post_init__)
    _body_links: tuple[str, ...] = field(init=False, repr=False)
    _parent_body: Any = field(init=False, repr=False)
    _pre: Any = field(init=False, repr=False)
    _axes: Any = field(init=False, repr=False)
    _prismatic: tuple[bool, ...] = field(init=False, repr=False)
    _tip_body: int = field(init=False, repr=False)
    _T_body_tip: Any = field(init=False, repr=False)
    _n_body_tip: Any = field(init=False, repr=False)
    _cap_body: Any = field(init=False, repr=False)
    _cap_a: Any = field(init=False, repr=False)
    _cap_b: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        """Read the URDF and fold it into the chain's fixed data (see the module
        docstring): the chain, each link's place on its body, the joints, the tip, the
        capsules and the pairs never checked."""
        path = Path(self.urdf_path)
        object.__setattr__(self, "urdf_path", path)
        tree = _chain(_load_urdf(path), self.tip_link, path)
        placed = _place_links(tree)
        # movable joint i: its parent body and the fixed transform to the joint frame
        parent_body, pre, axes, prismatic = [], [], [], []
        lower, upper, cont = [], [], []
        for j in tree.movable:
            b, T = placed[j.parent]
            parent_body.append(b)
            pre.append(T @ _origin(j))
            axes.append(_joint_axis(j))
            prismatic.append(j.type == "prismatic")
            lo, hi = _joint_limits(j)
            lower.append(lo)
            upper.append(hi)
            cont.append(j.type == "continuous")
        dof = len(tree.movable)
        if dof == 0:
            raise UrdfError(
                "tip_link",
                f"a link with movable joints between it and {tree.root}; {self.tip_link}",
            )
        tip_body, T_body_tip = placed[self.tip_link]
        T_body_tip = T_body_tip.copy()
        T_body_tip[:3, 3] = T_body_tip[:3, :3] @ np.asarray(self.tip_offset_m) + T_body_tip[:3, 3]
        tip_axis = np.asarray(self.tip_axis, dtype=float)
        norm = float(np.linalg.norm(tip_axis))
        if not (norm > 1e-9 and math.isfinite(norm)):
            raise UrdfError("tip_axis", f"a non-zero axis, got {list(self.tip_axis)}")
        R_body_tip = T_body_tip[:3, :3] @ (tip_axis / norm)
        from plannerlab.robots.urdf.meshes import default_cache_dir

        settings = CoverSettings(
            tuple(Path(p) for p in self.mesh_paths),
            float(self.cover_excess_m),
            int(self.cover_max_primitives),
            (
                None
                if not self.cover_cache
                else Path(self.cover_cache_dir)
                if self.cover_cache_dir is not None
                else default_cache_dir()
            ),
            (path.resolve().parent / SHIPPED_COVERS,),
        )
        n_fine = int(self.self_cover_max_primitives)
        if n_fine < 0 or not (self.self_cover_excess_m > 0):
            raise UrdfError(
                "self_cover_max_primitives",
                f"at least 0 primitives and a positive self_cover_excess_m; got {n_fine}, "
                f"{self.self_cover_excess_m}",
            )
        caps, covers, mesh_files, tiers = _capsules(
            tree,
            placed,
            path,
            settings,
            (float(self.self_cover_excess_m), n_fine) if n_fine > 0 else None,
        )
        bare = [n for n, link in tree.links.items() if placed[n][0] > 0 and not link.collisions]
        notes = []
        if bare:
            shown = [n + (" (it has a visual)" if tree.links[n].visuals else "") for n in bare]
            notes.append(
                f"{path.name}: {len(bare)} moving link(s) without collision geometry, never "
                f"checked: {', '.join(shown)}"
            )
        for note in notes:
            _LOG.warning(note)
        excluded = excluded_pairs(
            caps, parent_body, tree.links, self.srdf_path, self.allowed_collisions, path
        )
        T_wb = np.array(self.T_world_base, dtype=float)
        if T_wb.shape != (4, 4) or not np.all(np.isfinite(T_wb)):
            raise UrdfError("base_rpy_deg", "a finite base pose")
        reach = sum(float(np.linalg.norm(P[:3, 3])) for P in pre)
        reach += float(np.linalg.norm(T_body_tip[:3, 3]))
        reach += sum(
            max(abs(lo), abs(hi)) for lo, hi, p in zip(lower, upper, prismatic, strict=True) if p
        )

        frozen_array = _frozen_array
        L = len(caps.names)
        s = object.__setattr__
        s(self, "T_world_base", frozen_array(T_wb))
        s(self, "dof", dof)
        s(self, "joint_names", tuple(j.name for j in tree.movable))
        s(self, "link_names", tuple(caps.names))
        s(self, "link_urdf_names", tuple(caps.link))
        s(self, "lower", frozen_array(np.where(cont, -np.pi, lower)))
        s(self, "upper", frozen_array(np.where(cont, np.pi, upper)))
        s(self, "continuous", frozen_array(cont, bool))
        s(self, "link_radii_m", frozen_array(caps.radii))
        s(self, "fixed_links", frozenset(i for i in range(L) if caps.body[i] == 0))
        s(self, "excluded_pairs", frozenset(excluded))
        s(self, "frozen_joints", tree.frozen)
        s(self, "max_reach_m", float(reach))
        s(self, "mesh_covers", tuple(covers))
        s(self, "self_covers", tiers.reports)
        s(self, "scene_only_links", tiers.scene_only)
        s(self, "self_only_links", tiers.self_only)
        s(self, "links_without_geometry", tuple(bare))
        s(self, "notes", tuple(notes))
        s(self, "_mesh_files", mesh_files)
        s(self, "_body_links", (tree.root, *(j.child for j in tree.movable)))
        s(self, "_parent_body", np.array(parent_body, dtype=int))
        s(self, "_pre", frozen_array(pre))
        s(self, "_axes", frozen_array(axes))
        s(self, "_prismatic", tuple(prismatic))
        s(self, "_tip_body", int(tip_body))
        s(self, "_T_body_tip", frozen_array(T_body_tip))
        s(self, "_n_body_tip", frozen_array(R_body_tip))
        s(self, "_cap_body", np.array(caps.body, dtype=int))
        s(self, "_cap_a", frozen_array(caps.a))
        s(self, "_cap_b", frozen_array(caps.b))
        s(self, "_sim_mesh_files", self._check_sim_urdf(tree, settings))

    def _check_sim_urdf(self, tree: _Tree, cover: CoverSettings) -> dict[str, Path]:
        """The ``sim_urdf`` (the robot's real geometry for the simulator) checked: the
        chain's joints and links are in it, its collision meshes are found; their files
        by the name the URDF gives."""
        from plannerlab.robots.urdf.meshes import MeshError, resolve_mesh

        if self.sim_urdf_path is None:
            return {}
        path = Path(self.sim_urdf_path)
        object.__setattr__(self, "sim_urdf_path", path)
        try:
            sim = _load_urdf(path)
        except UrdfError as exc:
            raise UrdfError("sim_urdf", exc.expected) from None
        joints = {j.name for j in sim.joints}
        links = {link.name: link for link in sim.links}
        missing = [j for j in (*self.joint_names, *tree.frozen) if j not in joints]
        missing += [n for n in self.link_frame_names if n not in links]
        if missing:
            raise UrdfError(
                "sim_urdf",
                f"a URDF with the joints and links of {self.urdf_path.name}; {path.name} "
                f"lacks {', '.join(missing)}",
            )
        files: dict[str, Path] = {}
        for name, link in links.items():
            for col in link.collisions:
                if col.geometry.mesh is None:
                    continue
                fn = str(col.geometry.mesh.filename)
                try:
                    files[fn] = resolve_mesh(
                        fn, path, cover.mesh_paths, f"link {name} of {path.name}"
                    )
                except MeshError as exc:
                    raise UrdfError("sim_urdf", str(exc)) from None
        return files

    # ------------------------------------------------------------------ kinematics
    @property
    def link_frame_names(self) -> tuple[str, ...]:
        """URDF links of the ``fk`` frames: the root, each movable joint's child, the tip."""
        return (*self._body_links, self.tip_link)

    def _check_q(self, q: Array) -> Array:
        q = np.asarray(q, dtype=float)
        if q.shape[-1:] != (self.dof,) or q.ndim not in (1, 2):
            raise PlannerlabError(
                f"urdf robot: q must have shape ({self.dof},) or (k, {self.dof}), got {q.shape}"
            )
        return q

    def _bodies(self, q: Array) -> Array:
        """Body frames in the world (..., dof + 1, 4, 4)."""
        q = self._check_q(q)
        pre, axes, parent, prismatic = self._pre, self._axes, self._parent_body, self._prismatic
        frames = [np.broadcast_to(self.T_world_base, q.shape[:-1] + (4, 4))]
        for i in range(self.dof):
            M = axis_motion(axes[i], q[..., i], prismatic[i])
            frames.append(frames[parent[i]] @ pre[i] @ M)
        return np.stack(frames, axis=-3)

    def fk(self, q: Array) -> Array:
        """Frames ``T_world_frame`` of :attr:`link_frame_names`: (dof + 2, 4, 4) for q
        (dof,), (k, dof + 2, 4, 4) for (k, dof)."""
        B = self._bodies(q)
        tip = B[..., self._tip_body, :, :] @ self._T_body_tip
        return np.concatenate([B, tip[..., None, :, :]], axis=-3)

    def tip(self, q: Array) -> tuple[Array, Array]:
        """Tip position ``p_world`` [m] and unit normal ``n_world``: (3,) each, or (k, 3)."""
        B = self._bodies(q)
        Tb = B[..., self._tip_body, :, :]
        T_bt, n_b = self._T_body_tip, self._n_body_tip
        p = Tb[..., :3, :3] @ T_bt[:3, 3] + Tb[..., :3, 3]
        n = Tb[..., :3, :3] @ n_b
        return p, n

    def tip_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Analytic ``dp/dq`` and ``dn/dq`` (3, dof) each, world frame, at one q (dof,)."""
        q = self._check_q(q)
        if q.ndim != 1:
            raise PlannerlabError("urdf robot: tip_jacobian takes one q of shape (dof,)")
        B = self._bodies(q)
        p, n = self.tip(q)
        axes, prismatic = self._axes, self._prismatic
        Jp = np.zeros((3, self.dof))
        Jn = np.zeros((3, self.dof))
        # only the joints between the root and the tip body move the tip
        on_path = self._path_joints()
        for i in on_path:
            F = B[i + 1]
            w = F[:3, :3] @ axes[i]
            if prismatic[i]:
                Jp[:, i] = w
            else:
                Jp[:, i] = np.cross(w, p - F[:3, 3])
                Jn[:, i] = np.cross(w, n)
        return Jp, Jn

    def _path_joints(self) -> list[int]:
        parent = self._parent_body
        out = []
        b = int(self._tip_body)
        while b > 0:
            out.append(b - 1)
            b = int(parent[b - 1])
        return out

    def chain_data(self) -> tuple[Any, ...]:
        """The chain as plain arrays, for compiled kinematics
        (:mod:`plannerlab.collision.chain`): per movable joint its parent body (dof,), the
        fixed transform body -> joint frame (dof, 4, 4), the unit axis (dof, 3) and whether
        it slides (dof,); per capsule its body (L,) and its end points in that body's frame
        (L, 3) twice."""
        return (
            self._parent_body,
            self._pre,
            self._axes,
            np.array(self._prismatic, dtype=bool),
            self._cap_body,
            self._cap_a,
            self._cap_b,
        )

    def tip_data(self) -> tuple[int, Array, Array]:
        """The tip on the chain of :meth:`chain_data`, for compiled kinematics
        (:mod:`plannerlab.collision.chain_ik`): the body carrying it, the tip point (3,)
        and the unit tip normal (3,) in that body's frame."""
        return int(self._tip_body), self._T_body_tip[:3, 3].copy(), self._n_body_tip.copy()

    def link_segments(self, q: Array) -> Array:
        """Capsule axes in the world: (L, 2, 3) for one q, (k, L, 2, 3) for a batch.

        One matrix product per rigid body (its capsules' end points in its frame, turned
        and moved by its frame), not one per capsule: a mesh robot's ~1 000 capsules on 7
        bodies gathered a 4x4 frame per capsule and state before (``einsum`` over
        (k, L, 4, 4)), 0.3 s for 1 000 states of the UR10, most of an execution's
        measuring (``results/mesh_robots.md``, "UR10 execution")."""
        B = self._bodies(q)
        out = np.empty(B.shape[:-3] + (len(self._cap_body), 2, 3))
        for body, idx, ends in self._cap_groups():
            Fb = B[..., body, :, :]
            moved = ends @ np.swapaxes(Fb[..., :3, :3], -1, -2) + Fb[..., None, :3, 3]
            out[..., idx, :, :] = moved.reshape(moved.shape[:-2] + (len(idx), 2, 3))
        return out

    def _cap_groups(self) -> list[tuple[int, Array, Array]]:
        """Per body carrying capsules: (body, its capsules' indices (n,), their end points
        in its frame, a and b of each in turn (2n, 3)); computed once."""
        groups = self.__dict__.get("_cap_groups_cache")
        if groups is None:
            groups = []
            for body in np.unique(self._cap_body):
                idx = np.flatnonzero(self._cap_body == body)
                ends = np.stack([self._cap_a[idx], self._cap_b[idx]], axis=1).reshape(-1, 3)
                groups.append((int(body), idx, ends))
            object.__setattr__(self, "_cap_groups_cache", groups)
        return groups

    # ------------------------------------------------------------------ URDF
    def urdf(self) -> str:
        """The URDF text for the simulator (:func:`~plannerlab.robots.urdf.sim_text.
        simulator_urdf`): the file with its real collision meshes, paths made absolute,
        missing visuals left out, the frozen joints fixed at their value."""
        from plannerlab.robots.urdf.sim_text import simulator_urdf

        return simulator_urdf(self)


__all__ = [
    "CoverSettings",
    "MeshCover",
    "UrdfChain",
    "UrdfError",
    "axis_motion",
    "read_srdf_disabled",
]

"""The chord-arc solutions' motion check and motion sequence.

**Contact types** (the paper's Fig. 3, our reading). At a contact the obstacle lies on one
side of the robot, ``side = +1`` on the robot's right (the direction positive θ bends
toward), ``-1`` on its left. Changing the commanded curvature of the free part by ``Δκ``
moves a point at arc length s of a base-fixed arc sideways by ``(1 − cos κs)/κ² · Δκ``
toward the right, i.e. always toward the side that Δκ bends to. So the obstacle holds the
part before the contact (which then keeps its shape while only the part after it bends,
the paper's "support") exactly when the curvature change pushes the robot *into* it:

* **forward-constrained**: the obstacle is on the concave (inner) side of the arriving arc
  (``side·κ_in > 0``; a straight arrival counts here). It stops *further bending*: the
  robot wraps around it and the next arc must bend more toward it, ``side·(κ_out − κ_in)
  > 0``. Unbending would lift the robot off: both parts unbend as one section.
* **backward-constrained**: the obstacle is on the convex (outer) side
  (``side·κ_in < 0``). It stops *unbending*: the next arc must bend less (or the other
  way, an S shape), again ``side·(κ_out − κ_in) > 0``. Bending further would lift it off.

The search does not look at types (as in the paper); :func:`check_motion` drops the
solutions whose contacts do not hold, and keeps the reason. The same function also
checks the two motions that do not follow the final shape: the initial push (the arriving
arc extended along its own circle by ``l``, the paper's ``a = 1 + l/L``) and the re-bend
of those ``l`` metres from κ_in to κ_out. "Side" at a polygon vertex uses the direction
into the obstacle that bisects its corner.

**Motion sequence** (:class:`MotionStep`, every step a linear interpolation of the last
arc's (θ, L) from ``start_shape`` to ``end_shape``): follow the first arc (insert and bend
together, ``(aθ_1, aL_1)``, so the robot is always a prefix of the final shape); then per
contact: push by ``l = min(push_length_m, L_next/2)``, re-bend the pushed ``l`` to the next
curvature, follow the next arc (``a·θ`` with the curvature of the final shape) to the next
contact or the target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from plannerlab.planners.chord_arc.geometry import (
    ChordArcQuery,
    ChordArcSolution,
    Point,
    Shape,
)
from plannerlab.planners.chord_arc.search import (
    Prepared,
    SearchResult,
    prepare,
    sample_fractions,
    search_prepared,
)
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.robots.continuum.model import arc_points_local


@dataclass(frozen=True)
class ContactCheck:
    """How one contact of a solution behaves.

    Attributes:
        order: 1-based contact number from the port.
        point_index: index into the query's collision points.
        obstacle: name of the obstacle touched.
        side: +1 obstacle on the robot's right (toward positive θ), -1 on its left.
        contact_type: "forward" (obstacle on the concave side, blocks further bending) or
            "backward" (on the convex side, blocks unbending).
        kappa_in_per_m, kappa_out_per_m: curvature of the arcs before and after [1/m].
        ok: the contact holds the robot as its type requires (and push/re-bend are free).
        reason: empty when ok, else why not.
    """

    order: int
    point_index: int
    obstacle: str
    side: int
    contact_type: Literal["forward", "backward"]
    kappa_in_per_m: float
    kappa_out_per_m: float
    ok: bool
    reason: str = ""


@dataclass(frozen=True)
class MotionStep:
    """One motion: the last arc's (θ, L) goes linearly from ``start_shape`` to ``end_shape``.

    ``kind``: "follow" (insert and bend at constant curvature: the tip traces the final
    shape, the paper's ``a·θ``), "push" (extend the last arc along its circle, ``a = 1 +
    l/L``), "rebend" (the pushed part changes curvature at constant length).
    """

    kind: Literal["follow", "push", "rebend"]
    section: int
    description: str
    start_shape: Shape
    end_shape: Shape

    def shape_at(self, a: float) -> Shape:
        """Shape at fraction ``a`` ∈ [0, 1] of the step."""
        (t0, l0), (t1, l1) = self.start_shape[-1], self.end_shape[-1]
        return self.start_shape[:-1] + ((t0 + a * (t1 - t0), l0 + a * (l1 - l0)),)


@dataclass(frozen=True)
class ChordArcPlan:
    """A solution whose contacts all hold, with its motion sequence."""

    solution: ChordArcSolution
    contacts: tuple[ContactCheck, ...]
    motion: tuple[MotionStep, ...]


@dataclass(frozen=True)
class DroppedSolution:
    """A geometric solution the motion check rejected, and why."""

    solution: ChordArcSolution
    contacts: tuple[ContactCheck, ...]
    reason: str


@dataclass(frozen=True)
class ChordArcResult:
    """Search plus motion check: plans that hold, dropped solutions with reasons."""

    search: SearchResult
    plans: tuple[ChordArcPlan, ...]
    dropped: tuple[DroppedSolution, ...] = field(default=())

    @property
    def solutions(self) -> tuple[ChordArcSolution, ...]:
        """The solutions that survived the motion check."""
        return tuple(p.solution for p in self.plans)


# --------------------------------------------------------------------------- motion check


def _fmt_pt(p: Point) -> str:
    return f"({p[0]:.4g}, {p[1]:.4g})"


def _check(
    solution: ChordArcSolution, prep: Prepared, settings: ChordArcSettings
) -> ChordArcPlan | DroppedSolution:
    geo = prep.geometry
    checks: list[ContactCheck] = []
    motion: list[MotionStep] = []
    first = solution.arcs[0]
    motion.append(
        MotionStep(
            "follow",
            0,
            f"insert {first.length_m:.4g} m while bending to θ1 = {first.theta_rad:.4g} rad "
            "(the tip traces arc 1)",
            ((0.0, 0.0),),
            ((first.theta_rad, first.length_m),),
        )
    )
    done: Shape = ((first.theta_rad, first.length_m),)
    failure = ""
    for j, pi in enumerate(solution.contact_indices):
        a_in, a_out = solution.arcs[j], solution.arcs[j + 1]
        k_in, k_out = a_in.curvature_per_m, a_out.curvature_per_m
        obst = int(prep.owner[pi])
        name = geo.names[obst]
        c = np.asarray(a_in.end_xy_m)
        t = np.asarray(a_in.end_tangent)
        r = np.array([t[1], -t[0]])
        side_val = float(prep.into[pi] @ r)
        side = 1 if side_val > 0 else -1
        ctype: Literal["forward", "backward"] = "forward" if side * k_in >= 0 else "backward"
        where = f"contact {j + 1} (point {pi} {_fmt_pt(solution.contact_points_m[j])} on {name!r})"
        reason = ""
        dk = k_out - k_in
        if abs(side_val) < 1e-9:
            reason = f"{where}: the robot meets the obstacle head-on, no side holds it"
        elif side * dk <= settings.min_kappa_change_per_m:
            if abs(dk) <= settings.min_kappa_change_per_m:
                reason = (
                    f"{where}: curvature unchanged ({k_in:.4g} 1/m), the contact carries no load"
                )
            elif ctype == "forward":
                reason = (
                    f"{where} is forward-constrained (obstacle on the concave side: it "
                    f"blocks further bending) but the next arc bends less (κ {k_in:.4g} → "
                    f"{k_out:.4g} 1/m): the section would unbend as one and leave it"
                )
            else:
                reason = (
                    f"{where} is backward-constrained (obstacle on the convex side: it "
                    f"blocks unbending) but the next arc bends further (κ {k_in:.4g} → "
                    f"{k_out:.4g} 1/m): the section would bend as one and leave it"
                )
        push = min(settings.push_length_m, 0.5 * a_out.length_m)
        if not reason:
            a_push = 1.0 + push / a_in.length_m
            ext = a_in.points(
                np.linspace(1.0, a_push, 1 + max(2, math.ceil(push / settings.arc_step_m)))
            )
            if geo.inside_any(ext, settings.inside_tol_m).any():
                reason = (
                    f"{where}: the initial push by {push:.3g} m (a = {a_push:.6g}) "
                    "enters an obstacle"
                )
        if not reason:
            ks = k_in + np.linspace(0.0, 1.0, settings.rebend_steps + 1)[1:] * dk
            th = ks * push
            a = sample_fractions(push, settings.arc_step_m)
            loc = arc_points_local(th[:, None], push, a[None, :])
            pts = c + loc[..., :1] * r + loc[..., 1:] * t
            if geo.inside_any(pts.reshape(-1, 2), settings.inside_tol_m).any():
                reason = (
                    f"{where}: re-bending the pushed {push:.3g} m from κ {k_in:.4g} to "
                    f"{k_out:.4g} 1/m sweeps into an obstacle"
                )
        checks.append(
            ContactCheck(j + 1, int(pi), name, side, ctype, k_in, k_out, not reason, reason)
        )
        if reason and not failure:
            failure = reason
        if failure:
            continue
        pushed = done[:-1] + (
            (a_in.theta_rad * (1.0 + push / a_in.length_m), a_in.length_m + push),
        )
        motion.append(
            MotionStep(
                "push",
                j,
                f"initial push by {push:.4g} m at contact {j + 1} (a = 1 + l/L = "
                f"{1.0 + push / a_in.length_m:.6g})",
                done,
                pushed,
            )
        )
        start = done + ((k_in * push, push),)
        bent = done + ((k_out * push, push),)
        motion.append(
            MotionStep(
                "rebend",
                j + 1,
                f"{ctype}-constrained contact {j + 1} holds arc {j + 1}; the "
                f"pushed {push:.4g} m re-bends to κ = {k_out:.4g} 1/m",
                start,
                bent,
            )
        )
        done = done + ((a_out.theta_rad, a_out.length_m),)
        motion.append(
            MotionStep(
                "follow",
                j + 1,
                f"insert to {a_out.length_m:.4g} m past contact {j + 1} bending a·θ{j + 2}, "
                f"θ{j + 2} = {a_out.theta_rad:.4g} rad",
                bent,
                done,
            )
        )
    if failure:
        return DroppedSolution(solution, tuple(checks), failure)
    return ChordArcPlan(solution, tuple(checks), tuple(motion))


def check_motion(
    solution: ChordArcSolution,
    query: ChordArcQuery,
    settings: ChordArcSettings = ChordArcSettings(),  # noqa: B008
) -> ChordArcPlan | DroppedSolution:
    """Check a solution's contact types, push and re-bend; build its motion sequence."""
    return _check(solution, prepare(query, settings), settings)


def solve_chord_arc(
    query: ChordArcQuery,
    settings: ChordArcSettings = ChordArcSettings(),  # noqa: B008
) -> ChordArcResult:
    """Search, then check every solution's motion. Deterministic: no randomness.

    Raises:
        ChordArcInputError: see :func:`search_chord_arc`.
    """
    prep = prepare(query, settings)
    search = search_prepared(query, prep, settings)
    plans: list[ChordArcPlan] = []
    dropped: list[DroppedSolution] = []
    for sol in search.solutions:
        out = _check(sol, prep, settings)
        if isinstance(out, ChordArcPlan):
            plans.append(out)
        else:
            dropped.append(out)
    return ChordArcResult(search, tuple(plans), tuple(dropped))

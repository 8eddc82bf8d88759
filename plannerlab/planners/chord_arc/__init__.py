"""``chord_arc``: the continuum paper's chord-arc tree search with obstacle wrapping.

One concept per module: :mod:`.geometry` (planar obstacles, the query, a solution's
arcs), :mod:`.settings`, :mod:`.search` (the breadth-first chord-arc search),
:mod:`.motion` (the contact-type check and the motion sequence; :func:`~.motion.
solve_chord_arc` = search + check), :mod:`.scene` (a loaded problem as planar data, the
planar capsule distances) and :mod:`.planner` (the planner contract, the record it
returns: :class:`~plannerlab.record.contact_plan.ContactPlan`). Source:
``003_d410ec97f064abf9.txt`` (digest in ``docs/papers.md`` §3).
"""

"""How closely PyBullet tracked the executed plans of a comparison (docs/execution.md):
per problem and planner, over every executed leg of a trial store, the largest joint
tracking error, the largest tip tracking error, the largest deviation of the collision
geometry from the plan and the part of it that is the retimed reference's own distance
from the plan.

    python results/tracking/tracking.py STORE.jsonl [STORE.jsonl ...]

(a store: ``DIR/NAME/trials.jsonl`` of ``plannerlab compare ... --execute``)
"""

from __future__ import annotations

import json
import sys


def rows(paths: list[str]) -> dict[tuple[str, str], list[dict]]:
    out: dict[tuple[str, str], list[dict]] = {}
    for path in paths:
        with open(path, encoding="utf-8") as f:
            for line in f:
                rec = json.loads(line)
                legs = (rec.get("execution") or {}).get("legs") or []
                out.setdefault((rec["problem"], rec["planner"]), []).extend(legs)
    return out


def main(paths: list[str]) -> None:
    print(
        "| problem | planner | legs executed (clean) | joint tracking error, max [rad] "
        "| tip tracking error, max [mm] | deviation from the plan, max [mm] "
        "| of which the reference's, max [mm] |"
    )
    print("|---|---|---|---|---|---|---|")
    for (problem, planner), legs in sorted(rows(paths).items()):
        if not legs:
            continue
        clean = sum(bool(e.get("success")) for e in legs)

        def top(key: str, legs: list[dict] = legs) -> float:
            return max(float(e.get(key) or 0.0) for e in legs)

        print(
            f"| `{problem}` | `{planner}` | {len(legs)} ({clean}) "
            f"| {top('max_track_err_rad'):.1e} | {top('max_tip_track_err_m') * 1e3:.3f} "
            f"| {top('max_deviation_m') * 1e3:.2f} | {top('reference_deviation_m') * 1e3:.2f} |"
        )


if __name__ == "__main__":
    main(sys.argv[1:])

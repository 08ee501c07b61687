"""Search wall seconds against ``--budget`` on parts with many zones (issue 23: "budgets hold").

    python -m bench.budget_bench TARGET... [--budget S] [--guide heuristic]

Runs `zonegraph.reconstruction.reconstruct` (what ``zonegraph infer`` searches) on each target
(STEP, BREP or design JSON), one at a time, and prints its search seconds (both graphs, generator
set-up included: what the budget bounds) beside the budget, with the zone-graph build seconds
apart. The goal: no search more than 10% past its budget. The last line is the worst overrun.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from zonegraph.configs import InferConfig
from zonegraph.errors import ZoneGraphError
from zonegraph.reconstruction import reconstruct

LIMIT = 0.10  # the most a search may run past its budget, as a share of it


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("targets", nargs="+", type=Path)
    parser.add_argument("--budget", type=float, default=20.0)
    parser.add_argument("--guide", default="heuristic")
    args = parser.parse_args()
    config = InferConfig(guide=args.guide, budget_s=args.budget)
    overs: list[tuple[float, str]] = []
    for target in args.targets:
        try:
            rec = reconstruct(target, config)
        except ZoneGraphError as exc:
            print(f"{target.stem}: no zone graph ({exc})")
            continue
        over = rec.search_s / args.budget - 1
        overs.append((over, target.stem))
        print(
            f"{target.stem}: {rec.graph.n_zones} zones, search {rec.search_s:.2f} s of {args.budget:g} s "
            f"({over:+.1%}), {rec.result.expansions} expansions, zone IoU {rec.result.iou:.4f}, "
            f"build {rec.build_s:.2f} s"
        )
    if overs:
        worst, name = max(overs)
        verdict = "within" if worst <= LIMIT else "PAST"
        print(f"worst: {name} {worst:+.1%} ({verdict} the {LIMIT:.0%} limit; {len(overs)} searches)")


if __name__ == "__main__":
    main()

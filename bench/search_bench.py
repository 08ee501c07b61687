"""Proposals per state and time per search expansion (proposal generation + ranking).

    python -m bench.search_bench [--synthetic N] [--budget S] [--guide heuristic|random]

Runs the search on the simplified zone graph of each real sample and of N synthetic designs
(single process) and prints the median and worst figures, plus time to the best canvas.
"""

from __future__ import annotations

import argparse

import numpy as np

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.data.synthetic import synthetic_design
from zonegraph.errors import ZoneGraphError
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.sequence.rankers import make_ranker
from zonegraph.testing import SAMPLES
from zonegraph.zones.build import build_zone_graph


def run(name: str, designs, budget: float, guide: str, max_zones: int) -> None:
    props, times, per_design = [], [], []
    for design in designs:
        try:
            graph = build_zone_graph(list(replay(design).bodies), samples=0)
        except ZoneGraphError:
            continue
        if graph.n_zones > max_zones:
            continue
        result = search(graph, make_ranker(guide), SearchConfig(budget_s=budget), ProposalGenerator(graph))
        props += result.proposals_per_state
        times += result.expansion_s
        per_design.append(
            (design.id, graph.n_zones, result.exact, result.time_to_best_s, max(result.expansion_s or [0]))
        )
    p, t = np.array(props), 1e3 * np.array(times)
    exact = sum(d[2] for d in per_design)
    print(
        f"\n{name} ({guide}, budget {budget:g} s): {len(per_design)} designs searched, {exact} exact, "
        f"{len(t)} expansions"
    )
    if not len(t):  # nothing searched (e.g. --synthetic 0)
        return
    print(f"  proposals per state  median {np.median(p):.0f}  p90 {np.percentile(p, 90):.0f}  max {p.max()}")
    print(
        f"  ms per expansion     median {np.median(t):.2f}  p90 {np.percentile(t, 90):.2f}  max {t.max():.1f}"
    )
    tt = np.array([d[3] for d in per_design if d[2]])
    if len(tt):
        print(f"  time to exact s      median {np.median(tt):.3f}  max {tt.max():.3f}")
    misses = [d[0] for d in per_design if not d[2]]
    print(f"  not exact: {', '.join(misses) or 'none'}")
    worst = sorted(per_design, key=lambda d: -d[4])[:3]
    print("  slowest expansions: " + ", ".join(f"{d[0]} ({d[1]} zones, {1e3 * d[4]:.0f} ms)" for d in worst))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=100)
    parser.add_argument("--budget", type=float, default=5.0)
    parser.add_argument("--guide", default="heuristic")
    parser.add_argument(
        "--max-zones", type=int, default=2000, help="skip larger graphs (their build dominates)"
    )
    args = parser.parse_args()
    if SAMPLES.is_dir():
        run(
            "real samples",
            [load_design(p) for p in sorted(SAMPLES.glob("*.json"))],
            args.budget,
            args.guide,
            args.max_zones,
        )
    synthetic = (synthetic_design(i) for i in range(args.synthetic))
    run("synthetic", synthetic, args.budget, args.guide, args.max_zones)


if __name__ == "__main__":
    main()

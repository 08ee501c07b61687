"""Proposals per state and time per search expansion (proposal generation + ranking).

    python -m bench.search_bench [--synthetic N] [--budget S] [--guide heuristic|random] [--out DIR]

Runs the search on the simplified zone graph of each real sample and of N synthetic designs
(single process) and prints the median and worst figures, plus time to the best canvas; writes a
row per design (with its proposals per state and seconds per expansion) to ``--out/results.json``
(``python -m bench.figures search`` draws the documentation's table from it).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

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


def run(name: str, designs, budget: float, guide: str, max_zones: int) -> list[dict]:
    props, times, per_design, rows = [], [], [], []
    for design in designs:
        try:
            graph = build_zone_graph(list(replay(design).bodies), samples=0)
        except ZoneGraphError as exc:
            rows.append({"set": name, "design": design.id, "skipped": f"no zone graph: {exc}"})
            continue
        if graph.n_zones > max_zones:
            rows.append({"set": name, "design": design.id, "skipped": f"{graph.n_zones} zones > --max-zones"})
            continue
        result = search(graph, make_ranker(guide), SearchConfig(budget_s=budget), ProposalGenerator(graph))
        props += result.proposals_per_state
        times += result.expansion_s
        per_design.append(
            (design.id, graph.n_zones, result.exact, result.time_to_best_s, max(result.expansion_s or [0]))
        )
        rows.append(
            {
                "set": name,
                "design": design.id,
                "zones": graph.n_zones,
                "exact": result.exact,
                "ended": result.ended,
                "time_to_best_s": result.time_to_best_s,
                "proposals_per_state": result.proposals_per_state,
                "expansion_s": result.expansion_s,
                "guide": guide,
                "budget_s": budget,
            }
        )
    _print(name, guide, budget, props, times, per_design)
    return rows


def _print(name: str, guide: str, budget: float, props: list, times: list, per_design: list) -> None:
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
    parser.add_argument("--out", type=Path, default=Path("bench_out/search"))
    args = parser.parse_args()
    rows = []
    if SAMPLES.is_dir():
        samples = [load_design(p) for p in sorted(SAMPLES.glob("*.json"))]
        rows += run("samples", samples, args.budget, args.guide, args.max_zones)
    synthetic = (synthetic_design(i) for i in range(args.synthetic))
    rows += run("synthetic", synthetic, args.budget, args.guide, args.max_zones)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(rows, indent=1))
    print(f"\nwrote {args.out / 'results.json'}")


if __name__ == "__main__":
    main()

"""What a search's first expansion costs on saved zone graphs, and its search to exact.

    python -m bench.expansion_bench --graphs data/zonegraphs/graphs
        [--ids IDS.txt | --sample 60 --seed 5656 [--min-zones 500] [--exclude IDS.txt]]
        [--budget 5] [--max-expansions 30] [--repeat 2] [--out bench_out/expansion]

The first expansion of a graph is where every plane pair's sweeps are made, so on graphs of
thousands of zones it is most of a search's time (and of a short budget). For each graph, in this
one process, a fresh `ProposalGenerator` makes the proposals of the empty canvas, then the
heuristic guide searches the graph (``--budget`` seconds, at most ``--max-expansions``): both timed
in process CPU seconds (the least of ``--repeat`` runs), which a busy machine stretches less
than wall seconds. Graphs are named by ``--ids`` or drawn uniformly with ``--seed`` among those of
at least ``--min-zones`` zones. To compare commits, run the same command from a worktree of
each (this file copied in). Writes ``results.json`` and ``results.md`` to ``--out``.
"""

from __future__ import annotations

import argparse
import random
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np

from bench.corpus import write_results
from zonegraph.errors import ZoneGraphError
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.zones.storage import load_zone_graph, saved_zone_count

T = TypeVar("T")


def drawn(graphs: Path, sample: int, seed: int, min_zones: int, exclude: set[str]) -> list[str]:
    """``sample`` graph ids drawn uniformly (seeded) among those of at least ``min_zones`` zones."""
    saved = (p for p in graphs.iterdir() if (p / "zones.parquet").is_file())
    ids = sorted(p.name for p in saved if p.name not in exclude)
    kept = [i for i in ids if saved_zone_count(graphs / i) >= min_zones] if min_zones else ids
    return sorted(random.Random(seed).sample(kept, min(sample, len(kept))))


def cpu_seconds(work: Callable[[], T]) -> tuple[float, T]:
    """The process CPU seconds ``work()`` took, and what it returned."""
    start = time.process_time()
    out = work()
    return time.process_time() - start, out


def measure(folder: Path, config: SearchConfig, repeat: int) -> dict:
    """One graph's first expansion and search, the least CPU seconds of ``repeat`` runs."""
    graph = load_zone_graph(folder)
    empty = np.zeros(graph.n_zones, bool)
    first, searched = [], []
    for _ in range(repeat):
        first.append(cpu_seconds(lambda: ProposalGenerator(graph).proposals(empty))[0])
        seconds, result = cpu_seconds(lambda: search(graph, HeuristicRanker(), config))
        searched.append(seconds)
    return {
        "design_id": folder.name,
        "zones": graph.n_zones,
        "first_expansion_cpu_s": min(first),
        "search_cpu_s": min(searched),
        "exact": bool(result.exact),
        "expansions": result.expansions,
    }


def table(rows: list[dict]) -> str:
    """Medians and totals, then the ten costliest first expansions."""
    first = np.array([r["first_expansion_cpu_s"] for r in rows])
    searched = np.array([r["search_cpu_s"] for r in rows])
    lines = [
        f"{len(rows)} graphs, {sum(r['exact'] for r in rows)} exact; zones median "
        f"{int(np.median([r['zones'] for r in rows]))}, max {max(r['zones'] for r in rows)}",
        "",
        "| CPU s | median | p90 | max | total |",
        "|---|---|---|---|---|",
    ]
    for name, values in (("first expansion", first), ("search", searched)):
        lines.append(
            f"| {name} | {np.median(values):.4f} | {np.percentile(values, 90):.4f} | "
            f"{values.max():.3f} | {values.sum():.2f} |"
        )
    lines += ["", "| design | zones | first expansion | search | exact | expansions |", "|---" * 6 + "|"]
    for r in sorted(rows, key=lambda r: -r["first_expansion_cpu_s"])[:10]:
        lines.append(
            f"| {r['design_id']} | {r['zones']} | {r['first_expansion_cpu_s']:.3f} | "
            f"{r['search_cpu_s']:.3f} | {r['exact']} | {r['expansions']} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--graphs", type=Path, required=True)
    parser.add_argument("--ids", type=Path, help="a text file of design ids (one per line)")
    parser.add_argument("--sample", type=int, default=60)
    parser.add_argument("--seed", type=int, default=5656)
    parser.add_argument("--min-zones", type=int, default=0)
    parser.add_argument("--exclude", type=Path, help="ids never drawn (one per line)")
    parser.add_argument("--budget", type=float, default=5.0)
    parser.add_argument("--max-expansions", type=int, default=30)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("bench_out/expansion"))
    args = parser.parse_args()
    exclude = set(args.exclude.read_text().split()) if args.exclude else set()
    ids = (
        args.ids.read_text().split()
        if args.ids
        else drawn(args.graphs, args.sample, args.seed, args.min_zones, exclude)
    )
    config = SearchConfig(budget_s=args.budget, max_expansions=args.max_expansions)
    rows = []
    for n, design in enumerate(ids, 1):
        try:
            rows.append(measure(args.graphs / design, config, args.repeat))
        except ZoneGraphError as exc:  # a graph that does not load is left out, and said so
            print(f"  {n}/{len(ids)} {design}: left out: {exc}", flush=True)
            continue
        print(f"  {n}/{len(ids)} {design}: {rows[-1]['first_expansion_cpu_s']:.3f} CPU s", flush=True)
    write_results(rows, table(rows), args.out)


if __name__ == "__main__":
    main()

"""Milliseconds to score one search state on CPU: early, late and factored fusion vs the heuristic.

    python -m bench.scorer_bench [--graphs data/zonegraphs/graphs] [--zones 20 100 500]
                                 [--proposals 10 50 200] [--repeats 5] [--threads 1]

For each zone count, the saved zone graph (from a pipeline run: the corpus, or the default
synthetic data) closest to it is scored with P proposals of its own (the proposals at a few
canvases, cycled to reach P), by an untrained scorer of each fusion (weights do not change the
cost) and by the heuristic ranker. Late fusion's per-graph geometry encoding is timed apart: the
search pays it once per graph, not per state. Medians of ``--repeats`` runs, one thread.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

from bench.corpus import closest_graphs
from zonegraph.network.encoding import geometry_of
from zonegraph.network.model import ModelConfig, ProposalScorer
from zonegraph.network.scoring import score_state
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.zones.model import ZoneGraph
from zonegraph.zones.storage import load_zone_graph


def proposals_of(graph: ZoneGraph, count: int, seed: int = 0) -> tuple[np.ndarray, list[Proposal]]:
    """A canvas and ``count`` proposals (cycled from those at a few random canvases)."""
    gen, rng = ProposalGenerator(graph), np.random.default_rng(seed)
    canvas = np.zeros(graph.n_zones, bool)
    pool: list[Proposal] = gen.proposals(canvas)
    while len(pool) < count and len(pool) < 5000:
        more = gen.proposals(rng.random(graph.n_zones) < 0.5)
        if not more and len(pool) == 0:
            break
        pool += more
    pool = pool or [Proposal(0, 0, (), np.ones(graph.n_zones, bool), Op.UNION)]
    return canvas, [pool[i % len(pool)] for i in range(count)]


def _median_ms(fn, repeats: int) -> float:
    fn()  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000 * float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--graphs", type=Path, default=Path("data/zonegraphs/graphs"))
    parser.add_argument("--zones", type=int, nargs="+", default=[20, 100, 500])
    parser.add_argument("--proposals", type=int, nargs="+", default=[10, 50, 200])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    if not args.graphs.is_dir():
        raise SystemExit(f"{args.graphs}: no saved zone graphs (run the zonegraphs stage first)")
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    models = {f: ProposalScorer(ModelConfig(fusion=f)).eval() for f in ("early", "late", "factored")}
    print(
        "| zones | proposals | early ms | late ms | factored ms | encode ms (once per graph) | heuristic ms "
        "| heuristic expansion ms | early/late | late/expansion |\n" + "|---" * 10 + "|"
    )
    for folder in closest_graphs(args.graphs, args.zones).values():
        graph = load_zone_graph(folder, solids=False)
        for count in args.proposals:
            t = time_state(models, graph, count, args.repeats)
            print(
                f"| {graph.n_zones} | {count} | {t['early']:.1f} | {t['late']:.2f} | {t['factored']:.2f} | "
                f"{t['encode']:.1f} | {t['heuristic']:.2f} | {t['expansion']:.2f} | "
                f"{t['early'] / t['late']:.0f}x | {t['late'] / t['expansion']:.1f}x |",
                flush=True,
            )


def time_state(
    models: dict[str, ProposalScorer], graph: ZoneGraph, count: int, repeats: int
) -> dict[str, float]:
    """Median milliseconds of each way to score one state of ``graph`` with ``count`` proposals.

    ``expansion``: what a heuristic-guided expansion costs, generating the state's proposals
    (cold, as at a new canvas) and scoring them."""
    geometry = geometry_of(graph, 128)
    canvas, props = proposals_of(graph, count)
    zones = torch.from_numpy(np.stack([p.zones for p in props]))
    ops = torch.tensor([1 if p.op is Op.UNION else -1 for p in props])
    state = (geometry, torch.from_numpy(canvas), zones, ops, torch.device("cpu"))
    heuristic = HeuristicRanker()

    def expansion() -> None:
        heuristic.score(graph, canvas, ProposalGenerator(graph).proposals(canvas))

    out = {"heuristic": _median_ms(lambda: heuristic.score(graph, canvas, props), repeats)}
    out["expansion"] = _median_ms(expansion, repeats)
    with torch.no_grad():  # as the network guide scores: one state, in memory-sized chunks
        out["early"] = _median_ms(lambda: score_state(models["early"], *state), repeats)
        out["encode"] = _median_ms(lambda: models["late"].encode_geometry(geometry.points), repeats)
        for fusion in ("late", "factored"):
            codes = models[fusion].encode_geometry(geometry.points)
            out[fusion] = _median_ms(lambda m=models[fusion], c=codes: score_state(m, *state, c), repeats)
    return out


if __name__ == "__main__":
    main()

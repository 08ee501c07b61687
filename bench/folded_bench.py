"""Milliseconds the network guide spends on a state it scores, by graph size, beside the heuristic's.

    python -m bench.folded_bench [--graphs data/zonegraphs/graphs] [--zones 60 130 250 500 1300 4000]
                                 [--designs ID ...] [--states 40] [--top-m 8] [--model PATH]
                                 [--repeats 3] [--out bench_out/folded]

For each zone count, the saved zone graph (from a pipeline run) closest to it, or each of
``--designs``, is searched with the heuristic for up to ``--states`` expansions; the states it
expands are then scored, in the search's order, by the folded scorer the guide runs (the shipped
one by default) on the heuristic's best ``--top-m`` proposals of each (as the shipped guide
scores them) with their features, by one scorer that keeps what it encodes per graph between
states, as in search. The first state is scored untimed: it pays what a search pays once per
graph (the adjacency, every zone's codes). The least time of ``--repeats`` passes, one BLAS
thread; ``heuristic ms`` is the heuristic's scoring of every proposal of the same states,
``features ms`` the proposal features the network reads. A graph the heuristic solves in one
expansion has no state to time: name designs whose search backtracks. ``results.json`` is what
``python -m bench.figures folded`` reads.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from bench.corpus import closest_graphs, write_results
from zonegraph.network.folded import SHIPPED_FOLDED, FoldedScorer
from zonegraph.network.ranker import NumpyScorer
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.features import proposal_features, target_surfaces
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.zones.model import ZoneGraph
from zonegraph.zones.storage import load_zone_graph


@dataclass(frozen=True)
class Visit:
    """One expanded state: its canvas, every proposal, and the network's share of them."""

    canvas: np.ndarray
    proposals: list[Proposal]
    picked: list[Proposal]  # the heuristic's best M
    zones: np.ndarray  # (M, Z) bool
    ops: np.ndarray  # (M,) +1 / -1
    features: np.ndarray  # (M, F)


class Recorder(HeuristicRanker):
    """The heuristic, keeping every state it is asked to score (each expansion asks once) with
    its scores."""

    def __init__(self) -> None:
        self.seen: list[tuple[np.ndarray, list[Proposal], np.ndarray]] = []

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        scores = super().score(graph, canvas, proposals)
        self.seen.append((canvas.copy(), proposals, scores))
        return scores


# Expansions the recording search may make per state kept: states of one proposal are skipped,
# and the search stops there rather than at its budget on a design it cannot solve.
EXPANSIONS_PER_STATE = 10


def visits(graph: ZoneGraph, states: int, top_m: int) -> list[Visit]:
    """The first ``states`` states a heuristic search of ``graph`` expands with more than one
    proposal (a state with one is never scored)."""
    recorder = Recorder()
    config = SearchConfig(budget_s=60.0, max_depth=20, max_expansions=EXPANSIONS_PER_STATE * states)
    search(graph, recorder, config, ProposalGenerator(graph))
    on_target, out = target_surfaces(graph), []
    for canvas, proposals, scores in recorder.seen:
        if len(proposals) < 2:
            continue
        picked = [proposals[i] for i in np.sort(np.argsort(-scores, kind="stable")[:top_m])]
        zones = np.stack([p.zones for p in picked]).astype(bool)
        ops = np.array([1 if p.op is Op.UNION else -1 for p in picked], np.float32)
        features = proposal_features(graph, canvas, picked, 1, on_target)
        out.append(Visit(canvas, proposals, picked, zones, ops, features))
        if len(out) == states:
            break
    return out


def least_ms(run: Callable[[], None], count: int, repeats: int) -> float:
    """Milliseconds per item of the fastest of ``repeats`` passes over ``count`` items."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return 1000 * best / max(count, 1)


def time_graph(graph: ZoneGraph, model: Path, states: int, top_m: int, repeats: int) -> dict[str, float]:
    """Milliseconds per state of the network, its features and the heuristic on ``graph``."""
    seen = visits(graph, states, top_m)
    folded = FoldedScorer.load(model, projects=False)
    on_target = target_surfaces(graph)

    scorer = NumpyScorer(folded)
    spent: list[float] = []  # seconds of each timed pass

    def network() -> None:
        first = seen[0]  # back to the first state, untimed (as a search's set-up, once per graph)
        scorer.score(graph, first.canvas, first.zones, first.ops, first.features)
        start = time.perf_counter()
        for v in seen[1:]:
            scorer.score(graph, v.canvas, v.zones, v.ops, v.features)
        spent.append(time.perf_counter() - start)

    def features() -> None:
        for v in seen:
            proposal_features(graph, v.canvas, v.picked, 1, on_target)

    def heuristic() -> None:
        for v in seen:
            HeuristicRanker().score(graph, v.canvas, v.proposals)

    with threadpool_limits(limits=1, user_api="blas"):
        for _ in range(repeats):
            network()
        return {
            "states": len(seen),
            "network": 1000 * min(spent) / (len(seen) - 1) if len(seen) > 1 else float("nan"),
            "features": least_ms(features, len(seen), repeats),
            "heuristic": least_ms(heuristic, len(seen), repeats),
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--graphs", type=Path, default=Path("data/zonegraphs/graphs"))
    parser.add_argument("--zones", type=int, nargs="+", default=[60, 130, 250, 500, 1300, 4000])
    parser.add_argument("--designs", nargs="+", default=None, help="saved graphs by name, for --zones")
    parser.add_argument("--states", type=int, default=40)
    parser.add_argument("--top-m", type=int, default=8)
    parser.add_argument("--model", type=Path, default=SHIPPED_FOLDED)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=Path("bench_out/folded"))
    args = parser.parse_args()
    if not args.graphs.is_dir():
        raise SystemExit(f"{args.graphs}: no saved zone graphs (run the zonegraphs stage first)")
    rows = []
    if args.designs:
        folders = [args.graphs / d for d in args.designs]
        missing = [f.name for f in folders if not f.is_dir()]
        if missing:
            raise SystemExit(f"{args.graphs}: no saved graph of {', '.join(missing)}")
    else:
        folders = list(closest_graphs(args.graphs, args.zones).values())
    for folder in folders:
        graph = load_zone_graph(folder, solids=False)
        rows.append({"design_id": folder.name, "zones": graph.n_zones} | time_graph(
            graph, args.model, args.states, args.top_m, args.repeats
        ))
        print(f"  {folder.name}: {graph.n_zones} zones, {rows[-1]['network']:.2f} ms", flush=True)
    write_results(rows, table(rows), args.out)


def table(rows: list[dict]) -> str:
    """Milliseconds per state by graph, as markdown."""
    lines = [
        "| design | zones | states | network ms | features ms | heuristic ms | network / heuristic |",
        "|---" * 7 + "|",
    ]
    for r in rows:
        lines.append(
            f"| {r['design_id']} | {r['zones']} | {r['states']} | {r['network']:.2f} | {r['features']:.2f} | "
            f"{r['heuristic']:.2f} | {r['network'] / r['heuristic']:.1f}x |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    main()

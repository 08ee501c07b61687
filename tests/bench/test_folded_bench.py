"""The folded-scorer bench on saved graphs: the states a real search expands, timed per state."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from build123d import Align, Box, Cylinder, Pos

from bench.corpus import closest_graphs
from bench.folded_bench import time_graph, visits
from zonegraph.network.folded import SHIPPED_FOLDED
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import load_zone_graph, save_zone_graph


def test_the_states_a_search_expands_are_timed_with_the_heuristics_best_proposals(tmp_path: Path) -> None:
    plate = Box(4, 4, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    bosses = [Pos(x, 0, 1) * Cylinder(0.5, 1, align=(Align.CENTER, Align.CENTER, Align.MIN)) for x in (-1, 1)]
    save_zone_graph(build_zone_graph([plate], samples=0), tmp_path / "plate")
    save_zone_graph(build_zone_graph([plate + bosses[0] - bosses[1]], samples=64), tmp_path / "part")
    assert list(closest_graphs(tmp_path, [1, 100]).values()) == [tmp_path / "plate", tmp_path / "part"]
    graph = load_zone_graph(tmp_path / "part", solids=False)
    seen = visits(graph, states=3, top_m=2)
    assert 1 <= len(seen) <= 3
    for v in seen:
        scores = HeuristicRanker().score(graph, v.canvas, v.proposals)
        assert len(v.picked) == len(v.zones) == 2 and v.features.shape[0] == 2
        assert sorted(scores[[v.proposals.index(p) for p in v.picked]]) == sorted(np.sort(scores)[-2:])
    t = time_graph(graph, SHIPPED_FOLDED, states=3, top_m=2, repeats=1)
    assert t["states"] == len(seen) and min(t["features"], t["heuristic"]) > 0
    assert t["network"] > 0 if len(seen) > 1 else np.isnan(t["network"])

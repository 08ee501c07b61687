"""The guide-cost bench: repeated searches keep the first outcome and the least time."""

from __future__ import annotations

from bench.guide_cost_bench import fastest, one_search
from eval.guides import GuideSpec
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.testing import requires_samples
from zonegraph.zones.build import build_zone_graph


@requires_samples
def test_the_least_time_of_repeated_searches_keeps_their_outcome(samples_dir):
    graph = build_zone_graph(list(replay(load_design(samples_dir / "Couch.json")).bodies), samples=8)
    guide = GuideSpec.parse("heuristic")
    once = one_search(lambda: graph, guide, 5.0, 0)
    best = fastest(lambda: graph, guide, 5.0, 0, repeat=4)
    assert once["exact"] and (best["exact"], best["expansions"]) == (True, once["expansions"])
    assert 0 < best["time_to_exact_s"] <= best["search_wall_s"]

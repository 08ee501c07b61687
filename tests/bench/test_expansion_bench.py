"""The expansion bench on saved graphs: draws by zone count, measures a real search."""

from __future__ import annotations

from pathlib import Path

from build123d import Align, Box, Cylinder, Pos

from bench.expansion_bench import drawn, measure, table
from zonegraph.sequence.best_first import SearchConfig
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph


def test_a_saved_graph_is_drawn_by_its_zones_and_searched_to_exact(tmp_path: Path) -> None:
    plate = Box(4, 4, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    boss = Pos(0, 0, 1) * Cylinder(1, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    save_zone_graph(build_zone_graph([plate], samples=0), tmp_path / "plate")
    save_zone_graph(build_zone_graph([plate + boss], samples=0), tmp_path / "boss")
    assert drawn(tmp_path, 5, 0, 0, set()) == ["boss", "plate"]
    assert drawn(tmp_path, 5, 0, 2, set()) == ["boss"]  # the plate is one zone
    assert drawn(tmp_path, 5, 0, 0, {"boss"}) == ["plate"]
    row = measure(tmp_path / "boss", SearchConfig(budget_s=5, max_expansions=30), repeat=2)
    assert row["exact"] and row["expansions"] >= 1 and row["zones"] > 1
    assert 0 < row["first_expansion_cpu_s"] and 0 < row["search_cpu_s"]
    assert "1 graphs, 1 exact" in table([row])

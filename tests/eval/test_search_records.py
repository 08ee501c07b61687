"""An evaluation's search record is keyed by what the search read, not only by its settings."""

from __future__ import annotations

from eval.searches import Search, Target
from zonegraph.configs import InferConfig


def test_a_search_record_is_keyed_by_the_target_and_its_graph(tmp_path):
    target, graph = tmp_path / "final.brep", tmp_path / "graph"
    target.write_text("solid A")
    graph.mkdir()
    (graph / "faces.parquet").write_bytes(b"faces")
    search = Search("heuristic", InferConfig(budget_s=2), Target("d", str(target), str(graph), 2))
    first = search.fingerprint()
    assert search.fingerprint() == first
    (graph / "faces.parquet").write_bytes(b"garbled")
    changed_graph = search.fingerprint()
    target.write_text("solid B")
    assert len({first, changed_graph, search.fingerprint()}) == 3

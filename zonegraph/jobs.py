"""Job bodies shared by the CLI and the pipeline; each runs in an isolated child process and
returns only small plain data (the geometry goes to files)."""

from __future__ import annotations

from zonegraph.zones.build import build_zone_graph
from zonegraph.data.targets import load_target
from zonegraph.zones.storage import save_zone_graph


def build_and_save(target: str, out: str, simplify: bool = True, samples: int = 512, seed: int = 0) -> dict:
    """Build the zone graph of a target file and save it to ``out``; returns its summary."""
    graph = build_zone_graph(load_target(target), simplify=simplify, samples=samples, seed=seed, source=target)
    save_zone_graph(graph, out)
    return graph.summary()

"""Job bodies shared by the CLI and the pipeline; each runs in an isolated child process and
returns only small plain data (the geometry goes to files)."""

from __future__ import annotations

from typing import Any

from zonegraph.configs import BuildConfig
from zonegraph.data.targets import load_target
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph


def build_and_save(target: str, out: str, config: BuildConfig = BuildConfig()) -> dict[str, Any]:
    """Build the zone graph of a target file and save it to ``out``; returns its summary.

    Raises:
        InputError: the file cannot be read as solids.
        ZoneGraphBuildError: the graph cannot be built or breaks an invariant.
    """
    graph = build_zone_graph(
        load_target(target), simplify=config.simplify, samples=config.samples, seed=config.seed, source=target
    )
    save_zone_graph(graph, out)
    return graph.summary()

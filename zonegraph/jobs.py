"""Job bodies shared by the CLI and the pipeline; each runs in an isolated child process and
returns only small plain data (the geometry goes to files)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from zonegraph.configs import BuildConfig
from zonegraph.data.targets import load_target
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.sampling import export_zone_mesh
from zonegraph.zones.storage import save_zone_graph


def build_and_save(
    target: str, out: str, config: BuildConfig = BuildConfig(), mesh: bool = False
) -> dict[str, Any]:
    """Build the zone graph of a target file and save it to ``out``; returns its summary.

    ``mesh`` also writes ``zones.ply`` (every zone, inside blue, outside grey) for a viewer.

    Raises:
        InputError: the file cannot be read as solids.
        ZoneGraphBuildError: the graph cannot be built or breaks an invariant.
    """
    graph = build_zone_graph(
        load_target(target), simplify=config.simplify, samples=config.samples, seed=config.seed, source=target
    )
    save_zone_graph(graph, out)
    if mesh:
        export_zone_mesh(graph, Path(out) / "zones.ply")
    return graph.summary()

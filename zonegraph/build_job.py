"""The zone-graph build as one job: a target file in, a saved graph out.

Apart from `zonegraph.jobs`, whose other jobs import the search and the labels, so that
``zonegraph build PART.step`` imports the kernel, the build and its storage and nothing else.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from zonegraph.configs import BuildConfig
from zonegraph.data.targets import load_kernel_target
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
    solids = load_kernel_target(target)
    graph = build_zone_graph(
        solids, simplify=config.simplify, samples=config.samples, seed=config.seed, source=target
    )
    save_zone_graph(graph, out)
    if mesh:
        export_zone_mesh(graph, Path(out) / "zones.ply")
    return graph.summary()

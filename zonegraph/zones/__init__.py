"""Zone graphs (paper sec. 3): extend the target's faces, partition its box, label and link zones.

``extension`` and ``face_loops`` choose the extended surfaces, ``build`` runs the general fuse and
checks the invariants, ``model`` holds the resulting arrays (`ZoneGraph`), ``sampling``
draws the zones' surface samples and ``storage`` saves and loads a graph as Parquet + BREP.
Imports only `zonegraph.geometry`, `zonegraph.errors` and `zonegraph.status`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "build_zone_graph": "zonegraph.zones.build",
    "ZoneGraph": "zonegraph.zones.model",
    "ZoneGraphBuildError": "zonegraph.zones.model",
    "export_zone_mesh": "zonegraph.zones.sampling",
    "sample_zone_surfaces": "zonegraph.zones.sampling",
    "load_zone_graph": "zonegraph.zones.storage",
    "save_zone_graph": "zonegraph.zones.storage",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.zones.build import build_zone_graph
    from zonegraph.zones.model import ZoneGraph, ZoneGraphBuildError
    from zonegraph.zones.sampling import export_zone_mesh, sample_zone_surfaces
    from zonegraph.zones.storage import load_zone_graph, save_zone_graph

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)

"""Zone graphs (paper sec. 3): extend the target's faces, partition its box, label and link zones.

``extension`` and ``face_loops`` choose the extended surfaces, ``build`` runs the general fuse and
checks the invariants, ``model`` holds the resulting arrays (:class:`ZoneGraph`), ``sampling``
draws the zones' surface samples and ``storage`` saves and loads a graph as Parquet + BREP.
Imports only :mod:`zonegraph.geometry`, :mod:`zonegraph.errors` and :mod:`zonegraph.status`.
"""

from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.model import ZoneGraph, ZoneGraphBuildError
from zonegraph.zones.sampling import export_zone_mesh, sample_zone_surfaces
from zonegraph.zones.storage import load_zone_graph, save_zone_graph

__all__ = [
    "ZoneGraph",
    "ZoneGraphBuildError",
    "build_zone_graph",
    "export_zone_mesh",
    "load_zone_graph",
    "sample_zone_surfaces",
    "save_zone_graph",
]

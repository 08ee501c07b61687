"""Geometry helpers over OCP and build123d: B-rep I/O, the normalising transform, zones to solids.

The lowest layer: it imports nothing else from ``zonegraph`` but `zonegraph.errors`.
``occ`` holds small typed wrappers over OCP idioms (points, explorers, ancestors, properties).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "fuse_zones": "zonegraph.geometry.cells",
    "Normalization": "zonegraph.geometry.normalize",
    "read_shape": "zonegraph.geometry.shapes",
    "read_solids": "zonegraph.geometry.shapes",
    "symmetric_difference_volume": "zonegraph.geometry.shapes",
    "volume_of": "zonegraph.geometry.shapes",
    "write_brep": "zonegraph.geometry.shapes",
    "write_step": "zonegraph.geometry.shapes",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.geometry.cells import fuse_zones
    from zonegraph.geometry.normalize import Normalization
    from zonegraph.geometry.shapes import (
        read_shape,
        read_solids,
        symmetric_difference_volume,
        volume_of,
        write_brep,
        write_step,
    )

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)

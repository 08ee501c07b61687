"""Geometry helpers over OCP and build123d: B-rep I/O, the normalising transform, zones to solids.

The lowest layer: it imports nothing else from ``zonegraph`` but :mod:`zonegraph.errors`.
``occ`` holds small typed wrappers over OCP idioms (points, explorers, ancestors, properties).
"""

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

__all__ = [
    "Normalization",
    "fuse_zones",
    "read_shape",
    "read_solids",
    "symmetric_difference_volume",
    "volume_of",
    "write_brep",
    "write_step",
]

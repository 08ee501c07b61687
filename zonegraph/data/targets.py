"""Load a reconstruction target from a user's file: a STEP/BREP solid or a design JSON.

A STEP or BREP file is read by OCP alone (`load_kernel_target`), so building its zone
graph never imports build123d; a design JSON is replayed, which needs build123d's API.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from zonegraph.geometry.shapes import read_kernel_solids

if TYPE_CHECKING:
    from build123d import Shape, Solid
    from OCP.TopoDS import TopoDS_Shape


def _replayed(path: Path) -> list[Solid]:
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay

    return list(replay(load_design(path)).bodies)


def load_target(path: str | Path) -> list[Solid]:
    """The target solids; a design JSON stands for its final shape (all its bodies)."""
    from build123d import Solid

    path = Path(path)
    if path.suffix.lower() == ".json":
        return _replayed(path)
    return [Solid(s) for s in read_kernel_solids(path)]


def load_kernel_target(path: str | Path) -> list[TopoDS_Shape]:
    """The target solids as OCP shapes (the same solids as `load_target`)."""
    path = Path(path)
    if path.suffix.lower() == ".json":
        return [s.wrapped for s in _replayed(path)]
    return read_kernel_solids(path)


def target_region(solids: list[Solid]) -> Shape:
    """The region a target's solids fill, as one shape: overlapping bodies fused
    (`overlaps_merged`), so that a program that rebuilds the region
    measures IoU 1 against it, not against the bodies' volumes summed."""
    from build123d import Shape

    from zonegraph.data.replay import as_shape
    from zonegraph.geometry.occ import overlaps_merged

    merged = overlaps_merged([s.wrapped for s in solids])
    if len(merged) == len(solids):
        return as_shape(solids)
    return as_shape([Shape.cast(s) for s in merged])

"""Turn a set of zones back into one clean solid (for checks, canvases and rendering).

``BOPAlgo_CellsBuilder`` re-runs the general fuse on the zones, keeps the selected cells and
removes the boundaries between them; unifying same-domain faces then merges the pieces of each
face, so the result has the target's faces, not the zones'.
"""

from __future__ import annotations

from collections.abc import Sequence

from OCP.BOPAlgo import BOPAlgo_CellsBuilder
from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
from OCP.TopoDS import TopoDS_Shape

from zonegraph.geometry.occ import shape_list


def fuse_zones(zones: Sequence[TopoDS_Shape], selected: Sequence[int]) -> TopoDS_Shape:
    """The union of ``zones[i]`` for ``i`` in ``selected``, internal boundaries removed."""
    builder = BOPAlgo_CellsBuilder()
    for z in zones:
        builder.AddArgument(z)
    builder.SetRunParallel(False)
    builder.Perform()
    if builder.HasErrors():
        raise RuntimeError("cells builder failed")
    for i in selected:
        builder.AddToResult(shape_list([zones[i]]), shape_list([]), 1, False)
    builder.RemoveInternalBoundaries()
    unify = ShapeUpgrade_UnifySameDomain(builder.Shape(), True, True, True)
    unify.Build()
    return unify.Shape()

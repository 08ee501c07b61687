"""Turn a set of zones, or the cells of overlapping solids, back into one clean solid.

``BOPAlgo_CellsBuilder`` re-runs the general fuse on its arguments, keeps the selected cells and
removes the boundaries between them; unifying same-domain faces then merges the pieces of each
face, so the result has the target's faces, not the zones'.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

from OCP.BOPAlgo import BOPAlgo_CellsBuilder
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.TopAbs import TopAbs_SOLID
from OCP.TopoDS import TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import (
    make_compound,
    shape_index,
    shape_list,
    shapes_of,
    sub_shapes,
    unified,
    volume_props,
    without_open_shells,
)


def fuse_zones(zones: Sequence[TopoDS_Shape], selected: Sequence[int]) -> TopoDS_Shape:
    """The union of ``zones[i]`` for ``i`` in ``selected``, internal boundaries removed."""
    builder = _cells(zones, 0.0)
    for i in selected:
        builder.AddToResult(shape_list([zones[i]]), shape_list([]), 1, False)
    builder.RemoveInternalBoundaries()
    return unified(builder.Shape())


# Fuzzy values of a Boolean or a cells evaluation, as shares of the operands' bounding-box
# diagonal, tried in turn: exact first, then values that close the tolerance gaps of corpus parts.
FUZZY_SHARES = (0.0, 1e-7, 1e-5)

# How far removing the boundaries between cells may move their volume: the default integration's
# accuracy on surfaces of extrusion (``zonegraph.geometry.occ.precise_volume``); a wrong merge is
# off by far more.
MERGE_RTOL = 1e-4


def cells_by_fuzzy(
    arguments: Sequence[TopoDS_Shape], keep: Callable[[frozenset[int]], bool], diag: float
) -> Iterator[TopoDS_Shape]:
    """`select_cells` at each of ``FUZZY_SHARES`` of ``diag`` in turn (a fuse that raises is
    skipped), for the caller to take the first result it accepts."""
    for share in FUZZY_SHARES:
        try:
            yield select_cells(arguments, keep, share * diag)
        except RuntimeError:
            continue


def select_cells(
    arguments: Sequence[TopoDS_Shape], keep: Callable[[frozenset[int]], bool], fuzzy: float = 0.0
) -> TopoDS_Shape:
    """The cells of the general fuse of ``arguments`` whose owners (the indices of the arguments
    that contain the cell) ``keep`` accepts, as one solid with internal boundaries removed.

    One fuse of every operand at once evaluates any Boolean expression of them: it does not
    depend on a chain of Booleans, each of which may fail on the result of the one before.
    Unifying same-domain faces can break a valid result (and, working in place, the raw result
    too; a measured case: ``docs/results/evidence.md``), so a copy is unified and kept only when
    the checker accepts it or rejects the raw result as well.

    Removing the boundaries between the kept cells must keep their volume. On a corpus program
    (25199_d7aff7a5_0015, 16 steps) the exact fuse's cells held 1.22 cm3 where the part has 0.81,
    and with their boundaries removed they made a solid the checker accepts of volume -5e-8; the
    fuse at the next fuzzy value gave the part.

    Raises:
        RuntimeError: the general fuse reported errors, or merging its cells changed their volume.
    """
    builder = _cells(arguments, fuzzy)
    for owners in {o for o in _cell_owners(builder, arguments) if keep(o)}:
        take = [arguments[i] for i in sorted(owners)]
        avoid = [a for i, a in enumerate(arguments) if i not in owners]
        builder.AddToResult(shape_list(take), shape_list(avoid), 1, False)
    held = volume_props(builder.Shape())[0]
    builder.RemoveInternalBoundaries()
    raw = without_open_shells(builder.Shape())
    if abs(volume_props(raw)[0] - held) > MERGE_RTOL * abs(held):
        raise RuntimeError("merging the cells changed their volume")
    merged = without_open_shells(unified(raw))  # raw itself where the unifier raises
    return merged if _valid(merged) or not _valid(raw) else raw


def _cells(arguments: Sequence[TopoDS_Shape], fuzzy: float) -> BOPAlgo_CellsBuilder:
    builder = BOPAlgo_CellsBuilder()
    for a in arguments:
        builder.AddArgument(a)
    builder.SetFuzzyValue(fuzzy)
    builder.SetRunParallel(False)
    builder.SetNonDestructive(True)
    builder.Perform()
    if builder.HasErrors():
        raise RuntimeError("cells builder failed")
    return builder


def _cell_owners(builder: BOPAlgo_CellsBuilder, arguments: Sequence[TopoDS_Shape]) -> list[frozenset[int]]:
    """For every cell, the arguments containing it: the cells are the images of the arguments'
    solids (the builder's ``Modified`` history is empty for solids; ``Images`` holds them)."""
    cells = shape_index(make_compound(sub_shapes(builder.GetAllParts(), TopAbs_SOLID)), TopAbs_SOLID)
    owners: list[set[int]] = [set() for _ in range(cells.Size())]
    images = builder.Images()
    for i, argument in enumerate(arguments):
        for solid in sub_shapes(argument, TopAbs_SOLID):
            for cell in shapes_of(images.Find(solid)) if images.IsBound(solid) else [solid]:
                k = cells.FindIndex(cell)
                if k > 0:
                    owners[k - 1].add(i)
    return [frozenset(o) for o in owners]


def _valid(shape: TopoDS_Shape) -> bool:
    return bool(BRepCheck_Analyzer(shape).IsValid())

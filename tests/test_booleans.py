"""The Booleans of the rebuild, the replay and the IoU leave their operands as they were."""

from __future__ import annotations

import pytest
from build123d import Box, Edge, Face, Pos, Shape, Solid, Vector
from OCP.BRep import BRep_Builder
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_Copy,
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
)
from OCP.GC import GC_MakeSegment
from OCP.gp import gp_Pln, gp_Pnt
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_INTERNAL
from OCP.TopoDS import TopoDS, TopoDS_Shell, TopoDS_Solid, TopoDS_Vertex, TopoDS_Wire

from zonegraph.geometry.occ import (
    fuzzy_boolean,
    gaps_closed,
    overlaps_merged,
    precise_volume,
    without_internal_wires,
    without_open_shells,
)


def _max_tolerance(shape: Shape) -> float:
    return ShapeAnalysis_ShapeTolerance().Tolerance(shape.wrapped, 1)


@pytest.mark.parametrize("operation", [BRepAlgoAPI_Fuse, BRepAlgoAPI_Cut, BRepAlgoAPI_Common])
def test_a_fuzzy_boolean_does_not_enlarge_its_operands_tolerances(operation):
    """A fuzzy value bridges a gap by growing the tolerances of the sub-shapes it joins; done on
    the operands themselves, a part kept from an earlier step changes under the next Boolean
    (a rebuilt part after a cut that then held 2e-4 less of itself)."""
    a = Box(1, 1, 1)
    b = Pos(0.5, 0.3, 1e-5) * Box(1, 1, 1)  # its top face 1e-5 above a's
    before = _max_tolerance(a), _max_tolerance(b)
    result = Shape.cast(fuzzy_boolean(operation(), a.wrapped, b.wrapped, 1e-4))
    assert result.volume > 0
    assert (_max_tolerance(a), _max_tolerance(b)) == before


def _with_stray_face(solid: Shape) -> TopoDS_Solid:
    """``solid`` with a square face inside it as a second, open shell: what a cut left on a
    corpus part."""
    shell = TopoDS_Shell()
    builder = BRep_Builder()
    builder.MakeShell(shell)
    builder.Add(shell, (Pos(0, 0, 0.25) * Face.make_rect(0.5, 0.5)).wrapped)
    out = TopoDS_Solid()
    builder.MakeSolid(out)
    for s in solid.shells():
        builder.Add(out, s.wrapped)
    builder.Add(out, shell)
    return out


def test_a_stray_open_shell_is_dropped_and_the_solid_keeps_its_volume():
    box = Box(1, 1, 1)
    stray = _with_stray_face(box)
    assert Shape.cast(stray).volume != pytest.approx(1.0, abs=1e-6)  # the open shell counts
    kept = without_open_shells(stray)
    assert len(Shape.cast(kept).shells()) == 1 and Shape.cast(kept).is_valid
    assert Shape.cast(kept).volume == pytest.approx(1.0, abs=1e-12)
    assert without_open_shells(box.wrapped) is box.wrapped  # nothing to drop: the input itself


def _with_internal_trace(face: Face) -> Face:
    """``face`` with a line inside it as an INTERNAL wire of its own: what merging a corpus
    part's partition faces left where chamfers met the sketch plane."""
    builder = BRep_Builder()
    wire = TopoDS_Wire()
    builder.MakeWire(wire)
    builder.Add(wire, Edge.make_line((-0.2, 0, 0), (0.2, 0, 0)).wrapped.Oriented(TopAbs_INTERNAL))
    copy = BRepBuilderAPI_Copy(face.wrapped).Shape()
    copy.Free(True)
    builder.Add(copy, wire)
    return Face(TopoDS.Face(copy))


def test_internal_wires_are_dropped_and_the_prism_is_valid_again():
    square = Face.make_rect(1, 1)
    traced = _with_internal_trace(square)
    assert len(traced.wires()) == 2
    assert not Solid.extrude(traced, Vector(0, 0, 1)).is_valid  # an internal face inside the prism
    clean = Face(without_internal_wires(traced.wrapped))
    assert len(clean.wires()) == 1 and clean.area == pytest.approx(1.0)
    prism = Solid.extrude(clean, Vector(0, 0, 1))
    assert prism.is_valid and prism.volume == pytest.approx(1.0)
    assert without_internal_wires(square.wrapped) is square.wrapped  # nothing to drop


def test_overlapping_solids_are_merged_and_touching_or_apart_ones_kept():
    """Two unit boxes overlapping by a quarter become one region of 1.75; a box that only
    touches them and one far away stay as they are."""
    a, b = Box(1, 1, 1), Pos(0.5, 0.5, 0) * Box(1, 1, 1)
    touching, apart = Pos(0, 0, 1) * Box(1, 1, 1), Pos(5, 0, 0) * Box(1, 1, 1)
    merged = overlaps_merged([s.wrapped for s in (a, touching, b, apart)])
    volumes = sorted(precise_volume(s) for s in merged)
    assert volumes == pytest.approx([1, 1, 1.75])
    assert merged[1] is touching.wrapped and merged[2] is apart.wrapped


def _gapped_rectangle() -> Face:
    """A 4 x 3 rectangle whose right edge runs 0.01 right of both of its vertices, which their
    tolerance of 0.02 covers: valid, as partition faces with such gaps are."""
    vertices = []
    for x, y in [(0, 0), (4, 0), (4, 3), (0, 3)]:
        v = TopoDS_Vertex()
        BRep_Builder().MakeVertex(v, gp_Pnt(x, y, 0), 0.02)
        vertices.append(v)
    curves = [((0, 0), (4, 0)), ((4.01, 0), (4.01, 3)), ((4, 3), (0, 3)), ((0, 3), (0, 0))]
    wire = BRepBuilderAPI_MakeWire()
    for i, (a, b) in enumerate(curves):
        segment = GC_MakeSegment(gp_Pnt(*a, 0), gp_Pnt(*b, 0)).Value()
        wire.Add(BRepBuilderAPI_MakeEdge(segment, vertices[i], vertices[(i + 1) % 4]).Edge())
    return Face(BRepBuilderAPI_MakeFace(gp_Pln(), wire.Wire(), True).Face())


def test_a_face_whose_curves_miss_its_vertices_sweeps_a_sound_prism_once_its_gaps_are_closed():
    face = _gapped_rectangle()
    depth = Vector(0, 0, 2)
    assert face.is_valid
    assert Solid.extrude(face, depth).volume != pytest.approx(2 * face.area, rel=1e-4)
    healed = Face(gaps_closed(face.wrapped))
    assert healed.is_valid
    assert Solid.extrude(healed, depth).volume == pytest.approx(2 * healed.area, rel=1e-9)
    assert 12.0 - 1e-9 <= healed.area <= face.area

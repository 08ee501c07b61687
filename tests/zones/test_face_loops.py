"""The face-loop rules on real geometry: the looser rule finds walls the strict one misses, and the
strict rule takes over when the looser graph fails its checks."""

from __future__ import annotations

import pytest
from build123d import Box
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Plane
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopoDS import TopoDS

from zonegraph.geometry.occ import sub_shapes
from zonegraph.testing import requires_corpus
from zonegraph.testing.corpus import corpus_shape
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.face_loops import LoopRule, find_face_loops

# A part of 23 faces whose loop along y runs through planar walls with a side split in two or three
# edges where other faces meet it (drawn with seed 7 outside the tuning and validation samples).
SPLIT_WALLS = ("05_8to10ops/batch_003.py", "144780_918f74e1_0000")


def _faces(shape):
    return [TopoDS.Face(f) for f in sub_shapes(shape.wrapped, TopAbs_FACE)]


@requires_corpus
def test_the_loose_rule_takes_walls_with_split_sides():
    faces = _faces(corpus_shape(*SPLIT_WALLS))
    loose, strict = find_face_loops(faces, LoopRule.LOOSE), find_face_loops(faces, LoopRule.STRICT)
    assert set(strict) < set(loose)
    edges = {
        i: len(sub_shapes(BRepTools.OuterWire_s(faces[i]), TopAbs_EDGE)) for i in set(loose) - set(strict)
    }
    assert max(edges.values()) > 4
    assert all(BRepAdaptor_Surface(faces[i]).GetType() == GeomAbs_Plane for i in edges)


@requires_corpus
def test_the_loose_graph_has_fewer_zones_and_still_represents_the_part():
    solids = list(corpus_shape(*SPLIT_WALLS).solids())
    strict = build_zone_graph(solids, samples=0, loop_rules=(LoopRule.STRICT,))
    loose = build_zone_graph(solids, samples=0)
    assert (strict.n_zones, loose.n_zones) == (94, 38)
    assert (strict.info["face_loop_rule"], loose.info["face_loop_rule"]) == ("strict", "loose")
    assert loose.inside_volume == pytest.approx(loose.target_volume, rel=1e-4)


@requires_corpus
def test_the_strict_rule_is_the_fallback_when_the_loose_graph_fails_its_checks():
    """At fuzzy 1e-3 the fuse loses zones and the loose graph's inside zones miss the target; the
    loose rule gets that one partition, the strict rule the whole ladder."""
    solids = list(corpus_shape(*SPLIT_WALLS).solids())
    graph = build_zone_graph(solids, samples=0, fuzzy=(1e-3, 1e-6))
    assert graph.info["face_loop_rule"] == "strict"
    assert graph.info["loose_refused"] == "target_mismatch"
    assert graph.info["fuzzy"] == 1e-6 and graph.n_zones == 94


def test_a_part_both_rules_extend_alike_is_built_once_and_named_strict():
    part = Box(6, 4, 2) - Box(2, 1, 2)  # a through slot: every wall has four straight edges
    graph = build_zone_graph(part, samples=0)
    assert graph.info["face_loop_rule"] == "strict" and "loose_refused" not in graph.info
    assert graph.info["attempts"] == 1
    assert build_zone_graph(part, samples=0, simplify=False).info["face_loop_rule"] is None

"""Zone graphs on real B-reps: invariants, exact reassembly, classification and face loops."""

from __future__ import annotations

import numpy as np
import pytest
from build123d import Box, Cylinder, Pos, Shape
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.TopAbs import TopAbs_FACE, TopAbs_IN
from OCP.TopoDS import TopoDS

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.cells import fuse_zones
from zonegraph.geometry.occ import pnt, sub_shapes
from zonegraph.geometry.shapes import symmetric_difference_volume
from zonegraph.testing import requires_samples, sample_paths
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.face_loops import find_face_loops

DISTINCT = [p for p in sample_paths() if not p.stem.startswith(("SingleSketchExtrude_", "Z0HexagonCutJoin"))]


def final_bodies(path):
    return list(replay(load_design(path)).bodies)


@requires_samples
@pytest.mark.parametrize("simplify", [True, False], ids=["simplified", "full"])
@pytest.mark.parametrize("path", DISTINCT, ids=lambda p: p.stem)
def test_invariants_on_real_samples(path, simplify):
    graph = build_zone_graph(final_bodies(path), simplify=simplify, samples=16, source=str(path))
    # build_zone_graph checks the invariants itself; restate them so a regression reads clearly.
    assert graph.zone_volume.sum() == pytest.approx(graph.box_volume, rel=1e-6)
    assert graph.inside_volume == pytest.approx(graph.target_volume, rel=1e-4)
    assert np.isfinite(graph.zone_interior).all()
    assert graph.info["status"] == "ok" and graph.info["simplified"] is simplify
    if graph.n_zones > 1:
        assert len(graph.edges) >= graph.n_zones - 1


@requires_samples
@pytest.mark.parametrize(
    "name",
    [
        "Pattern2_6c40bf33_0000",
        "Pattern4_f830f176_0000",
        "Couch",
        "Hexagon",
        "51022_47816098_0003",
        "Pattern4-SteppedStartEndFace_17dd857d_0000",
    ],
)
def test_inside_zones_fuse_back_to_the_target(samples_dir, name):
    bodies = final_bodies(samples_dir / f"{name}.json")
    graph = build_zone_graph(bodies, samples=0)
    rebuilt = Shape.cast(fuse_zones(graph.solids, np.flatnonzero(graph.zone_inside)))
    assert len(bodies) == 1
    target = Shape.cast(graph.normalization.apply(bodies[0].wrapped))
    assert rebuilt.volume == pytest.approx(graph.target_volume, rel=1e-6)
    assert symmetric_difference_volume(rebuilt, target) <= 1e-4 * graph.target_volume


def test_ring_zone_with_centroid_outside_is_labelled_inside():
    part = Box(4, 4, 1) - Cylinder(1, 1)  # a plate with a through hole: the ring zone is not convex
    graph = build_zone_graph(part, samples=32)
    assert graph.n_zones == 2 and sorted(graph.zone_inside) == [False, True]
    ring = int(np.flatnonzero(graph.zone_inside)[0])
    clf = BRepClass3d_SolidClassifier(graph.solids[ring])
    clf.Perform(pnt(graph.zone_centroid[ring]), 1e-9)
    assert clf.State() != TopAbs_IN  # the centroid lies in the hole...
    clf.Perform(pnt(graph.zone_interior[ring]), 1e-9)
    assert clf.State() == TopAbs_IN  # ...the verified interior point does not


@pytest.mark.parametrize(
    "part, full, simplified",
    [
        (Box(6, 4, 2) - Box(2, 1, 2), 9, 2),  # through slot
        (Box(6, 4, 2) - Pos(0, 0, 0.5) * Box(2, 1, 1), 18, 4),  # pocket
    ],
    ids=["through-slot", "pocket"],
)
def test_face_loop_simplification_lowers_zone_count(part, full, simplified):
    a = build_zone_graph(part, simplify=False, samples=0)
    b = build_zone_graph(part, simplify=True, samples=0)
    assert (a.n_zones, b.n_zones) == (full, simplified)
    assert b.surface_strip.sum() == 4  # the four walls became strips along z
    for g in (a, b):
        assert g.inside_volume == pytest.approx(g.target_volume, rel=1e-4)


def test_face_loops_of_a_slot():
    part = Box(6, 4, 2) - Box(2, 1, 2)
    faces = [TopoDS.Face(f) for f in sub_shapes(part.wrapped, TopAbs_FACE)]
    loops = find_face_loops(faces)
    z_walls = [i for i, dirs in loops.items() if any(abs(d[2]) > 0.999 for d in dirs)]
    assert len(z_walls) == 8  # the slot's 4 walls and the box's 4 sides
    assert len(loops) == len(faces)  # top and bottom also close loops with the sides, along x and y


def test_two_separate_bodies(samples_dir):
    bodies = final_bodies(samples_dir / "Z0DoubleProfileSketchExtrude_795c7869_0000.json")
    assert len(bodies) == 2
    graph = build_zone_graph(bodies, samples=0)
    assert graph.info["target_solids"] == 2 and graph.zone_inside.sum() == 2

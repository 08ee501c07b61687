"""Sweeps past faces that are not side walls of the prism: a dangling face inside a zone, and a
curved cap that joins the columns of neighbouring sketch faces."""

from __future__ import annotations

import numpy as np
from build123d import Align, Box, Cylinder, Plane, Pos, Rot

from zonegraph.sequence.ground_truth import map_tool
from zonegraph.sequence.proposals import Op, ProposalGenerator
from zonegraph.zones.build import build_zone_graph


def test_a_block_under_a_post_is_proposed_past_a_dangling_strip_face():
    """A block with a post on top and a small slot cut in its front (corpus design
    25186_e5476b73_0003): the slot's face-loop strips end inside the block's zone, and the sweep
    used to stop at them as if they were the box's boundary, so the block was never proposed."""
    block = Plane.XZ * Box(0.8, 0.3, 0.7, align=(Align.CENTER, Align.CENTER, Align.MAX))
    post = Pos(0, 0.7, 0) * Box(0.2, 0.6, 0.2, align=(Align.CENTER, Align.MIN, Align.CENTER))
    slot = Pos(-0.35988, 0, -0.55) * Box(0.01988, 0.02, 0.7, align=Align.MIN)
    graph = build_zone_graph([block + post - slot], samples=0)
    generator = ProposalGenerator(graph)
    assert generator.internal.any()  # the case under test: a face with one zone, off the box
    zones, error = map_tool(graph, block.wrapped)
    assert error < 1e-4
    proposals = generator.proposals(np.zeros(graph.n_zones, bool))
    assert (np.packbits(zones).tobytes(), int(Op.UNION)) in {p.key for p in proposals}


def test_a_cylinder_across_the_sweep_joins_its_faces_into_one_prism():
    """A box minus a cylinder lying across z that cuts the bottom plane: its bottom holds three
    faces (left, under the cylinder, right) and the sweep from any one runs over the cylinder
    into the others' zones, so each face's prism is the whole box and needs the other two."""
    box = Box(4, 2, 2, align=(Align.CENTER, Align.CENTER, Align.MIN))
    graph = build_zone_graph([box - Pos(0, 0, 0.5) * Rot(90, 0, 0) * Cylinder(1, 2)], samples=0)
    generator = ProposalGenerator(graph)
    along_z = [int(s) for s in graph.planes if abs(graph.surface_normal[s, 2]) == 1]
    bottom, top = sorted(along_z, key=lambda s: graph.surface_offset[s] * graph.surface_normal[s, 2])
    faces = tuple(sorted(int(f) for f in generator.faces_on[bottom]))
    assert len(faces) == 3
    swept = generator.sweep(faces[0], bottom, top)
    assert swept is not None and swept.faces == faces and swept.zones.all()
    assert generator.extrusion(faces[:2], bottom, top) is None  # the prism needs all three
    assert generator.extrusion(faces, bottom, top).all()

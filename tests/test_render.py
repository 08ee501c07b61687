"""Pictures of a zone graph: the part beside its zones, pushed apart."""

import pytest
from build123d import Box, BuildPart, Cylinder, Mode
from PIL import Image

import zonegraph as zg
from zonegraph.export.render import render_zone_graph


def _plate_with_a_hole():
    with BuildPart() as part:
        Box(30, 20, 4)
        Cylinder(3, 4, mode=Mode.SUBTRACT)
    return part.part


def test_a_zone_graph_renders_the_part_beside_its_zones(tmp_path):
    part = _plate_with_a_hole()
    graph = zg.build_zone_graph(part)
    png = render_zone_graph(graph, tmp_path / "zones.png", part)
    width, height = Image.open(png).size
    assert width > 1.8 * height  # two panels side by side
    alone = render_zone_graph(graph, tmp_path / "alone.png")
    assert Image.open(alone).size[0] < width  # without the part: one panel


def test_a_graph_without_its_solids_cannot_be_drawn(tmp_path):
    graph = zg.build_zone_graph(_plate_with_a_hole(), keep_solids=False)
    with pytest.raises(ValueError, match="no zone solids"):
        render_zone_graph(graph, tmp_path / "zones.png")

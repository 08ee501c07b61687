"""Ground-truth sequences mapped onto zone graphs of the real samples."""

from __future__ import annotations

import numpy as np
import pytest
from build123d import Box, Cylinder

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.sequence.ground_truth import MAPPING_RTOL, ground_truth, map_tool
from zonegraph.testing import requires_samples, sample_paths
from zonegraph.zones.build import build_zone_graph


def _gt(path, levels=(1,)):
    r = replay(load_design(path))
    graph = build_zone_graph(list(r.bodies), samples=0)
    ops = [s["operation"] for s in r.summary()["steps"]]
    return graph, ground_truth(graph, [s.tool.wrapped for s in r.steps], ops, levels)


@requires_samples
@pytest.mark.parametrize("path", sample_paths(), ids=lambda p: p.stem[:40])
def test_every_sample_maps_and_replays_to_its_target(path):
    graph, gt = _gt(path)
    assert gt.reaches_target, gt.reason
    for step in gt.steps:
        assert step.mapped and step.mapping_error <= MAPPING_RTOL
        assert step.proposals[1] >= 0 and (step.captured[1] or step.reason)


@requires_samples
def test_captured_and_intersect_steps(samples_dir):
    _, couch = _gt(samples_dir / "Couch.json", levels=(1, 3))
    assert couch.captured(1) and couch.captured(3)
    _, inter = _gt(samples_dir / "Z0Intersect_b6eca862_0000.json")
    assert not inter.captured(1) and inter.steps[-1].reason == "intersect has no extrusion proposal"


def test_through_cut_tool_is_clipped_to_the_box():
    part = Box(4, 4, 1) - Cylinder(1, 1)
    graph = build_zone_graph(part, samples=0, simplify=False)
    zones, error = map_tool(graph, Cylinder(1, 10).wrapped)  # reaches far outside the box
    assert error <= MAPPING_RTOL
    assert not (zones & graph.zone_inside).any() and zones.any()
    assert np.isclose(graph.zone_volume[zones].sum(), np.pi * graph.normalization.scale**3, rtol=1e-3)

"""Proposals on real corpus parts that used to miss the one a program needs (issues 13 and 23)."""

from __future__ import annotations

import numpy as np
import pytest

from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.proposals import Op, ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.testing import requires_corpus
from zonegraph.testing.corpus import corpus_shape
from zonegraph.zones.build import build_zone_graph

pytestmark = requires_corpus


def test_a_prism_across_a_crossing_cylinder_is_proposed():
    """A cube trimmed by two cylinders on crossing axes: every prism along one axis crosses the
    other cylinder's wall, which the sweep used to treat as a side wall (no proposal at all)."""
    graph = build_zone_graph(corpus_shape("04_6to7ops/batch_006.py", "33655_f8991a06_0004"), samples=0)
    generator = ProposalGenerator(graph)
    proposals = generator.proposals(np.zeros(graph.n_zones, bool))
    assert proposals
    crossing = [p for p in proposals if p.zones.sum() > 1 and (p.zones & graph.zone_inside).any()]
    assert crossing  # a union that takes zones on both sides of a curved wall


@pytest.mark.parametrize(
    ("batch", "design_id"),
    [
        ("03_4to5ops/batch_007.py", "25364_b3985755_0002"),  # a through-cut across a boss
        ("04_6to7ops/batch_007.py", "41599_f66b4e5b_0010"),  # a body drawn past the part, then cut
        ("05_8to10ops/batch_007.py", "42601_bfe96b47_0006"),  # three pockets from the box face
    ],
)
def test_a_sketch_set_by_what_its_prism_reaches_is_proposed(batch, design_id):
    """Each part needs an extrusion whose sketch faces lie next to zones outside both canvas and
    target, joined on the sketch plane to faces that must not be extruded: the search used to
    exhaust its space without an exact program."""
    graph = build_zone_graph(corpus_shape(batch, design_id), samples=0)
    result = search(graph, HeuristicRanker(), SearchConfig(budget_s=10), ProposalGenerator(graph))
    assert result.exact
    assert Op.SUBTRACT in [p.op for p in result.steps]

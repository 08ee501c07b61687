"""Proposals on real corpus parts that used to have none on the empty canvas (issue 13)."""

from __future__ import annotations

import numpy as np

from zonegraph.sequence.proposals import ProposalGenerator
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

"""Budgets hold on a real graph of many zones: a deadline passed in the middle of an expansion stops
proposal generation there (issue 23: one expansion on 3,012 zones ran 35 s of a 20 s budget).

The deadlines here run on a clock that ticks once per check, so what is asserted is how much work
is done after the deadline passes, not how many seconds it took (timings: ``bench/budget_bench.py``).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.deadline import Deadline
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.testing import requires_corpus
from zonegraph.testing.corpus import corpus_shape
from zonegraph.zones.build import build_zone_graph

pytestmark = requires_corpus

UNBOUNDED = SearchConfig(budget_s=math.inf)


@pytest.fixture(scope="module")
def graph():
    """The unsimplified graph of a 16-to-20-operation corpus part: 1,487 zones."""
    shape = corpus_shape("07_16to20ops/batch_003.py", "61469_c09267fc_0000")
    return build_zone_graph(shape, simplify=False, samples=0)


def ticking(at: int) -> Deadline:
    """A deadline that passes at the check after the ``at``-th."""
    ticks = itertools.count(1)
    return Deadline(at, lambda: next(ticks))


def root_checks(graph) -> int:
    """The checks a full first expansion makes (one per sketch swept)."""
    deadline = Deadline()
    search(graph, HeuristicRanker(), SearchConfig(budget_s=math.inf, max_expansions=1), deadline=deadline)
    return deadline.checks


def test_a_deadline_passed_mid_expansion_stops_the_search_there(graph):
    checks = root_checks(graph)
    assert checks > 100  # the first expansion alone is a long piece of work
    deadline = ticking(checks // 2)
    result = search(graph, HeuristicRanker(), UNBOUNDED, ProposalGenerator(graph), deadline)
    # generation returns at the first check past the deadline; the search then looks once before
    # scoring and once before its next step, and does nothing in between
    assert deadline.expired_checks <= 3
    assert deadline.checks <= checks // 2 + 3
    assert result.expansions == 1 and result.steps == [] and not result.exact
    assert not result.canvas.any()  # the best so far: the empty canvas
    assert result.ended == "budget"  # what the reason of a partial result reports


def test_an_interrupted_generator_finishes_later_as_a_fresh_one(graph):
    """A face group cut short by the deadline is not memoised as if it were complete."""
    empty = np.zeros(graph.n_zones, bool)
    generator = ProposalGenerator(graph)
    partial = generator.proposals(empty, ticking(root_checks(graph) // 3))
    full = generator.proposals(empty)
    assert 0 < len(partial) < len(full)
    assert [p.key for p in full] == [p.key for p in ProposalGenerator(graph).proposals(empty)]


def test_an_unbounded_deadline_changes_nothing(graph):
    bounded = SearchConfig(budget_s=math.inf, max_expansions=30)
    runs = [
        search(graph, HeuristicRanker(), bounded, deadline=Deadline()),
        search(graph, HeuristicRanker(), bounded),
    ]
    assert [p.key for p in runs[0].steps] == [p.key for p in runs[1].steps]
    assert runs[0].proposals_per_state == runs[1].proposals_per_state
    assert {r.ended for r in runs} <= {"exact", "expansions"}

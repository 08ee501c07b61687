"""Proposal rules on small hand-made parts, and search invariants."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from build123d import Box, Cylinder, Pos

from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker, RandomRanker, zone_iou
from zonegraph.zones.build import build_zone_graph


def graph_of(part, simplify=True):
    return build_zone_graph(part, simplify=simplify, samples=0)


def test_plate_with_hole_needs_a_subtraction_or_a_ring():
    g = graph_of(Box(4, 4, 1) - Cylinder(1, 1))
    gen = ProposalGenerator(g)
    empty = np.zeros(g.n_zones, bool)
    first = gen.proposals(empty)
    assert all(p.op is Op.UNION for p in first)  # nothing to subtract from an empty canvas
    assert any(np.array_equal(p.zones, g.zone_inside) for p in first)  # the ring itself
    plate = next(p for p in first if p.zones.all())  # or the whole plate...
    holes = [p for p in gen.proposals(plate.apply(empty)) if p.op is Op.SUBTRACT]
    assert any(np.array_equal(p.apply(plate.apply(empty)), g.zone_inside) for p in holes)  # ...then the hole


def test_step_needs_two_unions():
    part = Box(4, 4, 1) + Pos(0, 0, 1) * Box(2, 2, 1)  # a block on a plate: no single prism
    g = graph_of(part)
    gen = ProposalGenerator(g)
    empty = np.zeros(g.n_zones, bool)
    assert not any(np.array_equal(p.apply(empty), g.zone_inside) for p in gen.proposals(empty))
    result = search(g, HeuristicRanker(), SearchConfig(budget_s=10), gen)
    assert result.exact and [p.op for p in result.steps] == [Op.UNION, Op.UNION]


def test_no_proposal_leaves_the_canvas_unchanged():
    g = graph_of(Box(4, 4, 1) - Cylinder(1, 1), simplify=False)
    gen = ProposalGenerator(g)
    for canvas in (np.zeros(g.n_zones, bool), g.zone_inside.copy(), np.ones(g.n_zones, bool)):
        props = gen.proposals(canvas)
        assert props and all(not np.array_equal(p.apply(canvas), canvas) for p in props)
        for p in props:  # and each proposal's type matches where its volume lies
            if p.op is Op.UNION:
                assert (p.zones & ~canvas).any()
            else:
                assert (p.zones & canvas).any()


def test_sweeps_fill_their_prisms_exactly():
    g = graph_of(Box(6, 4, 2) - Pos(0, 0, 0.5) * Box(2, 1, 1), simplify=False)
    gen = ProposalGenerator(g)
    gen.proposals(np.zeros(g.n_zones, bool))
    for (face, s, e), swept in gen._sweeps.items():
        if swept is not None:
            length = np.linalg.norm(gen.direction(s, e))
            assert face in swept.faces
            area = g.face_area[list(swept.faces)].sum()
            assert g.zone_volume[swept.zones].sum() == pytest.approx(area * length, rel=1e-4)


def test_search_never_undoes_its_own_steps():
    g = graph_of(Box(4, 4, 1) + Pos(0, 0, 1) * Box(2, 2, 1) - Cylinder(0.5, 4), simplify=False)
    result = search(g, RandomRanker(seed=3), SearchConfig(budget_s=3))
    keys = [p.key for p in result.steps]
    assert not any(p.inverse_key in keys[:i] for i, p in enumerate(result.steps))
    assert result.iou == pytest.approx(zone_iou(g, result.canvas, g.zone_inside))
    assert [t for t, _ in result.trace] == sorted(t for t, _ in result.trace)


def test_heuristic_prefers_agreeing_proposals():
    g = graph_of(Box(4, 4, 1) - Cylinder(1, 1))
    gen = ProposalGenerator(g)
    empty = np.zeros(g.n_zones, bool)
    props = gen.proposals(empty)
    scores = HeuristicRanker().score(g, empty, props)
    assert np.array_equal(props[int(np.argmax(scores))].zones, g.zone_inside)


def test_random_ranker_is_seeded():
    g = graph_of(Box(4, 4, 1) - Cylinder(1, 1))
    bounded = SearchConfig(budget_s=float("inf"), max_expansions=40)  # work, not wall clock, bounds it
    runs = [search(g, RandomRanker(seed=5), bounded) for _ in range(2)]
    assert [p.key for p in runs[0].steps] == [p.key for p in runs[1].steps]
    assert runs[0].expansions == runs[1].expansions
    assert runs[0].proposals_per_state == runs[1].proposals_per_state


def test_proposals_compare_and_hash_by_what_they_do():
    g = graph_of(Box(4, 4, 1) - Cylinder(1, 1), simplify=False)
    gen = ProposalGenerator(g)
    props = gen.proposals(np.zeros(g.n_zones, bool))
    twin = Proposal(props[0].end, props[0].start, (), props[0].zones.copy(), props[0].op)
    assert twin == props[0] and hash(twin) == hash(props[0])
    assert len(set(props)) == len(props)  # the generator already removes duplicates
    other = Proposal(props[0].start, props[0].end, props[0].faces, props[0].zones, Op(-props[0].op))
    assert other != props[0]
    assert repr(props[0]).startswith("Proposal(union") and "zones" in repr(g)


def test_zone_iou_is_never_above_one():
    """Zones outside the target far smaller than the float rounding of the target's volume (the
    slivers of a fuzzy fuse): summed as one union they made a wrong canvas score above 1."""
    rng = np.random.default_rng(0)
    everything = np.ones(40, bool)
    for _ in range(200):
        target = rng.random(40) < 0.5
        volumes = rng.random(40) * rng.choice([1, 1e-3, 1e-6], 40)
        graph = SimpleNamespace(zone_volume=np.where(target, volumes, 1e-17 * volumes))
        assert zone_iou(graph, everything, target) <= 1.0
        assert zone_iou(graph, target, target) == 1.0


class CountingRanker:
    """The heuristic reversed (its worst proposal first), counting the states it is asked about."""

    def __init__(self) -> None:
        self.calls = 0

    def score(self, graph, canvas, proposals):
        self.calls += 1
        return -HeuristicRanker().score(graph, canvas, proposals)


def test_a_step_that_completes_the_target_is_taken_without_scoring():
    ring = graph_of(Box(4, 4, 1) - Cylinder(1, 1))  # one extrusion of the ring completes it
    ranker = CountingRanker()
    result = search(ring, ranker, SearchConfig(budget_s=10))
    assert result.exact and len(result.steps) == 1 and result.expansions == 1
    assert ranker.calls == 0  # the reversed ranker would have put the ring last
    step = graph_of(Box(4, 4, 1) + Pos(0, 0, 1) * Box(2, 2, 1))  # two unions: the first is scored
    ranker = CountingRanker()
    result = search(step, ranker, SearchConfig(budget_s=10, k=50))
    assert result.exact and ranker.calls == result.expansions - 1


class Wanderer:
    """Tries only the state's worst proposal by the heuristic; with ``after``, offers a second walk
    in the heuristic's order after that many expansions."""

    def __init__(self, after: int | None = None) -> None:
        self.after = after

    def score(self, graph, canvas, proposals):
        return -HeuristicRanker().score(graph, canvas, proposals)

    def order_at(self, graph, canvas, proposals, step, k):
        return iter([int(np.argmax(self.score(graph, canvas, proposals)))])

    def relay(self):
        return None if self.after is None else (self.after, HeuristicRanker)


def test_a_relay_walk_from_the_empty_canvas_takes_turns_with_the_first():
    """A plate with a boss, a hole and a pocket (several steps): the wanderer's own walk never
    reaches it; with a relay after 3 expansions the heuristic's walk starts from the empty canvas
    and, a state each, finds the heuristic's own program, at the cost of the wanderer's turns."""
    part = Box(6, 4, 1) + Pos(-1.5, 0, 1) * Cylinder(0.8, 1) - Pos(1.5, 1, 0) * Cylinder(0.4, 1)
    g = graph_of(part - Pos(1.5, -1, 0.5) * Box(1, 1, 0.5))
    config = SearchConfig(budget_s=20, max_expansions=400)
    alone = search(g, Wanderer(), config)
    heuristic = search(g, HeuristicRanker(), config)
    relayed = search(g, Wanderer(after=3), config)
    assert not alone.exact and alone.ended == "exhausted" and heuristic.exact
    assert relayed.exact and [p.key for p in relayed.steps] == [p.key for p in heuristic.steps]
    first_walk = min(heuristic.expansions - 1, alone.expansions - 3)  # its turns after the relay began
    assert relayed.expansions == 3 + heuristic.expansions + first_walk

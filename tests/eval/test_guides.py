"""Guides named on a command line, with a network's knobs."""

from __future__ import annotations

import pytest

from eval.guides import GuideSpec
from eval.rank import make_guides
from zonegraph.network.folded import SHIPPED_FOLDED
from zonegraph.network.ranker import NetworkRanker
from zonegraph.sequence.rankers import HeuristicRanker


def test_a_network_spec_carries_its_knobs_to_the_ranker():
    spec = GuideSpec.parse(f"net={SHIPPED_FOLDED}@top_m=4,blend=0.25")
    assert (spec.name, spec.model, dict(spec.knobs)) == (
        "net",
        str(SHIPPED_FOLDED),
        {"top_m": 4, "blend": 0.25},
    )
    ranker = spec.ranker(0)
    assert isinstance(ranker, NetworkRanker) and (ranker.top_m, ranker.blend) == (4, 0.25)
    assert GuideSpec.parse("heuristic") == GuideSpec("heuristic", "heuristic")
    assert spec.label == "net:shipped@top_m=4,blend=0.25"
    assert GuideSpec.parse("net").label == GuideSpec.parse("net=").label == "net:shipped"
    assert GuideSpec.parse("net=runs/whole/scorer.npz").label == "net:whole"
    with pytest.raises(SystemExit, match="unknown option"):
        GuideSpec.parse("net=x.pt@depth=3")
    deferring = GuideSpec.parse("net=@defer=1")
    assert deferring.label == "net:shipped@defer=1" and deferring.ranker(0).defer


def test_the_shipped_network_named_without_a_path_holds_out_its_training_projects():
    """``net`` alone is the shipped scorer, whose training designs a benchmark must not search."""
    shipped = str(SHIPPED_FOLDED)
    assert GuideSpec.parse("net").checkpoint == GuideSpec.parse("net=@top_m=2").checkpoint == shipped
    assert GuideSpec.parse("net=runs/a.npz").checkpoint == "runs/a.npz"
    assert GuideSpec.parse("heuristic").checkpoint is None


def test_rank_guides_take_network_specs_beside_plain_checkpoints():
    guides = make_guides(["heuristic"], [str(SHIPPED_FOLDED), f"{SHIPPED_FOLDED}@top_m=2"])
    assert isinstance(guides["heuristic"], HeuristicRanker)
    assert guides["net:checkpoints"].top_m == 8 and guides["net:checkpoints@top_m=2"].top_m == 2

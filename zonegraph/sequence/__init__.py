"""Sequence search (paper sec. 4): extrusion proposals, rankers, best-first search, programs.

``proposals`` holds every proposal rule, ``rankers`` the random and heuristic guides and the
`Ranker` protocol a learned guide satisfies, ``best_first`` the top-k search with
backtracking, and ``program`` turns a found sequence into real sketches and extrusions rebuilt
with build123d. Imports `zonegraph.zones` and `zonegraph.geometry`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "SearchConfig": "zonegraph.sequence.best_first",
    "SearchResult": "zonegraph.sequence.best_first",
    "search": "zonegraph.sequence.best_first",
    "ProgramStep": "zonegraph.sequence.program",
    "RebuildError": "zonegraph.sequence.program",
    "brep_iou": "zonegraph.sequence.program",
    "build_program": "zonegraph.sequence.program",
    "execute": "zonegraph.sequence.program",
    "Op": "zonegraph.sequence.proposals",
    "Proposal": "zonegraph.sequence.proposals",
    "ProposalGenerator": "zonegraph.sequence.proposals",
    "HeuristicRanker": "zonegraph.sequence.rankers",
    "RandomRanker": "zonegraph.sequence.rankers",
    "Ranker": "zonegraph.sequence.rankers",
    "make_ranker": "zonegraph.sequence.rankers",
    "relative_rank": "zonegraph.sequence.rankers",
    "zone_iou": "zonegraph.sequence.rankers",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.sequence.best_first import SearchConfig, SearchResult, search
    from zonegraph.sequence.program import ProgramStep, RebuildError, brep_iou, build_program, execute
    from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
    from zonegraph.sequence.rankers import (
        HeuristicRanker,
        RandomRanker,
        Ranker,
        make_ranker,
        relative_rank,
        zone_iou,
    )

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)

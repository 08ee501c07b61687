"""Sequence search (paper sec. 4): extrusion proposals, rankers, best-first search, programs.

``proposals`` holds every proposal rule, ``rankers`` the random and heuristic guides and the
:class:`Ranker` protocol a learned guide satisfies, ``best_first`` the top-k search with
backtracking, and ``program`` turns a found sequence into real sketches and extrusions rebuilt
with build123d. Imports :mod:`zonegraph.zones` and :mod:`zonegraph.geometry`.
"""

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

__all__ = [
    "HeuristicRanker",
    "Op",
    "ProgramStep",
    "Proposal",
    "ProposalGenerator",
    "RandomRanker",
    "Ranker",
    "RebuildError",
    "SearchConfig",
    "SearchResult",
    "brep_iou",
    "build_program",
    "execute",
    "make_ranker",
    "relative_rank",
    "search",
    "zone_iou",
]

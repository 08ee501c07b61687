"""Rankers: how a search orders the proposals of one state (paper sec. 4.2).

A ranker sees all proposals of a state at once and returns one score each (higher is better), so a
learned ranker can score a whole state in one batched pass. ``RandomRanker`` is the paper's random
baseline (seeded); ``HeuristicRanker`` is its hand-made score: the share of zones whose label
agrees with the target after the operation, ties broken by volumetric IoU.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from zonegraph.plugins import guide_factory, guide_problem
from zonegraph.sequence.proposals import Proposal
from zonegraph.zones.model import ZoneGraph


def zone_iou(graph: ZoneGraph, canvas: np.ndarray, target: np.ndarray) -> float:
    """vol(C and T) / vol(C or T), from zone volumes.

    The union is summed as the common part plus the symmetric difference, so the ratio is at most
    1 and is 1 only when they differ by no volume (summed separately, float rounding reported a
    near-exact canvas of a corpus part as 1.00000000000015, above the exact one)."""
    inter = float(graph.zone_volume[canvas & target].sum())
    union = inter + float(graph.zone_volume[canvas ^ target].sum())
    return inter / union if union > 0 else 1.0


class Ranker(Protocol):
    """Scores all proposals of one state in one call (a network batches them); higher is better."""

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """One score per proposal, higher first.

        Shapes:
            canvas: (Z,) bool; returns (P,) float for P proposals.
        """
        ...


@dataclass
class RandomRanker:
    """The paper's random baseline: uniform scores from a generator seeded once per search."""

    seed: int = 0
    rng: np.random.Generator = field(init=False)

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.seed)

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """(P,) uniform random scores."""
        return self.rng.random(len(proposals))


class HeuristicRanker:
    """The paper's heuristic: the share of zones whose label agrees with the target after the
    operation, ties broken by volumetric IoU (scaled below the smallest label step)."""

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """(P,) scores: label agreement in [0, 1] plus a tie-breaking IoU below 1 / (Z + 1)."""
        target = graph.zone_inside
        after = np.stack([p.apply(canvas) for p in proposals])  # (P, Z)
        agree = (after == target).sum(axis=1) / graph.n_zones
        inter = (after & target) @ graph.zone_volume
        union = (after | target) @ graph.zone_volume
        iou = np.divide(inter, union, out=np.ones_like(inter), where=union > 0)
        return agree + iou / (graph.n_zones + 1)


def make_ranker(guide: str, seed: int = 0, model: str | None = None) -> Ranker:
    """The ranker a guide name stands for: ``heuristic``, ``random`` (seeded), or one that
    :mod:`zonegraph.plugins` loads by reference.

    Those are called with ``model`` and ``seed``: the network guide ``net``
    (:class:`zonegraph.network.ranker.NetworkRanker`, with the train extra) and the entry points
    of installed packages in the ``zonegraph.rankers`` group. This is how they reach the search
    without this layer importing torch.

    Raises:
        ValueError: an unknown guide, or a shipped guide whose extra is not installed.
    """
    if guide == "heuristic":
        return HeuristicRanker()
    if guide == "random":
        return RandomRanker(seed)
    factory = guide_factory(guide)
    if factory is None:
        raise ValueError(guide_problem(guide) or f"unknown guide {guide!r}")
    ranker: Ranker = factory(model=model, seed=seed)
    return ranker


def relative_rank(scores: np.ndarray, is_gt: np.ndarray) -> float:
    """The GT's rank among a state's proposals divided by their number (the paper's metric:
    1/P when the GT scores highest, about 0.5 for random scores; ties count half).

    Shapes:
        scores: (P,) float, higher first; is_gt: (P,) bool with exactly one true.
    """
    scores = np.where(np.isnan(scores), -np.inf, scores)  # a NaN score ranks last, never first
    gt = float(scores[np.flatnonzero(is_gt)[0]])
    others = np.delete(scores, np.flatnonzero(is_gt)[0])
    rank = 1 + float((others > gt).sum()) + 0.5 * float((others == gt).sum())
    return rank / len(scores)

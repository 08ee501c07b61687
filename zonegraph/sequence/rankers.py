"""Rankers: how a search orders the proposals of one state (paper sec. 4.2).

A ranker sees all proposals of a state at once and returns one score each (higher is better), so a
learned ranker can score a whole state in one batched pass. ``RandomRanker`` is the paper's random
baseline (seeded); ``HeuristicRanker`` is its hand-made score: the share of zones whose label
agrees with the target after the operation, ties broken by volumetric IoU.
"""

from __future__ import annotations

from collections.abc import Iterator
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
    near-exact canvas of a corpus part as 1.00000000000015, above the exact one). Degenerate zones
    of the fuse measure -1e-16 or so and count as empty, which kept such a canvas above 1."""
    volume = np.maximum(graph.zone_volume, 0.0)
    inter = float(volume[canvas & target].sum())
    union = inter + float(volume[canvas ^ target].sum())
    return inter / union if union > 0 else 1.0


def zone_exact(graph: ZoneGraph, canvas: np.ndarray, target: np.ndarray) -> bool:
    """Whether ``canvas`` is the target up to degenerate zones (volume 0 or a rounding below it):
    a search that waited for those too spent its whole budget on a part it had already found
    (a 627-zone corpus part differed in one zone of -1.6e-16)."""
    return not bool((graph.zone_volume[canvas ^ target] > 0).any())


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


def score_step(
    ranker: Ranker, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal], step: int
) -> np.ndarray:
    """(P,) scores of one state ``step`` operations deep: a ranker that reads the depth (the
    network with proposal features: the step index is one of them) offers ``score_at``; every
    other ranker is called through the protocol's ``score``."""
    score_at = getattr(ranker, "score_at", None)
    if score_at is not None:
        return np.asarray(score_at(graph, canvas, proposals, step), float)
    return np.asarray(ranker.score(graph, canvas, proposals), float)


def order_step(
    ranker: Ranker, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal], step: int, k: int
) -> Iterator[int]:
    """The indices of at most ``k`` proposals of one state, best first, as a search tries them.

    A ranker that can put off work until the search asks for a state's second choice (the network
    guide scores a state only when the search backtracks to it, with ``defer``) offers ``order_at``;
    every other ranker's ``k`` best scores are sorted at once (ties keep the generator's order)."""
    order_at = getattr(ranker, "order_at", None)
    if order_at is not None:
        return iter(order_at(graph, canvas, proposals, step, k))
    return iter(best_first(score_step(ranker, graph, canvas, proposals, step))[:k])


def best_first(scores: np.ndarray) -> list[int]:
    """Indices of ``scores``, highest first; ties keep the generator's order."""
    return np.argsort(-scores, kind="stable").tolist()


def make_ranker(guide: str, seed: int = 0, model: str | None = None) -> Ranker:
    """The ranker a guide name stands for: ``heuristic``, ``random`` (seeded), or one that
    `zonegraph.plugins` loads by reference.

    Those are called with ``model`` and ``seed``: the network guide ``net``
    (`zonegraph.network.ranker.NetworkRanker`, with the train extra) and the entry points
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


@dataclass(frozen=True)
class GTPlace:
    """Where the GT landed among a state's P proposals: ``above`` others scored higher, ``ties``
    scored the same (ties are broken uniformly at random, so they count half in the rank).

    Three scales of one rank: `relative` is the paper's rank / P (1/P at best, about
    (P + 1) / 2P for random scores, so it depends on P), `normalised` is (rank - 1) / (P - 1)
    (0 at best, 0.5 for random scores at any P; undefined for one proposal), `floor` is the
    best possible rank / P of the state.
    """

    above: int
    ties: int
    proposals: int

    @property
    def rank(self) -> float:
        """1-based rank, ties counting half."""
        return 1 + self.above + 0.5 * self.ties

    @property
    def relative(self) -> float:
        return self.rank / self.proposals

    @property
    def normalised(self) -> float:
        return (self.rank - 1) / (self.proposals - 1) if self.proposals > 1 else float("nan")

    @property
    def floor(self) -> float:
        return 1 / self.proposals

    def hit(self, k: int) -> float:
        """Probability that the GT is among the first ``k`` (under the random tie-break)."""
        return float(np.clip((k - self.above) / (self.ties + 1), 0.0, 1.0))


def gt_place(scores: np.ndarray, is_gt: np.ndarray) -> GTPlace:
    """The GT's place among one state's scored proposals (a NaN score ranks last, never first).

    Shapes:
        scores: (P,) float, higher first; is_gt: (P,) bool with exactly one true.
    """
    scores = np.where(np.isnan(scores), -np.inf, np.asarray(scores, float))
    at = int(np.flatnonzero(is_gt)[0])
    gt, others = float(scores[at]), np.delete(scores, at)
    return GTPlace(int((others > gt).sum()), int((others == gt).sum()), len(scores))


def relative_rank(scores: np.ndarray, is_gt: np.ndarray) -> float:
    """The GT's rank among a state's proposals divided by their number (the paper's metric:
    1/P when the GT scores highest, about 0.5 for random scores at large P; ties count half).

    Shapes:
        scores: (P,) float, higher first; is_gt: (P,) bool with exactly one true.
    """
    return gt_place(scores, is_gt).relative

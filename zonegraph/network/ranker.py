"""The network guide: a trained scorer behind the search's ``Ranker`` protocol.

:mod:`zonegraph.plugins` names it as the ``net`` guide by reference, and offers it only where
torch and torch_geometric can be found, so ``zonegraph infer PART --guide net`` and
``make_ranker("net")`` import this module (and torch) only when the guide is used. The model is
loaded once; with late fusion a graph's zone geometry is encoded once and every state's proposals
are scored in one batched pass, in eval mode.

Scoring counts inside the search's budget, so two knobs trade the network's cost against the
heuristic's: ``top_m`` scores only the heuristic's best M proposals of a state with the network
(the rest follow, in the heuristic's order, below every scored one), and ``blend`` mixes the
heuristic's score into the network's (``(1 - blend) * net + blend * heuristic``). A checkpoint
may carry its own defaults for both (its ``search`` entry); the arguments override them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from zonegraph.network.checkpoint import SHIPPED, read_checkpoint, scorer_from
from zonegraph.network.encoding import Geometry, geometry_of
from zonegraph.network.model import ProposalScorer
from zonegraph.network.scoring import score_state
from zonegraph.sequence.features import proposal_features, target_surfaces
from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.zones.model import ZoneGraph

UNSCORED = -3.0  # below any network score (a probability) minus the heuristic's (< 2)


class NetworkRanker:
    """Scores proposals with a trained :class:`ProposalScorer` (P(positive), higher first)."""

    samples = 128  # surface samples per zone the search builds graphs with: the checkpoint's own

    def __init__(
        self,
        model: str | Path | None = None,
        seed: int = 0,
        device: str = "cpu",
        top_m: int | None = None,
        blend: float | None = None,
    ) -> None:
        path = Path(model) if model else SHIPPED
        if not path.is_file():
            raise ValueError(f"{path}: no model checkpoint (in a checkout: python -m training.train)")
        torch.manual_seed(seed)
        self.device = torch.device(device)
        checkpoint = read_checkpoint(path, device)
        self.model: ProposalScorer = scorer_from(checkpoint, device)
        self.samples = int(checkpoint["train"].get("points_per_zone") or self.samples)
        search = checkpoint.get("search", {})
        self.top_m: int | None = top_m if top_m is not None else search.get("top_m")
        self.blend = float(blend if blend is not None else search.get("blend", 0.0))
        self._heuristic = HeuristicRanker()
        self._graph: ZoneGraph | None = None
        self._geometry: Geometry | None = None
        self._codes: torch.Tensor | None = None
        self._on_target: np.ndarray | None = None

    def _prepare(self, graph: ZoneGraph) -> Geometry:
        if graph is not self._graph or self._geometry is None:
            self._graph, self._geometry = graph, geometry_of(graph, self.samples)
            self._on_target = target_surfaces(graph)
            with torch.no_grad():
                self._codes = self.model.encode_geometry(self._geometry.points.to(self.device))
        return self._geometry

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """(P,) scores of one state whose depth is not known (the step feature reads 0)."""
        return self.score_at(graph, canvas, proposals, 0)

    def score_at(
        self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal], step: int
    ) -> np.ndarray:
        """(P,) scores of every proposal of one state ``step`` operations deep: P(positive), or
        its blend with the heuristic; proposals outside the heuristic's top M below them all."""
        if not proposals:
            return np.zeros(0)
        geometry = self._prepare(graph)
        heuristic = None
        if self.top_m or self.blend:
            heuristic = self._heuristic.score(graph, canvas, proposals)
        chosen = np.arange(len(proposals))
        if self.top_m and heuristic is not None and self.top_m < len(proposals):
            chosen = np.sort(np.argsort(-heuristic, kind="stable")[: self.top_m])
        picked = [proposals[i] for i in chosen]
        zones = torch.from_numpy(np.stack([p.zones for p in picked]))
        ops = torch.tensor([1 if p.op is Op.UNION else -1 for p in picked])
        features = None
        if self.model.columns:
            features = torch.from_numpy(proposal_features(graph, canvas, picked, step, self._on_target))
        canvas_t = torch.from_numpy(canvas.astype(bool))
        net = score_state(self.model, geometry, canvas_t, zones, ops, self.device, self._codes, features)
        if heuristic is None:
            return net
        out = UNSCORED + heuristic
        out[chosen] = (1 - self.blend) * net + self.blend * heuristic[chosen]
        return out

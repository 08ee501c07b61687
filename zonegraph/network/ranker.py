"""The network guide: a trained scorer behind the search's ``Ranker`` protocol.

:mod:`zonegraph.plugins` names it as the ``net`` guide by reference, and offers it only where
torch and torch_geometric can be found, so ``zonegraph infer PART --guide net`` and
``make_ranker("net")`` import this module (and torch) only when the guide is used. The model is
loaded once; with late fusion a graph's zone geometry is encoded once and every state's proposals
are scored in one batched pass, in eval mode.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from zonegraph.network.checkpoint import SHIPPED, read_checkpoint, scorer_from
from zonegraph.network.encoding import Geometry, geometry_of
from zonegraph.network.model import ProposalScorer
from zonegraph.network.scoring import score_state
from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.zones.model import ZoneGraph


class NetworkRanker:
    """Scores proposals with a trained :class:`ProposalScorer` (P(positive), higher first)."""

    samples = 128  # surface samples per zone the search builds graphs with: the checkpoint's own

    def __init__(self, model: str | Path | None = None, seed: int = 0, device: str = "cpu") -> None:
        path = Path(model) if model else SHIPPED
        if not path.is_file():
            raise ValueError(f"{path}: no model checkpoint (in a checkout: python -m training.train)")
        torch.manual_seed(seed)
        self.device = torch.device(device)
        checkpoint = read_checkpoint(path, device)
        self.model: ProposalScorer = scorer_from(checkpoint, device)
        self.samples = int(checkpoint["train"].get("points_per_zone") or self.samples)
        self._graph: ZoneGraph | None = None
        self._geometry: Geometry | None = None
        self._codes: torch.Tensor | None = None

    def _prepare(self, graph: ZoneGraph) -> Geometry:
        if graph is not self._graph or self._geometry is None:
            self._graph, self._geometry = graph, geometry_of(graph, self.samples)
            with torch.no_grad():
                self._codes = self.model.encode_geometry(self._geometry.points.to(self.device))
        return self._geometry

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """(P,) P(positive) of every proposal of one state (in memory-sized chunks of proposals)."""
        if not proposals:
            return np.zeros(0)
        geometry = self._prepare(graph)
        zones = torch.from_numpy(np.stack([p.zones for p in proposals]))
        ops = torch.tensor([1 if p.op is Op.UNION else -1 for p in proposals])
        canvas_t = torch.from_numpy(canvas.astype(bool))
        return score_state(self.model, geometry, canvas_t, zones, ops, self.device, self._codes)

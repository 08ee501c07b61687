"""Scoring one state's proposals, in chunks that fit in memory.

In eval mode a proposal's code does not depend on the others embedded with it, so a state with
hundreds of proposals over hundreds of zones is embedded in chunks of proposals (early fusion
runs a PointNet over every sample of every zone of every proposal, and one pass over 200
proposals of a 500-zone graph would need about 17 GB), and the readout then reads the whole
state at once (a scorer with a context reads each proposal beside its state's others).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import Tensor
from torch_geometric.data import Batch

from zonegraph.network.checkpoint import guide_settings, scorer_from
from zonegraph.network.encoding import Geometry, geometry_of, state_data
from zonegraph.network.model import ProposalScorer
from zonegraph.zones.model import ZoneGraph

MAX_POINTS = 1_000_000  # zone samples per forward pass (early fusion)
MAX_NODES = 200_000  # zone copies per forward pass (late and factored fusion)


def chunk_size(model: ProposalScorer, geometry: Geometry) -> int:
    """Proposals per forward pass for this model and graph."""
    if model.config.fusion == "early":
        return max(1, MAX_POINTS // max(1, geometry.n_zones * geometry.points.shape[2]))
    return max(1, MAX_NODES // max(1, geometry.n_zones))


@torch.no_grad()
def score_state(
    model: ProposalScorer,
    geometry: Geometry,
    canvas: Tensor,
    zones: Tensor,
    ops: Tensor,
    device: torch.device,
    codes: Tensor | None = None,
    features: Tensor | None = None,
) -> np.ndarray:
    """P(positive) of each proposal of one state, in eval mode.

    Shapes:
        canvas: (Z,) bool; zones: (P, Z) bool; ops: (P,) +1 union, -1 subtract; features: (P, F)
        (`zonegraph.sequence.features`; zeros when not given); returns (P,).
    """
    if model.training:  # eval() walks every module: 10% of a search's scoring when called per state
        model.eval()
    size, embedded = chunk_size(model, geometry), []
    for start in range(0, len(zones), size):
        chunk = slice(start, start + size)
        feats = None if features is None else features[chunk]
        data = state_data(geometry, canvas, zones[chunk], ops[chunk], feats)
        embedded.append(model.embed(Batch.from_data_list([data]).to(device), geometry=codes))
    if not embedded:
        return np.zeros(0)
    code = torch.cat(embedded)
    logits = model.read(code, torch.zeros(len(code), dtype=torch.long, device=code.device))
    return logits.softmax(dim=1)[:, 1].cpu().numpy()


class TorchScorer:
    """A checkpoint's `ProposalScorer` behind the ranker's ``StateScorer`` protocol, for
    what does not fold to numpy (early and factored fusion) or runs on another device."""

    def __init__(self, checkpoint: dict[str, Any], device: str = "cpu") -> None:
        self.device = torch.device(device)
        self.model = scorer_from(checkpoint, device)
        self.columns = tuple(self.model.columns)
        self.points_per_zone, self.search = guide_settings(checkpoint)
        self._graph: ZoneGraph | None = None
        self._geometry: Geometry | None = None
        self._codes: Tensor | None = None

    def score(
        self,
        graph: ZoneGraph,
        canvas: np.ndarray,
        zones: np.ndarray,
        ops: np.ndarray,
        features: np.ndarray | None,
    ) -> np.ndarray:
        """Shapes: canvas (Z,) bool; zones (P, Z) bool; ops (P,) +1/-1; features (P, F); returns (P,)."""
        if graph is not self._graph or self._geometry is None:
            self._graph, self._geometry = graph, geometry_of(graph, self.points_per_zone or 128)
            with torch.no_grad():
                self._codes = self.model.encode_geometry(self._geometry.points.to(self.device))
        return score_state(
            self.model,
            self._geometry,
            torch.from_numpy(canvas.astype(bool)),
            torch.from_numpy(zones.astype(bool)),
            torch.from_numpy(ops.astype(np.int64)),
            self.device,
            self._codes,
            None if features is None else torch.from_numpy(features),
        )

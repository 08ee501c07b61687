"""The proposal-scoring network (paper sec. 4.2, ``ALGORITHM.md`` sec. 5).

A state (zone graph, canvas) and one proposal (extrusion zones, operation) give every zone four
flags: in the target, in the canvas, in the extrusion, and the operation (+1 union, -1 subtract,
on the extrusion's zones). Zones carry surface samples (points and normals in the normalised
frame). The network scores a proposal by: a PointNet per zone, ``rounds`` of message passing over
zone adjacency, a global max pool over zones and an MLP to two logits (negative, positive).

Two ways to bring the flags in, both selectable:

- ``early`` (the paper): the flags are point channels (10 per point), so the PointNet runs for
  every zone of every proposal;
- ``late`` (ours): the PointNet encodes each zone's geometry once per graph, the flags join the
  128-d zone code after it; a state's proposals then cost only the message passing.

Shapes follow PyG: zones of all proposals in a batch are stacked ((N, ...) with ``batch`` the
proposal of each zone), ``edge_index`` (2, E) holds both directions of every adjacency.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import Tensor, nn
from torch_geometric.nn import MessagePassing, global_max_pool

FLAGS = 4  # in target, in canvas, in extrusion, operation
HIDDEN = 128


@dataclass(frozen=True)
class ModelConfig:
    """What the ablations vary: the fusion, the rounds of message passing, the point geometry."""

    fusion: str = "late"  # "late" or "early"
    rounds: int = 3
    use_points: bool = True  # False: zones are their flags only (the geometry ablation)
    hidden: int = HIDDEN

    def to_dict(self) -> dict:
        return asdict(self)


def _mlp(sizes: list[int], last_plain: bool = True) -> nn.Sequential:
    """Linear layers with BatchNorm and LeakyReLU between them (none after the last when plain)."""
    layers: list[nn.Module] = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:], strict=True)):
        layers.append(nn.Linear(a, b))
        if not (last_plain and i == len(sizes) - 2):
            layers += [nn.BatchNorm1d(b), nn.LeakyReLU(0.2)]
    return nn.Sequential(*layers)


class PointNet(nn.Module):
    """Per zone: shared point MLP (Conv1d), max over the zone's points, then an FC head.

    Shapes:
        points: (N, C, S) for N zones of S samples with C channels; returns (N, hidden).
    """

    def __init__(self, channels: int, hidden: int = HIDDEN):
        super().__init__()
        self.points = nn.Sequential(
            nn.Conv1d(channels, 64, 1),
            nn.BatchNorm1d(64),
            nn.LeakyReLU(0.2),
            nn.Conv1d(64, 128, 1),
            nn.BatchNorm1d(128),
            nn.LeakyReLU(0.2),
            nn.Conv1d(128, hidden, 1),
        )
        self.head = _mlp([hidden, hidden, hidden])

    def forward(self, points: Tensor) -> Tensor:
        return self.head(self.points(points).amax(dim=2))


class ZoneMessages(MessagePassing):
    """One round: a zone's new code is an MLP of its code and the mean of its neighbours' codes."""

    def __init__(self, hidden: int = HIDDEN):
        super().__init__(aggr="mean")
        self.mlp = _mlp([2 * hidden, hidden, hidden, hidden])

    def forward(self, x: Tensor, edge_index: Tensor) -> Tensor:
        return self.mlp(torch.cat([x, self.propagate(edge_index, x=x)], dim=1))

    def message(self, x_j: Tensor) -> Tensor:
        return x_j


class ProposalScorer(nn.Module):
    """Two logits per proposal (negative, positive); :meth:`score` gives P(positive)."""

    def __init__(self, config: ModelConfig = ModelConfig()):
        super().__init__()
        self.config = config
        h = config.hidden
        if config.fusion == "early":
            self.encoder: nn.Module | None = PointNet(6 + FLAGS if config.use_points else FLAGS, h)
            zone_in = h
        elif config.fusion == "late":
            self.encoder = PointNet(6, h) if config.use_points else None
            zone_in = (h if config.use_points else 0) + FLAGS
        else:
            raise ValueError(f"unknown fusion {config.fusion!r} (early or late)")
        self.zone_in = _mlp([zone_in, h, h]) if config.fusion == "late" else nn.Identity()
        self.rounds = nn.ModuleList(ZoneMessages(h) for _ in range(config.rounds))
        self.readout = nn.Sequential(_mlp([h, h, h], last_plain=False), nn.Linear(h, 2))

    def encode_geometry(self, points: Tensor) -> Tensor | None:
        """Late fusion's per-graph zone codes, (Z, hidden), from (Z, 6, S) points and normals."""
        if self.config.fusion != "late" or self.encoder is None:
            return None
        return self.encoder(points)

    def forward(
        self,
        flags: Tensor,
        edge_index: Tensor,
        batch: Tensor,
        points: Tensor | None = None,
        geometry: Tensor | None = None,
        zone_of: Tensor | None = None,
    ) -> Tensor:
        """Logits (P, 2) for the P proposals of a batch.

        Args:
            flags: (N, 4) per zone of every proposal.
            edge_index: (2, E) adjacency between those zones (both directions).
            batch: (N,) the proposal of each zone.
            points: early fusion: (N, 6, S) samples of each zone (repeated per proposal).
            geometry: late fusion: (Z, hidden) zone codes of the graphs in the batch, and
            zone_of: (N,) the row of ``geometry`` for each zone.
        """
        if self.config.fusion == "early":
            if self.config.use_points:
                assert points is not None
                channels = flags[:, :, None].expand(-1, -1, points.shape[2])
                x = self.encoder(torch.cat([points, channels], dim=1))  # type: ignore[misc]
            else:
                x = self.encoder(flags[:, :, None])  # type: ignore[misc]
        else:
            parts = [flags]
            if self.config.use_points:
                assert geometry is not None and zone_of is not None
                parts.insert(0, geometry[zone_of])
            x = self.zone_in(torch.cat(parts, dim=1))
        for layer in self.rounds:
            x = layer(x, edge_index)
        return self.readout(global_max_pool(x, batch))

    @torch.no_grad()
    def score(self, *args: Tensor | None, **kwargs: Tensor | None) -> Tensor:
        """P(positive) per proposal, in eval mode (the original scored with BatchNorm in training
        mode, so a proposal's score depended on the others batched with it)."""
        was_training = self.training
        self.eval()
        try:
            return self.forward(*args, **kwargs).softmax(dim=1)[:, 1]  # type: ignore[arg-type]
        finally:
            self.train(was_training)

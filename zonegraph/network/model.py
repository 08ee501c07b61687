"""The proposal-scoring network (paper sec. 4.2, ``docs/algorithm.md`` sec. 6).

A state (zone graph, canvas) and one proposal (extrusion zones, operation) give every zone four
flags: in the target, in the canvas, in the extrusion, and the operation (+1 union, -1 subtract,
on the extrusion's zones). Zones carry surface samples (points and normals in the normalised
frame). The network scores a proposal by: a PointNet per zone, ``rounds`` of message passing over
zone adjacency, a global max pool over zones and an MLP to two logits (negative, positive).

Three ways to bring the flags in, all selectable:

- ``early`` (the paper): the flags are point channels (10 per point), so the PointNet runs for
  every zone of every proposal;
- ``late``: the PointNet encodes each zone's geometry once per graph, the flags join the 128-d
  zone code after it; a state's proposals then cost the message passing, once per proposal;
- ``factored``: the message passing runs once per *state*, on the geometry and the state's own
  flags (target, canvas); the extrusion flags join after it. A zone then has only three codes
  (outside the extrusion, in a union's, in a subtraction's), computed once per state, and a
  proposal is a masked max over them: scoring costs element-wise work per proposal, no matmul.

Proposal features (``ModelConfig.features``, names from `zonegraph.sequence.features`: the
heuristic's terms, the extrusion's geometry, the step) join after the pool: standardised by a
BatchNorm, embedded by a small MLP and concatenated to the pooled zone code before the readout,
in every fusion. An empty tuple is the paper's network (and every checkpoint trained before).

With ``context`` the readout also reads the state's context: per channel, the greatest code
(pooled zones and features) among the proposals scored with it. Each proposal is otherwise
scored alone, so the network cannot tell a state's first choice from a runner-up of equal merit;
a max over the set (a DeepSets pooling) is the cheapest layer that sees them together, and it
is unchanged by leaving out proposals that hold no channel's greatest value (the search scores
the heuristic's top few only).

Shapes follow PyG: zones of all proposals in a batch are stacked ((N, ...) with ``batch`` the
proposal of each zone), ``edge_index`` (2, E) holds both directions of every adjacency.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import torch
from torch import Tensor, nn
from torch_geometric.nn import MessagePassing, global_max_pool
from torch_geometric.utils import scatter

from zonegraph.configs import Config
from zonegraph.sequence.features import FEATURES

FLAGS = 4  # in target, in canvas, in extrusion, operation
HIDDEN = 128


@dataclass(frozen=True)
class ModelConfig(Config):
    """What the ablations vary: the fusion, the rounds of message passing, the point geometry,
    the proposal features read beside the zones."""

    fusion: str = "late"  # "early", "late" or "factored"
    rounds: int = 3
    use_points: bool = True  # False: zones are their flags only (the geometry ablation)
    hidden: int = HIDDEN
    features: tuple[str, ...] = ()  # names of zonegraph.sequence.features.FEATURES; () the paper's
    context: bool = False  # the readout also reads the max over the state's proposals' codes

    def feature_columns(self) -> list[int]:
        """Columns of the data's ``feat`` this model reads."""
        unknown = sorted(set(self.features) - set(FEATURES))
        if unknown:
            known = ", ".join(FEATURES)
            raise ValueError(f"unknown proposal feature(s) {', '.join(unknown)} (known: {known})")
        return [FEATURES.index(name) for name in self.features]


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

    def __init__(self, channels: int, hidden: int = HIDDEN) -> None:
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

    def __init__(self, hidden: int = HIDDEN) -> None:
        super().__init__(aggr="mean")
        self.mlp = _mlp([2 * hidden, hidden, hidden, hidden])

    def forward(self, x: Tensor, edge_index: Tensor) -> Tensor:
        return self.mlp(torch.cat([x, self.propagate(edge_index, x=x)], dim=1))

    def message(self, x_j: Tensor) -> Tensor:
        return x_j


class ProposalScorer(nn.Module):
    """Two logits per proposal (negative, positive); `score` gives P(positive).

    Reads a PyG batch of states (``zonegraph.network.encoding.StateData``): ``x`` (N, 4) flags of the N zone
    copies (one copy of a state's zones per proposal), ``edge_index`` between them, ``proposal``
    (N,) the proposal of each, ``zone_of`` (N,) its row of ``points`` (Z, 6, S), the states' zones
    with ``zone_edge_index`` between them.
    """

    def __init__(self, config: ModelConfig = ModelConfig()) -> None:
        super().__init__()
        self.config = config
        h = config.hidden
        if config.fusion not in ("early", "late", "factored"):
            raise ValueError(f"unknown fusion {config.fusion!r} (early, late or factored)")
        geometry_in = 6 + FLAGS if config.fusion == "early" else 6
        self.encoder: nn.Module | None = None
        if config.use_points:
            self.encoder = PointNet(geometry_in, h)
        elif config.fusion == "early":
            self.encoder = PointNet(FLAGS, h)
        geometry = h if config.use_points else 0
        if config.fusion == "late":
            self.zone_in: nn.Module = _mlp([geometry + FLAGS, h, h])
        elif config.fusion == "factored":
            self.zone_in = _mlp([geometry + 2, h, h])  # the state's flags: target, canvas
            self.extrusion = _mlp([h + 3, h, h], last_plain=False)  # + one-hot: out, union, subtract
        else:
            self.zone_in = nn.Identity()
        self.rounds = nn.ModuleList(ZoneMessages(h) for _ in range(config.rounds))
        self.columns = config.feature_columns()
        extra = 0
        if self.columns:
            extra = h // 2
            self.features_in = nn.Sequential(
                nn.BatchNorm1d(len(self.columns)), _mlp([len(self.columns), extra, extra], last_plain=False)
            )
        width = (h + extra) * (2 if config.context else 1)
        self.readout = nn.Sequential(_mlp([width, h, h], last_plain=False), nn.Linear(h, 2))

    def encode_geometry(self, points: Tensor) -> Tensor | None:
        """Per-graph zone codes (late and factored fusion), (Z, hidden) from (Z, 6, S) samples."""
        if self.config.fusion == "early" or self.encoder is None:
            return None
        return self.encoder(points)

    def forward(self, data: Any, geometry: Tensor | None = None) -> Tensor:
        """Logits (P, 2) for the P proposals of a batch; ``geometry``: codes already encoded."""
        return self.read(self.embed(data, geometry), data.state if self.config.context else None)

    def embed(self, data: Any, geometry: Tensor | None = None) -> Tensor:
        """(P, H') each proposal as the readout reads it: its pooled zone codes and, with
        features, their embedding. Proposals embed apart from one another, so a state's may be
        embedded in chunks and read together."""
        if self.config.fusion != "early" and geometry is None:
            geometry = self.encode_geometry(data.points)
        if self.config.fusion == "factored":
            return self._features(self._factored(data, geometry), data)
        if self.config.fusion == "early":
            if self.config.use_points:
                channels = data.x[:, :, None].expand(-1, -1, data.points.shape[2])
                x = self.encoder(torch.cat([data.points[data.zone_of], channels], dim=1))  # type: ignore[misc]
            else:
                x = self.encoder(data.x[:, :, None])  # type: ignore[misc]
        else:
            parts = [data.x] if geometry is None else [geometry[data.zone_of], data.x]
            x = self.zone_in(torch.cat(parts, dim=1))
        for layer in self.rounds:
            x = layer(x, data.edge_index)
        return self._features(global_max_pool(x, data.proposal), data)

    def _features(self, pooled: Tensor, data: Any) -> Tensor:
        """The pooled zone codes (P, hidden) beside the proposal features' embedding, when read."""
        if not self.columns:
            return pooled
        return torch.cat([pooled, self.features_in(data.feat[:, self.columns])], dim=1)

    def read(self, code: Tensor, state: Tensor | None = None) -> Tensor:
        """Logits (P, 2) from the proposals' `embed`; with a context, each beside the greatest
        code of its state's proposals (``state`` (P,), the state of each: required then)."""
        if self.config.context:
            assert state is not None, "a scorer with a context reads each proposal's state"
            states = int(state.max()) + 1 if len(state) else 0
            context = scatter(code, state, dim=0, dim_size=states, reduce="max")
            code = torch.cat([code, context[state]], dim=1)
        return self.readout(code)

    def _factored(self, data: Any, geometry: Tensor | None) -> Tensor:
        """(P, hidden) the pooled zone codes of factored fusion."""
        state_flags = torch.zeros(data.points.shape[0], 2, device=data.x.device)
        state_flags[data.zone_of] = data.x[:, :2]  # the same in every copy of a state's zone
        x = self.zone_in(state_flags if geometry is None else torch.cat([geometry, state_flags], dim=1))
        for layer in self.rounds:
            x = layer(x, data.zone_edge_index)
        kinds = torch.eye(3, device=x.device)
        codes = torch.stack([self.extrusion(torch.cat([x, k.expand(len(x), 3)], dim=1)) for k in kinds])
        kind = (data.x[:, 2] * torch.where(data.x[:, 3] < 0, 2.0, 1.0)).long()  # 0 out, 1 union, 2 subtract
        return global_max_pool(codes[kind, data.zone_of], data.proposal)

    @torch.no_grad()
    def score(self, data: Any, geometry: Tensor | None = None) -> Tensor:
        """P(positive) per proposal, in eval mode (the original scored with BatchNorm in training
        mode, so a proposal's score depended on the others batched with it)."""
        was_training = self.training
        self.eval()
        try:
            return self.forward(data, geometry).softmax(dim=1)[:, 1]
        finally:
            self.train(was_training)

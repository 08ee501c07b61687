"""A zone graph and one state's proposals as the network reads them (PyG data).

One state (a canvas and P proposals) is a graph holding one copy of the design's zones per
proposal, each zone with its four flags (in target, in canvas, in extrusion, operation), so that
PyG's batching stacks proposals and states alike; ``proposal`` maps zones to proposals and
``zone_of`` to rows of ``points`` (the design's zones, stored once per state, with
``zone_edge_index`` between them). Per proposal it carries its features (``feat``, (P, F): every
column of `zonegraph.sequence.features.FEATURES`; a model reads those its configuration
names) and ``state``, the state it belongs to once batched (a listwise loss normalises over a
state's proposals). The search encodes the graph it is searching; the training
labels (``training.data``) encode the saved graphs the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor
from torch_geometric.data import Data

from zonegraph.network.folded import zone_samples
from zonegraph.sequence.features import FEATURES
from zonegraph.zones.model import ZoneGraph


@dataclass(frozen=True)
class Geometry:
    """A design's zone geometry as the network reads it.

    Shapes:
        points: (Z, 6, S) float32, sample xyz and normal per zone; edge_index: (2, E) int64, both
        directions; inside: (Z,) bool, the target.
    """

    points: Tensor
    edge_index: Tensor
    inside: Tensor

    @property
    def n_zones(self) -> int:
        return len(self.inside)

    @property
    def edges(self) -> np.ndarray:
        """(E / 2, 2) each adjacency once, as the zone graph lists it (`geometry_of` writes
        ``edge_index`` as those edges and then the same edges reversed)."""
        return self.edge_index[:, : self.edge_index.shape[1] // 2].T.numpy()


def geometry_of(graph: ZoneGraph, points_per_zone: int | None = None, seed: int = 0) -> Geometry:
    """The network's view of a zone graph, optionally keeping a seeded subset of the samples."""
    edges = graph.edges.astype(np.int64)
    both = np.concatenate([edges, edges[:, ::-1]]).T if len(edges) else np.zeros((2, 0), np.int64)
    return Geometry(
        torch.from_numpy(zone_samples(graph, points_per_zone, seed)),
        torch.from_numpy(np.ascontiguousarray(both)),
        torch.from_numpy(graph.zone_inside.astype(bool)),
    )


class StateData(Data):
    """One state with P proposals: P copies of the design's Z zones (PyG batches these)."""

    def __inc__(self, key: str, value: Tensor, *args: object, **kwargs: object) -> int:
        if key == "proposal":
            return int(self.num_proposals)
        if key in ("zone_of", "zone_edge_index"):
            return int(self.points.shape[0])
        if key == "state":
            return 1
        return int(super().__inc__(key, value, *args, **kwargs))


def state_data(
    geometry: Geometry,
    canvas: Tensor,
    zones: Tensor,
    ops: Tensor,
    features: Tensor | None = None,
    **extra: Tensor,
) -> StateData:
    """Flags and the proposal-replicated graph of one state.

    Shapes:
        canvas: (Z,) bool; zones: (P, Z) bool, the proposals' extrusions; ops: (P,) +1 union,
        -1 subtract; features: (P, F) float (zeros when not given). Returns nodes P x Z with
        ``x`` (N, 4) flags.
    """
    p, z = zones.shape
    if features is None:
        features = torch.zeros(p, len(FEATURES))
    flags = torch.stack(
        [
            geometry.inside.expand(p, z).float(),
            canvas.expand(p, z).float(),
            zones.float(),
            zones.float() * ops[:, None].float(),
        ],
        dim=2,
    ).reshape(p * z, 4)
    offsets = (torch.arange(p) * z)[:, None, None]
    edge_index = (geometry.edge_index[None] + offsets).permute(1, 0, 2).reshape(2, -1)
    return StateData(
        x=flags,
        edge_index=edge_index,
        proposal=torch.arange(p).repeat_interleave(z),
        zone_of=torch.arange(z).repeat(p),
        points=geometry.points,
        zone_edge_index=geometry.edge_index,
        num_proposals=p,
        num_nodes=p * z,
        feat=features.float(),
        state=torch.zeros(p, dtype=torch.long),
        **extra,
    )

"""Training data: the ``labels`` stage's Parquet shards and the saved zone graphs, as PyG batches.

One example is one GT step of one design (a *state*): its canvas and a set of proposals with their
labels. Its graph holds one copy of the design's zones per proposal, each zone with its four
flags (in target, in canvas, in extrusion, operation), so that PyG's batching stacks proposals and
states alike; ``proposal`` maps zones to proposals and ``zone_of`` to rows of ``points`` (the
design's zones, stored once per state, with ``zone_edge_index`` between them). Geometry is read
from each saved graph once, when the dataset is built, keeping ``points_per_zone`` of its surface
samples (seeded).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.dataset as ds
import torch
from torch import Tensor
from torch_geometric.data import Data, Dataset

from zonegraph.zones.model import ZoneGraph
from zonegraph.zones.storage import load_zone_graph


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


def geometry_of(graph: ZoneGraph, points_per_zone: int | None = None, seed: int = 0) -> Geometry:
    """The network's view of a zone graph, optionally keeping a seeded subset of the samples."""
    pts = np.concatenate([graph.zone_points, graph.zone_normals], axis=2)  # (Z, S, 6)
    if points_per_zone is not None and points_per_zone < pts.shape[1]:
        keep = np.sort(np.random.default_rng(seed).choice(pts.shape[1], points_per_zone, replace=False))
        pts = pts[:, keep]
    edges = graph.edges.astype(np.int64)
    both = np.concatenate([edges, edges[:, ::-1]]).T if len(edges) else np.zeros((2, 0), np.int64)
    return Geometry(
        torch.from_numpy(np.ascontiguousarray(pts.transpose(0, 2, 1), dtype=np.float32)),
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
        return super().__inc__(key, value, *args, **kwargs)


def state_data(geometry: Geometry, canvas: Tensor, zones: Tensor, ops: Tensor, **extra: Tensor) -> StateData:
    """Flags and the proposal-replicated graph of one state.

    Shapes:
        canvas: (Z,) bool; zones: (P, Z) bool, the proposals' extrusions; ops: (P,) +1 union,
        -1 subtract. Returns nodes P x Z with ``x`` (N, 4) flags.
    """
    p, z = zones.shape
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
        **extra,
    )


def _mask(ids: Sequence[int], n: int) -> np.ndarray:
    out = np.zeros(n, bool)
    out[np.asarray(ids, dtype=np.int64)] = True
    return out


@dataclass
class _State:
    design_id: str
    step: int
    canvas: np.ndarray
    zones: np.ndarray  # (P, Z)
    ops: np.ndarray  # (P,)
    labels: np.ndarray  # (P,) 1, 0, -1
    is_gt: np.ndarray  # (P,)


class LabelDataset(Dataset):
    """States from the label shards of ``labels_dir`` whose designs are in ``design_ids``.

    ``mode="train"`` keeps positives and negatives only (the focal loss ignores neutrals) and at
    most ``max_proposals`` of a state's proposals (the positive always, negatives seeded);
    ``mode="rank"`` keeps every proposal, to rank the GT among all of them.
    """

    def __init__(
        self,
        labels_dir: str | Path,
        graphs_dir: str | Path,
        design_ids: Sequence[str] | None = None,
        mode: str = "train",
        max_proposals: int = 64,
        points_per_zone: int | None = 128,
        seed: int = 0,
    ):
        super().__init__()
        self.mode, self.max_proposals, self.seed = mode, max_proposals, seed
        table = ds.dataset(Path(labels_dir) / "proposals", format="parquet").to_table()
        steps = ds.dataset(Path(labels_dir) / "steps", format="parquet").to_table()
        if design_ids is not None:
            wanted = set(design_ids)
            table = table.filter(ds.field("design_id").isin(wanted))
            steps = steps.filter(ds.field("design_id").isin(wanted))
        self.geometry: dict[str, Geometry] = {}
        for design_id in sorted(set(table.column("design_id").to_pylist())):
            graph = load_zone_graph(Path(graphs_dir) / design_id, solids=False)
            self.geometry[design_id] = geometry_of(graph, points_per_zone, seed)
        self.states = self._states(table.to_pandas(), steps.to_pandas())

    def _states(self, proposals, steps) -> list[_State]:
        canvas_of = {(r.design_id, r.step): r.canvas_zones for r in steps.itertuples()}
        out = []
        for (design_id, step), rows in proposals.groupby(["design_id", "step"], sort=True):
            n = self.geometry[design_id].n_zones
            out.append(
                _State(
                    design_id,
                    int(step),
                    _mask(canvas_of[(design_id, step)], n),
                    np.stack([_mask(z, n) for z in rows["zones"]]),
                    np.where(rows["operation"].to_numpy() == "union", 1, -1),
                    rows["label"].to_numpy().astype(np.int64),
                    rows["is_gt"].to_numpy().astype(bool),
                )
            )
        return out

    def len(self) -> int:
        return len(self.states)

    def _pick(self, state: _State, idx: int) -> np.ndarray:
        if self.mode == "rank":
            return np.arange(len(state.labels))
        pos = np.flatnonzero(state.labels == 1)
        neg = np.flatnonzero(state.labels == -1)
        if len(neg) > self.max_proposals - len(pos):
            rng = np.random.default_rng([self.seed, idx])
            neg = np.sort(rng.choice(neg, self.max_proposals - len(pos), replace=False))
        return np.concatenate([pos, neg])

    def get(self, idx: int) -> StateData:
        state = self.states[idx]
        keep = self._pick(state, idx)
        return state_data(
            self.geometry[state.design_id],
            torch.from_numpy(state.canvas),
            torch.from_numpy(state.zones[keep]),
            torch.from_numpy(state.ops[keep]),
            y=torch.from_numpy((state.labels[keep] == 1).astype(np.int64)),
            label=torch.from_numpy(state.labels[keep]),
            is_gt=torch.from_numpy(state.is_gt[keep]),
        )

"""Training data: the ``labels`` stage's Parquet shards and the saved zone graphs, as PyG batches.

One example is one GT step of one design (a *state*): its canvas and a set of proposals with their
labels, encoded as the search encodes a state (`zonegraph.network.encoding`) with the labels
added, and the proposal features the labels stage stored (``feat_<name>`` columns; zeros for
shards written before them, which `LabelDataset.has_features` tells). Geometry is read from
each saved graph once, when the dataset is built, keeping ``points_per_zone`` of its surface
samples (seeded).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.dataset as ds
import torch
from torch_geometric.data import Dataset

from training.shards import label_shards
from zonegraph.network.encoding import Geometry, StateData, geometry_of, state_data
from zonegraph.sequence.features import FEATURES, PROPOSAL_FEATURES, with_state_features
from zonegraph.zones.storage import load_zone_graph


def _mask(ids: Sequence[int], n: int) -> np.ndarray:
    out = np.zeros(n, bool)
    out[np.asarray(ids, dtype=np.int64)] = True
    return out


def kept_proposals(
    zones: int, positives: int, max_proposals: int | None, max_nodes: int | None
) -> int | None:
    """The most proposals a training state of ``zones`` zones keeps (None: all): ``max_proposals``,
    fewer where ``max_nodes`` zone copies run out first (never fewer than the positives and one
    other)."""
    if max_nodes is None:
        return max_proposals
    by_nodes = max(max_nodes // max(zones, 1), positives + 1)
    return by_nodes if max_proposals is None else min(max_proposals, by_nodes)


@dataclass
class _State:
    design_id: str
    step: int
    canvas: np.ndarray
    zones: np.ndarray  # (P, Z)
    ops: np.ndarray  # (P,)
    labels: np.ndarray  # (P,) 1, 0, -1
    is_gt: np.ndarray  # (P,)
    features: np.ndarray  # (P, F) float32, zonegraph.sequence.features.FEATURES


class LabelDataset(Dataset):
    """States from the label shards of ``labels_dir`` whose designs are in ``design_ids``: only
    the shards the labels stage lists as ok and intact (`training.shards.label_shards`).

    ``mode="train"`` keeps positives and negatives only (the focal loss ignores neutrals; with
    ``neutrals`` the neutrals too, for a listwise loss that gives them partial credit) and at most
    ``max_proposals`` of a state's proposals (the positive always, the others seeded; None: all,
    as the rank judges a state), and with ``max_nodes`` at most that many zone copies (proposals
    times zones): a state of a 16,500-zone graph keeps a few proposals where a small graph's keeps
    them all, since a batch's memory grows with the copies, not the proposals;
    ``mode="rank"`` keeps every proposal, to rank the GT among all of them.
    """

    def __init__(
        self,
        labels_dir: str | Path,
        graphs_dir: str | Path,
        design_ids: Sequence[str] | None = None,
        mode: str = "train",
        max_proposals: int | None = 64,
        points_per_zone: int | None = 128,
        seed: int = 0,
        neutrals: bool = False,
        max_nodes: int | None = None,
    ):
        super().__init__()
        self.mode, self.max_proposals, self.seed, self.neutrals = mode, max_proposals, seed, neutrals
        self.max_nodes = max_nodes
        shards = label_shards(labels_dir)
        table = ds.dataset(shards.proposals, format="parquet").to_table()
        self.has_features = all(f"feat_{name}" in table.column_names for name in PROPOSAL_FEATURES)
        steps = ds.dataset(shards.steps, format="parquet").to_table()
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
                    self._features(rows),
                )
            )
        return out

    def _features(self, rows) -> np.ndarray:
        if not self.has_features:
            return np.zeros((len(rows), len(FEATURES)), np.float32)
        return with_state_features(rows[[f"feat_{name}" for name in PROPOSAL_FEATURES]].to_numpy(np.float32))

    def len(self) -> int:
        return len(self.states)

    def _pick(self, state: _State, idx: int) -> np.ndarray:
        if self.mode == "rank":
            return np.arange(len(state.labels))
        pos = np.flatnonzero(state.labels == 1)
        neg = np.flatnonzero(state.labels == -1 if not self.neutrals else state.labels != 1)
        limit = kept_proposals(state.zones.shape[1], len(pos), self.max_proposals, self.max_nodes)
        if limit is not None and len(neg) > limit - len(pos):
            rng = np.random.default_rng([self.seed, idx])
            neg = np.sort(rng.choice(neg, limit - len(pos), replace=False))
        return np.concatenate([pos, neg])

    def get(self, idx: int) -> StateData:
        state = self.states[idx]
        keep = self._pick(state, idx)
        return state_data(
            self.geometry[state.design_id],
            torch.from_numpy(state.canvas),
            torch.from_numpy(state.zones[keep]),
            torch.from_numpy(state.ops[keep]),
            torch.from_numpy(state.features[keep]),
            y=torch.from_numpy((state.labels[keep] == 1).astype(np.int64)),
            label=torch.from_numpy(state.labels[keep]),
            is_gt=torch.from_numpy(state.is_gt[keep]),
        )

"""The trained scorer as plain arrays: scoring a search state with numpy alone.

In search the network scores a handful of proposals of a small graph at every state, thousands of
times per second; there PyG's batching and PyTorch's per-operation dispatch cost more than the
arithmetic (about 4 ms a state with the heuristic's top 8, against the heuristic's 0.3 ms), and
importing torch costs a command-line call seconds. In eval mode the network is a chain of affine
maps and LeakyReLUs, so `zonegraph.network.checkpoint.fold` folds every BatchNorm into the
Linear (or 1x1 convolution) beside it and writes the weights as a ``.npz``; this module evaluates
that chain with numpy and scipy's sparse mean over zone neighbours, and imports no torch.

It covers late fusion (the default and the shipped checkpoint), with or without the point
encoder, with or without proposal features; early and factored fusion stay on the PyTorch path.
The forward is the one of `zonegraph.network.model.ProposalScorer` operation for
operation (tests compare both on real graphs).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from zonegraph.zones.model import ZoneGraph

SLOPE = 0.2  # the LeakyReLU of every layer (zonegraph.network.model)
# Up to this many zones the neighbour mean is a dense product: scipy's sparse one costs tens of
# microseconds per call before any arithmetic, more than a small graph's whole product.
DENSE_ZONES = 256
# The shipped checkpoint folded (python -m training.fold); a test keeps it equal to scorer.pt's.
SHIPPED_FOLDED = Path(__file__).resolve().parent / "checkpoints" / "scorer.npz"


@dataclass(frozen=True)
class Affine:
    """``x @ weight + bias``, a BatchNorm after it already folded in, then a LeakyReLU or none."""

    weight: np.ndarray  # (in, out) float32
    bias: np.ndarray  # (out,) float32
    activation: bool

    def __call__(self, x: np.ndarray) -> np.ndarray:
        y = x @ self.weight
        y += self.bias
        if self.activation:
            np.maximum(y, SLOPE * y, out=y)
        return y


Chain = tuple[Affine, ...]


def _arrays(data: Any, meta: dict[str, Any]) -> Callable[[str], np.ndarray]:
    """An array of a saved scorer by name: a slice of the one ``weights`` member, or (files saved
    before it) a member of its own."""
    if "arrays" not in meta:
        return lambda name: np.asarray(data[name])
    weights = data["weights"]

    def array(name: str) -> np.ndarray:
        offset, shape = meta["arrays"][name]
        return weights[offset : offset + int(np.prod(shape))].reshape(shape)

    return array


def run(chain: Chain, x: np.ndarray) -> np.ndarray:
    """The chain's layers applied in order."""
    for layer in chain:
        x = layer(x)
    return x


@dataclass(frozen=True)
class FoldedScorer:
    """A late-fusion `ProposalScorer` in eval mode, as arrays.

    ``points``/``head`` encode a zone's samples (absent without the point encoder), ``zone_in``
    reads its code and four flags, each of ``rounds`` reads a zone's code beside its neighbours'
    mean, ``features`` embeds the proposal features (the model's ``columns`` of
    `zonegraph.sequence.features.FEATURES`), ``readout`` gives the two logits.
    """

    config: dict[str, Any]
    columns: tuple[int, ...]
    zone_in: Chain
    rounds: tuple[Chain, ...]
    readout: Chain
    points: Chain = ()
    head: Chain = ()
    features: Chain = ()
    points_per_zone: int | None = None  # the surface samples per zone it was trained with
    search: dict[str, Any] = field(default_factory=dict)  # the guide's defaults (top_m, blend)
    train_projects: tuple[str, ...] = ()  # the projects it saw in training: evaluation skips them
    holdout_projects: tuple[str, ...] = ()  # training-split projects it never saw, kept for evaluation

    def encode_geometry(self, points: np.ndarray) -> np.ndarray | None:
        """(Z, H) each zone's geometry as it enters ``zone_in``'s first layer (its PointNet code
        times that layer's geometry rows), from (Z, 6, S) samples: once per graph. None without
        points."""
        if not self.points:
            return None
        z, c, s = points.shape
        per_point = run(self.points, points.transpose(0, 2, 1).reshape(z * s, c).astype(np.float32))
        codes = run(self.head, per_point.reshape(z, s, -1).max(axis=1))
        return codes @ self.zone_in[0].weight[:-4]

    def score(
        self,
        state: State,
        zones: np.ndarray,
        ops: np.ndarray,
        geometry: np.ndarray | None = None,
        features: np.ndarray | None = None,
    ) -> np.ndarray:
        """P(positive) of each of P proposals of one state.

        A proposal changes the flags of its extrusion's zones only, and a round of message passing
        carries a change one zone further, so after round r a proposal's zone codes differ from
        the state's own (no extrusion) only within r steps of its extrusion. Where that saves
        work, the state's codes are computed once (row 0) and each proposal's only where they can
        differ: on a large graph most zones of most proposals are never computed. On a small
        graph, where every zone is soon within reach, every zone of every proposal is computed
        and the state's row is left out. Exact either way: an untouched zone's code *is* the
        state's.

        Shapes:
            zones: (P, Z) bool, the extrusions; ops: (P,) +1 union, -1 subtract; geometry: (Z, H)
            from `encode_geometry`; features: (P, F) every column of FEATURES; returns (P,).
        """
        p, z = zones.shape
        masks = self._computed(state, zones.astype(bool))
        k = len(masks[0])  # P + 1 with the state's row first, or P
        own = slice(k - p, None)  # the proposals' rows
        first = self.zone_in[0]
        flags = np.zeros((k, z, 4), np.float32)
        flags[:, :, 0] = state.inside
        flags[:, :, 1] = state.canvas
        flags[own, :, 2] = zones
        flags[own, :, 3] = zones * ops[:, None]
        rows = np.nonzero(masks[0])
        x = flags[rows] @ first.weight[-4:] + first.bias
        if geometry is not None:
            x += geometry[rows[1]]
        x = _spread(run(self.zone_in[1:], _activate(x, first)), rows, k, z, with_state=k > p)
        for chain, mask in zip(self.rounds, masks[1:], strict=True):
            rows = np.nonzero(mask)
            mean = state.neighbours @ x.transpose(1, 0, 2).reshape(z, -1)
            mean = mean.reshape(z, k, -1).transpose(1, 0, 2)
            codes = run(chain, np.concatenate([x[rows], mean[rows]], axis=1))
            x = _spread(codes, rows, k, z, with_state=k > p)
        pooled = x[own].max(axis=1)
        if self.columns:
            taken = np.zeros((p, max(self.columns) + 1), np.float32) if features is None else features
            pooled = np.concatenate([pooled, run(self.features, taken[:, list(self.columns)])], axis=1)
        logits = run(self.readout, pooled)
        return 1.0 / (1.0 + np.exp(logits[:, 0] - logits[:, 1]))

    def _computed(self, state: State, zones: np.ndarray) -> list[np.ndarray]:
        """Which zone codes each layer computes, (K, Z) per layer: K = P + 1 with the state's
        row first (every zone) and each proposal's zones within reach of its extrusion, or K = P
        with every zone, whichever computes fewer rows."""
        reach = [zones]
        for _ in self.rounds:
            reach.append(reach[-1] | state.reach(reach[-1]))
        p, z = zones.shape
        if sum(int(m.sum()) for m in reach) + z * len(reach) >= p * z * len(reach):
            return [np.ones((p, z), bool)] * len(reach)
        return [np.concatenate([np.ones((1, z), bool), m]) for m in reach]

    def save(self, path: str | Path) -> None:
        """Writes the configuration and every layer's arrays as one ``.npz`` (no pickled objects):
        the layers in one flat member (``weights``, each array's offset and shape in the header),
        since a guide reads them inside its search and each member costs a zip lookup and a header
        parse (measured: docs/results/network.md, "Search at equal wall-clock")."""
        flat: list[np.ndarray] = []
        places: dict[str, list[Any]] = {}
        layout: dict[str, list[list[bool]]] = {}
        offset = 0
        for name, chains in self._chains().items():
            layout[name] = []
            for c, chain in enumerate(chains):
                layout[name].append([layer.activation for layer in chain])
                for i, layer in enumerate(chain):
                    for part, array in (("weight", layer.weight), ("bias", layer.bias)):
                        places[f"{name}.{c}.{i}.{part}"] = [offset, list(array.shape)]
                        flat.append(np.asarray(array, np.float32).ravel())
                        offset += array.size
        meta = {
            "config": self.config,
            "columns": list(self.columns),
            "layout": layout,
            "arrays": places,
            "points_per_zone": self.points_per_zone,
            "search": self.search,
        }
        members: dict[str, Any] = {
            "meta": np.array(json.dumps(meta, sort_keys=True)),
            "weights": np.concatenate(flat) if flat else np.zeros(0, np.float32),
            "train_projects": np.array(self.train_projects, dtype=str),
        }
        if self.holdout_projects:  # older files, and models with no holdout, have no such member
            members["holdout_projects"] = np.array(self.holdout_projects, dtype=str)
        np.savez(path, **members)

    @staticmethod
    def header(path: str | Path) -> dict[str, Any]:
        """The configuration `save` wrote beside the arrays, without reading the arrays (an
        ``.npz`` is a zip: members are read when asked for).

        Raises:
            ValueError: not a scorer `save` wrote, or one missing a layer's arrays.
        """
        try:
            with np.load(path, allow_pickle=False) as data:
                meta: dict[str, Any] = json.loads(str(data["meta"]))
                names = set(data.files)
            layers = [
                f"{name}.{c}.{i}"
                for name, layout in meta["layout"].items()
                for c, acts in enumerate(layout)
                for i in range(len(acts))
            ]
        except (OSError, KeyError, TypeError, ValueError) as e:
            raise ValueError(f"{path}: not a folded scorer ({e})") from e
        names |= set(meta.get("arrays", {}))  # one flat member, or (older files) one per array
        missing = [layer for layer in layers if not {f"{layer}.weight", f"{layer}.bias"} <= names]
        if missing:
            raise ValueError(f"{path}: a folded scorer without the arrays of {', '.join(missing[:3])}")
        return meta

    @classmethod
    def load(cls, path: str | Path, projects: bool = True) -> FoldedScorer:
        """The scorer `save` wrote; ``projects`` False leaves its training projects unread (a
        guide never needs them, and 2,000 names cost more than the weights)."""
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            array = _arrays(data, meta)
            # their own member, so that a guide reads a small header (older files: in the header)
            own = "train_projects" in data.files
            names = (data["train_projects"] if own else meta.get("train_projects", ())) if projects else ()
            held = data["holdout_projects"] if projects and "holdout_projects" in data.files else ()
            chains = {
                name: tuple(
                    tuple(
                        Affine(array(f"{name}.{c}.{i}.weight"), array(f"{name}.{c}.{i}.bias"), bool(act))
                        for i, act in enumerate(acts)
                    )
                    for c, acts in enumerate(layout)
                )
                for name, layout in meta["layout"].items()
            }
        return cls(
            config=meta["config"],
            columns=tuple(meta["columns"]),
            zone_in=chains["zone_in"][0],
            rounds=chains["rounds"],
            readout=chains["readout"][0],
            points=chains["points"][0] if chains["points"] else (),
            head=chains["head"][0] if chains["head"] else (),
            features=chains["features"][0] if chains["features"] else (),
            points_per_zone=meta["points_per_zone"],
            search=meta["search"],
            train_projects=tuple(str(p) for p in names),
            holdout_projects=tuple(str(p) for p in held),
        )

    def _chains(self) -> dict[str, tuple[Chain, ...]]:
        def one(chain: Chain) -> tuple[Chain, ...]:
            return (chain,) if chain else ()

        return {
            "zone_in": (self.zone_in,),
            "rounds": self.rounds,
            "readout": (self.readout,),
            "points": one(self.points),
            "head": one(self.head),
            "features": one(self.features),
        }


def zone_samples(graph: ZoneGraph, points_per_zone: int | None = None, seed: int = 0) -> np.ndarray:
    """(Z, 6, S) float32 sample positions and normals per zone, optionally a seeded subset of S."""
    pts = np.concatenate([graph.zone_points, graph.zone_normals], axis=2)  # (Z, S, 6)
    if points_per_zone is not None and points_per_zone < pts.shape[1]:
        keep = np.sort(np.random.default_rng(seed).choice(pts.shape[1], points_per_zone, replace=False))
        pts = pts[:, keep]
    return np.ascontiguousarray(pts.transpose(0, 2, 1), dtype=np.float32)


def _spread(codes: np.ndarray, rows: tuple[np.ndarray, ...], k: int, z: int, with_state: bool) -> np.ndarray:
    """(K, Z, H) zone codes from those computed at ``rows``: with the state's row (0, whole and
    first), every zone of a proposal not computed keeps the state's code; without, every zone
    was computed."""
    if not with_state:
        return codes.reshape(k, z, -1)
    x = np.empty((k, z, codes.shape[1]), np.float32)
    x[:] = codes[:z]
    x[rows] = codes
    return x


def _activate(x: np.ndarray, layer: Affine) -> np.ndarray:
    """The activation of a layer whose affine part was computed in pieces."""
    if layer.activation:
        np.maximum(x, SLOPE * x, out=x)
    return x


@dataclass(frozen=True)
class State:
    """What a state gives every proposal alike: the graph's adjacency and the two state flags.

    Shapes:
        inside, canvas: (Z,) bool; neighbours: (Z, Z) the mean over a zone's neighbours (a zone
        with none gets zeros, as PyG's mean).
    """

    inside: np.ndarray
    canvas: np.ndarray
    neighbours: sp.csr_matrix | np.ndarray

    @classmethod
    def of(cls, inside: np.ndarray, canvas: np.ndarray, edges: np.ndarray) -> State:
        """From the graph's adjacency, ``edges`` (E, 2) each once (a repeat counts twice, as in PyG)."""
        n = len(inside)
        rows = np.concatenate([edges[:, 0], edges[:, 1]]).astype(np.int64)
        cols = np.concatenate([edges[:, 1], edges[:, 0]]).astype(np.int64)
        adjacency = sp.csr_matrix((np.ones(len(rows), np.float32), (rows, cols)), shape=(n, n))
        degree = np.asarray(adjacency.sum(axis=1)).ravel()
        scale = np.divide(1.0, degree, out=np.zeros_like(degree), where=degree > 0).astype(np.float32)
        neighbours = sp.csr_matrix(sp.diags(scale) @ adjacency, dtype=np.float32)
        if n <= DENSE_ZONES:
            return cls(inside.astype(bool), canvas.astype(bool), neighbours.toarray())
        return cls(inside.astype(bool), canvas.astype(bool), neighbours)

    def with_canvas(self, canvas: np.ndarray) -> State:
        """The same graph at another canvas."""
        return State(self.inside, canvas.astype(bool), self.neighbours)

    def reach(self, changed: np.ndarray) -> np.ndarray:
        """(K, Z) bool: zones with a neighbour among each row's ``changed`` zones (K, Z)."""
        return (self.neighbours @ changed.T.astype(np.float32)).T > 0

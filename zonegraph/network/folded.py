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
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from zonegraph.zones.model import ZoneGraph

SLOPE = 0.2  # the LeakyReLU of every layer (zonegraph.network.model)
# Up to this many zones the neighbour mean is a dense product, above it scipy's sparse one: a zone
# has four or five neighbours whatever the graph's size, so the dense product does Z / 5 times the
# arithmetic, and scipy's few microseconds of overhead per call are won back from about 32 zones
# on (measured on corpus graphs, one thread: 47 zones 29 vs 15 us, 128 zones 146 vs 30 us).
DENSE_ZONES = 32
# The fixed cost of scoring a state within the proposals' reach (a dozen sparse products and their
# index arrays, about 0.75 ms) in zone rows of scoring every zone of every proposal (0.3 us each):
# measured on corpus graphs of 57 to 422 zones, where every zone costs less up to about 100.
REACH_ROWS = 2500
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
    `zonegraph.sequence.features.FEATURES`), ``readout`` gives the two logits (with the config's
    ``context``, from each proposal's code beside the state's greatest).
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
        memo: CodeMemo | None = None,
    ) -> np.ndarray:
        """P(positive) of each of P proposals of one state: `read` of their `embed`."""
        return self.read(self.embed(state, zones, ops, geometry, features, memo))

    def embed(
        self,
        state: State,
        zones: np.ndarray,
        ops: np.ndarray,
        geometry: np.ndarray | None = None,
        features: np.ndarray | None = None,
        memo: CodeMemo | None = None,
    ) -> np.ndarray:
        """(P, H') each of P proposals of one state as the readout reads it: its pooled zone
        codes and, with features, their embedding. Proposals embed apart from one another, so a
        state's may be embedded in parts and read together.

        A proposal changes the flags of its extrusion's zones only, and a round of message passing
        carries a change one zone further, so after round r a proposal's zone codes differ from
        the state's own (no extrusion) only within r steps of its extrusion. Where that saves
        work, the state's codes are computed once and each proposal's only where they can differ
        (`_pool_within_reach`): on a large graph most zones of most proposals are never computed.
        On a small graph, where every zone is soon within reach, every zone of every proposal is
        computed (`_pool_every_zone`). Exact either way: an untouched zone's code *is* the state's.
        The state's own codes change between two states of a search only within reach of the zones
        whose canvas flag differs, so with a ``memo`` of the graph's last state they are updated
        there rather than computed again, in the same products as the proposals' codes.

        Shapes:
            zones: (P, Z) bool, the extrusions; ops: (P,) +1 union, -1 subtract; geometry: (Z, H)
            from `encode_geometry`; features: (P, F) every column of FEATURES; returns (P, H').
        """
        zones = zones.astype(bool)
        extrusion = np.where(zones, np.where(ops > 0, 1, 2)[:, None], 0)  # (P, Z): 0 none, 1 union, 2 cut
        reach = self._reach(state, zones, fresh=memo is None or memo.last is None)
        if reach is None:
            pooled = self._pool_every_zone(state, extrusion, geometry)
        else:
            last = memo.last if memo else None
            pooled, codes = self._pool_within_reach(state, extrusion, geometry, reach, last)
            if memo is not None:
                memo.last = codes
        if not self.columns:
            return pooled
        taken = np.zeros((len(zones), max(self.columns) + 1), np.float32) if features is None else features
        return np.concatenate([pooled, run(self.features, taken[:, list(self.columns)])], axis=1)

    def read(self, codes: np.ndarray) -> np.ndarray:
        """(P,) P(positive) of a state's P proposals from their (P, H') `embed`."""
        return 1.0 / (1.0 + np.exp(-self.log_odds(codes)))

    def log_odds(self, codes: np.ndarray) -> np.ndarray:
        """(P,) the log-odds of a state's P proposals from their (P, H') `embed` (with a
        context, beside the greatest of each channel over them: every proposal of the state)."""
        if not len(codes):
            return np.zeros(0, np.float32)
        if self.config.get("context"):
            codes = np.concatenate([codes, np.broadcast_to(codes.max(axis=0), codes.shape)], axis=1)
        logits = run(self.readout, codes)
        return logits[:, 1] - logits[:, 0]

    def _reach(self, state: State, zones: np.ndarray, fresh: bool = False) -> list[np.ndarray] | None:
        """(P, Z) per layer: the zones whose codes each proposal changes after ``zone_in`` and
        each round; None where computing them (and, ``fresh``, the state's codes) costs as much
        as every zone of every proposal."""
        reach = self._spread(state, zones)
        p, z = zones.shape
        rows = sum(int(m.sum()) for m in reach) + REACH_ROWS + (z * len(reach) if fresh else 0)
        return None if rows >= p * z * len(reach) else reach

    def _spread(self, state: State, changed: np.ndarray) -> list[np.ndarray]:
        """(K, Z) per layer: the zones whose codes a change of flags at ``changed`` (K, Z) reaches
        after ``zone_in`` and each round (a round carries it one neighbour further)."""
        reach = [changed]
        for _ in self.rounds:
            reach.append(reach[-1] | state.reach(reach[-1]))
        return reach

    def _entry(
        self, inside: np.ndarray, canvas: np.ndarray, extrusion: np.ndarray, geometry: np.ndarray | None
    ) -> np.ndarray:
        """(N, H) ``zone_in`` of N zones from their flags (extrusion 0 none, 1 union, 2 subtract)
        and their rows of ``geometry``: without geometry a zone's input takes one of twelve values,
        so its code is a row of `flag_codes`."""
        if geometry is None:
            return self.flag_codes[6 * inside + 3 * canvas + extrusion]
        first = self.zone_in[0]
        flags = np.stack([inside, canvas, extrusion > 0, (extrusion == 1) - 1.0 * (extrusion == 2)], axis=1)
        x = flags.astype(np.float32) @ first.weight[-4:] + first.bias + geometry
        return run(self.zone_in[1:], _activate(x, first))

    @cached_property
    def flag_codes(self) -> np.ndarray:
        """(12, H) ``zone_in`` of each flag value a zone without geometry can have, row ``6 *
        inside + 3 * canvas + extrusion``."""
        flags = np.zeros((12, 4), np.float32)
        for row in range(12):
            inside, rest = divmod(row, 6)
            canvas, extrusion = divmod(rest, 3)
            flags[row] = (inside, canvas, extrusion > 0, (0, 1, -1)[extrusion])
        return run(self.zone_in, flags)

    def _pool_every_zone(
        self, state: State, extrusion: np.ndarray, geometry: np.ndarray | None
    ) -> np.ndarray:
        """(P, H) each proposal's zone codes pooled, every zone of every proposal computed."""
        p, z = extrusion.shape
        x = self._entry(
            np.tile(state.inside, p),
            np.tile(state.canvas, p),
            extrusion.ravel(),
            None if geometry is None else np.tile(geometry, (p, 1)),
        ).reshape(p, z, -1)
        for chain in self.rounds:
            mean = state.neighbours @ x.transpose(1, 0, 2).reshape(z, -1)
            mean = mean.reshape(z, p, -1).transpose(1, 0, 2)
            x = _round(chain, x.reshape(p * z, -1), mean.reshape(p * z, -1)).reshape(p, z, -1)
        return x.max(axis=1)

    def _update_reach(self, state: State, previous: StateCodes) -> list[np.ndarray] | None:
        """(Z,) per layer: the zones whose codes differ from ``previous``'s, or None where they
        are half the graph or more (computing every zone costs less there)."""
        reach = [m[0] for m in self._spread(state, (state.canvas != previous.canvas)[None])]
        return None if 2 * sum(int(m.sum()) for m in reach) >= len(state.canvas) * len(reach) else reach

    def _pool_within_reach(
        self,
        state: State,
        extrusion: np.ndarray,
        geometry: np.ndarray | None,
        reach: list[np.ndarray],
        previous: StateCodes | None = None,
    ) -> tuple[np.ndarray, StateCodes]:
        """(P, H) each proposal's zone codes pooled, and the state's own codes: a proposal's
        codes are the state's where it left a zone's code as it is, computed within its reach;
        the state's are ``previous``'s (the same graph at another canvas) but where a changed flag
        reaches, or every zone's.

        In each round one sparse product gives the neighbour mean of every zone computed, the
        state's first: a layer's codes are the state's (rows ``0 .. Z-1``) and then the
        proposals' reached zones in the order of `np.nonzero`, and ``where`` (P + 1, Z) holds the
        row of each one's code of each zone (the last row, the state's own)."""
        p, z = extrusion.shape
        changed = None if previous is None else self._update_reach(state, previous)
        if changed is None or previous is None:  # every zone of the state computed
            update, base = [np.arange(z)] * len(reach), None
        else:
            update, base = [np.flatnonzero(m) for m in changed], previous.layers
        pk, pz = np.nonzero(reach[0])
        rows = update[0]
        own = self._entry(
            np.concatenate([state.inside[rows], state.inside[pz]]),
            np.concatenate([state.canvas[rows], state.canvas[pz]]),
            np.concatenate([np.zeros(len(rows), np.int64), extrusion[pk, pz]]),
            None if geometry is None else geometry[np.concatenate([rows, pz])],
        )
        layers = [_updated(base[0] if base else None, rows, own[: len(rows)])]
        own = own[len(rows) :]
        where = np.tile(np.arange(z, dtype=np.int32), (p + 1, 1))
        for layer, (chain, mask) in enumerate(zip(self.rounds, reach[1:], strict=True), 1):
            where[pk, pz] = z + np.arange(len(pk))  # a round reaches every zone the one before did
            pk, pz = np.nonzero(mask)
            rows = update[layer]
            zones, owners = np.concatenate([rows, pz]), np.concatenate([np.full(len(rows), p), pk])
            x = np.concatenate([layers[-1], own])
            out = _round(chain, x[where[owners, zones]], _mean_at(state.links, zones, x, where, owners))
            layers.append(_updated(base[layer] if base else None, rows, out[: len(rows)]))
            own = out[len(rows) :]
        pooled = np.full((p, own.shape[1]), -np.inf, np.float32)
        firsts = np.flatnonzero(np.diff(pk, prepend=-1))  # each proposal's first reached zone
        pooled[pk[firsts]] = np.maximum.reduceat(own, firsts, axis=0)
        codes = StateCodes(state.canvas, tuple(layers))
        return np.maximum(pooled, _max_elsewhere(layers[-1], reach[-1])), codes

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


def _round(chain: Chain, x: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """One round of message passing over N zones: (N, H) their codes and their neighbours' means
    in, (N, H) out (the first layer reads both side by side: two products instead of a copy)."""
    first, h = chain[0], x.shape[1]
    y = x @ first.weight[:h]
    y += mean @ first.weight[h:]
    y += first.bias
    return run(chain[1:], _activate(y, first))


def _updated(before: np.ndarray | None, rows: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """A layer of the state's codes: ``codes`` at ``rows`` and ``before`` elsewhere (``codes``
    themselves where there is no layer before, every zone computed)."""
    if before is None:
        return codes
    layer = before.copy()
    layer[rows] = codes
    return layer


def _mean_at(
    links: sp.csr_matrix, zones: np.ndarray, x: np.ndarray, where: np.ndarray, owners: np.ndarray
) -> np.ndarray:
    """(N, H) the neighbour mean of N ``zones``, the i-th zone's neighbour ``j`` read from row
    ``where[owners[i], j]`` of ``x``. The product's index arrays are 32-bit, as scipy's own: it
    checks 64-bit ones at twice the cost."""
    counts = np.diff(links.indptr)[zones]
    indptr = np.zeros(len(zones) + 1, np.int32)
    np.cumsum(counts, out=indptr[1:])
    at = np.repeat(links.indptr[zones] - indptr[:-1], counts) + np.arange(indptr[-1], dtype=np.int32)
    columns = where[np.repeat(owners, counts), links.indices[at]]
    matrix = sp.csr_matrix((links.data[at], columns.astype(np.int32), indptr), shape=(len(zones), len(x)))
    return matrix @ x


def _max_elsewhere(codes: np.ndarray, reached: np.ndarray, top: int = 16) -> np.ndarray:
    """(P, H) per proposal the greatest code of each channel over the zones it did not reach,
    from the state's (Z, H) ``codes`` (-inf where it reached every zone): of each channel's
    ``top`` greatest zones, the first the proposal did not reach; the whole graph only for a
    channel whose ``top`` it reached all of."""
    z, h = codes.shape
    t = min(top, z)
    best_zones = np.argpartition(-codes, t - 1, axis=0)[:t] if t < z else np.argsort(-codes, axis=0)
    values = np.take_along_axis(codes, best_zones, axis=0)
    order = np.argsort(-values, axis=0, kind="stable")
    best_zones, values = np.take_along_axis(best_zones, order, 0), np.take_along_axis(values, order, 0)
    free = ~reached[:, best_zones]  # (P, t, H)
    best = values[free.argmax(axis=1), np.arange(h)]
    blocked = np.logical_not(np.any(free, axis=1))  # (P, H): every one of the channel's top reached
    for k in np.flatnonzero(np.any(blocked, axis=1)):
        rest = codes[~reached[k]]
        best[k] = rest.max(axis=0) if len(rest) else -np.inf
    return best


def _activate(x: np.ndarray, layer: Affine) -> np.ndarray:
    """The activation of a layer whose affine part was computed in pieces."""
    if layer.activation:
        np.maximum(x, SLOPE * x, out=x)
    return x


@dataclass(frozen=True)
class StateCodes:
    """Every zone's code at one canvas with no extrusion: after ``zone_in``, then each round."""

    canvas: np.ndarray  # (Z,) bool
    layers: tuple[np.ndarray, ...]  # (Z, H) each


@dataclass
class CodeMemo:
    """The last state's codes of one graph, kept by its scorer between the states of a search."""

    last: StateCodes | None = None


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
    links: sp.csr_matrix  # the same mean, sparse whatever the size (`FoldedScorer._pool_within_reach`)

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
        dense = neighbours.toarray() if n <= DENSE_ZONES else neighbours
        return cls(inside.astype(bool), canvas.astype(bool), dense, neighbours)

    def with_canvas(self, canvas: np.ndarray) -> State:
        """The same graph at another canvas."""
        return State(self.inside, canvas.astype(bool), self.neighbours, self.links)

    def reach(self, changed: np.ndarray) -> np.ndarray:
        """(K, Z) bool: zones with a neighbour among each row's ``changed`` zones (K, Z)."""
        return (self.neighbours @ changed.T.astype(np.float32)).T > 0

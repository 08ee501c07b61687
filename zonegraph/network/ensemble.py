"""An ensemble of folded scorers as one folded scorer: the members side by side.

An ensemble ranks by the mean of its members' log-odds. Every layer of a folded scorer is an
affine map followed by an element-wise LeakyReLU, a max over zones per channel, or a neighbour
mean per channel, so K members of one architecture are one network K times as wide: a layer
that reads the members' shared input (the zone flags, the proposal features, the point
samples) stacks their weights side by side, a layer that reads their own codes is
block-diagonal, and the last layer averages their logits. The guide, the reach bookkeeping and
the `.npz` format stay as they are. The block-diagonal products are dense, zeros included, so a
scored state costs more than the members' sum (docs/results/network.md: two members 2 - 2.5
times one, four 5 - 6 times).

Members must share the fusion, rounds, points, features and context (students of one recipe,
trained with different seeds); their widths may differ.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.linalg import block_diag

from zonegraph.network.folded import Affine, Chain, FoldedScorer

FLAGS = 4  # the zone flags every member's zone_in reads after its geometry rows
SAME = ("fusion", "rounds", "use_points", "features", "context")


def side_by_side(members: Sequence[FoldedScorer]) -> FoldedScorer:
    """One folded scorer whose P(positive) is the sigmoid of the members' mean log-odds.

    Raises:
        ValueError: fewer than two members, or members of different architectures.
    """
    if len(members) < 2:
        raise ValueError("an ensemble needs two members or more")
    first = members[0]
    for member in members[1:]:
        differ = [key for key in SAME if member.config.get(key) != first.config.get(key)]
        if differ or member.columns != first.columns:
            raise ValueError(f"ensemble members differ in {', '.join(differ or ['columns'])}")
    widths = [m.zone_in[-1].weight.shape[1] for m in members]
    embeds = [m.features[-1].weight.shape[1] if m.features else 0 for m in members]
    points = bool(first.points)
    config = {**first.config, "hidden": sum(widths), "members": len(members)}
    return FoldedScorer(
        config=config,
        columns=first.columns,
        zone_in=_zone_in([m.zone_in for m in members], points),
        rounds=tuple(_round([m.rounds[r] for m in members], widths) for r in range(len(first.rounds))),
        readout=_readout([m.readout for m in members], widths, embeds, bool(first.config.get("context"))),
        points=_shared([m.points for m in members]) if points else (),
        head=_own([m.head for m in members]) if points else (),
        features=_shared([m.features for m in members]) if first.features else (),
        points_per_zone=first.points_per_zone,
        search=first.search,
        train_projects=tuple(sorted(set().union(*(m.train_projects for m in members)))),
        holdout_projects=tuple(sorted(set.intersection(*(set(m.holdout_projects) for m in members)))),
    )


def _layer(weight: np.ndarray, biases: Sequence[np.ndarray], like: Affine) -> Affine:
    return Affine(weight.astype(np.float32), np.concatenate(biases).astype(np.float32), like.activation)


def _blocks(weights: Sequence[np.ndarray]) -> np.ndarray:
    return np.asarray(block_diag(*weights))


def _own(chains: Sequence[Chain]) -> Chain:
    """Every layer block-diagonal: each member reads its own codes."""
    return tuple(
        _layer(_blocks([c[i].weight for c in chains]), [c[i].bias for c in chains], chains[0][i])
        for i in range(len(chains[0]))
    )


def _shared(chains: Sequence[Chain]) -> Chain:
    """The first layer reads an input every member reads (side by side), the rest their own."""
    first = _layer(np.hstack([c[0].weight for c in chains]), [c[0].bias for c in chains], chains[0][0])
    return (first, *_own([c[1:] for c in chains]))


def _zone_in(chains: Sequence[Chain], points: bool) -> Chain:
    """The first layer reads each member's geometry code (its own) and the flags (shared)."""
    if not points:
        return _shared(chains)
    heads = [c[0].weight for c in chains]
    rows = np.vstack([_blocks([w[:-FLAGS] for w in heads]), np.hstack([w[-FLAGS:] for w in heads])])
    return (_layer(rows, [c[0].bias for c in chains], chains[0][0]), *_own([c[1:] for c in chains]))


def _segments(weights: Sequence[np.ndarray], sizes: Sequence[Sequence[int]]) -> np.ndarray:
    """A first layer whose input is several segments (each segment the members' parts in
    member order), from each member's weight whose rows are its own parts in segment order."""
    parts = []
    for segment in range(len(sizes[0])):
        pieces = []
        for weight, own in zip(weights, sizes, strict=True):
            start = sum(own[:segment])
            pieces.append(weight[start : start + own[segment]])
        parts.append(_blocks(pieces))
    return np.vstack(parts)


def _round(chains: Sequence[Chain], widths: Sequence[int]) -> Chain:
    """A round reads a zone's codes beside its neighbours' mean: two segments of the members'."""
    first = _segments([c[0].weight for c in chains], [[w, w] for w in widths])
    return (_layer(first, [c[0].bias for c in chains], chains[0][0]), *_own([c[1:] for c in chains]))


def _readout(chains: Sequence[Chain], widths: Sequence[int], embeds: Sequence[int], context: bool) -> Chain:
    """The readout reads pooled codes and feature embeddings (again for the context, with one);
    its last layer averages the members' logits."""
    own = [[w, e] * (2 if context else 1) for w, e in zip(widths, embeds, strict=True)]
    sizes = [[s for s in parts if s] for parts in own]
    first = _segments([c[0].weight for c in chains], sizes)
    middle = _own([c[1:-1] for c in chains])
    last = np.vstack([c[-1].weight for c in chains]) / len(chains)
    bias = np.mean([c[-1].bias for c in chains], axis=0)
    out = Affine(last.astype(np.float32), bias.astype(np.float32), chains[0][-1].activation)
    return (_layer(first, [c[0].bias for c in chains], chains[0][0]), *middle, out)

"""The network guide: a trained scorer behind the search's ``Ranker`` protocol.

`zonegraph.plugins` names it as the ``net`` guide by reference, so ``zonegraph infer PART
--guide net`` and ``make_ranker("net")`` import this module only when the guide is used. A
late-fusion scorer (the default, and the shipped one) runs folded to numpy
(`zonegraph.network.folded`): the shipped ``scorer.npz`` needs no torch at all, and a
PyTorch checkpoint of late fusion is folded when loaded. Early and factored fusion, or a
``device`` other than the CPU, keep the PyTorch forward (`zonegraph.network.scoring`).
Either way a graph's zone geometry is encoded once and each state's proposals are scored in one
batched pass, in eval mode; a folded scorer's weights are read on the first state that needs
them (`LazyScorer`).

Scoring counts inside the search's budget, so knobs trade the network's cost against the
heuristic's: ``top_m`` scores only the heuristic's best M proposals of a state with the network
(the rest follow, in the heuristic's order, below every scored one), ``margin`` only those whose
heuristic score is within that much of the best one's (a state where the heuristic's first
choice leads by more costs no network call at all), and ``blend`` mixes the heuristic's score
into the network's (``(1 - blend) * net + blend * heuristic``), and ``defer`` takes the heuristic's
first choice of a state unscored and asks the network only when the search comes back for a
second one (a search that never backtracks costs what the heuristic's does), and ``wake``, with
``defer``, lets the network order every state of a graph from the first time the search backtracks
in it on: a design the heuristic's first choices solve costs what the heuristic's search does, one
where they failed once is searched in the network's order; and ``relay`` N searches in the
heuristic's order alone (no network call) and, after N expansions without the target, starts a
second walk from the empty canvas in the network's order (every state scored), the two walks
taking turns (`zonegraph.sequence.best_first.search`): a design the heuristic solves within N
expansions costs what the heuristic's search does, and a wrong first choice near the root, which
backtracking deep in its subtree does not undo within a budget, is not the only way left. ``calls``
N lets the network score at most N states of one search, the rest taking the heuristic's order: a
network call costs a few heuristic expansions, so a search that backtracks through thousands of
states without finding the target (where neither order solves the design) makes the heuristic's
progress after the first N instead of a fraction of it. A
checkpoint may carry its own defaults (its ``search`` entry); the arguments override them. A state
where a proposal completes the target never reaches a ranker in search
(`zonegraph.sequence.best_first` takes that step unscored), so where the guide is asked to rank
one (the relative GT rank), the network ranks it with its own scores, as the paper's network
ranks every state.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterator
from functools import cache
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from threadpoolctl import ThreadpoolController

from zonegraph.network.folded import SHIPPED_FOLDED, CodeMemo, FoldedScorer, State, zone_samples
from zonegraph.plugins import model_problem
from zonegraph.sequence.features import proposal_features, target_surfaces
from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.sequence.rankers import HeuristicRanker, best_first
from zonegraph.zones.model import ZoneGraph

UNSCORED = -3.0  # below any network score (a probability) minus the heuristic's (< 2)


class StateScorer(Protocol):
    """P(positive) of one state's proposals; keeps what it encodes per graph."""

    columns: tuple[int, ...]  # the proposal features it reads (none: it needs none computed)
    points_per_zone: int | None
    search: dict[str, Any]

    def score(
        self,
        graph: ZoneGraph,
        canvas: np.ndarray,
        zones: np.ndarray,
        ops: np.ndarray,
        features: np.ndarray | None,
    ) -> np.ndarray:
        """Shapes: canvas (Z,) bool; zones (P, Z) bool; ops (P,) +1/-1; features (P, F); returns (P,)."""
        ...


class NumpyScorer:
    """A `FoldedScorer` with its graph's adjacency, geometry codes and last state's zone codes kept
    between states.

    OpenBLAS would spread each small product over every core, and with the other core busy (two
    pipeline workers on two cores) its threads wait on each other: a 40-zone state took 94 ms
    instead of 2 ms. Scoring runs on one BLAS thread.
    """

    def __init__(self, folded: FoldedScorer) -> None:
        self.folded = folded
        self.columns = folded.columns
        self.points_per_zone = folded.points_per_zone
        self.search = folded.search
        self._graph: ZoneGraph | None = None
        self._state: State | None = None
        self._geometry: np.ndarray | None = None
        self._memo = CodeMemo()

    def score(
        self,
        graph: ZoneGraph,
        canvas: np.ndarray,
        zones: np.ndarray,
        ops: np.ndarray,
        features: np.ndarray | None,
    ) -> np.ndarray:
        with _blas_threads().limit(limits=1, user_api="blas"):
            if graph is not self._graph or self._state is None:
                self._graph, self._memo = graph, CodeMemo()
                self._state = State.of(graph.zone_inside, canvas, graph.edges.astype(np.int64))
                points = zone_samples(graph, self.points_per_zone) if self.folded.points else None
                self._geometry = None if points is None else self.folded.encode_geometry(points)
            state = self._state.with_canvas(canvas)
            ops32 = ops.astype(np.float32)
            return self.folded.score(state, zones, ops32, self._geometry, features, self._memo)


class LazyScorer:
    """A folded scorer (``.npz``) whose weights are read when it first scores a state.

    Most corpus designs are solved in one expansion whose completing step is taken unscored, so
    the network is never called on them, and a search that never needs the weights should not
    pay for holding them (measured: docs/results/network.md, "Search at equal wall-clock"). Only
    the header is read up front: the knobs, the features to compute and the samples per zone.
    """

    def __init__(self, path: Path) -> None:
        meta = FoldedScorer.header(path)
        self.path = path
        self.columns: tuple[int, ...] = tuple(meta["columns"])
        self.points_per_zone: int | None = meta["points_per_zone"]
        self.search: dict[str, Any] = meta["search"]
        self._scorer: NumpyScorer | None = None

    @property
    def loaded(self) -> bool:
        return self._scorer is not None

    def score(
        self,
        graph: ZoneGraph,
        canvas: np.ndarray,
        zones: np.ndarray,
        ops: np.ndarray,
        features: np.ndarray | None,
    ) -> np.ndarray:
        if self._scorer is None:
            self._scorer = NumpyScorer(FoldedScorer.load(self.path, projects=False))
        return self._scorer.score(graph, canvas, zones, ops, features)


@cache
def _blas_threads() -> ThreadpoolController:
    """The process's BLAS thread pools (finding them reads every loaded library: once)."""
    return ThreadpoolController()


def open_scorer(path: Path, device: str = "cpu") -> StateScorer:
    """The scorer a checkpoint holds: numpy where it folds (a ``.npz``, or a late-fusion ``.pt``
    on the CPU), PyTorch otherwise (which then must be installed)."""
    if path.suffix == ".npz":
        return NumpyScorer(FoldedScorer.load(path))
    problem = model_problem(str(path))
    if problem is not None:
        raise ValueError(problem)
    from zonegraph.network.checkpoint import fold_checkpoint, read_checkpoint
    from zonegraph.network.scoring import TorchScorer

    checkpoint = read_checkpoint(path, device)
    if checkpoint["model"].get("fusion", "late") == "late" and device == "cpu":
        return NumpyScorer(fold_checkpoint(checkpoint))
    return TorchScorer(checkpoint, device)


class NetworkRanker:
    """Scores proposals with a trained scorer (P(positive), higher first)."""

    samples = 128  # surface samples per zone the search builds graphs with: the checkpoint's own

    def __init__(
        self,
        model: str | Path | None = None,
        seed: int = 0,  # the guides' factory signature; the forward draws nothing
        device: str = "cpu",
        top_m: int | None = None,
        blend: float | None = None,
        margin: float | None = None,
        defer: bool | None = None,
        wake: bool | None = None,
        relay: int | None = None,
        calls: int | None = None,
    ) -> None:
        path = Path(model) if model else SHIPPED_FOLDED
        if not path.is_file():
            raise ValueError(f"{path}: no model checkpoint (in a checkout: python -m training.train)")
        self.scorer = LazyScorer(path) if path.suffix == ".npz" else open_scorer(path, device)
        self.samples = int(self.scorer.points_per_zone or self.samples)
        search = self.scorer.search
        self.top_m: int | None = top_m if top_m is not None else search.get("top_m")
        self.blend = float(blend if blend is not None else search.get("blend", 0.0))
        self.margin: float | None = margin if margin is not None else search.get("margin")
        self.defer = bool(defer if defer is not None else search.get("defer", False))
        self.wake = bool(wake if wake is not None else search.get("wake", False))
        self.relay_after: int | None = (relay if relay is not None else search.get("relay")) or None
        self.calls: int | None = calls if calls is not None else search.get("calls")
        self._made = 0  # network calls of the current search
        self._woken: ZoneGraph | None = None  # the graph in whose search the network took over
        self._heuristic = HeuristicRanker()
        self._graph: ZoneGraph | None = None
        self._on_target: np.ndarray | None = None

    def score(self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal]) -> np.ndarray:
        """(P,) scores of one state whose depth is not known (the step feature reads 0)."""
        return self.score_at(graph, canvas, proposals, 0)

    def relay(self) -> tuple[int, Callable[[], NetworkRanker]] | None:
        """With ``relay`` N: N, and how to make the search's second walk's guide (this one
        ordering every state itself), made only if the relay starts; else None."""
        return (self.relay_after, self._relayed) if self.relay_after else None

    def _relayed(self) -> NetworkRanker:
        second = copy.copy(self)  # the same scorer and its per-graph encodings
        second.defer, second.relay_after = False, None
        return second

    def order_at(
        self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal], step: int, k: int
    ) -> Iterator[int]:
        """At most ``k`` proposals of one state, best first, as the search asks for them: ordered
        by `score_at`, or with ``defer`` the heuristic's first choice, then (scored only when
        the search backtracks to this state) the network's order of the others; with ``wake``
        every state of a graph is ordered by `score_at` once the search has backtracked in it;
        with ``relay`` by the heuristic (the network orders the search's second walk)."""
        if step == 0:  # a search's first state: a new search, asleep again
            self._woken, self._made = None, 0
        if not proposals:
            return iter(())
        if self.relay_after:  # the first walk of a relay: the heuristic's order
            return iter(best_first(self._heuristic.score(graph, canvas, proposals))[:k])
        heuristic = self._heuristic.score(graph, canvas, proposals)
        if not self.defer or self._woken is graph:
            if not self._charge():
                return iter(best_first(heuristic)[:k])
            return iter(best_first(self._scored(heuristic, graph, canvas, proposals, step))[:k])
        return self._after(heuristic, graph, canvas, proposals, step, k)

    def _charge(self) -> bool:
        """Whether the network may score one more state of the current search (``calls``);
        counts the call."""
        self._made += 1
        return self.calls is None or self._made <= self.calls

    def _after(
        self,
        heuristic: np.ndarray,
        graph: ZoneGraph,
        canvas: np.ndarray,
        proposals: list[Proposal],
        step: int,
        k: int,
    ) -> Iterator[int]:
        """The heuristic's first choice, then the network's next ``k - 1``, scored when the search
        asks for them (with the heuristic's scores of the state, computed once)."""
        first = int(np.argmax(heuristic))
        yield first
        if self.wake:
            self._woken = graph
        if k > 1 and len(proposals) > 1:
            charged = self._charge()
            scores = self._scored(heuristic, graph, canvas, proposals, step) if charged else heuristic
            yield from [i for i in best_first(scores) if i != first][: k - 1]

    def score_at(
        self, graph: ZoneGraph, canvas: np.ndarray, proposals: list[Proposal], step: int
    ) -> np.ndarray:
        """(P,) scores of every proposal of one state ``step`` operations deep: P(positive), or
        its blend with the heuristic; proposals outside the heuristic's top M or its margin below
        them all."""
        if not proposals:
            return np.zeros(0)
        return self._scored(self._heuristic.score(graph, canvas, proposals), graph, canvas, proposals, step)

    def _scored(
        self,
        heuristic: np.ndarray,
        graph: ZoneGraph,
        canvas: np.ndarray,
        proposals: list[Proposal],
        step: int,
    ) -> np.ndarray:
        """`score_at` given the heuristic's scores of the state's proposals."""
        chosen = np.arange(len(proposals))
        if self.margin is not None:
            chosen = np.flatnonzero(heuristic >= heuristic.max() - self.margin)
        if self.top_m and self.top_m < len(chosen):
            chosen = np.sort(chosen[np.argsort(-heuristic[chosen], kind="stable")[: self.top_m]])
        if len(chosen) == 1:  # the heuristic's first choice, alone in reach: its order stands
            return heuristic
        picked = [proposals[i] for i in chosen]
        zones = np.stack([p.zones for p in picked]).astype(bool)
        ops = np.array([1 if p.op is Op.UNION else -1 for p in picked])
        features = None
        if self.scorer.columns:
            if graph is not self._graph:
                self._graph, self._on_target = graph, target_surfaces(graph)
            features = proposal_features(graph, canvas, picked, step, self._on_target)
        net = self.scorer.score(graph, canvas.astype(bool), zones, ops, features)
        out = UNSCORED + heuristic
        out[chosen] = (1 - self.blend) * net + self.blend * heuristic[chosen]
        return out

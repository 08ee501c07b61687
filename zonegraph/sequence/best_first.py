"""Best-first search with top-k and backtracking over zone-graph canvases (paper sec. 4, Alg. 2).

A state is only a canvas (a bool vector over zones): the geometry never changes. At each state all
proposals are scored at once by a ranker (unless one completes the target: it is taken unscored),
the top k are kept (k may shrink with depth, as the paper's 15 - 0.5 per level), the best is
explored first, and a dead end (no proposal, depth limit, a canvas seen before) backs up to the
next of the top k. The search stops when the canvas equals the target or a budget (wall clock,
expansions) is spent, and returns the best canvas seen: highest zone IoU, then fewest steps. The
wall clock is a `Deadline` that proposal generation checks too, since one expansion of a
graph of thousands of zones can outlast the whole budget. The anytime trace of (seconds, best IoU)
feeds IoU-vs-time curves.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from zonegraph.configs import Config
from zonegraph.sequence.deadline import Deadline
from zonegraph.sequence.proposals import Proposal, ProposalGenerator
from zonegraph.sequence.rankers import Ranker, order_step, zone_exact, zone_iou
from zonegraph.zones.model import ZoneGraph


@dataclass(frozen=True)
class SearchConfig(Config):
    """How far a search may go: top-k width (shrinking with depth), depth, time and work bounds.

    Args:
        k: proposals kept per state.
        k_decay: decrease of k per depth level (the paper's harder runs: k 15, decay 0.5).
        max_depth: longest program searched.
        budget_s: wall-clock budget in seconds.
        max_expansions: a work bound (states expanded); unlike seconds it is the same on any
            machine, so seeded runs bounded by it are reproducible.

    ``zonegraph infer`` derives it from its `InferConfig` (which holds
    every field of it) with ``SearchConfig.from_mapping(asdict(infer_config))``.
    """

    k: int = 5
    k_decay: float = 0.0  # per depth level: the paper's harder runs used k = 15, decay 0.5
    max_depth: int = 20
    budget_s: float = 10.0
    max_expansions: int | None = None

    def k_at(self, depth: int) -> int:
        """Proposals kept at ``depth`` (at least one)."""
        return max(1, int(round(self.k - self.k_decay * depth)))


@dataclass
class SearchResult:
    """The best canvas a search found and how it got there.

    Shapes:
        canvas: (Z,) bool, the best canvas; steps: the proposals leading to it, in order.
    """

    exact: bool
    iou: float
    steps: list[Proposal]
    canvas: np.ndarray
    expansions: int
    seconds: float
    time_to_best_s: float
    trace: list[tuple[float, float]]  # (seconds, best IoU so far)
    proposals_per_state: list[int]
    expansion_s: list[float]  # seconds per expansion (proposals + scoring; a deferred scoring not)
    ended: str = "exhausted"  # why it stopped: exact, exhausted (its space), budget or expansions


def _finishing(
    graph: ZoneGraph, canvas: np.ndarray, target: np.ndarray, proposals: list[Proposal]
) -> list[int]:
    """The proposals whose canvas is the target, those agreeing on the most zones first (the
    degenerate ones need not agree), else in the generator's order.

    A step that completes the target ends the search with the shortest program left to find, so
    it goes first without asking the ranker (a goal test on generation): the heuristic already
    scores it first by its agreement, and a network's forward pass on such a state is pure cost,
    paid on most corpus designs, which are one step from the empty canvas.
    """
    after = {i: p.apply(canvas) for i, p in enumerate(proposals)}
    done = [i for i, c in after.items() if zone_exact(graph, c, target)]
    return sorted(done, key=lambda i: int((after[i] != target).sum()))


@dataclass
class _Frame:
    canvas: np.ndarray
    path: list[Proposal]
    children: Iterator[Proposal]


class _Search:
    """What the walks of one search share: the generator and its budget, the best canvas so far
    with its anytime trace, and the per-expansion statistics."""

    def __init__(self, graph: ZoneGraph, config: SearchConfig, gen: ProposalGenerator, deadline: Deadline):
        self.graph, self.config, self.gen, self.deadline = graph, config, gen, deadline
        self.target = graph.zone_inside.astype(bool)
        self.t0 = time.perf_counter()
        self.empty = np.zeros(graph.n_zones, bool)
        iou = zone_iou(graph, self.empty, self.target)
        self.best: tuple[float, int, np.ndarray, list[Proposal]] = (iou, 0, self.empty, [])
        self.trace = [(0.0, iou)]
        self.time_to_best = 0.0
        self.exact = zone_exact(graph, self.empty, self.target)
        self.counts: list[int] = []
        self.times: list[float] = []

    def expand(self, ranker: Ranker, canvas: np.ndarray, path: list[Proposal]) -> Iterator[Proposal]:
        """A state's proposals in the order the walk tries them: a completing one alone, else
        the ranker's best ``k``."""
        start = time.perf_counter()
        used = {p.inverse_key for p in path}
        props = [p for p in self.gen.proposals(canvas, self.deadline) if p.key not in used]
        self.counts.append(len(props))
        order: Iterator[int] = iter(())
        if props and not self.deadline.passed():  # past it, the search stops: nothing to score for
            done = _finishing(self.graph, canvas, self.target, props)[:1]
            k = self.config.k_at(len(path))
            order = iter(done) if done else order_step(ranker, self.graph, canvas, props, len(path), k)
        self.times.append(time.perf_counter() - start)
        return (props[i] for i in order)

    def reached(self, canvas: np.ndarray, path: list[Proposal]) -> None:
        """Keep ``canvas`` if it is the best so far (highest zone IoU, then fewest steps)."""
        iou = zone_iou(self.graph, canvas, self.target)
        if (iou, -len(path)) > (self.best[0], -self.best[1]):
            self.best = (iou, len(path), canvas, path)
            self.time_to_best = time.perf_counter() - self.t0
            self.trace.append((self.time_to_best, iou))
        self.exact = zone_exact(self.graph, canvas, self.target)


class _Walk:
    """One depth-first walk from the empty canvas, ordered by one ranker: its stack, and the
    canvases it has seen (a canvas reached before is a dead end)."""

    def __init__(self, search: _Search, ranker: Ranker) -> None:
        self.search, self.ranker = search, ranker
        self.seen = {np.packbits(search.empty).tobytes()}
        self.stack = [_Frame(search.empty, [], search.expand(ranker, search.empty, []))]

    def step(self) -> bool:
        """Try the next child of the deepest state: True when a new state was expanded."""
        frame = self.stack[-1]
        child = next(frame.children, None)
        if child is None:
            self.stack.pop()
            return False
        canvas = child.apply(frame.canvas)
        key = np.packbits(canvas).tobytes()
        if key in self.seen:
            return False
        self.seen.add(key)
        path = frame.path + [child]
        self.search.reached(canvas, path)
        if self.search.exact or len(path) >= self.search.config.max_depth:
            return False
        self.stack.append(_Frame(canvas, path, self.search.expand(self.ranker, canvas, path)))
        return True


def search(
    graph: ZoneGraph,
    ranker: Ranker,
    config: SearchConfig = SearchConfig(),
    generator: ProposalGenerator | None = None,
    deadline: Deadline | None = None,
) -> SearchResult:
    """Find a proposal sequence whose canvas equals the target's zones (best-first, top-k).

    A ranker may offer ``relay() -> (n, make)``: once ``n`` states are expanded without the target
    (or its own walk is exhausted), a second walk starts from the empty canvas in the order of the
    ranker ``make()`` returns, and the two walks take turns, a state each (the network guide's
    ``relay``: where the heuristic's first choices went wrong near the root, backtracking deep in
    their subtree cannot undo them).

    Args:
        graph: the zone graph; its ``zone_inside`` is the target.
        ranker: scores all proposals of a state at once (see `Ranker`).
        config: width, depth and budget.
        generator: a proposal generator to reuse (its memoised sweeps carry over); by default a
            new level-1 generator.
        deadline: when the search stops, checked between and within expansions; by default
            ``config.budget_s`` from now (a caller passes one to count work done before, such
            as building the generator, against the budget).

    Returns:
        The best canvas seen (highest zone IoU, then fewest steps), exact or not, with the anytime
            trace and per-expansion statistics.
    """
    if deadline is None:
        deadline = Deadline.after(config.budget_s)
    state = _Search(graph, config, generator or ProposalGenerator(graph), deadline)
    relay = getattr(ranker, "relay", None)
    second: tuple[int, Callable[[], Ranker]] | None = relay() if relay is not None else None
    walks = [_Walk(state, ranker)]
    turn = 0
    ended = "exhausted"
    while not state.exact:
        if deadline.passed():
            ended = "budget"
            break
        if config.max_expansions and len(state.counts) >= config.max_expansions:
            ended = "expansions"
            break
        if second is not None and (len(state.counts) >= second[0] or not walks):
            walks.append(_Walk(state, second[1]()))  # its first state expanded as it starts
            second, turn = None, len(walks)  # so the first walk goes next
            continue
        if not walks:
            break
        walk = walks[turn % len(walks)]
        if not walk.stack:
            walks.remove(walk)  # exhausted
        elif walk.step():
            turn += 1
    return SearchResult(
        exact=state.exact,
        iou=state.best[0],
        steps=state.best[3],
        canvas=state.best[2],
        expansions=len(state.counts),
        seconds=time.perf_counter() - state.t0,
        time_to_best_s=state.time_to_best,
        trace=state.trace,
        proposals_per_state=state.counts,
        expansion_s=state.times,
        ended="exact" if state.exact else ended,
    )

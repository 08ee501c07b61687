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
from collections.abc import Iterator
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


def search(
    graph: ZoneGraph,
    ranker: Ranker,
    config: SearchConfig = SearchConfig(),
    generator: ProposalGenerator | None = None,
    deadline: Deadline | None = None,
) -> SearchResult:
    """Find a proposal sequence whose canvas equals the target's zones (best-first, top-k).

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
    gen = generator or ProposalGenerator(graph)
    target = graph.zone_inside.astype(bool)
    t0 = time.perf_counter()
    empty = np.zeros(graph.n_zones, bool)
    best: tuple[float, int, np.ndarray, list[Proposal]] = (zone_iou(graph, empty, target), 0, empty, [])
    trace = [(0.0, best[0])]
    time_to_best = 0.0
    seen = {np.packbits(empty).tobytes()}
    counts: list[int] = []
    times: list[float] = []

    def expand(canvas: np.ndarray, path: list[Proposal]) -> Iterator[Proposal]:
        start = time.perf_counter()
        used = {p.inverse_key for p in path}
        props = [p for p in gen.proposals(canvas, deadline) if p.key not in used]
        counts.append(len(props))
        order: Iterator[int] = iter(())
        if props and not deadline.passed():  # past it, the search stops: nothing to score for
            done = _finishing(graph, canvas, target, props)[:1]
            k = config.k_at(len(path))
            order = iter(done) if done else order_step(ranker, graph, canvas, props, len(path), k)
        times.append(time.perf_counter() - start)
        return (props[i] for i in order)

    stack = [_Frame(empty, [], expand(empty, []))]
    exact = zone_exact(graph, empty, target)
    ended = "exhausted"
    while stack and not exact:
        if deadline.passed():
            ended = "budget"
            break
        if config.max_expansions and len(counts) >= config.max_expansions:
            ended = "expansions"
            break
        frame = stack[-1]
        child = next(frame.children, None)
        if child is None:
            stack.pop()
            continue
        canvas = child.apply(frame.canvas)
        key = np.packbits(canvas).tobytes()
        if key in seen:
            continue
        seen.add(key)
        path = frame.path + [child]
        iou = zone_iou(graph, canvas, target)
        if (iou, -len(path)) > (best[0], -best[1]):
            best = (iou, len(path), canvas, path)
            time_to_best = time.perf_counter() - t0
            trace.append((time_to_best, iou))
        if zone_exact(graph, canvas, target):
            exact = True
            break
        if len(path) < config.max_depth:
            stack.append(_Frame(canvas, path, expand(canvas, path)))
    return SearchResult(
        exact=exact,
        iou=best[0],
        steps=best[3],
        canvas=best[2],
        expansions=len(counts),
        seconds=time.perf_counter() - t0,
        time_to_best_s=time_to_best,
        trace=trace,
        proposals_per_state=counts,
        expansion_s=times,
        ended="exact" if exact else ended,
    )

"""Ternary training labels by random completions (paper sec. 4.2, ``docs/algorithm.md`` sec. 6).

At every ground-truth (GT) step i whose GT is captured, the proposals at C_{i-1} are those the
search itself would see there: the same generator and level, minus inverses of the GT steps
already taken. The GT proposal is positive. Every other proposal starts N random completions
(N = ``multiplier`` x the GT steps from this one on, at least 1): the proposal, then
uniformly random proposals (same generator, no inverse of a step on the path) until the canvas
equals the target, no proposal is left, or the completion is ``remaining + slack`` steps long,
where ``remaining`` = the GT steps from i on. The bound: a completion that needs more steps than
the GT plus a small slack is almost never a useful alternative, while unbounded random walks are
what made labelling take "hours to days"; ``slack`` (default 2) lets an alternative order or a
split of one step into two count. p = the share of completions that reach the target. Proposals
with p = 0 are negative; if none has p = 0, the one with the smallest p (the first in proposal
order on ties) is negative; the rest are neutral.

Every proposal row also carries its `zonegraph.sequence.features` (columns ``feat_<name>``),
the numbers the network guide reads beside the zone flags, computed by the same function the
search calls, so training and search see one definition.

Costs are shared across all completions of a design: the generator's memoised sweeps and a
canvas -> proposals cache (canvases as packed bit vectors), each bounded, the least recently used
dropped first (`zonegraph.sequence.memo`). Everything random comes from one
generator seeded by (seed, design id): the same seed gives the same labels.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa

from zonegraph.sequence.features import FEATURES, PROPOSAL_FEATURES, proposal_features, target_surfaces
from zonegraph.sequence.memo import Memo
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.zones.model import ZoneGraph

POSITIVE, NEUTRAL, NEGATIVE = 1, 0, -1
DEFAULT_SLACK = 2
# The canvases' proposal lists kept: each counted with the zones of the proposals it holds (shared
# ones counted again), since a kept list keeps them alive after the generator drops them.
CANVAS_MEMO_BYTES = 256 * 2**20

_IDS = pa.list_(pa.int32())
PROPOSAL_SCHEMA = pa.schema(
    [
        ("design_id", pa.string()),
        ("split", pa.string()),
        ("step", pa.int32()),
        ("gt_length", pa.int32()),
        ("operation", pa.string()),  # union or subtract
        ("start_plane", pa.int32()),  # surface index of the sketch plane
        ("end_plane", pa.int32()),  # surface index of the plane the extrusion ends on
        ("sketch_faces", _IDS),  # partition faces of the sketch
        ("zones", _IDS),  # the extrusion's zone ids
        ("label", pa.int8()),  # 1 positive (the GT), 0 neutral, -1 negative
        ("p", pa.float32()),  # share of completions reaching the target; null for the GT
        ("completions", pa.int32()),
        ("is_gt", pa.bool_()),
        *((f"feat_{name}", pa.float32()) for name in PROPOSAL_FEATURES),  # the state's are derived
    ]
)
STEP_SCHEMA = pa.schema(
    [
        ("design_id", pa.string()),
        ("split", pa.string()),
        ("step", pa.int32()),
        ("gt_length", pa.int32()),
        ("gt_operation", pa.string()),  # Fusion's operation: new_body, join, cut or intersect
        ("canvas_zones", _IDS),  # C_{i-1}: the zones inside before the step
        ("gt_zones", _IDS),
        ("proposals", pa.int32()),
        ("captured", pa.bool_()),
        ("reason", pa.string()),  # why the step has no positive (empty when it has one)
        ("seconds", pa.float64()),
    ]
)


@dataclass(frozen=True)
class GTOperation:
    """One GT step as the labeller needs it: its zones and operation, and whether it is captured."""

    zones: np.ndarray  # (Z,) bool
    op: Op | None  # None: not an extrusion the search can propose (an intersect)
    captured: bool
    operation: str = ""  # Fusion's operation, for the tables
    reason: str = ""  # why the GT is not captured (from the ground truth)


@dataclass
class LabelledProposal:
    """One proposal at one GT step with its label."""

    proposal: Proposal
    is_gt: bool
    label: int = NEUTRAL
    p: float = float("nan")  # share of completions reaching the target (NaN for the GT)
    completions: int = 0


@dataclass
class LabelledStep:
    """The labels of one GT step (empty when its GT is not captured)."""

    step: int
    canvas: np.ndarray  # (Z,) bool, C_{i-1}
    captured: bool
    proposals: list[LabelledProposal] = field(default_factory=list)
    reason: str = ""
    seconds: float = 0.0
    features: np.ndarray = field(default_factory=lambda: np.zeros((0, len(FEATURES)), np.float32))  # (P, F)


class Completer:
    """Random completions on one zone graph, sharing proposals across all of them."""

    def __init__(self, graph: ZoneGraph, generator: ProposalGenerator, rng: np.random.Generator):
        self.target = graph.zone_inside.astype(bool)
        self.target_key = np.packbits(self.target).tobytes()
        self.generator = generator
        self.rng = rng
        held = 8 + graph.n_zones  # a reference and the proposal's zones
        self._cache: Memo[list[Proposal]] = Memo(CANVAS_MEMO_BYTES, lambda props: 100 + held * len(props))
        self.expansions = 0

    def proposals(self, canvas: np.ndarray, banned: set[tuple[bytes, int]]) -> list[Proposal]:
        """The search's proposals at ``canvas``, minus those whose key is in ``banned``."""
        key = np.packbits(canvas).tobytes()
        props = self._cache.get(key)
        if props is None:
            props = self._cache[key] = self.generator.proposals(canvas)
            self.expansions += 1
        return [p for p in props if p.key not in banned] if banned else props

    def complete(
        self, canvas: np.ndarray, first: Proposal, banned: set[tuple[bytes, int]], length: int
    ) -> bool:
        """One random completion starting with ``first``; True when it reaches the target."""
        banned = banned | {first.inverse_key}
        canvas = first.apply(canvas)
        for left in range(length - 1, 0, -1):
            if np.packbits(canvas).tobytes() == self.target_key:
                return True
            if left == 1 and (canvas & ~self.target).any() and (self.target & ~canvas).any():
                return False  # one extrusion either adds or removes: the target is out of reach
            options = self.proposals(canvas, banned)
            if not options:
                return False
            step = options[int(self.rng.integers(len(options)))]
            banned = banned | {step.inverse_key}
            canvas = step.apply(canvas)
        return np.packbits(canvas).tobytes() == self.target_key


def design_rng(seed: int, design_id: str) -> np.random.Generator:
    """A generator for one design: reproducible, and independent of the order designs run in."""
    return np.random.default_rng([seed, zlib.crc32(design_id.encode())])


def label_design(
    graph: ZoneGraph,
    gt: Sequence[GTOperation],
    design_id: str,
    seed: int = 0,
    level: int = 1,
    multiplier: float = 1.0,
    slack: int = DEFAULT_SLACK,
) -> list[LabelledStep]:
    """Ternary labels for every GT step of one design.

    Args:
        graph: the zone graph of the design's final shape (its zones' inside flags are the target).
        gt: the GT steps in order, mapped onto the graph.
        design_id: seeds the design's generator together with ``seed``.
        level: proposal level (as the search).
        multiplier: completions per remaining GT step; 0 runs none (rank only: the GT is positive,
            every other proposal neutral; for ranking the GT on test designs).
        slack: completion length beyond the remaining GT steps.

    Returns:
        One `LabelledStep` per GT step; steps whose GT is not captured carry a reason and
            no proposals.
    """
    completer = Completer(graph, ProposalGenerator(graph, level=level), design_rng(seed, design_id))
    canvas = np.zeros(graph.n_zones, bool)
    banned: set[tuple[bytes, int]] = set()
    on_target = target_surfaces(graph)
    out = []
    for i, step in enumerate(gt):
        t0 = time.perf_counter()
        labelled = LabelledStep(i, canvas, step.captured)
        if step.captured and step.op is not None:
            _label_step(labelled, completer, step, banned, len(gt) - i, multiplier, slack)
            props = [x.proposal for x in labelled.proposals]
            labelled.features = proposal_features(graph, canvas, props, i, on_target)
        else:
            labelled.reason = step.reason or "GT not captured at this level"
        labelled.seconds = time.perf_counter() - t0
        out.append(labelled)
        after = _apply(step, canvas)
        if step.op is not None:
            banned = banned | {(np.packbits(step.zones).tobytes(), -int(step.op))}
        canvas = after
    return out


def _apply(step: GTOperation, canvas: np.ndarray) -> np.ndarray:
    if step.op is Op.UNION:
        return canvas | step.zones
    if step.op is Op.SUBTRACT:
        return canvas & ~step.zones
    return canvas & step.zones


def _label_step(
    labelled: LabelledStep,
    completer: Completer,
    step: GTOperation,
    banned: set[tuple[bytes, int]],
    remaining: int,
    multiplier: float,
    slack: int,
) -> None:
    assert step.op is not None
    gt_key = (np.packbits(step.zones).tobytes(), int(step.op))
    props = completer.proposals(labelled.canvas, banned)
    runs = max(1, int(round(multiplier * remaining))) if multiplier > 0 else 0
    for p in props:
        item = LabelledProposal(p, is_gt=p.key == gt_key)
        if item.is_gt:
            item.label = POSITIVE
        elif runs:
            wins = sum(completer.complete(labelled.canvas, p, banned, remaining + slack) for _ in range(runs))
            item.p, item.completions = wins / runs, runs
        labelled.proposals.append(item)
    if not any(x.is_gt for x in labelled.proposals):
        labelled.reason = "GT is the inverse of an earlier GT step: the search filters it"
    others = [x for x in labelled.proposals if not x.is_gt]
    if not others or not runs:  # rank only: the GT among all proposals, no negatives
        return
    zero = [x for x in others if x.p == 0]
    for x in zero or [min(others, key=lambda x: x.p)]:
        x.label = NEGATIVE


def _ids(mask: np.ndarray) -> list[int]:
    return np.flatnonzero(mask).astype(np.int32).tolist()


def label_tables(
    steps: Sequence[LabelledStep], gt: Sequence[GTOperation], design_id: str, split: str
) -> tuple[pa.Table, pa.Table]:
    """The labels of one design as the ``(proposals, steps)`` tables of `PROPOSAL_SCHEMA`
    and `STEP_SCHEMA`: plain Parquet columns, readable without this package."""
    n = len(gt)
    stored = [f"feat_{name}" for name in PROPOSAL_FEATURES]  # the state's are derived on reading
    proposals = [
        {
            "design_id": design_id,
            "split": split,
            "step": st.step,
            "gt_length": n,
            "operation": x.proposal.op.name.lower(),
            "start_plane": x.proposal.start,
            "end_plane": x.proposal.end,
            "sketch_faces": list(x.proposal.faces),
            "zones": _ids(x.proposal.zones),
            "label": x.label,
            "p": None if x.is_gt else x.p,
            "completions": x.completions,
            "is_gt": x.is_gt,
            **dict(zip(stored, map(float, st.features[j, : len(stored)]), strict=True)),
        }
        for st in steps
        for j, x in enumerate(st.proposals)
    ]
    rows = [
        {
            "design_id": design_id,
            "split": split,
            "step": st.step,
            "gt_length": n,
            "gt_operation": g.operation,
            "canvas_zones": _ids(st.canvas),
            "gt_zones": _ids(g.zones),
            "proposals": len(st.proposals),
            "captured": st.captured,
            "reason": st.reason,
            "seconds": st.seconds,
        }
        for st, g in zip(steps, gt, strict=True)
    ]
    return (
        pa.Table.from_pylist(proposals, schema=PROPOSAL_SCHEMA),
        pa.Table.from_pylist(rows, schema=STEP_SCHEMA),
    )

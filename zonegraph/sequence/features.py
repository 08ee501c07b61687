"""Proposal features: what the search already knows about a proposal, as numbers a scorer reads.

A learned guide that sees only zone flags must rediscover what the hand-made heuristic is handed:
how far a step brings the canvas towards the target. These features give it the heuristic's own
terms and the proposal's geometry, computed from the zone graph alone (no OpenCASCADE), so the
``labels`` stage stores them in its Parquet shards and the search computes the same numbers for
the network at every state (`proposal_features` is the one definition of both).

Scales are the normalised frame's (the target's box has unit diagonal), so they do not depend on
the part's size; counts are kept raw (the network standardises its inputs).
"""

from __future__ import annotations

import numpy as np

from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.zones.model import ZoneGraph

PROPOSAL_FEATURES: tuple[str, ...] = (
    "agree_after",  # the heuristic's first term: share of zones agreeing with the target after the step
    "agree_gain",  # ... minus the same share before it
    "iou_after",  # volumetric IoU with the target after the step (the heuristic's tie-break)
    "iou_gain",  # ... minus the IoU before it
    "depth",  # extrusion depth: distance between the sketch and the end plane
    "sketch_area",  # area of the sketch's partition faces
    "sketch_faces",  # how many partition faces the sketch has
    "start_on_target",  # 1 when the sketch plane holds a face of the target
    "end_on_target",  # 1 when the end plane holds a face of the target
    "union",  # the operation: 1 union, 0 subtract
    "step",  # the state's depth: operations already applied (the GT step index in the labels)
    "missing",  # share of the target's volume the canvas still lacks
)
# A scorer reads each proposal apart from the others of its state, so on its own it cannot tell the
# heuristic's first choice from a runner-up of equal merit; these say how far a proposal is behind
# the best of the proposals scored with it. Computed from the stored columns whenever a state's
# proposals are read (`with_state_features`), never stored: older label shards serve them too.
STATE_FEATURES: tuple[str, ...] = (
    "agree_gap",  # the state's best agree_after minus this proposal's
    "iou_gap",  # the state's best iou_after minus this proposal's
)
FEATURES: tuple[str, ...] = PROPOSAL_FEATURES + STATE_FEATURES


def with_state_features(proposal: np.ndarray) -> np.ndarray:
    """(P, len(FEATURES)): a state's (P, len(PROPOSAL_FEATURES)) columns and the state's own."""
    agree = proposal[:, PROPOSAL_FEATURES.index("agree_after")]
    iou = proposal[:, PROPOSAL_FEATURES.index("iou_after")]
    gaps = [agree.max(initial=0.0) - agree, iou.max(initial=0.0) - iou]
    return np.concatenate([proposal, np.stack(gaps, axis=1)], axis=1).astype(np.float32)


def target_surfaces(graph: ZoneGraph) -> np.ndarray:
    """(S,) bool: surfaces holding a face of the target (a partition face between a zone inside
    and one outside, or the box's outside)."""
    inside = graph.zone_inside.astype(bool)
    first = inside[graph.face_zones[:, 0]]
    second = np.where(graph.face_zones[:, 1] >= 0, inside[np.maximum(graph.face_zones[:, 1], 0)], False)
    on = graph.face_surface[(first != second) & (graph.face_surface >= 0)]
    out = np.zeros(graph.n_surfaces, bool)
    out[on] = True
    return out


def _agreement_and_iou(graph: ZoneGraph, canvases: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(K,) share of agreeing zones and volumetric IoU of K canvases (K, Z)."""
    target = graph.zone_inside.astype(bool)
    agree = (canvases == target).sum(axis=1) / graph.n_zones
    inter = (canvases & target) @ graph.zone_volume
    union = inter + (canvases ^ target) @ graph.zone_volume
    iou = np.divide(inter, union, out=np.ones_like(inter), where=union > 0)
    return agree, iou


def _depth(graph: ZoneGraph, start: int, end: int) -> float:
    """Distance between two parallel planes n . x = d (their normals may point either way)."""
    n_s, n_e = graph.surface_normal[start], graph.surface_normal[end]
    return float(abs(float(np.dot(n_s, n_e)) * graph.surface_offset[end] - graph.surface_offset[start]))


def proposal_features(
    graph: ZoneGraph,
    canvas: np.ndarray,
    proposals: list[Proposal],
    step: int,
    on_target: np.ndarray | None = None,
) -> np.ndarray:
    """(P, len(FEATURES)) float32: the features of every proposal of one state, those relative to
    the state taken over ``proposals``.

    Args:
        canvas: (Z,) bool, the state's canvas.
        step: operations applied before this state.
        on_target: `target_surfaces` of ``graph``, when the caller keeps it per graph.
    """
    if not proposals:
        return np.zeros((0, len(FEATURES)), np.float32)
    on_target = target_surfaces(graph) if on_target is None else on_target
    canvas = canvas.astype(bool)
    after = np.stack([p.apply(canvas) for p in proposals])  # (P, Z)
    agree, iou = _agreement_and_iou(graph, after)
    agree0, iou0 = _agreement_and_iou(graph, canvas[None])
    target = graph.zone_inside.astype(bool)
    total = float(graph.zone_volume[target].sum())
    missing = float(graph.zone_volume[target & ~canvas].sum()) / total if total > 0 else 0.0
    columns = [
        agree,
        agree - agree0[0],
        iou,
        iou - iou0[0],
        [_depth(graph, p.start, p.end) for p in proposals],
        [float(graph.face_area[list(p.faces)].sum()) for p in proposals],
        [len(p.faces) for p in proposals],
        [float(on_target[p.start]) for p in proposals],
        [float(on_target[p.end]) for p in proposals],
        [float(p.op is Op.UNION) for p in proposals],
        np.full(len(proposals), float(step)),
        np.full(len(proposals), missing),
    ]
    return with_state_features(np.stack([np.asarray(c, np.float64) for c in columns], axis=1))

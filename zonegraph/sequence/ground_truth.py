"""Ground-truth sequences on zone graphs (paper sec. 4.2, ``docs/algorithm.md`` sec. 5).

A design's extrude tools X_1..X_n (the replay's tool bodies, in the design's units) are mapped onto
the zone graph of its final shape: a zone belongs to X_i when its verified interior point lies in
the tool. Tools may reach outside the box (through-cuts); they are clipped to it, and the mapping
is checked by volume: the mapped zones must hold the tool's volume inside the box (relative
``MAPPING_RTOL``). Replaying the mapped steps on zones (C_0 empty; NewBody/Join add, Cut
removes, Intersect keeps C and X) must end on the target zones. A step is *captured* at a proposal
level when its (zone set, operation) is among the proposals at C_{i-1}; it is *effect-captured*
when some proposal leads to the same next canvas (another sketch of the same change).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.TopAbs import TopAbs_IN, TopAbs_ON, TopAbs_SOLID
from OCP.TopoDS import TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import pnt, sub_shapes, volume_props
from zonegraph.sequence.proposals import Op, ProposalGenerator
from zonegraph.zones.model import ZoneGraph

MAPPING_RTOL = 1e-4
CLASSIFY_TOL = 1e-9
OPERATIONS = ("new_body", "join", "cut", "intersect")


@dataclass
class GTStep:
    """One ground-truth extrude on the zone graph.

    Shapes:
        zones: (Z,) bool, the tool's zones X_i; canvas_before: (Z,) bool, C_{i-1}.
    """

    index: int
    operation: str  # new_body, join, cut or intersect (Fusion's operation)
    zones: np.ndarray
    canvas_before: np.ndarray
    mapping_error: float  # |vol(zones) - vol(tool in box)| / vol(tool in box)
    mapped: bool  # the mapping check passed
    captured: dict[int, bool] = field(default_factory=dict)  # proposal level -> captured
    effect_captured: dict[int, bool] = field(default_factory=dict)
    proposals: dict[int, int] = field(default_factory=dict)  # proposal level -> count at C_{i-1}
    reason: str = ""  # why the step is not captured (empty when it is)

    @property
    def op(self) -> Op | None:
        """The search's operation for this step (None: an intersect has none)."""
        return search_op(self.operation)


def search_op(operation: str) -> Op | None:
    """The search's operation for Fusion's ``operation`` (None: an intersect has no proposal)."""
    if operation in ("new_body", "join"):
        return Op.UNION
    return Op.SUBTRACT if operation == "cut" else None


@dataclass
class GroundTruth:
    """A design's ground truth on one zone graph."""

    steps: list[GTStep]
    reaches_target: bool  # replaying the mapped steps on zones ends on the target zones
    reason: str = ""

    def captured(self, level: int) -> bool:
        """Every step captured at ``level``: the paper's "reconstructable with the GT sequence"."""
        return self.reaches_target and all(s.captured.get(level, False) for s in self.steps)


def _box_solid(graph: ZoneGraph) -> TopoDS_Shape:
    lo, hi = graph.box[:3], graph.box[3:]
    return BRepPrimAPI_MakeBox(pnt(lo), pnt(hi)).Solid()


def map_tool(graph: ZoneGraph, tool: TopoDS_Shape) -> tuple[np.ndarray, float]:
    """The zones of a tool body (in the graph's input units) and the relative volume error.

    Returns:
        zones: (Z,) bool, the zones whose interior point lies in the tool;
        error: relative difference between their volume and the tool's volume inside the box.
    """
    tool_n = graph.normalization.apply(tool)
    zones = np.zeros(graph.n_zones, bool)
    for solid in sub_shapes(tool_n, TopAbs_SOLID):
        classifier = BRepClass3d_SolidClassifier(solid)
        for z in np.flatnonzero(~zones):
            classifier.Perform(pnt(graph.zone_interior[z]), CLASSIFY_TOL)
            zones[z] = classifier.State() in (TopAbs_IN, TopAbs_ON)
    common = BRepAlgoAPI_Common(tool_n, _box_solid(graph))
    clipped = volume_props(common.Shape())[0] if common.IsDone() else float("nan")
    mapped = float(graph.zone_volume[zones].sum())
    error = abs(mapped - clipped) / clipped if clipped > 0 else (0.0 if mapped == 0 else float("inf"))
    return zones, error


def apply_operation(operation: str, canvas: np.ndarray, zones: np.ndarray) -> np.ndarray:
    """The canvas after a Fusion operation (new body and join add, cut removes, intersect keeps)."""
    if operation == "cut":
        return canvas & ~zones
    if operation == "intersect":
        return canvas & zones
    return canvas | zones


def ground_truth(
    graph: ZoneGraph, tools: Sequence[TopoDS_Shape], operations: Sequence[str], levels: Sequence[int] = (1,)
) -> GroundTruth:
    """Map a design's tools onto ``graph``, replay them on zones and test capture at each level.

    Args:
        graph: the zone graph of the design's final shape.
        tools: the extrude tool bodies in timeline order, in the graph's input units.
        operations: Fusion's operation of each extrude (``new_body``, ``join``, ``cut``, ``intersect``).
        levels: proposal levels to test capture at (the paper compares 1 and 3).
    """
    generators = {level: ProposalGenerator(graph, level=level) for level in levels}
    canvas = np.zeros(graph.n_zones, bool)
    steps = []
    for i, (tool, operation) in enumerate(zip(tools, operations, strict=True)):
        zones, error = map_tool(graph, tool)
        step = GTStep(i, operation, zones, canvas, error, bool(error <= MAPPING_RTOL))
        after = apply_operation(operation, canvas, zones)
        for level, gen in generators.items():
            _test_capture(step, gen, level, after)
        steps.append(step)
        canvas = after
    reaches = bool(np.array_equal(canvas, graph.zone_inside))
    reason = (
        "" if reaches else f"GT replay on zones ends {int((canvas != graph.zone_inside).sum())} zones off"
    )
    return GroundTruth(steps, reaches, reason)


def _test_capture(step: GTStep, gen: ProposalGenerator, level: int, after: np.ndarray) -> None:
    props = gen.proposals(step.canvas_before)
    step.proposals[level] = len(props)
    key = (np.packbits(step.zones).tobytes(), int(step.op)) if step.op is not None else None
    step.captured[level] = bool(step.mapped and key is not None and any(p.key == key for p in props))
    step.effect_captured[level] = any(np.array_equal(p.apply(step.canvas_before), after) for p in props)
    if step.captured[level] or step.reason:
        return
    if not step.mapped:
        step.reason = f"tool does not map onto zones (volume error {step.mapping_error:.2e})"
    elif step.op is None:
        step.reason = "intersect has no extrusion proposal"
    elif np.array_equal(after, step.canvas_before):
        step.reason = "the step does not change the canvas"
    elif step.effect_captured[level]:
        step.reason = "captured only as another sketch of the same change"
    else:
        step.reason = "no proposal has the GT extrusion"

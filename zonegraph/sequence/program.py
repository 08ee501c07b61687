"""Turn a found proposal sequence into real sketch + extrude + Boolean operations.

Each step's sketch is the union of its partition faces on the start plane (merged into clean
faces with outer and inner wires), mapped back to the user's units and position; the extrude runs
along d for |d|. The program is rebuilt with build123d from those sketches, not by fusing zones,
and compared with the target by OpenCASCADE Booleans: that B-rep IoU is the honest measure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from build123d import Face, Shape, Solid, Vector
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID

from zonegraph.geometry.occ import ancestors, fuzzy_boolean, make_compound, volume_props
from zonegraph.geometry.shapes import volume_of
from zonegraph.geometry.vec import vec3
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.zones.model import ZoneGraph


@dataclass(frozen=True)
class ProgramStep:
    """One operation in the user's units: extrude ``faces`` by ``distance`` along ``direction``."""

    op: Op
    faces: tuple[Face, ...]  # the sketch: planar faces on the start plane, world coordinates
    origin: tuple[float, float, float]  # a point of the start plane
    direction: tuple[float, float, float]  # unit extrusion direction (the sketch normal)
    distance: float

    def tool(self) -> Solid:
        """The extruded sketch faces (fused when there are several)."""
        d = Vector(*self.direction) * self.distance
        solids = [Solid.extrude(f, d) for f in self.faces]
        return solids[0] if len(solids) == 1 else solids[0].fuse(*solids[1:]).clean()


def partition_faces(graph: ZoneGraph) -> list:
    """The OCC partition faces in the graph's face order (the order the build indexed them)."""
    if graph.solids is None:
        raise ValueError("zone graph was loaded without its zone solids")
    face_map = ancestors(make_compound(graph.solids), TopAbs_FACE, TopAbs_SOLID)
    if face_map.Size() != graph.n_faces:
        raise ValueError(f"zone solids have {face_map.Size()} faces, the graph {graph.n_faces}")
    return [face_map.FindKey(i) for i in range(1, face_map.Size() + 1)]


def merge_faces(faces: list) -> list[Face]:
    """Coplanar faces sharing edges merged into as few clean faces as possible."""
    shapes = [Shape.cast(f) for f in faces]
    merged = shapes[0].fuse(*shapes[1:]) if len(shapes) > 1 else shapes[0]
    return list(merged.clean().faces())


def build_program(graph: ZoneGraph, steps: list[Proposal], generator: ProposalGenerator) -> list[ProgramStep]:
    """Real sketches and extrusions, in the input's units, for a found proposal sequence.

    Each sketch is the union of the proposal's partition faces (merged into clean faces), mapped
    back from the normalised frame; the extrusion runs from the start plane to the end plane.

    Raises:
        ValueError: the graph was loaded without its zone solids.
    """
    faces = partition_faces(graph)
    norm = graph.normalization
    out = []
    for p in steps:
        sketch = [
            Shape.cast(norm.apply(f.wrapped, inverse=True)) for f in merge_faces([faces[i] for i in p.faces])
        ]
        d = generator.direction(p.start, p.end) / norm.scale
        length = float(np.linalg.norm(d))
        origin = norm.to_original(graph.surface_normal[p.start] * graph.surface_offset[p.start])
        out.append(
            ProgramStep(
                p.op,
                tuple(sketch),
                vec3(origin),
                vec3(d / length),
                length,
            )
        )
    return out


class RebuildError(RuntimeError):
    """An OpenCASCADE Boolean failed on the program's own tools (a robustness failure, not a
    wrong program): the shapes share coincident curved faces it cannot resolve."""


def execute(program: list[ProgramStep]) -> list[Shape | None]:
    """The shape after each step: the first union starts the part, then unions and subtractions."""
    shape: Shape | None = None
    states = []
    for i, step in enumerate(program):
        tool = step.tool()
        try:
            if shape is None:
                shape = tool if step.op is Op.UNION else None
            elif step.op is Op.UNION:
                shape = shape.fuse(tool).clean()
            else:
                shape = shape.cut(tool).clean()
        except ValueError as exc:  # build123d's word for a null Boolean result
            raise RebuildError(f"step {i + 1}: Boolean failed ({exc})") from None
        states.append(shape)
    return states


def _common_volume(a: Shape, b: Shape, fuzzy: float) -> float:
    if fuzzy <= 0.0:
        return volume_of(a.intersect(b))
    return volume_props(fuzzy_boolean(BRepAlgoAPI_Common(), a.wrapped, b.wrapped, fuzzy))[0]


def _cut_volume(a: Shape, b: Shape, fuzzy: float) -> float:
    if fuzzy <= 0.0:
        return volume_of(a.cut(b))
    return volume_props(fuzzy_boolean(BRepAlgoAPI_Cut(), a.wrapped, b.wrapped, fuzzy))[0]


def brep_iou(a: Shape | None, b: Shape, fuzzy: float = 0.0) -> float:
    """vol(a and b) / vol(a or b) with OpenCASCADE Booleans (the common part, else a - b).

    A common of two nearly coincident solids with B-spline faces can come back empty on the first
    call (the Boolean then fixes tolerances in place and a second call succeeds): an empty common
    is therefore measured again through the difference, and only when both fail is IoU unknown.
    ``fuzzy`` > 0 takes faces closer than that as one: for a part meant to lie that close to the
    other (an export with snapped numbers), whose plain common of faces a hair apart can come
    back with almost no volume."""
    if a is None:
        return 0.0
    try:
        inter = _common_volume(a, b, fuzzy)
    except ValueError:  # a null Boolean result: measure the same thing through the difference
        inter = 0.0
    if inter <= 0.0:
        try:
            rest = _cut_volume(a, b, fuzzy)
        except ValueError:
            raise RebuildError("Booleans against the target failed; IoU unknown") from None
        inter = a.volume - rest
    volume_a, volume_b = a.volume, b.volume
    inter = min(inter, volume_a, volume_b)  # volume integration error can exceed an operand's volume
    union = volume_a + volume_b - inter
    return inter / union if union > 0 else 1.0

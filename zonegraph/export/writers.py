"""Write a program out: an editable build123d script, Fusion-format JSON, STEP per step, a PNG strip.

Sketch curves are written in each sketch's own frame (origin on the start plane, z along the
extrusion), lines as lines, circular arcs and circles exactly, any other curve as a B-spline (JSON)
or an interpolating spline through points (script).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from build123d import Edge, Face, GeomType, Shape, Unit, Vector

from zonegraph.data.design import (
    Arc,
    Circle,
    Curve,
    Design,
    Extent,
    ExtentType,
    Extrude,
    Frame,
    Line,
    Loop,
    Nurbs,
    Operation,
    Profile,
    ProfileRef,
    Sketch,
    design_to_json,
)
from zonegraph.export.render import render_sequence
from zonegraph.geometry.shapes import write_step
from zonegraph.geometry.vec import vec3
from zonegraph.sequence.program import ProgramStep
from zonegraph.sequence.proposals import Op

# A curve that is not a line, circle or arc is written as a B-spline. build123d's default (cubic,
# 1e-3) moved a profile's area by 1.5e-4, more than the reader's AREA_RTOL: our own JSON failed to
# replay. A tight tolerance at a higher degree keeps the written curve on the original.
SPLINE_DEGREE = 8
SPLINE_TOL = 1e-7
ZERO = 1e-9  # a written coordinate this close to zero is zero


def step_frame(step: ProgramStep) -> Frame:
    z = np.asarray(step.direction, float)
    helper = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = helper - z * float(helper @ z)
    x /= np.linalg.norm(x)
    return Frame(step.origin, tuple(x), tuple(np.cross(z, x)), tuple(z))


def _local(frame: Frame, p: Sequence[float] | np.ndarray | Vector) -> np.ndarray:
    return frame.matrix.T @ (np.asarray(tuple(p), float) - np.asarray(frame.origin, float))


@dataclass(frozen=True)
class LocalEdge:
    """An edge in sketch coordinates: kind is line, arc, circle or spline (with sample points)."""

    kind: str
    points: np.ndarray  # line: start, end; arc: start, mid, end; circle: centre; spline: samples
    radius: float = 0.0


def local_edges(edge: Edge, frame: Frame) -> LocalEdge:
    kind = edge.geom_type
    if kind == GeomType.LINE:
        return LocalEdge("line", np.array([_local(frame, edge.position_at(t)) for t in (0, 1)]))
    if kind == GeomType.CIRCLE:
        if edge.is_closed:
            return LocalEdge("circle", np.array([_local(frame, edge.arc_center)]), edge.radius)
        return LocalEdge(
            "arc", np.array([_local(frame, edge.position_at(t)) for t in (0, 0.5, 1)]), edge.radius
        )
    return LocalEdge("spline", np.array([_local(frame, edge.position_at(t)) for t in np.linspace(0, 1, 24)]))


def face_wires(face: Face) -> list[tuple[bool, list[Edge]]]:
    """(is_outer, edges) per boundary loop; merged faces can carry empty wires, which are dropped."""
    wires = [(True, face.outer_wire())] + [(False, w) for w in face.inner_wires()]
    return [(outer, list(w.edges())) for outer, w in wires if w.edges()]


def face_loops(face: Face, frame: Frame) -> list[tuple[bool, list[LocalEdge]]]:
    return [(outer, [local_edges(e, frame) for e in edges]) for outer, edges in face_wires(face)]


# --------------------------------------------------------------------------- build123d script


def _num(x: float) -> str:
    """A coordinate for people to read: float noise below 1e-9 (far under OpenCASCADE's 1e-7
    tolerance) is written as 0, and never as -0."""
    x = float(x)
    return "0" if abs(x) < ZERO else f"{x:.12g}"


def _xy(p: np.ndarray) -> str:
    return f"({_num(p[0])}, {_num(p[1])})"


def _vec(v: Sequence[float] | np.ndarray) -> str:
    return "(" + ", ".join(_num(c) for c in v) + ")"


def _edge_code(e: LocalEdge) -> str:
    if e.kind == "line":
        return f"Line({_xy(e.points[0])}, {_xy(e.points[1])})"
    if e.kind == "arc":
        return f"ThreePointArc({_xy(e.points[0])}, {_xy(e.points[1])}, {_xy(e.points[2])})"
    if e.kind == "circle":
        return f"CenterArc({_xy(e.points[0])}, {e.radius:.12g}, 0, 360)"
    return "Spline(" + ", ".join(_xy(p) for p in e.points) + ")  # interpolates the original curve"


def program_script(program: list[ProgramStep], name: str, unit: Unit) -> str:
    lines = [
        f'"""{name}: {len(program)} sketch + extrude steps found by `zonegraph infer`.',
        "",
        f"Units ({unit.name.lower()}) and position are the input's. Run `python sequence.py [out.step]`.",
        '"""',
        "",
        "import sys",
        "",
        "from build123d import *",
        "",
        "with BuildPart() as part:",
    ]
    for i, step in enumerate(program, 1):
        frame = step_frame(step)
        verb = "union" if step.op is Op.UNION else "subtract"
        lines.append(f"    # Step {i}: {verb}, extrude {step.distance:.6g} along the sketch normal")
        lines.append(
            f"    with BuildSketch(Plane(origin={_vec(frame.origin)}, x_dir={_vec(frame.x_axis)}, "
            f"z_dir={_vec(frame.z_axis)})):"
        )
        for face in step.faces:
            for outer, edges in face_loops(face, frame):
                lines.append("        with BuildLine(mode=Mode.PRIVATE) as loop:")
                lines += [f"            {_edge_code(e)}" for e in edges]
                lines.append(
                    "        make_face(loop.edges())"
                    if outer
                    else "        make_face(loop.edges(), mode=Mode.SUBTRACT)"
                )
        mode = "Mode.ADD" if step.op is Op.UNION else "Mode.SUBTRACT"
        lines.append(f"    extrude(amount={step.distance:.12g}, mode={mode})")
        lines.append("")
    lines += [
        "result = part.part",
        "",
        'if __name__ == "__main__" and len(sys.argv) > 1:',
        f"    export_step(result, sys.argv[1], unit=Unit.{unit.name})",
        "",
    ]
    return "\n".join(lines)


# ------------------------------------------------------------------------- Fusion-format JSON


def _curve(e: LocalEdge, edge: Edge, frame: Frame) -> Curve:
    p = [vec3(q) for q in e.points]
    if e.kind == "line":
        return Line(p[0], p[1])
    if e.kind == "circle":
        return Circle(p[0], e.radius, (0.0, 0.0, 1.0))
    if e.kind == "arc":
        centre = _local(frame, edge.arc_center)
        a, m, b = (np.asarray(q) - centre for q in e.points)
        sign = 1.0 if a[0] * m[1] - a[1] * m[0] > 0 else -1.0
        ref = a / np.linalg.norm(a)
        perp = np.cross((0.0, 0.0, sign), ref)
        sweep = math.atan2(float(b @ perp), float(b @ ref)) % (2 * math.pi) or 2 * math.pi
        return Arc(p[0], p[2], vec3(centre), e.radius, (0.0, 0.0, sign), 0.0, sweep, vec3(ref))
    spline = edge.to_splines(degree=SPLINE_DEGREE, tolerance=SPLINE_TOL)
    geom = spline.geom_adaptor().BSpline()
    poles = [_local(frame, (q.X(), q.Y(), q.Z())) for q in geom.Poles()]
    knots = [k for k, m in zip(geom.Knots(), geom.Multiplicities(), strict=False) for _ in range(m)]
    weights = list(geom.Weights()) if geom.IsRational() else None
    return Nurbs(
        geom.Degree(),
        tuple(knots),
        tuple(vec3(q) for q in poles),
        tuple(weights) if weights else None,
    )


def program_design(program: list[ProgramStep], name: str) -> Design:
    timeline: list[Sketch | Extrude] = []
    for i, step in enumerate(program):
        frame = step_frame(step)
        profiles = {}
        for j, face in enumerate(step.faces):
            loops = tuple(
                Loop(outer, tuple(_curve(local_edges(e, frame), e, frame) for e in edges))
                for outer, edges in face_wires(face)
            )
            profiles[f"profile{i}_{j}"] = Profile(f"profile{i}_{j}", loops, face.area)
        sketch = Sketch(f"sketch{i}", f"Sketch{i + 1}", frame, profiles)
        op = (Operation.NEW_BODY if i == 0 else Operation.JOIN) if step.op is Op.UNION else Operation.CUT
        extrude = Extrude(
            f"extrude{i}",
            f"Extrude{i + 1}",
            tuple(ProfileRef(sketch.id, p) for p in profiles),
            op,
            ExtentType.ONE_SIDE,
            Extent(step.distance),
        )
        timeline += [sketch, extrude]
    return Design(name, tuple(timeline))


# ------------------------------------------------------------------------------ STEP and PNG


def write_outputs(
    program: list[ProgramStep], states: list[Shape], out: Path, name: str, unit: Unit, render: bool = True
) -> None:
    """sequence.py, sequence.json and, when ``render``, steps/NN.step and sequence.png.

    ``unit`` is what the input's numbers mean (mm for STEP as read, cm for a design JSON); the
    STEP files declare it, so they open at the input's size.
    """
    out.mkdir(parents=True, exist_ok=True)
    (out / "sequence.py").write_text(program_script(program, name, unit))
    (out / "sequence.json").write_text(json.dumps(design_to_json(program_design(program, name)), indent=1))
    if not render:
        return
    for i, state in enumerate(states):
        if state is not None:
            write_step(state, out / "steps" / f"{i:02d}.step", unit)
    render_sequence(program, states, out / "sequence.png")

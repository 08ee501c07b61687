"""Faces to profile curves: each recorded face as sketch-local loops of exact curves.

Every edge becomes a Line3D, Arc3D, Circle3D, Ellipse3D, EllipticalArc3D or NurbsCurve3D from its
exact OCP geometry (never sampled), in the frame of the plane build123d extruded the face along.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from zonegraph.data.b123d.reasons import one_line
from zonegraph.data.design import Arc, Circle, Curve, Ellipse, EllipticalArc, Frame, Line, Loop, Nurbs, Vec3
from zonegraph.data.profiles import SNAP_TOL
from zonegraph.errors import UnsupportedFeatureError
from zonegraph.geometry.occ import precise_area

PLANE_TOL = 1e-6  # cm: a profile point may sit this far off its sketch plane
VERTEX_TOL = 1e-7  # cm: a wire's walk is back at a vertex it passed (OCC shares the vertex)


@dataclass(frozen=True)
class RecordedFace:
    """One face build123d extruded: its sketch frame (z = extrusion normal) and local loops."""

    frame: Frame
    loops: tuple[Loop, ...]
    area: float | None  # exact face area; None where build123d's quick measure disagrees (see face_area)
    center: Vec3  # world, to match the faces of the two calls of a TwoSides pair
    normal: Vec3  # world unit vector the amount is measured along
    quick_area: float = 0.0  # build123d's own measure, to match the faces of two calls
    dropped: int = 0  # lines shorter than the replay's snap tolerance, left out


def _v3(x: Any) -> np.ndarray:
    """A build123d Vector (X attributes) or an OCP gp_Pnt/gp_Dir (X methods) as an array."""
    if callable(x.X):
        return np.array([float(x.X()), float(x.Y()), float(x.Z())])
    return np.array([float(x.X), float(x.Y), float(x.Z)])


class _Local:
    """World <-> sketch-local coordinates of one plane (right-handed: y = z x x)."""

    def __init__(self, plane: Any) -> None:
        self.origin = _v3(plane.origin)
        x, z = _v3(plane.x_dir), _v3(plane.z_dir)
        x, z = x / np.linalg.norm(x), z / np.linalg.norm(z)
        self.rot = np.vstack([x, np.cross(z, x), z])  # rows: local axes in world
        self.frame = Frame(_t(self.origin), _t(x), _t(np.cross(z, x)), _t(z))

    def point(self, p: np.ndarray) -> Vec3:
        q = self.rot @ (np.asarray(p, float) - self.origin)
        if abs(q[2]) > PLANE_TOL:
            raise UnsupportedFeatureError("", None, f"a profile point lies {q[2]:.3g} cm off its plane")
        return (float(q[0]), float(q[1]), 0.0)

    def vector(self, v: np.ndarray) -> Vec3:
        return _t(self.rot @ np.asarray(v, float))


def _t(a: np.ndarray) -> Vec3:
    return (float(a[0]), float(a[1]), float(a[2]))


def face_record(face: Any, plane: Any) -> RecordedFace:
    """A build123d face on ``plane`` as sketch-local loops (outer first, then the holes)."""
    local = _Local(plane)
    wires = [(True, face.outer_wire())] + [(False, w) for w in face.inner_wires()]
    loops: list[Loop] = []
    dropped = 0
    area = float(face.area) if len(wires) == 1 else None
    for role, wire in wires:
        whole = _loop(role, list(wire.edges()), local)
        pieces = [whole] if _replay_keeps(whole[0], local.frame, area) else None
        if pieces is None:  # a wire the replay cannot rebuild whole: its simple loops instead
            pieces = [_loop(r, edges, local) for r, edges in wire_loops(face, wire, role)]
        loops += [loop for loop, _ in pieces]
        dropped += sum(n for _, n in pieces)
    normal = _v3(plane.z_dir)
    return RecordedFace(
        local.frame,
        tuple(loops),
        face_area(face),
        _t(_v3(face.center())),
        _t(normal / np.linalg.norm(normal)),
        float(face.area),
        dropped,
    )


def _loop(outer: bool, edges: list[Any], local: _Local) -> tuple[Loop, int]:
    """The edges as one loop of profile curves, and how many short lines it left out.

    The replay snaps end points closer than SNAP_TOL together, so such a line would collapse to
    a point (and fail); its neighbours are joined across the gap instead, as the replay does.
    """
    curves = [edge_curve(e, local) for e in edges]
    kept = [c for c in curves if not (isinstance(c, Line) and _length(c) < SNAP_TOL)]
    if not kept:  # the whole loop is smaller than the replay can draw
        reason = f"a profile loop of {len(curves)} line(s), each shorter than {SNAP_TOL:g} cm"
        raise UnsupportedFeatureError("", None, reason)
    return Loop(outer, tuple(kept)), len(curves) - len(kept)


def _replay_keeps(loop: Loop, frame: Frame, area: float | None) -> bool:
    """Whether the replay joins the loop's curves into one closed wire (in world coordinates, as
    the replay builds it: rounding there decides) whose face has ``area`` (when given: the face
    is bounded by this loop alone)."""
    from zonegraph.data.profiles import loop_face, new_snapper
    from zonegraph.errors import DesignError, is_kernel_error

    try:
        built = loop_face(loop, frame, new_snapper(), "")
    except DesignError:
        return False
    except Exception as exc:  # a curve the kernel cannot build: the replay reports it itself
        if not is_kernel_error(exc):
            raise
        return True
    return area is None or abs(float(built.area) - area) <= 1e-6 * abs(area)


def wire_loops(face: Any, wire: Any, outer: bool) -> list[tuple[bool, list[Any]]]:
    """A wire's edges as simple loops, each with its role (outer or hole).

    OpenCASCADE accepts a wire that passes a vertex twice: a hole touching the outer boundary at
    one point (a circle tangent to it) is walked as part of the outer wire. The replay joins each
    loop into one closed wire, so such a wire is cut at its repeated vertices; the largest piece
    keeps the wire's role, and a piece inside it bounds the opposite side (a hole of an outer wire).
    A wire with no repeated vertex is returned as it is, edges in their own order.
    """
    from build123d import Edge, Face, Wire

    pieces = _simple_cycles(face, wire)
    if len(pieces) == 1:
        return [(outer, list(wire.edges()))]
    edges = [[Edge(e) for e in p] for p in pieces]
    filled = sorted(((Face(Wire(p)), p) for p in edges), key=lambda fp: -fp[0].area)
    main = filled[0][0]
    out = [(outer, filled[0][1])]
    for piece_face, piece in filled[1:]:
        common: Any = main.intersect(piece_face) or []
        inside = sum(f.area for f in common.faces()) if hasattr(common, "faces") else 0.0
        within = abs(inside - piece_face.area) <= 1e-6 * piece_face.area
        out.append((outer != within, piece))
    return out


def _simple_cycles(face: Any, wire: Any) -> list[list[Any]]:
    """The wire's edges in walking order, cut into cycles wherever the walk returns to a vertex."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.TopExp import TopExp

    explorer = BRepTools_WireExplorer(wire.wrapped, face.wrapped)
    walk = []
    while explorer.More():
        walk.append(explorer.Current())
        explorer.Next()
    if len(walk) < 2:
        return [walk]

    def end(edge: Any, last: bool) -> np.ndarray:
        vertex = TopExp.LastVertex_s(edge, True) if last else TopExp.FirstVertex_s(edge, True)
        return _v3(BRep_Tool.Pnt_s(vertex))

    path = [end(walk[0], False)]
    stack: list[Any] = []
    cycles: list[list[Any]] = []
    for edge in walk:
        stack.append(edge)
        v = end(edge, True)
        hit = next((k for k, q in enumerate(path) if np.linalg.norm(v - q) <= VERTEX_TOL), None)
        if hit is None:
            path.append(v)
            continue
        cycles.append(stack[hit:])
        del stack[hit:], path[hit + 1 :]
    if stack:  # the walk did not close on its start: leave the wire whole
        return [walk]
    return cycles


def face_area(face: Any) -> float | None:
    """The profile area to store in the JSON, or None where storing it would mislead.

    The replay checks each rebuilt profile against this area (1e-4 relative) with build123d's
    fixed-order Gauss measure, which is off by ~1e-4 on faces bounded by long high-degree splines
    (the measured case: ``docs/results/evidence.md``). So the exact (adaptive) area is stored only
    when the quick measure agrees with it; otherwise the check is skipped.
    """
    exact = float(precise_area(face.wrapped))
    return exact if abs(float(face.area) - exact) <= 1e-6 * abs(exact) else None


def _length(line: Line) -> float:
    return float(np.linalg.norm(np.subtract(line.end, line.start)))


def edge_curve(edge: Any, local: _Local) -> Curve:
    """One edge as a profile curve, from its exact OCP geometry (never sampled)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_BSplineCurve, GeomAbs_Circle, GeomAbs_Ellipse, GeomAbs_Line

    ad = BRepAdaptor_Curve(edge.wrapped)
    kind = ad.GetType()
    f, last = ad.FirstParameter(), ad.LastParameter()
    if kind == GeomAbs_Line:
        return Line(local.point(_v3(ad.Value(f))), local.point(_v3(ad.Value(last))))
    if kind == GeomAbs_Circle:
        circ = ad.Circle()
        ax = circ.Position()
        center, normal = local.point(_v3(ax.Location())), local.vector(_v3(ax.Direction()))
        if abs((last - f) - 2 * math.pi) < 1e-9:
            return Circle(center, circ.Radius(), normal)
        return Arc(
            local.point(_v3(ad.Value(f))),
            local.point(_v3(ad.Value(last))),
            center,
            circ.Radius(),
            normal,
            f,
            last,
            local.vector(_v3(ax.XDirection())),
        )
    if kind == GeomAbs_Ellipse:
        el = ad.Ellipse()
        ax = el.Position()
        common = (
            local.point(_v3(ax.Location())),
            local.vector(_v3(ax.XDirection())),
            el.MajorRadius(),
            el.MinorRadius(),
            local.vector(_v3(ax.Direction())),
        )
        if abs((last - f) - 2 * math.pi) < 1e-9:
            return Ellipse(*common)
        return EllipticalArc(*common, f, last)
    return _nurbs(edge, ad, kind == GeomAbs_BSplineCurve, f, last, local)


def _nurbs(edge: Any, ad: Any, is_bspline: bool, f: float, last: float, local: _Local) -> Nurbs:
    """A B-spline edge (trimmed to the edge's range), or any other curve converted exactly."""
    from OCP.BRep import BRep_Tool
    from OCP.Geom import Geom_TrimmedCurve
    from OCP.GeomConvert import GeomConvert

    if is_bspline:
        curve = ad.BSpline()
        if abs(curve.FirstParameter() - f) > 1e-12 or abs(curve.LastParameter() - last) > 1e-12:
            curve = GeomConvert.SplitBSplineCurve_s(curve, f, last, 1e-12)
    else:
        try:
            base = BRep_Tool.Curve_s(edge.wrapped, 0.0, 1.0)  # with the edge's location applied
            curve = GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(base, f, last))
        except Exception as exc:  # offset curves and the like have no exact B-spline form
            reason = f"profile curve type {ad.GetType()} ({one_line(exc)})"
            raise UnsupportedFeatureError("", None, reason) from None
    if curve.IsPeriodic():
        raise UnsupportedFeatureError("", None, "periodic B-spline profile curve")
    poles = tuple(local.point(_v3(curve.Pole(i))) for i in range(1, curve.NbPoles() + 1))
    knots: list[float] = []
    for i in range(1, curve.NbKnots() + 1):
        knots += [curve.Knot(i)] * curve.Multiplicity(i)
    weights = tuple(curve.Weight(i) for i in range(1, curve.NbPoles() + 1)) if curve.IsRational() else None
    return Nurbs(curve.Degree(), tuple(knots), poles, weights, False)

"""Sketch profiles to planar build123d faces, in world coordinates.

Fusion's profile loops are neither ordered nor consistently oriented, and their coordinates carry
float32 noise. So curve end points are snapped together first (within ``SNAP_TOL``), each loop is
joined into a wire by proximity, and the profile face is built as "outer faces minus inner faces",
which is indifferent to loop orientation.
"""

from __future__ import annotations

import math

import numpy as np
from build123d import Edge, Face, Plane, Vector, Wire
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
from OCP.GC import GC_MakeArcOfEllipse
from OCP.Geom import Geom_BSplineCurve
from OCP.gp import gp_Ax2, gp_Dir, gp_Elips, gp_Pnt

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.data.design import (
    Arc,
    Circle,
    Curve,
    Ellipse,
    EllipticalArc,
    Frame,
    Line,
    Loop,
    Nurbs,
    Profile,
)
from zonegraph.errors import DesignError, UnsupportedFeatureError
from zonegraph.geometry.vec import Vec3

SNAP_TOL = 1e-5  # cm; Fusion's float32 noise is ~1e-7, real gaps are far larger
AREA_RTOL = 1e-4  # a built face must match Fusion's profile area this closely


def _pnt(p: np.ndarray) -> gp_Pnt:
    return gp_Pnt(float(p[0]), float(p[1]), float(p[2]))


def _dir(v: np.ndarray) -> gp_Dir:
    return gp_Dir(float(v[0]), float(v[1]), float(v[2]))


class _Snapper:
    """Merges end points closer than SNAP_TOL so consecutive edges meet exactly."""

    def __init__(self) -> None:
        self.points: list[np.ndarray] = []

    def __call__(self, p: Vec3 | np.ndarray) -> np.ndarray:
        p = np.asarray(p, float)
        for q in self.points:
            if np.linalg.norm(p - q) < SNAP_TOL:
                return q
        self.points.append(p)
        return p


def new_snapper() -> _Snapper:
    """A fresh snapper, for code outside this module that builds loops as the replay does."""
    return _Snapper()


def curve_edge(c: Curve, frame: Frame, snap: _Snapper) -> Edge:
    """One profile curve as a world-space edge."""
    if isinstance(c, Line):
        a, b = frame.point(snap(c.start)), frame.point(snap(c.end))
        return Edge.make_line(Vector(*a), Vector(*b))
    if isinstance(c, Arc):
        pts = [frame.point(snap(c.start)), frame.point(c.midpoint()), frame.point(snap(c.end))]
        return Edge.make_three_point_arc(*(Vector(*p) for p in pts))
    if isinstance(c, Circle):
        plane = Plane(origin=tuple(frame.point(c.center)), z_dir=tuple(frame.vector(c.normal)))
        return Edge.make_circle(c.radius, plane)
    if isinstance(c, (Ellipse, EllipticalArc)):
        return _ellipse_edge(c, frame)
    if isinstance(c, Nurbs):
        return _nurbs_edge(c, frame, snap)
    raise TypeError(f"not a curve: {c!r}")


def _ellipse_edge(c: Ellipse | EllipticalArc, frame: Frame) -> Edge:
    # Axes built from the mapped local axes keep the local parameterisation even when the sketch
    # frame is left-handed in world space.
    u = np.asarray(c.major_axis, float)
    u /= np.linalg.norm(u)
    v = np.cross(np.asarray(c.normal, float), u)
    xw, yw = frame.vector(u), frame.vector(v)
    ax = gp_Ax2(_pnt(frame.point(c.center)), _dir(np.cross(xw, yw)), _dir(xw))
    elips = gp_Elips(ax, c.major_radius, c.minor_radius)
    if isinstance(c, Ellipse):
        return Edge(BRepBuilderAPI_MakeEdge(elips).Edge())
    arc = GC_MakeArcOfEllipse(elips, c.start_angle, c.end_angle, True).Value()
    return Edge(BRepBuilderAPI_MakeEdge(arc).Edge())


def _nurbs_edge(c: Nurbs, frame: Frame, snap: _Snapper) -> Edge:
    if c.periodic:
        raise UnsupportedFeatureError("", None, "periodic NURBS profile curves are not supported")
    pts = [np.asarray(p, float) for p in c.control_points]
    pts[0], pts[-1] = snap(pts[0]), snap(pts[-1])  # clamped: the end poles are the end points
    poles = Array1_gp_Pnt(1, len(pts))
    for i, p in enumerate(pts, 1):
        poles.SetValue(i, _pnt(frame.point(p)))
    values, mults = _unique_knots(c.knots)
    knots = Array1_double(1, len(values))
    mult = Array1_int(1, len(values))
    for i, (k, m) in enumerate(zip(values, mults, strict=True), 1):
        knots.SetValue(i, k)
        mult.SetValue(i, m)
    if c.weights:
        weights = Array1_double(1, len(c.weights))
        for i, w in enumerate(c.weights, 1):
            weights.SetValue(i, w)
        curve = Geom_BSplineCurve(poles, weights, knots, mult, c.degree, False)
    else:
        curve = Geom_BSplineCurve(poles, knots, mult, c.degree, False)
    return Edge(BRepBuilderAPI_MakeEdge(curve).Edge())


def _unique_knots(flat: tuple[float, ...], tol: float = 1e-12) -> tuple[list[float], list[int]]:
    values: list[float] = []
    mults: list[int] = []
    for k in flat:
        if values and abs(k - values[-1]) <= tol:
            mults[-1] += 1
        else:
            values.append(k)
            mults.append(1)
    return values, mults


def loop_face(loop: Loop, frame: Frame, snap: _Snapper, where: str) -> Face:
    """A planar face bounded by one closed loop (orientation normalised by the face builder)."""
    edges = [curve_edge(c, frame, snap) for c in loop.curves]
    wires = Wire.combine(edges, tol=SNAP_TOL)
    if len(wires) != 1 or not wires[0].is_closed:
        raise DesignError(where, None, f"a profile loop of {len(edges)} curves does not close")
    face = Face(wires[0])
    if face.area <= 0:
        raise DesignError(where, None, "a profile loop encloses no area")
    return face


def face_profile_area(profile: Profile, frame: Frame, where: str) -> float:
    """The area `profile_faces` builds for the profile of one face (one outer loop, its
    holes inside it and apart), measured loop by loop: the outer loop's face less its holes'.
    ``profile_faces`` cuts the holes out one Boolean at a time, which took minutes on a sketch
    face of a corpus part with hundreds of holes."""
    snap = _Snapper()
    return sum(
        (1.0 if lp.is_outer else -1.0) * loop_face(lp, frame, snap, where).area for lp in profile.loops
    )


def profile_faces(profile: Profile, frame: Frame, where: str) -> list[Face]:
    """The profile region: union of outer loops minus inner loops, checked against Fusion's area."""
    snap = _Snapper()
    outer = [loop_face(lp, frame, snap, where) for lp in profile.loops if lp.is_outer]
    inner = [loop_face(lp, frame, snap, where) for lp in profile.loops if not lp.is_outer]
    if not outer:
        raise DesignError(where, profile.id, "profile has no outer loop")
    region = outer[0]
    for f in outer[1:]:
        region = region.fuse(f)
    for f in inner:
        region = region.cut(f)
    faces = region.faces()
    if not faces:
        raise DesignError(where, profile.id, "profile is empty")
    if profile.area is not None:
        built = sum(f.area for f in faces)
        if not math.isclose(built, profile.area, rel_tol=AREA_RTOL):
            raise DesignError(
                where, profile.id, f"built profile area {built:.6g} differs from Fusion's {profile.area:.6g}"
            )
    return list(faces)

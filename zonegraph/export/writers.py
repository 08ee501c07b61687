"""Write a program out: an editable build123d script, Fusion-format JSON, STEP per step, a PNG strip.

Sketch curves are written in each sketch's own frame (origin: the start plane's point nearest the
input's origin, so a sketch on a principal plane reads in the input's own coordinates; z along the
extrusion), lines as lines, circular arcs and circles exactly, any other curve as a B-spline (JSON)
or an interpolating spline through points (script). The script and the JSON are both written from
one list of `WrittenStep`, whose numbers a `Snapper` chose.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from build123d import Edge, Face, GeomType, Shape, Unit, Vector
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_UniformAbscissa
from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
from OCP.gp import gp_Pnt
from scipy.optimize import minimize_scalar

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
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
from zonegraph.data.profiles import face_profile_area
from zonegraph.errors import DesignError
from zonegraph.export.idioms import named_plane, plane_code, plane_of_frame, plane_phrase, sketch_object
from zonegraph.export.loops import LoopEdge, loop_edges
from zonegraph.export.render import render_sequence
from zonegraph.export.snap import Snapper, written
from zonegraph.geometry.cells import MERGE_RTOL
from zonegraph.geometry.shapes import write_step
from zonegraph.geometry.vec import vec3
from zonegraph.sequence.program import ProgramStep
from zonegraph.sequence.proposals import Op

# A curve that is not a line, circle or arc is written as a B-spline. build123d's default (cubic,
# 1e-3) moved a profile's area by 1.5e-4, more than the reader's AREA_RTOL: our own JSON failed to
# replay. A tight tolerance at a higher degree keeps the written curve on the original.
SPLINE_DEGREE = 8
SPLINE_TOL = 1e-7
SPLINE_SAMPLES = 24  # the fewest points the script's interpolating spline runs through
# The script's spline doubles its points until it stays this close to the curve, relative to the
# curve's length: 24 points of a 94 cm spline of the corpus strayed 3e-4 of it, so the written
# script rebuilt its part to IoU 0.99988 (96 points: 3.6e-6 and 0.999998). Not tighter: every
# point is a knot, and the exact volume integration of the written part slows with each (48-point
# splines instead of 24 made a partial program's IoU take 275 s instead of about 50).
SPLINE_FIT = 1e-5
SPLINE_MAX_SAMPLES = 384
# A closed free-form loop is sampled from its point farthest along this direction of the sketch
# plane (x, y): any seam-free point would do; a direction along neither axis keeps a straight run
# of the loop (common along an axis) from making that point ambiguous.
SEAM_DIRECTION = (math.cos(0.7), math.sin(0.7))
EXTREME_SAMPLES = 256


def step_frame(step: ProgramStep, snap: Snapper | None = None) -> Frame:
    """The sketch frame of a step, with its numbers snapped.

    A step along a principal axis is sketched on build123d's named plane of that axis
    (`NAMED_PLANES`), whose coordinates are the input's own; its
    normal can point against the extrusion (the written distance is then negative). Otherwise x is
    the principal axis least along z, made orthogonal to z; after snapping, x is made orthogonal
    to the snapped z again, so the frame stays orthonormal."""
    snap = snap or Snapper.raw()
    z = snap.direction(step.direction)
    named = named_plane(z)
    if named is not None:
        normal = np.array(named.z_dir)
        origin = snap.point(normal * float(np.asarray(step.origin, float) @ normal)) + 0.0
        return Frame(vec3(origin), named.x_dir, named.y_dir, named.z_dir)
    helper = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = snap.direction(helper - z * float(helper @ z))
    x = x - z * float(x @ z)
    x /= np.linalg.norm(x)
    origin = snap.point(z * float(np.asarray(step.origin, float) @ z))
    return Frame(vec3(origin), vec3(x), vec3(np.cross(z, x) + 0.0), vec3(z))


def _local(frame: Frame, p: Sequence[float] | np.ndarray | Vector) -> np.ndarray:
    """A point of the sketch in its frame, on the plane: a loop corner is its vertex, which can lie
    up to the vertex tolerance off the plane (1.1e-6 cm on the corpus), and a profile whose curves
    are not coplanar loses its holes in the JSON reader (a hole-less area, refused)."""
    local = frame.matrix.T @ (np.asarray(tuple(p), float) - np.asarray(frame.origin, float))
    local[2] = 0.0
    return local


@dataclass(frozen=True)
class LocalEdge:
    """An edge in sketch coordinates, as the script writes it (kind, points, radius) and as the
    JSON does (``curve``). kind is line, arc, circle or spline; ``points``: line: start, end;
    arc: start, mid, end; circle: centre; spline: samples (the script interpolates them)."""

    kind: str
    points: np.ndarray
    curve: Curve
    radius: float = 0.0


def _arc_through(
    start: np.ndarray, end: np.ndarray, centre: np.ndarray, curve: np.ndarray
) -> tuple[np.ndarray, float, np.ndarray]:
    """Centre, radius and mid point of the arc from ``start`` to ``end`` (the loop's corners,
    which lie up to the vertex tolerance off the edge's circle) that stays nearest the edge's own
    ``curve`` (points along it, its mid point in the middle): of the circles through both
    corners, whose centres lie on their bisector, the first among `_bisector_centres` that
    the curve's points miss by no more than the least miss and what the corners miss the edge's
    own circle by (so a short arc keeps its designer's radius: every circle through its corners
    follows it about as well).

    No one construction suits every arc. Keeping the edge's radius and solving for the centre
    from the chord is ill-conditioned on a half circle: a corpus semicircle of radius 4 whose
    corners sat 1.8e-5 off it has a chord longer than its diameter, and was written about its
    chord's midpoint, 0.006 cm off (the part lost 2.4e-4 of its volume). The circle through the
    corners and the edge's mid point degenerates on a short arc (a 0.008 cm arc of radius 2.6
    whose corner sat 1.3e-5 off it: "GC_MakeArcOfCircle::Value() - no result")."""
    mid = curve[len(curve) // 2]
    half = (end - start) / 2
    chord = float(np.linalg.norm(half[:2]))
    if chord == 0.0:
        return centre, _radius(centre, mid), mid
    middle = start + half
    normal = np.array([-half[1], half[0], 0.0]) / chord

    def miss(offset: float) -> float:
        radii = np.linalg.norm((curve - (middle + offset * normal))[:, :2], axis=1)
        return float(np.max(np.abs(radii - math.hypot(chord, offset))))

    offsets = _bisector_centres(middle, normal, chord, centre, mid)
    misses = [miss(o) for o in offsets]
    slack = max(abs(_radius(centre, q) - _radius(centre, mid)) for q in (start, end))
    offset = next(o for o, m in zip(offsets, misses, strict=True) if m <= min(misses) + slack)
    new_centre = middle + offset * normal
    radius = math.hypot(chord, offset)
    out = mid - new_centre
    return new_centre, radius, new_centre + radius * out / np.linalg.norm(out)


def _radius(centre: np.ndarray, point: np.ndarray) -> float:
    return float(np.linalg.norm((point - centre)[:2]))


def _bisector_centres(
    middle: np.ndarray,
    normal: np.ndarray,
    chord: float,
    centre: np.ndarray,
    mid: np.ndarray,
) -> list[float]:
    """Offsets along the corners' bisector (from the chord's middle) of three centres: the edge's
    own centre moved onto it; the centre at the edge's radius on the own centre's side; the
    centre of the circle through the corners and the edge's mid point, where they are not
    collinear."""
    own = float((centre - middle) @ normal)
    radius = _radius(centre, mid)
    out = [own, math.copysign(math.sqrt(max(radius**2 - chord**2, 0.0)), own)]
    to_mid = (mid - middle)[:2]
    across = float(to_mid @ normal[:2])
    if abs(across) > 1e-12 * chord:
        out.append((float(to_mid @ to_mid) - chord**2) / (2 * across))
    return out


# Points along an arc (an odd count: the middle one is its mid point) by which a written arc is
# chosen (`_arc_through`).
ARC_SAMPLES = 9


def _bulge(start: np.ndarray, mid: np.ndarray, end: np.ndarray) -> float:
    """How far ``mid`` lies off the chord from ``start`` to ``end`` (in the sketch plane)."""
    chord = (end - start)[:2]
    length = float(np.linalg.norm(chord))
    off = (mid - start)[:2]
    return (
        float(np.linalg.norm(off))
        if length == 0.0
        else abs(float(chord[0] * off[1] - chord[1] * off[0])) / length
    )


def _line(start: np.ndarray, end: np.ndarray, snap: Snapper) -> LocalEdge:
    ends = [snap.point(start), snap.point(end)]
    return LocalEdge("line", np.array(ends), Line(vec3(ends[0]), vec3(ends[1])))


def _arc(piece: LoopEdge, frame: Frame, snap: Snapper) -> LocalEdge:
    """Start, mid and end point (the script's ThreePointArc); centre and radius (the JSON's arc),
    each snapped like any other number; the JSON's reference direction is a snapped unit vector."""
    edge = piece.edge
    start, end = (_local(frame, q) for q in (piece.start, piece.end))
    curve = np.array([_local(frame, edge.position_at(t)) for t in np.linspace(0.0, 1.0, ARC_SAMPLES)])
    raw_centre, raw_radius, raw_mid = _arc_through(start, end, _local(frame, edge.arc_center), curve)
    if _bulge(start, raw_mid, end) <= snap.tol:
        return _line(start, end, snap)  # straight within what a number may move; snapped, no arc
    points = [snap.point(start), snap.point(raw_mid), snap.point(end)]
    centre = snap.point(raw_centre)
    radius = snap.length(raw_radius)
    a, m, b = (q - centre for q in points)
    sign = 1.0 if a[0] * m[1] - a[1] * m[0] > 0 else -1.0
    ref = snap.direction(a)
    perp = np.cross((0.0, 0.0, sign), ref)
    sweep = math.atan2(float(b @ perp), float(b @ ref)) % (2 * math.pi) or 2 * math.pi
    arc = Arc(vec3(points[0]), vec3(points[2]), vec3(centre), radius, (0.0, 0.0, sign), 0.0, sweep, vec3(ref))
    return LocalEdge("arc", np.array(points), arc, radius)


def _nurbs(piece: LoopEdge, frame: Frame, snap: Snapper) -> Nurbs:
    """The JSON's B-spline of a free-form edge, in the (snapped) sketch frame, its end poles on the
    loop's (snapped) corners. The other poles are not snapped: nobody edits them, and moving the
    curve off the original would buy nothing."""
    spline = piece.edge.to_splines(degree=SPLINE_DEGREE, tolerance=SPLINE_TOL)
    geom = spline.geom_adaptor().BSpline()
    world = [np.array((q.X(), q.Y(), q.Z())) for q in geom.Poles()]
    poles = [_local(frame, q) for q in world]
    ends = _from_nearest(world[0], piece.start, piece.end)
    poles[0], poles[-1] = (snap.point(_local(frame, q)) for q in ends)  # clamped: end poles are the ends
    knots = [k for k, m in zip(geom.Knots(), geom.Multiplicities(), strict=False) for _ in range(m)]
    weights = list(geom.Weights()) if geom.IsRational() else None
    return Nurbs(
        geom.Degree(), tuple(knots), tuple(vec3(q) for q in poles), tuple(weights) if weights else None
    )


def local_edge(
    piece: LoopEdge, frame: Frame, snap: Snapper | None = None, shared: SharedLoops | None = None
) -> LocalEdge:
    """An edge of a sketch loop in the sketch's frame between the loop's corners, its numbers
    snapped (a corner snaps to the same point for both edges that meet there); a closed free-form
    loop that ``shared`` holds from an earlier step is written as that loop."""
    snap = snap or Snapper.raw()
    edge = piece.edge
    kind = edge.geom_type
    if kind == GeomType.CIRCLE and edge.is_closed:
        centre = snap.point(_local(frame, edge.arc_center))
        radius = snap.length(edge.radius)
        return LocalEdge("circle", np.array([centre]), Circle(vec3(centre), radius, (0.0, 0.0, 1.0)), radius)
    if kind == GeomType.LINE:
        return _line(_local(frame, piece.start), _local(frame, piece.end), snap)
    if kind == GeomType.CIRCLE:
        return _arc(piece, frame, snap)
    if edge.is_closed:
        return _closed_spline(piece, frame, snap, shared)
    begin = np.array(tuple(edge.position_at(0)))
    first, last = (snap.point(_local(frame, q)) for q in _from_nearest(begin, piece.start, piece.end))
    inside = [snap.point(_local(frame, q)) for q in spline_points(edge)[1:-1]]
    return LocalEdge("spline", np.array([first, *inside, last]), _nurbs(piece, frame, snap))


def _closed_spline(
    piece: LoopEdge, frame: Frame, snap: Snapper, shared: SharedLoops | None = None
) -> LocalEdge:
    """A closed free-form loop, sampled from a point of the curve that does not depend on its seam,
    running anticlockwise; the loop an earlier step wrote where ``shared`` holds one it follows.

    Two steps of a corpus part sketch one closed spline, each on a face the partition cut with its
    own seam (25364_b3985755_0002). Sampled from each seam, the two interpolating splines crossed
    each other and their union failed (script IoU 0); sampled from the curve's extreme point along
    `SEAM_DIRECTION` they are the same points, up to the 8e-6 cm the two faces' curves part."""
    curve = piece.edge.geom_adaptor()
    direction = SEAM_DIRECTION[0] * np.asarray(frame.x_axis, float) + SEAM_DIRECTION[1] * np.asarray(
        frame.y_axis, float
    )
    start = _extreme_parameter(curve, direction)
    raw = np.array([_local(frame, q) for q in spline_points(piece.edge, start)])
    raw[-1] = raw[0]
    if _signed_area(raw) < 0:  # one running sense too: an edge's own runs either way
        raw = raw[::-1]
    earlier = shared.follows(frame, raw) if shared is not None else None
    if earlier is not None:
        return earlier
    samples = np.array([snap.point(q) for q in raw])  # raw ends alike, so the snapped ones are
    loop = LocalEdge("spline", samples, _nurbs(piece, frame, snap))
    if shared is not None:
        shared.add(frame, raw, loop)
    return loop


def _signed_area(points: np.ndarray) -> float:
    """Twice the signed area of a closed polygon in the sketch plane (positive: anticlockwise)."""
    x, y = points[:, 0], points[:, 1]
    return float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]))


def spline_points(edge: Edge, start: float | None = None) -> list[np.ndarray]:
    """Points evenly spaced along ``edge`` by arc length, from its start (``position_at(0)``) or,
    on a closed edge, from parameter ``start`` round to it again, that an interpolating spline
    through them follows within ``SPLINE_FIT`` of the edge's length, checked half-way between
    them: ``SPLINE_SAMPLES`` doubled until it does (at most ``SPLINE_MAX_SAMPLES``). One pass of
    OpenCASCADE's uniform abscissa per try: build123d's ``position_at`` measures the whole curve
    at every call, which made the check minutes long on a corpus part with many free-form sketch
    edges."""
    curve = edge.geom_adaptor()
    length = GCPnts_AbscissaPoint.Length_s(curve)
    n = SPLINE_SAMPLES
    while True:
        points = (
            _even_points(curve, 2 * n - 1, edge.is_forward)
            if start is None
            else _points_from(curve, start, length, 2 * n - 1)
        )
        samples, halfway = points[::2], points[1::2]
        if n >= SPLINE_MAX_SAMPLES or _strays(samples, halfway) <= SPLINE_FIT * length:
            return samples
        n *= 2


def _even_points(curve: BRepAdaptor_Curve, count: int, forward: bool) -> list[np.ndarray]:
    abscissa = GCPnts_UniformAbscissa(curve, count)
    if not abscissa.IsDone():
        raise ValueError("OpenCASCADE could not space points along a sketch edge")
    params = [abscissa.Parameter(i) for i in range(1, abscissa.NbPoints() + 1)]
    points = [np.array(curve.Value(u).Coord()) for u in params]
    return points if forward else points[::-1]


def _points_from(curve: BRepAdaptor_Curve, start: float, length: float, count: int) -> list[np.ndarray]:
    """``count`` points evenly spaced by arc length round a closed curve, from parameter ``start``
    back to it (the last point is the first)."""
    first = curve.FirstParameter()
    offset = GCPnts_AbscissaPoint.Length_s(curve, first, start)
    points = []
    for i in range(count - 1):
        along = (offset + i * length / (count - 1)) % length
        at = GCPnts_AbscissaPoint(curve, along, first)
        if not at.IsDone():
            raise ValueError("OpenCASCADE could not space points along a sketch edge")
        points.append(np.array(curve.Value(at.Parameter()).Coord()))
    return [*points, points[0]]


def _extreme_parameter(curve: BRepAdaptor_Curve, direction: np.ndarray) -> float:
    """The parameter of the curve's point farthest along ``direction``: coarse samples, then a
    bounded search between the best one's neighbours."""
    first, last = curve.FirstParameter(), curve.LastParameter()
    params = np.linspace(first, last, EXTREME_SAMPLES + 1)

    def height(u: float) -> float:
        return -float(np.asarray(curve.Value(u).Coord()) @ direction)

    best = int(np.argmin([height(u) for u in params[:-1]]))
    step = params[1] - params[0]
    found = minimize_scalar(
        lambda t: height(first + (t - first) % (last - first)),
        bounds=(params[best] - step, params[best] + step),
        method="bounded",
        options={"xatol": 1e-12 * (last - first)},
    )
    return float(first + (found.x - first) % (last - first))


def _strays(samples: list[np.ndarray], halfway: list[np.ndarray]) -> float:
    """How far the spline interpolating ``samples`` passes from ``halfway`` at most."""
    fitted = Edge.make_spline([Vector(*q) for q in samples])
    spline = BRep_Tool.Curve_s(fitted.wrapped, 0.0, 1.0)
    project = GeomAPI_ProjectPointOnCurve()
    far = 0.0
    for q in halfway:
        project.Init(gp_Pnt(*q), spline)
        far = max(far, project.LowerDistance() if project.NbPoints() else math.inf)
    return far


def _from_nearest(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two corners of an edge, the one nearest ``p`` (where its samples or poles begin) first.

    Decided by geometry, not by the edge's orientation flag: build123d's ``position_at`` and the
    B-spline's poles each run in their own direction, and a spline written from the wrong corner
    crosses itself ("TopoDS::Face" type mismatch in the script, a wrong profile area in the JSON)."""
    return (a, b) if float(np.linalg.norm(p - a)) <= float(np.linalg.norm(p - b)) else (b, a)


def face_wires(face: Face) -> list[tuple[bool, list[LoopEdge]]]:
    """(is_outer, edges in loop order) per boundary loop; merged faces can carry empty wires,
    which are dropped."""
    wires = [(True, face.outer_wire())] + [(False, w) for w in face.inner_wires()]
    return [(outer, loop_edges(w, face)) for outer, w in wires if w.edges()]


FaceLoops = tuple[tuple[bool, tuple[LocalEdge, ...]], ...]  # a sketch face's loops: (is_outer, edges)


@dataclass(frozen=True)
class WrittenStep:
    """One step with the numbers that go into the files: frame, loops per sketch face, distance
    (along the frame's z; negative where the extrusion runs against the sketch normal)."""

    op: Op
    frame: Frame
    faces: tuple[FaceLoops, ...]
    areas: tuple[float, ...]  # each sketch face's area (the JSON's profile area)
    distance: float
    tol: float = 0.0  # how far the snapper could move a number (a sketch object matches within it)


@dataclass
class SharedLoops:
    """The closed free-form loops written so far, so that a loop another step sketched (within
    what snapping may move a number) is written as the same curve.

    Two steps of a corpus part (25364_b3985755_0002) sketch one closed spline, cut from the part's
    side face at both ends of it, 8e-6 cm apart: snapped apart, their union failed in the script
    (IoU 0) and left 1.2% of the part out of the JSON's replay."""

    tol: float  # 0 (a raw snapper): nothing is shared
    loops: list[tuple[tuple[float, ...], np.ndarray, LocalEdge]] = field(default_factory=list)

    @staticmethod
    def _plane(frame: Frame) -> tuple[float, ...]:
        return tuple(round(c, 9) for c in (*frame.x_axis, *frame.y_axis))

    def follows(self, frame: Frame, samples: np.ndarray) -> LocalEdge | None:
        """The loop written earlier in a parallel frame whose samples ``samples`` (raw, in
        ``frame``) follow within ``tol``; None when none does."""
        plane = self._plane(frame)
        for other_plane, other, loop in self.loops:
            if other_plane == plane and _strays(list(other), list(samples)) <= self.tol:
                return loop
        return None

    def add(self, frame: Frame, samples: np.ndarray, loop: LocalEdge) -> None:
        if self.tol > 0:
            self.loops.append((self._plane(frame), samples, loop))


def written_steps(program: list[ProgramStep], snap: Snapper | None = None) -> list[WrittenStep]:
    """The program in sketch coordinates, every number passed through ``snap`` once (and a closed
    free-form loop that an earlier step sketched within what snapping may move written as that
    loop, `SharedLoops`)."""
    snap = snap or Snapper.raw()
    shared = SharedLoops(snap.tol)
    out = []
    for step in program:
        frame = step_frame(step, snap)
        faces = tuple(
            tuple(
                (outer, tuple(local_edge(e, frame, snap, shared) for e in edges))
                for outer, edges in face_wires(f)
            )
            for f in step.faces
        )
        areas = tuple(f.area for f in step.faces)
        sign = 1.0 if float(np.dot(step.direction, frame.z_axis)) > 0 else -1.0
        out.append(WrittenStep(step.op, frame, faces, areas, sign * snap.length(step.distance), snap.tol))
    return out


# --------------------------------------------------------------------------- build123d script


def _xy(p: np.ndarray) -> str:
    return f"({written(p[0])}, {written(p[1])})"


def _vec(v: Sequence[float] | np.ndarray) -> str:
    return "(" + ", ".join(written(c) for c in v) + ")"


def _edge_code(e: LocalEdge) -> str:
    if e.kind == "line":
        return f"Line({_xy(e.points[0])}, {_xy(e.points[1])})"
    if e.kind == "arc":
        return f"ThreePointArc({_xy(e.points[0])}, {_xy(e.points[1])}, {_xy(e.points[2])})"
    if e.kind == "circle":
        return f"CenterArc({_xy(e.points[0])}, {written(e.radius)}, 0, 360)"
    return "Spline(" + ", ".join(_xy(p) for p in e.points) + ")  # interpolates the original curve"


@dataclass(frozen=True)
class ScriptStyle:
    """Which idioms a script may use. `zonegraph.export.verify.verified_export` drops them
    (holes first, then objects) where the script they give does not rebuild the part as well."""

    objects: bool = True  # loops as Circle, Rectangle, SlotCenterToCenter, RegularPolygon
    holes: bool = True  # a cut of lone circles into a named plane as Hole
    # not empty: each step's Boolean tries these fuzzy values (input units; `FUZZY_CODE`)
    fuzzy: tuple[float, ...] = ()
    # with fuzzy values: no Boolean per step; the part is the point set of all the steps' tools,
    # from one general fuse of them at those values (`POINT_SET_CODE`)
    cells: bool = False


IDIOMATIC = ScriptStyle()
LITERAL = ScriptStyle(objects=False, holes=False)
OBJECT_CALL = re.compile(r"^\s*(Circle|Rectangle|SlotCenterToCenter|RegularPolygon|Hole)\(", re.MULTILINE)


def profile_counts(script: str) -> tuple[int, int]:
    """(loops written as build123d objects, loops in all) of a script this module wrote (a Hole
    counts once per location)."""
    objects = 0
    lines = script.splitlines()
    for i, line in enumerate(lines):
        if OBJECT_CALL.match(line):
            above = lines[i - 1].strip() if i else ""
            objects += above.count("), (") + 1 if above.startswith("with Locations((") else 1
    return objects, objects + script.count("make_face(")


def _where(step: WrittenStep, unit: str) -> tuple[str, str, str]:
    """The plane's code, its description and the extrusion's direction in words."""
    frame, origin = step.frame, step.frame.origin
    named = plane_of_frame(frame.x_axis, frame.z_axis)
    if named is None:
        code = f"Plane(origin={_vec(origin)}, x_dir={_vec(frame.x_axis)}, z_dir={_vec(frame.z_axis)})"
        return code, f"a plane through {_vec(origin)} {unit}", "along its normal"
    axis = "xyz"[named.axis]
    sign = "+" if (named.z_dir[named.axis] > 0) == (step.distance > 0) else "-"
    return plane_code(named, origin), plane_phrase(named, origin, unit), f"along {sign}{axis}"


def _hole_circles(step: WrittenStep) -> list[LocalEdge] | None:
    """The circles of a cut into a named plane (against its normal) whose every face is one
    circle, or None: build123d's Hole cuts along -z of its location."""
    named = plane_of_frame(step.frame.x_axis, step.frame.z_axis)
    if step.op is not Op.SUBTRACT or named is None or step.distance >= 0:
        return None
    circles = [loops[0][1][0] for loops in step.faces if len(loops) == 1 and len(loops[0][1]) == 1]
    if len(circles) != len(step.faces) or any(c.kind != "circle" for c in circles):
        return None
    return circles


def _hole_code(step: WrittenStep, circles: list[LocalEdge], plane: str) -> list[str]:
    """Hole(r, depth=d) cuts d either side of its location: exact where nothing lies above the
    plane within d (the rebuild check decides)."""
    by_radius: dict[str, list[str]] = {}
    for c in circles:
        by_radius.setdefault(written(c.radius), []).append(_xy(c.points[0]))
    lines = [f"    with Locations({plane}):"]
    for radius, centres in by_radius.items():
        lines += [
            f"        with Locations({', '.join(centres)}):",
            f"            Hole({radius}, depth={written(-step.distance)})",
        ]
    return lines


def _sketch_code(step: WrittenStep, style: ScriptStyle) -> list[str]:
    lines = []
    for loops in step.faces:
        for outer, edges in loops:
            found = sketch_object(edges, step.tol) if style.objects else None
            if found is not None:
                lines += [f"        {line}" for line in found.lines(subtract=not outer)]
                continue
            lines.append("        with BuildLine(mode=Mode.PRIVATE) as loop:")
            lines += [f"            {_edge_code(e)}" for e in edges]
            mode = "" if outer else ", mode=Mode.SUBTRACT"
            lines.append(f"        make_face(loop.edges(){mode})")
    return lines


def _step_code(i: int, step: WrittenStep, unit: str, style: ScriptStyle) -> list[str]:
    verb = "union" if step.op is Op.UNION else "subtract"
    plane, where, direction = _where(step, unit)
    depth = f"{written(abs(step.distance))} {unit}"
    mode = "Mode.ADD" if step.op is Op.UNION else "Mode.SUBTRACT"
    if style.fuzzy:
        what = f"{verb}: sketch on {where}, extruded {depth} {direction}"
        return _fuzzy_step_code(i, step, plane, what, mode, style)
    circles = _hole_circles(step) if style.holes else None
    if circles is not None:
        count = f"{len(circles)} holes" if len(circles) > 1 else "a hole"
        return [f"    # Step {i}: {count} {depth} deep into {where}", *_hole_code(step, circles, plane), ""]
    return [
        f"    # Step {i}: {verb}: sketch on {where}, extruded {depth} {direction}",
        f"    with BuildSketch({plane}):",
        *_sketch_code(step, style),
        f"    extrude(amount={written(step.distance)}, mode={mode})",
        "",
    ]


# The helper a fuzzy-style script defines: build123d's own Booleans (``mode=Mode.SUBTRACT``) have
# no fuzzy value and no check, and on a part whose steps leave faces a hair apart (tolerances grown
# by earlier Booleans to 1e-5 of the part) they came back valid and wrong: a corpus part's 14th cut
# left 1.2 of its 15 cm3 in place. The helper does what the program's own rebuild does
# (`zonegraph.sequence.program.execute`): each Boolean on copies, exact and then at fuzzy
# values, the first result valid with a volume its operation allows.
FUZZY_CODE = """
def boolean(part, tool, mode):
    \"\"\"part fused with (Mode.ADD) or cut by (Mode.SUBTRACT) tool: the first result that is valid
    with a volume the operation allows, faces closer than each of FUZZY in turn taken as one (the
    steps meet on faces that OpenCASCADE's plain Booleans can miss), else the last result
    repaired by OpenCASCADE's shape fixer where that is such a result, else as it came.\"\"\"
    if part is None:
        return tool
    a, b = part.volume, tool.volume
    low, high = (max(a, b), a + b) if mode == Mode.ADD else (a - b, a)
    slack = 1e-5 * (a + b)
    result = None
    for fuzzy in FUZZY:
        op = BRepAlgoAPI_Fuse() if mode == Mode.ADD else BRepAlgoAPI_Cut()
        args, tools = List_TopoDS_Shape(), List_TopoDS_Shape()
        args.Append(BRepBuilderAPI_Copy(part.wrapped).Shape())
        tools.Append(BRepBuilderAPI_Copy(tool.wrapped).Shape())
        op.SetArguments(args)
        op.SetTools(tools)
        op.SetFuzzyValue(fuzzy)
        op.Build()
        if not op.IsDone():
            continue
        result = Part(op.Shape()).clean()
        if result.is_valid and low - slack <= result.volume <= high + slack:
            return result
    if result is None:
        raise RuntimeError("a Boolean failed at every fuzzy value")
    fixed = result.fix()
    return fixed if fixed.is_valid and low - slack <= fixed.volume <= high + slack else result
"""


# The helper a point-set script defines, the last style tried: a chain of Booleans fails where one
# link does, and on a corpus part (21638_0a984848_0011) the written tools' sixth cut failed in
# every chain, at every fuzzy value, while one general fuse of all seven tools gave the part (IoU
# 0.999998). As `zonegraph.data.replay.cells_bodies` does for a replay: each cell of the
# fuse is material when the last tool that holds it adds, i.e. the cells inside an adding tool and
# outside every later tool. A fuse whose cells change volume when merged is passed over, as in
# `zonegraph.geometry.cells.select_cells` (a 16-step corpus program's exact fuse merged into
# a "valid" solid of volume -1e-8).
POINT_SET_CODE = """
def point_set(steps):
    \"\"\"The part that steps (tool, Mode.ADD or Mode.SUBTRACT) make, in order: the pieces of one
    general fuse of all the tools that the last tool holding them adds, faces closer than each of
    FUZZY in turn taken as one; the first valid result whose volume is the cells' (shared faces
    merged where that keeps it so).\"\"\"
    tools = [BRepBuilderAPI_Copy(tool.wrapped).Shape() for tool, _ in steps]
    for fuzzy in FUZZY:
        cells = BOPAlgo_CellsBuilder()
        for tool in tools:
            cells.AddArgument(tool)
        cells.SetFuzzyValue(fuzzy)
        cells.SetNonDestructive(True)
        cells.Perform()
        if cells.HasErrors():
            continue
        for i, (_, mode) in enumerate(steps):
            if mode == Mode.ADD:
                take, avoid = List_TopoDS_Shape(), List_TopoDS_Shape()
                take.Append(tools[i])
                for later in tools[i + 1 :]:
                    avoid.Append(later)
                cells.AddToResult(take, avoid, 1, False)
        held = Part(cells.Shape()).volume
        cells.RemoveInternalBoundaries()
        part = Part(cells.Shape())
        if abs(part.volume - held) > MERGE_RTOL * abs(held):
            continue  # the cells' boundaries were removed wrongly at this fuzzy value
        merged = Part(BRepBuilderAPI_Copy(part.wrapped).Shape()).clean()
        if merged.is_valid and abs(merged.volume - held) <= MERGE_RTOL * abs(held):
            return merged
        if part.is_valid:
            return part
    raise RuntimeError("the general fuse of the tools failed at every fuzzy value")
"""


def _fuzzy_step_code(
    i: int, step: WrittenStep, plane: str, what: str, mode: str, style: ScriptStyle
) -> list[str]:
    """A step in build123d's algebra mode: the sketch extruded alone, then `FUZZY_CODE`'s
    ``boolean`` with the part so far (or, point-set style, the tool kept for
    `POINT_SET_CODE`)."""
    tool = f"extrude(sketch.sketch, amount={written(step.distance)})"
    combined = f"steps.append(({tool}, {mode}))" if style.cells else f"part = boolean(part, {tool}, {mode})"
    return [
        f"# Step {i}: {what}",
        f"with BuildSketch({plane}) as sketch:",
        *[line[4:] for line in _sketch_code(step, style)],
        combined,
        "",
    ]


def _fuzzy_body(steps: list[WrittenStep], unit: str, style: ScriptStyle) -> list[str]:
    merge = f"MERGE_RTOL = {MERGE_RTOL}  # how far merging the cells may move their volume"
    imports = (
        ["from OCP.BOPAlgo import BOPAlgo_CellsBuilder"]
        if style.cells
        else ["from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse"]
    )
    lines = [
        *imports,
        "from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy",
        "from OCP.collections import List_TopoDS_Shape",
        "",
        f"FUZZY = ({', '.join(written(f) for f in style.fuzzy)})  # {unit}",
        *([merge] if style.cells else []),
        *(POINT_SET_CODE if style.cells else FUZZY_CODE).splitlines(),
        "",
        "steps = []" if style.cells else "part = None",
    ]
    for i, step in enumerate(steps, 1):
        lines += _step_code(i, step, unit, style)
    return [*lines, "result = point_set(steps)" if style.cells else "result = part"]


def program_script(steps: list[WrittenStep], name: str, unit: Unit, style: ScriptStyle = IDIOMATIC) -> str:
    """The build123d script of a program: lengths in the input's unit, at the input's position."""
    u = unit.name.lower()
    lines = [
        f'"""{name}: {len(steps)} sketch + extrude steps found by `zonegraph infer`.',
        "",
        f"Lengths are in {u}, the input's unit, and the part sits where the input's did. Run",
        "`python sequence.py [out.step]` to write it as STEP (default: sequence.step beside this",
        "file); with no argument it is also shown in the OCP CAD Viewer where ocp_vscode is installed.",
        '"""',
        "",
        "import sys",
        "from pathlib import Path",
        "",
        "from build123d import *",
    ]
    if style.fuzzy:
        lines += _fuzzy_body(steps, u, style)
    else:
        lines += ["", "with BuildPart() as part:"]
        for i, step in enumerate(steps, 1):
            lines += _step_code(i, step, u, style)
        lines.append("result = part.part")
    lines += [
        "",
        'if __name__ == "__main__":',
        '    out = sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).with_suffix(".step"))',
        f"    export_step(result, out, unit=Unit.{unit.name})",
        '    print(f"wrote {out}")',
        "    if len(sys.argv) == 1:",
        "        try:",
        "            from ocp_vscode import show",
        "        except ImportError:",
        "            pass",
        "        else:",
        "            show(result)",
        "",
    ]
    return "\n".join(lines)


# ------------------------------------------------------------------------- Fusion-format JSON


def written_profile(pid: str, loops: FaceLoops, frame: Frame, face_area: float) -> Profile:
    """A sketch face as the JSON's profile, its area that of the written curves as the reader
    builds them (Fusion's profile area is its curves'). The sketch face's own area can differ by
    more than the reader allows: on a corpus part a merged face kept a 2e-5 cm stray of a
    neighbouring circle, which the written arc (the loop's corners, the designer's radius) does
    not, so the file was refused although it rebuilt the part. ``face_area`` stands in where the
    written loops do not build, so the replay reports that instead. A sketch face is one outer
    loop with its holes (`face_profile_area`)."""
    profile = Profile(pid, tuple(Loop(outer, tuple(e.curve for e in edges)) for outer, edges in loops), None)
    try:
        area = face_profile_area(profile, frame, pid)
    except DesignError:
        area = face_area
    return replace(profile, area=area)


def program_design(steps: list[WrittenStep], name: str) -> Design:
    timeline: list[Sketch | Extrude] = []
    for i, step in enumerate(steps):
        profiles = {
            f"profile{i}_{j}": written_profile(f"profile{i}_{j}", loops, step.frame, area)
            for j, (loops, area) in enumerate(zip(step.faces, step.areas, strict=True))
        }
        sketch = Sketch(f"sketch{i}", f"Sketch{i + 1}", step.frame, profiles)
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


def design_text(steps: list[WrittenStep], name: str, properties: dict | None = None) -> str:
    """``sequence.json``'s text; ``properties``: the final figures its replay is checked against
    (`zonegraph.verified`)."""
    return json.dumps(design_to_json(program_design(steps, name), properties=properties), indent=1)


# ------------------------------------------------------------------------------ STEP and PNG


def write_outputs(
    script: str,
    design: str,
    program: list[ProgramStep],
    states: list[Shape | None],
    out: Path,
    unit: Unit,
    render: bool = True,
) -> None:
    """sequence.py and sequence.json (the texts given) and, when ``render``, steps/NN.step and
    sequence.png of the program's own states.

    ``unit`` is what the input's numbers mean (mm for STEP as read, cm for a design JSON); the
    STEP files declare it, so they open at the input's size.
    """
    out.mkdir(parents=True, exist_ok=True)
    (out / "sequence.py").write_text(script)
    (out / "sequence.json").write_text(design)
    if not render:
        return
    for i, state in enumerate(states):
        if state is not None:
            write_step(state, out / "steps" / f"{i:02d}.step", unit)
    render_sequence(program, states, out / "sequence.png")

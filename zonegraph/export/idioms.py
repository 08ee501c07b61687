"""What a build123d user writes: named planes, and the sketch objects a profile loop is.

A written step's sketch plane is one of build123d's named planes when its normal is a principal
axis, oriented so that the sketch's coordinates are the input's own (x and y along + global axes):
``Plane.XY`` (x, y), ``Plane.YZ`` (y, z) and ``Plane.XZ`` (x, z; build123d's normal is -Y, so the
plane y = c is ``Plane.XZ.offset(-c)``). An extrusion against the named normal is written with a
negative distance rather than with a mirrored frame.

A loop is written as one object (``Circle``, ``Rectangle``, ``SlotCenterToCenter``,
``RegularPolygon``) only when the object, built from the numbers as written, has the loop's own
corners (within the snapping tolerance): recognising is a geometric identity, not a fit. The
written script is still rebuilt and measured (`zonegraph.export.verify`), which falls back to
literal loops when an object's script is not as exact.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from zonegraph.export.snap import simplest, written

if TYPE_CHECKING:
    from zonegraph.export.writers import LocalEdge

AXIS_TOL = 1e-12  # a direction this close to a principal axis is that axis (turns the part by 1e-12)
MIN_TOL = 1e-9  # the least tolerance a loop's corners are matched within (the raw, unsnapped numbers)
MAX_POLYGON_SIDES = 64


@dataclass(frozen=True)
class NamedPlane:
    """One of build123d's named planes: its axes and the global coordinate its normal measures."""

    name: str
    x_dir: tuple[float, float, float]
    y_dir: tuple[float, float, float]
    z_dir: tuple[float, float, float]
    axis: int  # 0, 1, 2: x, y, z

    def offset_of(self, origin: Sequence[float]) -> float:
        """build123d's ``offset`` that puts this plane through ``origin`` (along its own normal)."""
        return float(np.dot(self.z_dir, origin)) + 0.0


NAMED_PLANES = (
    NamedPlane("XY", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), 2),
    NamedPlane("YZ", (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), 0),
    NamedPlane("XZ", (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0), 1),
)
AXIS_NAMES = "xyz"


def named_plane(direction: Sequence[float] | np.ndarray) -> NamedPlane | None:
    """The named plane whose normal is +-``direction`` (a unit vector), or None (an oblique plane)."""
    z = np.asarray(direction, float)
    for plane in NAMED_PLANES:
        if abs(abs(float(np.dot(plane.z_dir, z))) - 1.0) <= AXIS_TOL:
            return plane
    return None


def plane_of_frame(x_axis: Sequence[float], z_axis: Sequence[float]) -> NamedPlane | None:
    """The named plane a written frame is exactly (same x and z axes), or None."""
    for plane in NAMED_PLANES:
        if tuple(map(float, x_axis)) == plane.x_dir and tuple(map(float, z_axis)) == plane.z_dir:
            return plane
    return None


def plane_code(plane: NamedPlane, origin: Sequence[float]) -> str:
    """``Plane.XY.offset(2.2)``, or ``Plane.XY`` through the input's origin."""
    offset = plane.offset_of(origin)
    return (
        f"Plane.{plane.name}" if written(offset) == "0" else f"Plane.{plane.name}.offset({written(offset)})"
    )


def plane_phrase(plane: NamedPlane, origin: Sequence[float], unit: str) -> str:
    """The plane in words: ``the plane z = 2.2 cm``."""
    return f"the plane {AXIS_NAMES[plane.axis]} = {written(float(origin[plane.axis]))} {unit}"


# ------------------------------------------------------------------------------ sketch objects


@dataclass(frozen=True)
class SketchObject:
    """A loop as one build123d object: the call (no mode) and the centre it is placed at."""

    call: str
    centre: tuple[float, float]  # sketch coordinates, as written

    def lines(self, subtract: bool) -> list[str]:
        """The object's lines in a BuildSketch, a ``Locations`` block when it is off the origin."""
        call = self.call[:-1] + (", mode=Mode.SUBTRACT)" if subtract else ")")
        if all(written(c) == "0" for c in self.centre):
            return [call]
        return [f"with Locations(({written(self.centre[0])}, {written(self.centre[1])})):", f"    {call}"]


@dataclass(frozen=True)
class Tolerance:
    """``snap``: how far a derived number (a centre, a radius) may be shortened, as the snapper
    shortens the loop's own; ``match``: how far the object's corners may lie from the loop's
    (three times ``snap``: each written corner moved up to ``snap`` per coordinate, the object's
    numbers once more)."""

    snap: float
    match: float


def _short(x: float, tol: Tolerance) -> float:
    """A derived number as the script will read it back, shortened like the loop's own numbers."""
    return float(written(simplest(x, tol.snap)))


def _match(points: Sequence[np.ndarray], expected: Sequence[np.ndarray], tol: float) -> bool:
    """Whether each point is within ``tol`` of a distinct expected point (same number of each)."""
    left = [np.asarray(q, float)[:2] for q in expected]
    if len(left) != len(points):
        return False
    for p in points:
        gaps = [float(np.linalg.norm(np.asarray(p, float)[:2] - q)) for q in left]
        i = int(np.argmin(gaps))
        if gaps[i] > tol:
            return False
        left.pop(i)
    return True


def _circle(edges: Sequence[LocalEdge], tol: Tolerance) -> SketchObject | None:
    if len(edges) != 1 or edges[0].kind != "circle":
        return None
    centre = edges[0].points[0]
    return SketchObject(
        f"Circle({written(edges[0].radius)})", (_short(centre[0], tol), _short(centre[1], tol))
    )


def _rectangle(edges: Sequence[LocalEdge], tol: Tolerance) -> SketchObject | None:
    """Four lines along the sketch axes."""
    if len(edges) != 4 or any(e.kind != "line" for e in edges):
        return None
    corners = [e.points[0] for e in edges]
    lo, hi = np.min(corners, axis=0), np.max(corners, axis=0)
    w, h = _short(hi[0] - lo[0], tol), _short(hi[1] - lo[1], tol)
    if min(w, h) <= tol.match:
        return None
    cx, cy = _short((lo[0] + hi[0]) / 2, tol), _short((lo[1] + hi[1]) / 2, tol)
    expected = [np.array((cx + sx * w / 2, cy + sy * h / 2)) for sx in (-1, 1) for sy in (-1, 1)]
    if not _match(corners, expected, tol.match):
        return None
    return SketchObject(f"Rectangle({written(w)}, {written(h)})", (cx, cy))


def _degrees(angle: float, length: float, tol: float) -> float:
    """An angle in degrees with the fewest decimals that turn a ``length`` by no more than ``tol``."""
    return simplest(math.degrees(angle), math.degrees(tol / length) if length > 0 else 0.0)


def _slot(edges: Sequence[LocalEdge], tol: Tolerance) -> SketchObject | None:
    """Line, half circle, line, half circle: two equal half circles joined by their tangents."""
    kinds = [e.kind for e in edges]
    if len(edges) != 4 or sorted(kinds) != ["arc", "arc", "line", "line"] or kinds[0] == kinds[1]:
        return None
    arcs = [e for e in edges if e.kind == "arc"]
    centres = [np.asarray(e.curve.center, float)[:2] for e in arcs]  # type: ignore[union-attr]
    axis = centres[1] - centres[0]
    separation = float(np.linalg.norm(axis))
    if separation <= tol.match:
        return None
    height = _short(arcs[0].radius + arcs[1].radius, tol)
    rotation = _degrees(math.atan2(axis[1], axis[0]) % math.pi, separation, tol.snap)
    turn = math.radians(rotation)
    u = np.array((math.cos(turn), math.sin(turn)))
    n = np.array((-u[1], u[0]))
    sep = _short(separation, tol)
    mid = np.array(
        (_short((centres[0][0] + centres[1][0]) / 2, tol), _short((centres[0][1] + centres[1][1]) / 2, tol))
    )
    ends = [mid + s * sep / 2 * u for s in (-1, 1)]
    expected = [end + t * height / 2 * n for end in ends for t in (-1, 1)]
    expected += [ends[0] - height / 2 * u, ends[1] + height / 2 * u]
    if not _match([q for e in arcs for q in e.points], expected, tol.match):
        return None
    return SketchObject(
        f"SlotCenterToCenter({written(sep)}, {written(height)}"
        + (f", rotation={written(rotation)})" if written(rotation) != "0" else ")"),
        (float(mid[0]), float(mid[1])),
    )


def _regular_polygon(edges: Sequence[LocalEdge], tol: Tolerance) -> SketchObject | None:
    """Three or more equal lines whose corners lie evenly on one circle."""
    n = len(edges)
    if not 3 <= n <= MAX_POLYGON_SIDES or any(e.kind != "line" for e in edges):
        return None
    corners = np.array([e.points[0][:2] for e in edges])
    centre = np.array([_short(c, tol) for c in corners.mean(axis=0)])
    radius = _short(float(np.mean(np.linalg.norm(corners - centre, axis=1))), tol)
    if radius <= tol.match:
        return None
    first = corners[0] - centre
    rotation = _degrees(math.atan2(first[1], first[0]) % (2 * math.pi / n), radius, tol.snap)
    turn = math.radians(rotation)
    expected = [
        centre
        + radius * np.array((math.cos(turn + 2 * math.pi * i / n), math.sin(turn + 2 * math.pi * i / n)))
        for i in range(n)
    ]
    if not _match(list(corners), expected, tol.match):
        return None
    args = [written(radius), str(n)]
    if written(rotation) != "0":
        args.append(f"rotation={written(rotation)}")
    if n % 2:  # build123d centres a polygon on its bounding box; an odd one's is off its centre
        args.append("align=None")
    return SketchObject(f"RegularPolygon({', '.join(args)})", (float(centre[0]), float(centre[1])))


RECOGNISERS: tuple[Callable[[Sequence[LocalEdge], Tolerance], SketchObject | None], ...] = (
    _circle,
    _rectangle,
    _slot,
    _regular_polygon,
)


def _merged(edges: Sequence[LocalEdge], tol: float) -> list[LocalEdge]:
    """The loop with each run of collinear lines as one line (a side split at a point, as
    build123d's own slot is), corners within ``tol`` of the merged line."""
    out = list(edges)
    i = 0
    while len(out) > 3 and i < len(out):
        a, b = out[i], out[(i + 1) % len(out)]
        if a.kind == b.kind == "line" and _on_segment(a.points[1], a.points[0], b.points[1], tol):
            out[i] = replace(a, points=np.array([a.points[0], b.points[1]]))
            out.pop((i + 1) % len(out))
            i = 0
            continue
        i += 1
    return out


def _on_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Whether ``p`` lies within ``tol`` of the segment from ``a`` to ``b``, strictly between them."""
    ab, ap = (b - a)[:2], (p - a)[:2]
    length = float(np.linalg.norm(ab))
    if length <= tol:
        return False
    t = float(ap @ ab) / length**2
    return 0 < t < 1 and abs(float(ab[0] * ap[1] - ab[1] * ap[0])) / length <= tol


def sketch_object(edges: Sequence[LocalEdge], tol: float) -> SketchObject | None:
    """The build123d object a loop is (its corners within ``tol`` of the object's), or None."""
    size = max((float(np.abs(e.points[:, :2]).max()) for e in edges), default=0.0)
    tolerance = Tolerance(tol, max(3 * tol, MIN_TOL * max(size, 1.0)))
    edges = _merged(edges, tolerance.match)
    for recognise in RECOGNISERS:
        found = recognise(edges, tolerance)
        if found is not None:
            return found
    return None

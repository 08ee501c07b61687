"""Typed model of a Fusion 360 Gallery reconstruction design, read from and written to its JSON.

The model keeps exactly what an exact replay needs (sketch frames, trimmed profile loops, extrude
extents and operations) plus the published labels used for validation (final ``properties`` and
per-extrude body/face counts). Everything else in the file (constraints, dimensions, the
``sequence`` block) is ignored on read and left out on write.

Units are the file's: centimetres and radians. Points and vectors are plain ``(x, y, z)`` tuples in
the sketch's local frame; `Frame` maps them to world coordinates.
"""

from __future__ import annotations

import enum
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from zonegraph.errors import DesignError, InputError, require_file
from zonegraph.geometry.vec import Vec3


class Operation(str, enum.Enum):
    NEW_BODY = "NewBodyFeatureOperation"
    JOIN = "JoinFeatureOperation"
    CUT = "CutFeatureOperation"
    INTERSECT = "IntersectFeatureOperation"


class ExtentType(str, enum.Enum):
    ONE_SIDE = "OneSideFeatureExtentType"
    TWO_SIDES = "TwoSidesFeatureExtentType"
    SYMMETRIC = "SymmetricFeatureExtentType"


# --------------------------------------------------------------------------- geometry primitives


@dataclass(frozen=True)
class Frame:
    """A sketch's placement: world = origin + x * x_axis + y * y_axis + z * z_axis.

    The axes come from the file's ``transform`` and are used as given: Fusion frames are not
    always right-handed with respect to the named construction planes, so nothing is derived.
    """

    origin: Vec3
    x_axis: Vec3
    y_axis: Vec3
    z_axis: Vec3

    @property
    def matrix(self) -> np.ndarray:
        """3x3 matrix whose columns are the axes (local vector -> world vector)."""
        return np.column_stack([self.x_axis, self.y_axis, self.z_axis]).astype(float)

    def point(self, p: Vec3 | np.ndarray) -> np.ndarray:
        return np.asarray(self.origin, float) + self.matrix @ np.asarray(p, float)

    def vector(self, v: Vec3 | np.ndarray) -> np.ndarray:
        return self.matrix @ np.asarray(v, float)


# ------------------------------------------------------------------------------ profile curves


@dataclass(frozen=True)
class Line:
    start: Vec3
    end: Vec3


@dataclass(frozen=True)
class Arc:
    """Circular arc running counter-clockwise about ``normal`` from reference rotated by start."""

    start: Vec3
    end: Vec3
    center: Vec3
    radius: float
    normal: Vec3
    start_angle: float
    end_angle: float
    reference_vector: Vec3

    def midpoint(self) -> np.ndarray:
        """The point half-way along the arc: fixes which of the two arcs is meant."""
        t = 0.5 * (self.start_angle + self.end_angle)
        ref = np.asarray(self.reference_vector, float)
        ref = ref / np.linalg.norm(ref)
        perp = np.cross(np.asarray(self.normal, float), ref)
        return np.asarray(self.center, float) + self.radius * (math.cos(t) * ref + math.sin(t) * perp)


@dataclass(frozen=True)
class Circle:
    center: Vec3
    radius: float
    normal: Vec3


@dataclass(frozen=True)
class Ellipse:
    center: Vec3
    major_axis: Vec3
    major_radius: float
    minor_radius: float
    normal: Vec3


@dataclass(frozen=True)
class EllipticalArc:
    """Part of an ellipse between two parameters, counter-clockwise about ``normal``."""

    center: Vec3
    major_axis: Vec3
    major_radius: float
    minor_radius: float
    normal: Vec3
    start_angle: float
    end_angle: float

    def point_at(self, t: float) -> np.ndarray:
        u = np.asarray(self.major_axis, float)
        u = u / np.linalg.norm(u)
        v = np.cross(np.asarray(self.normal, float), u)
        return (
            np.asarray(self.center, float)
            + self.major_radius * math.cos(t) * u
            + self.minor_radius * math.sin(t) * v
        )


@dataclass(frozen=True)
class Nurbs:
    """A B-spline with Fusion's flat knot vector (length = poles + degree + 1)."""

    degree: int
    knots: tuple[float, ...]
    control_points: tuple[Vec3, ...]
    weights: tuple[float, ...] | None = None
    periodic: bool = False

    @property
    def rational(self) -> bool:
        return self.weights is not None


Curve = Line | Arc | Circle | Ellipse | EllipticalArc | Nurbs


@dataclass(frozen=True)
class Loop:
    is_outer: bool
    curves: tuple[Curve, ...]


@dataclass(frozen=True)
class Profile:
    id: str
    loops: tuple[Loop, ...]
    area: float | None = None  # Fusion's own measure, for validating the built face


@dataclass(frozen=True)
class Sketch:
    id: str
    name: str
    frame: Frame
    profiles: dict[str, Profile]


# ------------------------------------------------------------------------------------ extrudes


@dataclass(frozen=True)
class Extent:
    distance: float  # signed, along the sketch normal
    taper: float = 0.0  # radians; Fusion's positive angle tapers outward


@dataclass(frozen=True)
class ProfileRef:
    sketch: str
    profile: str


@dataclass(frozen=True)
class StepLabels:
    """Published per-step counts: all bodies and faces after this extrude."""

    body_count: int
    face_count: int


@dataclass(frozen=True)
class Extrude:
    id: str
    name: str
    profiles: tuple[ProfileRef, ...]
    operation: Operation
    extent_type: ExtentType
    extent_one: Extent
    extent_two: Extent | None = None
    start_offset: float = 0.0
    symmetric_full_length: bool = False
    labels: StepLabels | None = None

    def interval(self) -> tuple[float, float]:
        """The extrusion's span [a, b] along the sketch normal (start offset included)."""
        s, d1 = self.start_offset, self.extent_one.distance
        if self.extent_type is ExtentType.ONE_SIDE:
            a, b = s, s + d1
        elif self.extent_type is ExtentType.SYMMETRIC:
            h = d1 / 2 if self.symmetric_full_length else d1
            a, b = s - abs(h), s + abs(h)
        else:
            assert self.extent_two is not None
            a, b = s - self.extent_two.distance, s + d1
        return (min(a, b), max(a, b))


@dataclass(frozen=True)
class DesignProperties:
    """The subset of Fusion's final ``properties`` block used to validate a replay."""

    volume: float
    area: float
    body_count: int
    face_count: int
    bbox_min: Vec3 | None = None
    bbox_max: Vec3 | None = None


Entity = Sketch | Extrude


@dataclass(frozen=True)
class Design:
    """A Fusion 360 Gallery design: its timeline of sketches and extrudes, in centimetres."""

    id: str
    timeline: tuple[Entity, ...]
    properties: DesignProperties | None = None
    source: str = ""

    @property
    def sketches(self) -> dict[str, Sketch]:
        return {e.id: e for e in self.timeline if isinstance(e, Sketch)}

    @property
    def extrudes(self) -> list[Extrude]:
        return [e for e in self.timeline if isinstance(e, Extrude)]


# --------------------------------------------------------------------------------------- reading


def load_design(path: str | Path) -> Design:
    """Read a design file; raises `InputError` or `DesignError` with the reason."""
    path = Path(path)
    require_file(path)
    try:
        data = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(str(path), f"invalid JSON ({exc})") from None
    return parse_design(data, design_id=path.stem, source=str(path))


def parse_design(data: Any, design_id: str, source: str = "") -> Design:
    """A design from parsed JSON; the schema (`zonegraph.data.schema`) and every reference
    are checked before any geometry is built.

    Raises:
        InputError: not a design at all; DesignError or UnsupportedFeatureError: naming the entity.
    """
    from zonegraph.data.schema import validate_design  # here: the schema builds this module's classes

    name = source or design_id
    if not isinstance(data, dict) or "timeline" not in data or "entities" not in data:
        raise InputError(name, "not a Fusion 360 Gallery design (no timeline/entities)")
    design = validate_design(data, name).to_domain(design_id, source)
    _check_references(design, name)
    return design


def _check_references(design: Design, name: str) -> None:
    """Every extrude must name profiles of sketches that come before it in the timeline."""
    seen: dict[str, Sketch] = {}
    for entity in design.timeline:
        if isinstance(entity, Sketch):
            seen[entity.id] = entity
            continue
        if not entity.profiles:
            raise DesignError(name, entity.id, "extrude has no profiles")
        for ref in entity.profiles:
            sketch = seen.get(ref.sketch)
            if sketch is None:
                raise DesignError(name, entity.id, f"references missing sketch {ref.sketch}")
            if ref.profile not in sketch.profiles:
                raise DesignError(name, entity.id, f"references missing profile {ref.profile}")


# --------------------------------------------------------------------------------------- writing


def _pt(p: Vec3 | np.ndarray) -> dict:
    return {"type": "Point3D", "x": float(p[0]), "y": float(p[1]), "z": float(p[2])}


def _vc(v: Vec3 | np.ndarray) -> dict:
    return {
        "type": "Vector3D",
        "x": float(v[0]),
        "y": float(v[1]),
        "z": float(v[2]),
        "length": float(np.linalg.norm(v)),
    }


def curve_to_json(c: Curve) -> dict:
    if isinstance(c, Line):
        return {"type": "Line3D", "start_point": _pt(c.start), "end_point": _pt(c.end)}
    if isinstance(c, Arc):
        return {
            "type": "Arc3D",
            "start_point": _pt(c.start),
            "end_point": _pt(c.end),
            "center_point": _pt(c.center),
            "radius": c.radius,
            "normal": _vc(c.normal),
            "start_angle": c.start_angle,
            "end_angle": c.end_angle,
            "reference_vector": _vc(c.reference_vector),
        }
    if isinstance(c, Circle):
        return {
            "type": "Circle3D",
            "center_point": _pt(c.center),
            "radius": c.radius,
            "normal": _vc(c.normal),
        }
    if isinstance(c, (Ellipse, EllipticalArc)):
        out = {
            "type": "Ellipse3D",
            "center_point": _pt(c.center),
            "major_axis": _vc(c.major_axis),
            "major_axis_radius": c.major_radius,
            "minor_axis_radius": c.minor_radius,
            "normal": _vc(c.normal),
        }
        if isinstance(c, EllipticalArc):
            out.update(type="EllipticalArc3D", start_angle=c.start_angle, end_angle=c.end_angle)
        return out
    if isinstance(c, Nurbs):
        return {
            "type": "NurbsCurve3D",
            "degree": c.degree,
            "knots": list(c.knots),
            "rational": c.rational,
            "control_points": [_pt(p) for p in c.control_points],
            "weights": list(c.weights) if c.weights else [],
            "periodic": c.periodic,
        }
    raise TypeError(f"not a curve: {c!r}")


def _extent_json(x: Extent, is_full_length: bool | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {
        "type": "DistanceExtentDefinition",
        "distance": {"type": "ModelParameter", "value": x.distance, "role": "AlongDistance"},
        "taper_angle": {"type": "ModelParameter", "value": x.taper, "role": "TaperAngle"},
    }
    if is_full_length is not None:
        out["is_full_length"] = is_full_length
    return out


def sketch_to_json(s: Sketch) -> dict:
    f = s.frame
    return {
        "name": s.name,
        "type": "Sketch",
        "transform": {
            "origin": _pt(f.origin),
            "x_axis": _vc(f.x_axis),
            "y_axis": _vc(f.y_axis),
            "z_axis": _vc(f.z_axis),
        },
        "profiles": {
            p.id: {
                "loops": [
                    {"is_outer": lp.is_outer, "profile_curves": [curve_to_json(c) for c in lp.curves]}
                    for lp in p.loops
                ],
                **({"properties": {"area": p.area}} if p.area is not None else {}),
            }
            for p in s.profiles.values()
        },
    }


def extrude_to_json(x: Extrude) -> dict:
    out: dict[str, Any] = {
        "name": x.name,
        "type": "ExtrudeFeature",
        "profiles": [{"profile": r.profile, "sketch": r.sketch} for r in x.profiles],
        "operation": x.operation.value,
        "start_extent": (
            {"type": "ProfilePlaneStartDefinition"}
            if x.start_offset == 0
            else {
                "type": "OffsetStartDefinition",
                "offset": {"type": "ModelParameter", "value": x.start_offset},
            }
        ),
        "extent_type": x.extent_type.value,
        "extent_one": _extent_json(
            x.extent_one, x.symmetric_full_length if x.extent_type is ExtentType.SYMMETRIC else None
        ),
    }
    if x.extent_two is not None:
        out["extent_two"] = _extent_json(x.extent_two)
    return out


def design_to_json(
    design: Design,
    extra: dict[str, dict] | None = None,
    properties: dict | None = None,
    metadata: dict | None = None,
) -> dict:
    """Fusion-format JSON; ``extra`` adds per-entity fields (labels such as bodies/faces)."""
    entities: dict[str, dict] = {}
    for e in design.timeline:
        entities[e.id] = sketch_to_json(e) if isinstance(e, Sketch) else extrude_to_json(e)
        entities[e.id].update((extra or {}).get(e.id, {}))
    out: dict[str, Any] = {
        "metadata": metadata or {"parent_project": design.id},
        "timeline": [{"index": i, "entity": e.id} for i, e in enumerate(design.timeline)],
        "entities": entities,
    }
    if properties is not None:
        out["properties"] = properties
    return out


__all__ = [
    "Arc",
    "Circle",
    "Curve",
    "Design",
    "DesignProperties",
    "Ellipse",
    "EllipticalArc",
    "Entity",
    "Extent",
    "ExtentType",
    "Extrude",
    "Frame",
    "Line",
    "Loop",
    "Nurbs",
    "Operation",
    "Profile",
    "ProfileRef",
    "Sketch",
    "StepLabels",
    "design_to_json",
    "load_design",
    "parse_design",
]

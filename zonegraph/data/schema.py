"""The schema of a Fusion 360 Gallery design JSON, checked with pydantic before any geometry.

Only the fields that replay reads are described; everything else in a file (constraints,
dimensions, ``sequence``, per-step face lists) passes through unchecked. A value that is present
must have the right type (strict: ``"5"`` is not a number, ``true`` is not a length) and every
number must be finite and of a sane magnitude. Without this, a NaN sketch origin surfaced as "a
profile loop of 4 curves does not close", a NaN distance as "extrude has zero length", an
``Infinity`` distance spun for over ten minutes in OpenCASCADE, and ``{"timeline": 5}`` was a
``TypeError`` traceback.

Types the replay does not support (an entity or curve ``type`` it does not know, a non-distance
extent) are let through here, so that the parser can name them as unsupported features rather than
as malformed input.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError, model_validator

from zonegraph.errors import DesignError

# Centimetres. 10 km: a thousand times the largest Fusion 360 Gallery part, yet far from the
# magnitudes (1e12) at which OpenCASCADE's Booleans fail with an empty Standard_DomainError.
MAX_LENGTH = 1e6
MAX_ANGLE = 100.0  # radians; Fusion's arc and ellipse parameters lie within a few turns
MAX_DEGREE = 25  # OpenCASCADE's Geom_BSplineCurve limit

Length = Annotated[float, Field(allow_inf_nan=False, ge=-MAX_LENGTH, le=MAX_LENGTH)]
PositiveLength = Annotated[float, Field(allow_inf_nan=False, gt=0, le=MAX_LENGTH)]
Angle = Annotated[float, Field(allow_inf_nan=False, ge=-MAX_ANGLE, le=MAX_ANGLE)]
Measure = Annotated[float, Field(allow_inf_nan=False, ge=0)]
Count = Annotated[int, Field(ge=0)]


class Node(BaseModel):
    """Strict types; unknown fields kept (the format carries much that replay never reads)."""

    model_config = ConfigDict(strict=True, extra="allow", frozen=True)


class Point3D(Node):
    x: Length
    y: Length
    z: Length


class Vector3D(Point3D):
    """A direction: any finite vector but the zero vector, which orients nothing."""

    @model_validator(mode="after")
    def _nonzero(self) -> Vector3D:
        if math.hypot(self.x, self.y, self.z) == 0:
            raise ValueError("a direction cannot be the zero vector")
        return self


class Line3D(Node):
    start_point: Point3D
    end_point: Point3D


class Circle3D(Node):
    center_point: Point3D
    radius: PositiveLength
    normal: Vector3D


class Arc3D(Circle3D):
    start_point: Point3D
    end_point: Point3D
    start_angle: Angle
    end_angle: Angle
    reference_vector: Vector3D


class Ellipse3D(Node):
    center_point: Point3D
    major_axis: Vector3D
    major_axis_radius: PositiveLength
    minor_axis_radius: PositiveLength
    normal: Vector3D


class EllipticalArc3D(Ellipse3D):
    start_angle: Angle
    end_angle: Angle


class NurbsCurve3D(Node):
    degree: Annotated[int, Field(ge=1, le=MAX_DEGREE)]
    knots: list[Length]
    control_points: Annotated[list[Point3D], Field(min_length=2)]
    rational: bool = False
    weights: list[Annotated[float, Field(allow_inf_nan=False, gt=0, le=MAX_LENGTH)]] = []
    periodic: bool = False

    @model_validator(mode="after")
    def _consistent(self) -> NurbsCurve3D:
        if any(b < a for a, b in zip(self.knots, self.knots[1:], strict=False)):
            raise ValueError("knots must not decrease")
        if not self.periodic and len(self.knots) != len(self.control_points) + self.degree + 1:
            raise ValueError(
                f"{len(self.knots)} knots for {len(self.control_points)} poles of degree {self.degree} "
                f"(a clamped spline has poles + degree + 1)"
            )
        if self.rational and len(self.weights) != len(self.control_points):
            raise ValueError(f"{len(self.weights)} weights for {len(self.control_points)} poles")
        return self


class OtherKind(Node):
    """A type the replay does not know: the parser reports it as an unsupported feature."""

    type: str


CURVES: dict[str, type[Node]] = {
    c.__name__: c for c in (Line3D, Arc3D, Circle3D, Ellipse3D, EllipticalArc3D, NurbsCurve3D)
}


def _tag(known: dict[str, type[Node]]) -> Any:
    """A discriminator on the ``type`` field: a known type's model, "other" for the rest, None (an
    error) for a value that is not an object with a string ``type``."""

    def tag(value: Any) -> str | None:
        kind = value.get("type") if isinstance(value, dict) else getattr(value, "type", None)
        if not isinstance(kind, str):
            return None
        return kind if kind in known else "other"

    return Discriminator(
        tag, custom_error_type="not_typed", custom_error_message="must be an object with a string 'type'"
    )


Curve = Annotated[
    Annotated[Line3D, Tag("Line3D")]
    | Annotated[Arc3D, Tag("Arc3D")]
    | Annotated[Circle3D, Tag("Circle3D")]
    | Annotated[Ellipse3D, Tag("Ellipse3D")]
    | Annotated[EllipticalArc3D, Tag("EllipticalArc3D")]
    | Annotated[NurbsCurve3D, Tag("NurbsCurve3D")]
    | Annotated[OtherKind, Tag("other")],
    _tag(CURVES),
]


class Loop(Node):
    is_outer: bool
    profile_curves: Annotated[list[Curve], Field(min_length=1)]


class ProfileProperties(Node):
    area: Measure | None = None


class Profile(Node):
    loops: Annotated[list[Loop], Field(min_length=1)]
    properties: ProfileProperties | None = None


class Transform(Node):
    origin: Point3D
    x_axis: Vector3D
    y_axis: Vector3D
    z_axis: Vector3D


class Sketch(Node):
    type: str
    transform: Transform
    profiles: dict[str, Profile] = {}


class Parameter(Node):
    value: Length


class AngleParameter(Node):
    value: Annotated[float, Field(allow_inf_nan=False, gt=-math.pi / 2, lt=math.pi / 2)]


class Extent(Node):
    """A distance extent; other kinds (to an object, through all) keep only their ``type``."""

    type: str = "DistanceExtentDefinition"
    distance: Parameter | None = None
    taper_angle: AngleParameter | None = None
    is_full_length: bool = False

    @model_validator(mode="after")
    def _distance(self) -> Extent:
        if self.type == "DistanceExtentDefinition" and self.distance is None:
            raise ValueError("a distance extent needs 'distance'")
        return self


class StartExtent(Node):
    type: str
    offset: Parameter | None = None

    @model_validator(mode="after")
    def _offset(self) -> StartExtent:
        if self.type == "OffsetStartDefinition" and self.offset is None:
            raise ValueError("an offset start needs 'offset'")
        return self


class ProfileRef(Node):
    profile: str
    sketch: str


class ExtrudeFeature(Node):
    type: str
    profiles: list[ProfileRef]
    operation: str
    extent_type: str
    extent_one: Extent
    extent_two: Extent | None = None
    start_extent: StartExtent | None = None
    bodies: dict[str, Any] | list[Any] | None = None  # per-step labels: only their count is read
    faces: dict[str, Any] | list[Any] | None = None

    @model_validator(mode="after")
    def _two_sides(self) -> ExtrudeFeature:
        if self.extent_type == "TwoSidesFeatureExtentType" and self.extent_two is None:
            raise ValueError("a two-sided extrude needs 'extent_two'")
        return self


ENTITIES: dict[str, type[Node]] = {"Sketch": Sketch, "ExtrudeFeature": ExtrudeFeature}

Entity = Annotated[
    Annotated[Sketch, Tag("Sketch")]
    | Annotated[ExtrudeFeature, Tag("ExtrudeFeature")]
    | Annotated[OtherKind, Tag("other")],
    _tag(ENTITIES),
]


TAGS = {*CURVES, *ENTITIES, "other"}  # discriminator tags pydantic puts in an error's path


class TimelineItem(Node):
    entity: str


class BoundingBox(Node):
    min_point: Point3D
    max_point: Point3D


class Properties(Node):
    volume: Measure | None = None
    area: Measure | None = None
    body_count: Count = 1
    face_count: Count = 0
    bounding_box: BoundingBox | None = None

    @model_validator(mode="after")
    def _area_with_volume(self) -> Properties:
        if self.volume is not None and self.area is None:
            raise ValueError("'volume' without 'area'")
        return self


class DesignFile(Node):
    timeline: list[TimelineItem]
    entities: dict[str, Entity]
    properties: Properties | None = None


def validate_design(data: Any, name: str) -> None:
    """Check parsed design JSON against :class:`DesignFile`.

    Raises:
        DesignError: naming the first offending field by its path in the file (the entity's uuid
            in brackets), the problem and the value found, and how many other problems there are.
    """
    try:
        DesignFile.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        first = errors[0]
        loc = [str(p) for p in first["loc"] if str(p) not in TAGS]
        entity = loc[1] if len(loc) > 1 and loc[0] == "entities" else None
        field = ".".join(loc[2:] if entity else loc) or ("the entity" if entity else "the file")
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        got = _short(first.get("input"))
        raise DesignError(name, entity, f"{field}: {_message(first['msg'])}{got}{more}") from None


def _message(msg: str) -> str:
    """pydantic's message, lower-cased, without the "Value error, " of a model validator."""
    return msg.removeprefix("Value error, ").lower()


def _short(value: Any) -> str:
    """The offending value, when it is a scalar worth showing (not a whole sub-tree)."""
    if isinstance(value, (dict, list)):
        return ""
    text = repr(value)
    return f" (got {text if len(text) <= 40 else text[:37] + '...'})"

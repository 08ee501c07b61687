"""The schema of a Fusion 360 Gallery design JSON: checked with pydantic, then built into the model.

Only the fields that replay reads are described; everything else in a file (constraints,
dimensions, ``sequence``, per-step face lists) passes through unchecked. A value that is present
must have the right type (strict: ``"5"`` is not a number, ``true`` is not a length) and every
number must be finite and of a sane magnitude. Without this, a NaN sketch origin surfaced as "a
profile loop of 4 curves does not close", a NaN distance as "extrude has zero length", an
``Infinity`` distance spun for over ten minutes in OpenCASCADE, and ``{"timeline": 5}`` was a
``TypeError`` traceback.

Types the replay does not support (an entity or curve ``type`` it does not know, a non-distance
extent) are let through by validation, so that building can name them as unsupported features
rather than as malformed input.

Each model builds its `zonegraph.data.design` object (``to_domain``), so the file's layout
is described once, here: the validated tree converts itself, with no second walk over the dicts.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError, model_validator

from zonegraph.data import design as domain
from zonegraph.errors import DesignError, UnsupportedFeatureError
from zonegraph.geometry.vec import Vec3

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

    def vec(self) -> Vec3:
        return (self.x, self.y, self.z)


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

    def to_domain(self) -> domain.Curve:
        return domain.Line(self.start_point.vec(), self.end_point.vec())


class Circle3D(Node):
    center_point: Point3D
    radius: PositiveLength
    normal: Vector3D

    def to_domain(self) -> domain.Curve:
        return domain.Circle(self.center_point.vec(), self.radius, self.normal.vec())


class Arc3D(Circle3D):
    start_point: Point3D
    end_point: Point3D
    start_angle: Angle
    end_angle: Angle
    reference_vector: Vector3D

    def to_domain(self) -> domain.Curve:
        return domain.Arc(
            self.start_point.vec(),
            self.end_point.vec(),
            self.center_point.vec(),
            self.radius,
            self.normal.vec(),
            self.start_angle,
            self.end_angle,
            self.reference_vector.vec(),
        )


class Ellipse3D(Node):
    center_point: Point3D
    major_axis: Vector3D
    major_axis_radius: PositiveLength
    minor_axis_radius: PositiveLength
    normal: Vector3D

    def to_domain(self) -> domain.Curve:
        return domain.Ellipse(
            self.center_point.vec(),
            self.major_axis.vec(),
            self.major_axis_radius,
            self.minor_axis_radius,
            self.normal.vec(),
        )


class EllipticalArc3D(Ellipse3D):
    start_angle: Angle
    end_angle: Angle

    def to_domain(self) -> domain.Curve:
        return domain.EllipticalArc(
            self.center_point.vec(),
            self.major_axis.vec(),
            self.major_axis_radius,
            self.minor_axis_radius,
            self.normal.vec(),
            self.start_angle,
            self.end_angle,
        )


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

    def to_domain(self) -> domain.Curve:
        return domain.Nurbs(
            self.degree,
            tuple(self.knots),
            tuple(p.vec() for p in self.control_points),
            tuple(self.weights) if self.rational else None,
            self.periodic,
        )


class OtherKind(Node):
    """A type the replay does not know: building reports it as an unsupported feature."""

    type: str

    def unsupported(self, what: str, design: str, where: str) -> UnsupportedFeatureError:
        return UnsupportedFeatureError(design, where, f"unsupported {what} {self.type!r}")


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

    def to_domain(self, profile: str, design: str) -> domain.Loop:
        """Raises UnsupportedFeatureError (naming the profile) for a curve type we do not know."""
        curves = []
        for c in self.profile_curves:
            if isinstance(c, OtherKind):
                raise c.unsupported("curve type", design, profile)
            curves.append(c.to_domain())
        return domain.Loop(self.is_outer, tuple(curves))


class ProfileProperties(Node):
    area: Measure | None = None


class Profile(Node):
    loops: Annotated[list[Loop], Field(min_length=1)]
    properties: ProfileProperties | None = None

    def to_domain(self, pid: str, design: str) -> domain.Profile:
        area = None if self.properties is None else self.properties.area
        return domain.Profile(pid, tuple(lp.to_domain(pid, design) for lp in self.loops), area)


class Transform(Node):
    origin: Point3D
    x_axis: Vector3D
    y_axis: Vector3D
    z_axis: Vector3D

    def to_domain(self) -> domain.Frame:
        return domain.Frame(self.origin.vec(), self.x_axis.vec(), self.y_axis.vec(), self.z_axis.vec())


class Sketch(Node):
    type: str
    name: Any = ""  # a label replay never reads: kept as found, unchecked
    transform: Transform
    profiles: dict[str, Profile] = {}

    def to_domain(self, uuid: str, design: str) -> domain.Sketch:
        profiles = {pid: p.to_domain(pid, design) for pid, p in self.profiles.items()}
        return domain.Sketch(uuid, self.name, self.transform.to_domain(), profiles)


DISTANCE = "DistanceExtentDefinition"  # the only extent kind replay builds


class Parameter(Node):
    value: Length


class AngleParameter(Node):
    value: Annotated[float, Field(allow_inf_nan=False, gt=-math.pi / 2, lt=math.pi / 2)]


class Extent(Node):
    """A distance extent; other kinds (to an object, through all) keep only their ``type``."""

    type: str = DISTANCE
    distance: Parameter | None = None
    taper_angle: AngleParameter | None = None
    is_full_length: bool = False

    @model_validator(mode="after")
    def _distance(self) -> Extent:
        if self.type == DISTANCE and self.distance is None:
            raise ValueError("a distance extent needs 'distance'")
        return self

    def to_domain(self) -> domain.Extent:
        """Only for a distance extent (the extrude refuses other kinds first)."""
        assert self.distance is not None  # _distance requires it of a distance extent
        return domain.Extent(self.distance.value, 0.0 if self.taper_angle is None else self.taper_angle.value)


class StartExtent(Node):
    type: str
    offset: Parameter | None = None

    @model_validator(mode="after")
    def _offset(self) -> StartExtent:
        if self.type == "OffsetStartDefinition" and self.offset is None:
            raise ValueError("an offset start needs 'offset'")
        return self

    def to_offset(self, design: str, uuid: str) -> float:
        """The start plane's offset along the normal; UnsupportedFeatureError for other starts."""
        if self.type == "OffsetStartDefinition":
            assert self.offset is not None  # _offset requires it
            return self.offset.value
        if self.type == "ProfilePlaneStartDefinition":
            return 0.0
        raise UnsupportedFeatureError(design, uuid, f"unsupported start extent {self.type!r}")


class ProfileRef(Node):
    profile: str
    sketch: str


class ExtrudeFeature(Node):
    type: str
    name: Any = ""  # a label replay never reads: kept as found, unchecked
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

    def to_domain(self, uuid: str, design: str) -> domain.Extrude:
        """Raises UnsupportedFeatureError for an operation, extent or start replay cannot build."""
        op, extent_type = self._kinds(uuid, design)
        offset = 0.0 if self.start_extent is None else self.start_extent.to_offset(design, uuid)
        two = None
        if extent_type is domain.ExtentType.TWO_SIDES:
            assert self.extent_two is not None  # _two_sides requires it
            two = self.extent_two.to_domain()
        labels = None
        if self.bodies is not None and self.faces is not None:
            labels = domain.StepLabels(len(self.bodies), len(self.faces))
        return domain.Extrude(
            id=uuid,
            name=self.name,
            profiles=tuple(domain.ProfileRef(p.sketch, p.profile) for p in self.profiles),
            operation=op,
            extent_type=extent_type,
            extent_one=self.extent_one.to_domain(),
            extent_two=two,
            start_offset=offset,
            symmetric_full_length=self.extent_one.is_full_length,
            labels=labels,
        )

    def _kinds(self, uuid: str, design: str) -> tuple[domain.Operation, domain.ExtentType]:
        """The operation and extent type, once both (and both extents) are kinds replay builds."""
        try:
            op = domain.Operation(self.operation)
        except ValueError:
            raise UnsupportedFeatureError(design, uuid, f"unsupported operation {self.operation!r}") from None
        try:
            extent_type = domain.ExtentType(self.extent_type)
        except ValueError:
            why = f"unsupported extent type {self.extent_type!r}"
            raise UnsupportedFeatureError(design, uuid, why) from None
        for key, extent in (("extent_one", self.extent_one), ("extent_two", self.extent_two)):
            if extent is not None and extent.type != DISTANCE:
                why = f"unsupported {key} {extent.type!r} (only distances)"
                raise UnsupportedFeatureError(design, uuid, why)
        return op, extent_type


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

    def to_domain(self) -> domain.DesignProperties | None:
        """None without a volume: nothing to validate a replay against."""
        if self.volume is None:
            return None
        assert self.area is not None  # _area_with_volume requires it
        box = self.bounding_box
        return domain.DesignProperties(
            self.volume,
            self.area,
            self.body_count,
            self.face_count,
            box.min_point.vec() if box else None,
            box.max_point.vec() if box else None,
        )


class DesignFile(Node):
    timeline: list[TimelineItem]
    entities: dict[str, Entity]
    properties: Properties | None = None

    def to_domain(self, design_id: str, source: str) -> domain.Design:
        """The timeline's entities in order (entities it does not name are not built).

        Raises:
            DesignError: the timeline names an entity that does not exist;
            UnsupportedFeatureError: an entity replay cannot build, named by its uuid.
        """
        name = source or design_id
        timeline: list[domain.Entity] = []
        for item in self.timeline:
            entity = self.entities.get(item.entity)
            if entity is None:
                raise DesignError(name, item.entity, "timeline names an entity that does not exist")
            if isinstance(entity, OtherKind):
                raise entity.unsupported("entity type", name, item.entity)
            timeline.append(entity.to_domain(item.entity, name))
        properties = None if self.properties is None else self.properties.to_domain()
        return domain.Design(design_id, tuple(timeline), properties, source)


def validate_design(data: Any, name: str) -> DesignFile:
    """Parsed design JSON checked against `DesignFile`.

    Raises:
        DesignError: naming the first offending field by its path in the file (the entity's uuid
            in brackets), the problem and the value found, and how many other problems there are.
    """
    try:
        return DesignFile.model_validate(data)
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

"""Hand-written Fusion-format JSON fixtures, independent of zonegraph's own serializer.

The replay and error tests build their designs from these, so a bug in zonegraph's Fusion JSON
writer cannot hide the same bug in its reader."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

Json = dict[str, Any]
XYZ = Sequence[float]

Frame = dict[str, tuple[float, float, float]]

XY: Frame = {"origin": (0, 0, 0), "x_axis": (1, 0, 0), "y_axis": (0, 1, 0), "z_axis": (0, 0, 1)}


def pt(x: float, y: float, z: float = 0.0) -> Json:
    return {"type": "Point3D", "x": x, "y": y, "z": z}


def vec(x: float, y: float, z: float) -> Json:
    return {"type": "Vector3D", "x": x, "y": y, "z": z, "length": math.sqrt(x * x + y * y + z * z)}


def line(a: XYZ, b: XYZ) -> Json:
    return {"type": "Line3D", "start_point": pt(*a), "end_point": pt(*b)}


def arc(c: XYZ, r: float, a0: float, a1: float) -> Json:
    """Counter-clockwise arc about +z from angle a0 to a1 (reference vector +x)."""

    def p(t: float) -> tuple[float, float]:
        return c[0] + r * math.cos(t), c[1] + r * math.sin(t)

    return {
        "type": "Arc3D",
        "start_point": pt(*p(a0)),
        "end_point": pt(*p(a1)),
        "center_point": pt(*c),
        "radius": r,
        "normal": vec(0, 0, 1),
        "start_angle": a0,
        "end_angle": a1,
        "reference_vector": vec(1, 0, 0),
    }


def circle(c: XYZ, r: float) -> Json:
    return {"type": "Circle3D", "center_point": pt(*c), "radius": r, "normal": vec(0, 0, 1)}


def ellipse(c: XYZ, a: float, b: float) -> Json:
    return {
        "type": "Ellipse3D",
        "center_point": pt(*c),
        "major_axis": vec(1, 0, 0),
        "major_axis_radius": a,
        "minor_axis_radius": b,
        "normal": vec(0, 0, 1),
    }


def nurbs(points: Sequence[XYZ], degree: int, knots: Sequence[float]) -> Json:
    return {
        "type": "NurbsCurve3D",
        "degree": degree,
        "knots": knots,
        "rational": False,
        "control_points": [pt(*p) for p in points],
        "weights": [],
        "periodic": False,
    }


def rect(x0: float, y0: float, x1: float, y1: float) -> list[Json]:
    c = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return [line(c[i], c[(i + 1) % 4]) for i in range(4)]


def sketch(loops: Sequence[tuple[bool, list[Json]]], frame: Frame = XY, name: str = "Sketch1") -> Json:
    """``loops``: a list of (is_outer, curves); one profile named 'p'."""
    return {
        "type": "Sketch",
        "name": name,
        "transform": {k: (pt(*v) if k == "origin" else vec(*v)) for k, v in frame.items()},
        "profiles": {"p": {"loops": [{"is_outer": o, "profile_curves": c} for o, c in loops]}},
    }


def extent(d: float, taper: float = 0.0, full: bool | None = None) -> Json:
    out: Json = {
        "type": "DistanceExtentDefinition",
        "distance": {"value": d},
        "taper_angle": {"value": taper},
    }
    if full is not None:
        out["is_full_length"] = full
    return out


def extrude(
    sketch_id: str,
    op: str = "NewBodyFeatureOperation",
    kind: str = "OneSideFeatureExtentType",
    one: Json | None = None,
    two: Json | None = None,
    offset: float | None = None,
    profile: str = "p",
) -> Json:
    e: Json = {
        "type": "ExtrudeFeature",
        "name": "Extrude",
        "operation": op,
        "extent_type": kind,
        "profiles": [{"profile": profile, "sketch": sketch_id}],
        "extent_one": one or extent(1.0),
        "start_extent": (
            {"type": "ProfilePlaneStartDefinition"}
            if offset is None
            else {"type": "OffsetStartDefinition", "offset": {"value": offset}}
        ),
    }
    if two is not None:
        e["extent_two"] = two
    return e


def design(*entities: Json) -> Json:
    """Entities in timeline order; ids are s0/e1/... by position."""
    ents = {}
    for i, e in enumerate(entities):
        ents[f"{'s' if e['type'] == 'Sketch' else 'e'}{i}"] = e
    return {"timeline": [{"index": i, "entity": k} for i, k in enumerate(ents)], "entities": ents}


def write(tmp_path: Path, data: Json, name: str = "fixture") -> Path:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return path

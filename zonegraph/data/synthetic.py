"""Seeded synthetic designs in the Fusion 360 Gallery reconstruction JSON format.

The generator builds each design step by step with the same replay that reads real files, so every
design replays by construction; a step that fails, splits the part into several bodies or leaves
the shape unchanged is drawn again. Proportions follow the published r1.0.1 statistics
(``../shared/docs/FUSION_JSON.md``): short sequences dominate, NewBody/Join/Cut with rare Intersect,
mostly one-sided extents, profiles of lines, arcs and circles with a few splines and ellipses.
"""

from __future__ import annotations

import math
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from build123d import Face, GeomType, Shape, Solid, Vector

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.configs import Config
from zonegraph.data.design import (
    Arc,
    Circle,
    Curve,
    Design,
    Ellipse,
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
    parse_design,
)
from zonegraph.data.profiles import profile_faces
from zonegraph.data.replay import ReplayStep, as_shape, replay_extrude
from zonegraph.errors import ZoneGraphError

Vec2 = tuple[float, float]

# Fusion's construction-plane frames (x_axis, y_axis, z_axis): XY, XZ (y points down -z), YZ.
CONSTRUCTION_FRAMES = {
    "XY": ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    "XZ": ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
    "YZ": ((0, 0, -1), (0, 1, 0), (1, 0, 0)),
}

FUSION_SURFACE_TYPES = {
    GeomType.PLANE: "PlaneSurfaceType",
    GeomType.CYLINDER: "CylinderSurfaceType",
    GeomType.CONE: "ConeSurfaceType",
    GeomType.SPHERE: "SphereSurfaceType",
    GeomType.TORUS: "TorusSurfaceType",
    GeomType.EXTRUSION: "ExtrusionSurfaceType",
}


@dataclass(frozen=True)
class SyntheticConfig(Config):
    """Knobs of the design distribution; defaults mimic the published data set."""

    max_extrudes: int = 12
    p_single: float = 0.527  # share of one-extrude designs
    length_decay: float = 0.65  # geometric decay of longer sequences
    op_weights: tuple[float, float, float] = (0.48, 0.5, 0.02)  # join, cut, intersect
    p_face_sketch: float = 0.7  # later sketches on a planar face of the body (else a construction plane)
    p_symmetric: float = 0.09
    p_two_sides: float = 0.04
    p_taper: float = 0.04
    p_offset_start: float = 0.06
    p_inner_loop: float = 0.25
    p_spline: float = 0.05
    p_ellipse: float = 0.02
    max_tries: int = 25


class _Ids:
    def __init__(self, rng: np.random.Generator):
        self.rng = rng

    def __call__(self) -> str:
        return str(uuid.UUID(bytes=self.rng.bytes(16), version=4))


# ------------------------------------------------------------------------------- 2D profiles


def _rot(p: Vec2, angle: float, centre: Vec2) -> tuple[float, float, float]:
    c, s = math.cos(angle), math.sin(angle)
    return (centre[0] + c * p[0] - s * p[1], centre[1] + s * p[0] + c * p[1], 0.0)


def _polyline(pts: list[Vec2], angle: float, centre: Vec2) -> list[Curve]:
    world = [_rot(p, angle, centre) for p in pts]
    return [Line(world[i], world[(i + 1) % len(world)]) for i in range(len(world))]


def _arc(centre_local: Vec2, r: float, a0: float, a1: float, angle: float, centre: Vec2) -> Arc:
    """Counter-clockwise arc from a0 to a1 (radians) in shape coordinates."""
    c = _rot(centre_local, angle, centre)
    ref = (math.cos(angle), math.sin(angle), 0.0)
    point = lambda t: (c[0] + r * math.cos(t + angle), c[1] + r * math.sin(t + angle), 0.0)  # noqa: E731
    return Arc(point(a0), point(a1), c, r, (0.0, 0.0, 1.0), a0, a1, ref)


def _rounded_rect(w: float, h: float, r: float, angle: float, c: Vec2) -> list[Curve]:
    x, y = w / 2, h / 2
    pi = math.pi
    return [
        Line(_rot((-x + r, -y), angle, c), _rot((x - r, -y), angle, c)),
        _arc((x - r, -y + r), r, -pi / 2, 0, angle, c),
        Line(_rot((x, -y + r), angle, c), _rot((x, y - r), angle, c)),
        _arc((x - r, y - r), r, 0, pi / 2, angle, c),
        Line(_rot((x - r, y), angle, c), _rot((-x + r, y), angle, c)),
        _arc((-x + r, y - r), r, pi / 2, pi, angle, c),
        Line(_rot((-x, y - r), angle, c), _rot((-x, -y + r), angle, c)),
        _arc((-x + r, -y + r), r, pi, 3 * pi / 2, angle, c),
    ]


def _slot(length: float, r: float, angle: float, c: Vec2) -> list[Curve]:
    x = length / 2
    return [
        Line(_rot((-x, -r), angle, c), _rot((x, -r), angle, c)),
        _arc((x, 0), r, -math.pi / 2, math.pi / 2, angle, c),
        Line(_rot((x, r), angle, c), _rot((-x, r), angle, c)),
        _arc((-x, 0), r, math.pi / 2, 3 * math.pi / 2, angle, c),
    ]


def _major_segment(r: float, sweep: float, angle: float, c: Vec2) -> list[Curve]:
    """A circle cut by a chord: an arc of more than 180 degrees closed by a line."""
    a0 = -sweep / 2
    arc = _arc((0, 0), r, a0, a0 + sweep, angle, c)
    return [arc, Line(arc.end, arc.start)]


def _spline_rect(w: float, h: float, bulge: float, angle: float, c: Vec2) -> list[Curve]:
    """A rectangle whose top side is a clamped cubic B-spline bump."""
    x, y = w / 2, h / 2
    ctrl = [(x, y), (x / 3, y + bulge), (-x / 3, y - bulge / 2), (-x, y)]
    knots = (0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)
    spline = Nurbs(3, knots, tuple(_rot(p, angle, c) for p in ctrl))
    return [*_polyline([(-x, y), (-x, -y), (x, -y), (x, y)], angle, c)[:3], spline]


def _outline(kind: str, s: float, rng: np.random.Generator, angle: float, c: Vec2) -> list[Curve]:
    u = lambda lo, hi: float(rng.uniform(lo, hi))  # noqa: E731
    if kind == "rect":
        w, h = s, s * u(0.4, 1.0)
        return _polyline([(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)], angle, c)
    if kind == "rounded_rect":
        w, h = s, s * u(0.5, 1.0)
        return _rounded_rect(w, h, min(w, h) * u(0.1, 0.3), angle, c)
    if kind == "circle":
        return [Circle((c[0], c[1], 0.0), s / 2, (0.0, 0.0, 1.0))]
    if kind == "slot":
        return _slot(s * u(0.4, 0.7), s * u(0.12, 0.2), angle, c)
    if kind == "segment":
        return _major_segment(s / 2, u(1.15, 1.7) * math.pi, angle, c)
    if kind == "polygon":
        n = int(rng.integers(5, 9))
        return _polyline(
            [
                (s / 2 * math.cos(2 * math.pi * k / n), s / 2 * math.sin(2 * math.pi * k / n))
                for k in range(n)
            ],
            angle,
            c,
        )
    if kind == "L":
        a, t = s / 2, s * u(0.15, 0.3)
        return _polyline([(-a, -a), (a, -a), (a, -a + t), (-a + t, -a + t), (-a + t, a), (-a, a)], angle, c)
    if kind == "T":
        a, t = s / 2, s * u(0.12, 0.2)
        return _polyline(
            [
                (-a, a),
                (a, a),
                (a, a - 2 * t),
                (t, a - 2 * t),
                (t, -a),
                (-t, -a),
                (-t, a - 2 * t),
                (-a, a - 2 * t),
            ],
            angle,
            c,
        )
    if kind == "spline":
        return _spline_rect(s, s * u(0.5, 0.9), s * u(0.1, 0.25), angle, c)
    if kind == "ellipse":
        major = (math.cos(angle), math.sin(angle), 0.0)
        return [Ellipse((c[0], c[1], 0.0), major, s / 2, s / 2 * u(0.4, 0.8), (0.0, 0.0, 1.0))]
    raise ValueError(kind)


HOLE_HOSTS = ("rect", "rounded_rect", "circle", "polygon")


def _shuffle_loop(curves: list[Curve], rng: np.random.Generator) -> tuple[Curve, ...]:
    """Fusion lists loop curves in no particular order or direction; so do we."""
    out = [Line(c.end, c.start) if isinstance(c, Line) and rng.random() < 0.3 else c for c in curves]
    order = rng.permutation(len(out))
    return tuple(out[i] for i in order)


def random_profile(
    rng: np.random.Generator, cfg: SyntheticConfig, size: float, centre: Vec2, pid: str, simple: bool = False
) -> Profile:
    kinds = ["rect", "rounded_rect", "circle", "slot", "polygon", "L", "T", "segment"]
    weights = [0.3, 0.12, 0.2, 0.08, 0.07, 0.1, 0.05, 0.08]
    if simple:
        kind = str(rng.choice(["rect", "circle"]))
    elif rng.random() < cfg.p_spline:
        kind = "spline"
    elif rng.random() < cfg.p_ellipse:
        kind = "ellipse"
    else:
        kind = str(rng.choice(kinds, p=np.array(weights) / sum(weights)))
    angle = float(rng.choice([0.0, math.pi / 2])) if rng.random() < 0.7 else float(rng.uniform(0, math.pi))
    loops = [Loop(True, _shuffle_loop(_outline(kind, size, rng, angle, centre), rng))]
    if kind in HOLE_HOSTS and not simple and rng.random() < cfg.p_inner_loop:
        hole = "circle" if rng.random() < 0.7 else "rect"
        loops.append(
            Loop(False, _shuffle_loop(_outline(hole, size * rng.uniform(0.2, 0.4), rng, angle, centre), rng))
        )
    return Profile(pid, tuple(loops))


# ------------------------------------------------------------------------------- sketch frames


def _construction_frame(name: str, offset: float) -> Frame:
    x, y, z = (np.array(v, float) for v in CONSTRUCTION_FRAMES[name])
    return Frame(tuple(z * offset), tuple(x), tuple(y), tuple(z))


def _face_frame(face: Face, rng: np.random.Generator) -> tuple[Frame, float]:
    """A frame on a random interior point of ``face``; returns it and the face's size."""
    verts, tris = face.tessellate(1e-3)
    pts = np.array([tuple(v) for v in verts])
    tri = np.array(tris)
    areas = 0.5 * np.linalg.norm(
        np.cross(pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]]), axis=1
    )
    k = rng.choice(len(tri), p=areas / areas.sum())
    origin = pts[tri[k]].mean(axis=0)
    normal = np.array(tuple(face.normal_at()))
    if rng.random() < 0.2:  # Fusion's face sketches may have z into the material
        normal = -normal
    lines = [e for e in face.edges() if e.geom_type == GeomType.LINE]
    if lines and rng.random() < 0.7:
        x = np.array(tuple(lines[int(rng.integers(len(lines)))].tangent_at(0)))
    else:
        x = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
        t = rng.uniform(0, 2 * math.pi)
        x = math.cos(t) * x + math.sin(t) * np.cross(normal, x)
    x = x - normal * (x @ normal)
    x /= np.linalg.norm(x)
    y = np.cross(normal, x)
    return Frame(tuple(origin), tuple(x), tuple(y), tuple(normal)), math.sqrt(face.area)


def _local(frame: Frame, p: np.ndarray) -> np.ndarray:
    return frame.matrix.T @ (np.asarray(p, float) - np.asarray(frame.origin, float))


# ------------------------------------------------------------------------------- the generator


class _Builder:
    def __init__(self, design_id: str, rng: np.random.Generator, cfg: SyntheticConfig):
        self.design_id, self.rng, self.cfg = design_id, rng, cfg
        self.ids = _Ids(rng)
        self.timeline: list = []
        self.sketches: dict[str, Sketch] = {}
        self.steps: list[ReplayStep] = []

    @property
    def bodies(self) -> tuple[Solid, ...]:
        return self.steps[-1].bodies if self.steps else ()

    def u(self, lo: float, hi: float) -> float:
        return float(self.rng.uniform(lo, hi))

    def sketch(self, frame: Frame, size: float, centre: Vec2, simple: bool = False) -> Sketch:
        sid, pid = self.ids(), self.ids()
        profile = random_profile(self.rng, self.cfg, size, centre, pid, simple)
        faces = profile_faces(profile, frame, self.design_id)
        profile = Profile(pid, profile.loops, sum(f.area for f in faces))
        return Sketch(sid, f"Sketch{len(self.sketches) + 1}", frame, {pid: profile})

    def extents(self, op: Operation, depth: float, outward: float) -> dict:
        """Extent fields for an extrude of roughly ``depth`` in direction ``outward`` (+1/-1)."""
        r = self.rng.random()
        if r < self.cfg.p_symmetric:
            return dict(
                extent_type=ExtentType.SYMMETRIC,
                extent_one=Extent(depth),
                symmetric_full_length=bool(self.rng.random() < 0.5),
            )
        if r < self.cfg.p_symmetric + self.cfg.p_two_sides:
            return dict(
                extent_type=ExtentType.TWO_SIDES,
                extent_one=Extent(outward * depth),
                extent_two=Extent(outward * depth * self.u(0.2, 0.8)),
            )
        start = 0.0
        if op is not Operation.CUT and self.rng.random() < self.cfg.p_offset_start:
            start = outward * depth * self.u(0.1, 0.5)
        return dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(outward * depth), start_offset=start)

    def first_step(self) -> tuple[Sketch, Extrude]:
        plane = str(self.rng.choice(list(CONSTRUCTION_FRAMES)))
        offset = self.u(-3, 3) if self.rng.random() < 0.15 else 0.0
        size = self.u(2.0, 10.0)
        centre = (self.u(-size, size) * 0.5, self.u(-size, size) * 0.5)
        taper = self.rng.random() < self.cfg.p_taper
        sketch = self.sketch(_construction_frame(plane, offset), size, centre, simple=taper)
        depth = size * self.u(0.1, 0.8)
        fields = self.extents(Operation.NEW_BODY, depth, float(self.rng.choice([-1, 1])))
        if taper and fields["extent_type"] is ExtentType.ONE_SIDE:
            limit = math.atan(0.35 * size / depth)  # an inward taper must not close the profile
            angle = math.radians(self.u(2, 12)) * float(self.rng.choice([-1, 1]))
            fields["extent_one"] = Extent(fields["extent_one"].distance, max(-limit, angle))
        return self.extrude(sketch, Operation.NEW_BODY, fields)

    def later_step(self) -> tuple[Sketch, Extrude]:
        op = [Operation.JOIN, Operation.CUT, Operation.INTERSECT][
            int(self.rng.choice(3, p=np.array(self.cfg.op_weights) / sum(self.cfg.op_weights)))
        ]
        shape = as_shape(self.bodies)
        box = shape.bounding_box()
        diag = box.diagonal
        planar = [f for f in shape.faces() if f.geom_type == GeomType.PLANE and f.area > 1e-3 * diag**2]
        if op is not Operation.INTERSECT and planar and self.rng.random() < self.cfg.p_face_sketch:
            return self.face_step(op, planar, diag)
        return self.plane_step(op, shape, diag)

    def face_step(self, op: Operation, faces: list[Face], diag: float) -> tuple[Sketch, Extrude]:
        areas = np.array([f.area for f in faces])
        face = faces[int(self.rng.choice(len(faces), p=areas / areas.sum()))]
        frame, face_size = _face_frame(face, self.rng)
        outward = 1.0 if np.dot(frame.z_axis, tuple(face.normal_at())) > 0 else -1.0
        size = face_size * self.u(0.2, 0.8)
        depth = diag * (self.u(0.05, 0.4) if op is Operation.JOIN else self.u(0.05, 1.2))
        sketch = self.sketch(frame, size, (0.0, 0.0))
        distance = (outward if op is Operation.JOIN else -outward) * depth
        tapered = op is Operation.JOIN and self.rng.random() < self.cfg.p_taper
        taper = math.radians(self.u(-8, 8)) if tapered else 0.0
        fields = dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(distance, taper))
        return self.extrude(sketch, op, fields)

    def plane_step(self, op: Operation, shape: Shape, diag: float) -> tuple[Sketch, Extrude]:
        plane = str(self.rng.choice(list(CONSTRUCTION_FRAMES)))
        centre = np.array(tuple(shape.bounding_box().center()))
        z = np.array(CONSTRUCTION_FRAMES[plane][2], float)
        frame = _construction_frame(plane, float(centre @ z) + self.u(-0.3, 0.3) * diag)
        local = _local(frame, centre)
        scale = 1.3 if op is Operation.INTERSECT else self.u(0.2, 0.8)
        sketch = self.sketch(frame, diag * scale, (float(local[0]), float(local[1])))
        fields = dict(
            extent_type=ExtentType.SYMMETRIC,
            extent_one=Extent(diag * self.u(0.3, 1.2)),
            symmetric_full_length=True,
        )
        if self.rng.random() < 0.5:
            fields = self.extents(op, diag * self.u(0.2, 1.0), float(self.rng.choice([-1, 1])))
        return self.extrude(sketch, op, fields)

    def extrude(self, sketch: Sketch, op: Operation, fields: dict) -> tuple[Sketch, Extrude]:
        ref = ProfileRef(sketch.id, next(iter(sketch.profiles)))
        return sketch, Extrude(self.ids(), f"Extrude{len(self.steps) + 1}", (ref,), op, **fields)

    def try_step(self, first: bool) -> bool:
        """Draw one step; keep it only if it replays to one valid, changed solid."""
        try:
            sketch, extrude = self.first_step() if first else self.later_step()
            step = replay_extrude(self.bodies, extrude, {**self.sketches, sketch.id: sketch}, self.design_id)
        except (ZoneGraphError, ValueError, RuntimeError):
            return False
        if len(step.bodies) != 1 or not step.bodies[0].is_valid:
            return False
        before = sum(b.volume for b in self.bodies)
        if abs(step.volume - before) <= 1e-3 * max(before, step.volume):
            return False
        if step.volume < 0.05 * before or _has_sliver(step.bodies[0]):
            return False
        self.sketches[sketch.id] = sketch
        self.timeline += [sketch, extrude]
        self.steps.append(step)
        return True


def _has_sliver(solid: Solid) -> bool:
    """Faces thinner than 1e-3 of the part make zone graphs fragile; real parts rarely have them."""
    diag = solid.bounding_box().diagonal
    return any(f.area < 1e-6 * diag**2 for f in solid.faces())


def sample_length(rng: np.random.Generator, cfg: SyntheticConfig) -> int:
    if rng.random() < cfg.p_single:
        return 1
    n = np.arange(2, cfg.max_extrudes + 1)
    w = cfg.length_decay ** (n - 2)
    return int(rng.choice(n, p=w / w.sum()))


def synthetic_id(index: int) -> str:
    return f"synth_{index:05d}"


def design_seed(base: int, index: int) -> int:
    """The seed of design ``index`` in the set seeded ``base``: each design is reproducible alone."""
    return base * 1_000_003 + index


def synthetic_design(index: int, base_seed: int = 2021) -> Design:
    """Design ``index`` of the set seeded ``base_seed`` (``params.yaml: synthetic.seed``), exactly as
    the ``generate`` stage writes it; the benchmarks use it to rebuild the same designs."""
    name = synthetic_id(index)
    return parse_design(generate_design(name, design_seed(base_seed, index)), name)


def generate_design(design_id: str, seed: int, cfg: SyntheticConfig = SyntheticConfig()) -> dict:
    """One design as Fusion-format JSON (a dict), reproducible from ``seed``."""
    rng = np.random.default_rng(seed)
    target = sample_length(rng, cfg)
    builder = _Builder(design_id, rng, cfg)
    while not builder.steps:
        builder.try_step(first=True)
    while len(builder.steps) < target:
        if not any(builder.try_step(first=False) for _ in range(cfg.max_tries)):
            break
    design = Design(design_id, tuple(builder.timeline))
    labels = {s.extrude.id: step_labels(s, builder.ids) for s in builder.steps}
    return design_to_json(
        design,
        extra=labels,
        properties=shape_properties(builder.steps[-1].bodies),
        metadata={"parent_project": design_id, "generator": "zonegraph.synthetic", "seed": seed},
    )


def step_labels(step: ReplayStep, new_id: Callable[[], str]) -> dict[str, Any]:
    """The ``bodies``/``faces`` labels Fusion records after an extrude (fresh ids per step)."""
    faces: dict[str, Any] = {}
    bodies: dict[str, Any] = {}
    for b, body in enumerate(step.bodies):
        ids = []
        for face in body.faces():
            fid = new_id()
            ids.append(fid)
            faces[fid] = {
                "index": len(faces),
                "surface_type": FUSION_SURFACE_TYPES.get(face.geom_type, "NurbsSurfaceType"),
                "point_on_face": _point(face.center()),
            }
        bodies[new_id()] = {"index": b, "name": f"Body{b + 1}", "faces": ids}
    return {"bodies": bodies, "faces": faces}


def _point(v: Vector) -> dict[str, Any]:
    return {"type": "Point3D", "x": v.X, "y": v.Y, "z": v.Z}


def shape_properties(bodies: tuple[Solid, ...]) -> dict:
    """Fusion's ``properties`` block, computed by our own replay."""
    shape = as_shape(bodies)
    box = shape.bounding_box()
    counts: dict[str, int] = {}
    for f in shape.faces():
        name = FUSION_SURFACE_TYPES.get(f.geom_type, "NurbsSurfaceType")
        counts[name] = counts.get(name, 0) + 1
    return {
        "bounding_box": {"type": "BoundingBox3D", "min_point": _point(box.min), "max_point": _point(box.max)},
        "vertex_count": len(shape.vertices()),
        "edge_count": len(shape.edges()),
        "face_count": len(shape.faces()),
        "shell_count": len(shape.shells()),
        "body_count": len(bodies),
        "area": sum(b.area for b in bodies),
        "volume": sum(b.volume for b in bodies),
        "center_of_mass": _point(shape.center()),
        "surface_types": [{"surface_type": k, "face_count": v} for k, v in sorted(counts.items())],
    }

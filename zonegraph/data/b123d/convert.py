"""Fusion 360 Gallery designs written as build123d scripts -> our reconstruction JSON, verified.

The corpus (``../shared/data/fusion360_b123d``, see its ``PROVENANCE.md``) holds each design as a
function ``model_<id>()`` whose body replays Fusion's sketch + extrude timeline with build123d. We
do not parse that code into geometry ourselves: we *run* the function with ``extrude`` replaced by
a recording wrapper, so the faces we convert are exactly the faces build123d extrudes, whatever
sketch API produced them (``BuildLine`` + ``make_face``, ``Circle`` under ``Locations``, OCP
B-splines, booleans between sketch faces). Each recorded face is turned back into sketch-local
profile curves (Line3D, Arc3D, Circle3D, Ellipse3D, EllipticalArc3D, NurbsCurve3D) in the frame
of the plane build123d extruded it along, and each Fusion feature (a ``# Sketch -> Extrude (Op)``
comment in the source) becomes one ExtrudeFeature that keeps Fusion's own operation.

The JSON is then replayed with :func:`zonegraph.data.replay.replay` and compared with the solid the
script itself returned (volume and area, 1e-6 relative) and with Fusion's recorded volume and area
(``MODELS``, 1%). Nothing a design does can escape as an exception: every failure becomes a
:class:`ConvertedDesign` with a status and a one-line reason.

Semantics that differ between the two worlds, and how they are bridged:

- build123d's ``both=True`` extrudes ``amount`` to each side: Fusion's Symmetric extent with
  ``is_full_length = False`` and the same distance (or ``True`` with twice the distance when the
  script's comment says Fusion used the full length).
- build123d's positive ``taper`` (degrees) closes the profile; Fusion's positive taper opens it, so
  the JSON holds ``-radians(taper)`` (the replay negates it again).
- Fusion's TwoSides extents are written as two ``extrude`` calls (the second on ``sk.sketch``);
  the pair is merged back into one TwoSides feature. The "offset" variant (Join the full depth,
  then Cut the trim depth) is merged into a TwoSides extent whose both ends lie on one side; where
  that differs from the script (its Cut also removes older material), the calls are written as
  separate features instead.
- build123d's ``Mode.ADD`` fuses everything into one part, while Fusion's NewBody keeps separate
  bodies (and so does our replay). We compare the *union* of our bodies with the script's part:
  Join, Cut and Intersect all distribute over the union (a cut of each body is the cut of the
  union, and so on), so the union of a correct replay is the script's point set exactly, while the
  body-summed volume double counts overlapping NewBody bodies. Fusion's own ``properties`` sum over
  bodies, so the Fusion check uses our replay's body sums (and the script's fused part as well).
- build123d's ``volume``/``area`` integrate with a fixed Gauss order that is off by up to ~1e-4
  on faces trimmed by B-spline curves; a replay that misses 1e-6 is re-measured adaptively (and,
  failing that, by its symmetric difference with the script's part) before it is a mismatch.
- A sketch whose ``BuildSketch`` is not followed by ``extrude`` leaves its faces pending, and the
  next ``extrude`` sweeps them too: we record what build123d actually extrudes, so the JSON does
  the same (and the result notes the feature comment left without a call).
- The scripts target build123d 0.10; ``EllipticalCenterArc``'s old positional form is mapped onto
  the 0.13 signature, and the OCP 8 array classes are aliased under their old names.
"""

from __future__ import annotations

import ast
import contextlib
import hashlib
import importlib.util
import math
import re
import signal
import sys
import threading
import time
import types
import uuid
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from zonegraph.data.design import (
    Arc,
    Circle,
    Curve,
    Design,
    Ellipse,
    EllipticalArc,
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
    Vec3,
    design_to_json,
    parse_design,
)
from zonegraph.data.profiles import SNAP_TOL
from zonegraph.errors import UnsupportedFeatureError, ZoneGraphError

VOLUME_RTOL = 1e-6  # replay vs the script's own part
FUSION_RTOL = 0.01  # script / replay vs Fusion's recorded volume and area
PLANE_TOL = 1e-6  # cm: a profile point may sit this far off its sketch plane
SAME_TOL = 1e-9  # relative: two recorded face sets are the same profiles
PRECISE_EPS = 1e-9  # relative accuracy of the adaptive volume/area integration
SYMDIFF_AREA_RTOL = 1e-5  # area agreement required before a symmetric difference may settle volume

FOLDER_RE = re.compile(r"^\d\d_")
FEATURE_RE = re.compile(
    r"^\s*#\s*(?P<sketch>.+?)\s*->\s*(?P<name>.+?)\s*\((?P<op>NewBody|Join|Cut|Intersect)\)\s*$"
)
EXTENT_RE = re.compile(r"^\s*#\s*(OneSide|Symmetric|TwoSides)\b.*extrude")
FULL_LENGTH_RE = re.compile(r"full_length\s*=\s*True")

OPERATIONS = {
    "NewBody": Operation.NEW_BODY,
    "Join": Operation.JOIN,
    "Cut": Operation.CUT,
    "Intersect": Operation.INTERSECT,
}
SHORT_NAMES = {v: k for k, v in OPERATIONS.items()}
# The script mode each Fusion operation should have been written with.
EXPECTED_MODE = {"NewBody": "ADD", "Join": "ADD", "Cut": "SUBTRACT", "Intersect": "INTERSECT"}
MODE_OPERATION = {"ADD": Operation.JOIN, "SUBTRACT": Operation.CUT, "INTERSECT": Operation.INTERSECT}


# ------------------------------------------------------------------------------------ the corpus


@dataclass(frozen=True)
class CorpusEntry:
    """One design of the corpus, found without running any code."""

    design_id: str
    folder: str
    batch: str
    function: str
    fusion_volume: float | None
    fusion_area: float | None


def list_corpus(root: str | Path) -> list[CorpusEntry]:
    """Every design under ``root`` (folders ``NN_*`` of ``batch_*.py``), read with ``ast`` only.

    Importing the batches would execute build123d for every model; parsing is ~100x faster and
    cannot be broken by a bad model. A batch that does not parse still lists its ``def model_*``
    functions (found by a regular expression) so that converting them reports ``syntax_error``.
    """
    root = Path(root)
    out: list[CorpusEntry] = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir() and FOLDER_RE.match(p.name)):
        for batch in sorted(folder.glob("batch_*.py")):
            out.extend(_batch_entries(batch, folder.name))
    return out


def _batch_entries(batch: Path, folder: str) -> list[CorpusEntry]:
    """The designs of one batch: ``def model_*`` at top level plus the literal ``MODELS`` block.

    Only the ``MODELS`` assignment goes through ``ast`` (the function bodies are ~99% of the text
    and parsing them all takes ~10 s for the corpus); whether the whole file is valid Python is
    the converter's business (``syntax_error``).
    """
    text = batch.read_text(encoding="utf-8", errors="replace")
    names = re.findall(r"^def (model_\w+)\s*\(", text, flags=re.M)
    measures: dict[str, tuple[float | None, float | None]] = {}
    m = re.search(r"^MODELS\s*=", text, flags=re.M)
    if m:
        tail = text[m.start() :]
        stop = re.search(r"^if __name__", tail, flags=re.M)
        with contextlib.suppress(SyntaxError, ValueError):
            measures = _models_measures(ast.parse(tail[: stop.start()] if stop else tail))
    return [
        CorpusEntry(n.removeprefix("model_"), folder, str(batch), n, *measures.get(n, (None, None)))
        for n in names
    ]


def _models_measures(tree: ast.Module) -> dict[str, tuple[float | None, float | None]]:
    """``MODELS`` -> {function: (volume, area)} from the literal dict (its ``func`` is a name)."""
    out: dict[str, tuple[float | None, float | None]] = {}
    for node in tree.body:
        if not (
            isinstance(node, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "MODELS" for t in node.targets)
        ):
            continue
        if not isinstance(node.value, ast.Dict):
            continue
        for key, value in zip(node.value.keys, node.value.values, strict=True):
            if not (isinstance(key, ast.Constant) and isinstance(key.value, str)):
                continue
            if not isinstance(value, ast.Dict):
                continue
            fields: dict[str, float] = {}
            for k, v in zip(value.keys, value.values, strict=True):
                if (
                    isinstance(k, ast.Constant)
                    and isinstance(v, ast.Constant)
                    and isinstance(v.value, (int, float))
                ):
                    fields[str(k.value)] = float(v.value)
            out[key.value] = (fields.get("volume"), fields.get("area"))
    return out


# ---------------------------------------------------------------------------------- source facts


@dataclass(frozen=True)
class FeatureComment:
    """A ``# Sketch2 -> Extrude2 (Join)`` comment: where a Fusion feature starts in the source."""

    line: int
    sketch: str
    name: str
    operation: str  # NewBody / Join / Cut / Intersect
    full_length: bool  # the extent comment says Symmetric with is_full_length=True


def feature_comments(lines: list[str], start: int, end: int) -> list[FeatureComment]:
    """The feature comments of the function spanning 1-based source lines ``start``..``end``."""
    out: list[FeatureComment] = []
    for no in range(start, min(end, len(lines)) + 1):
        m = FEATURE_RE.match(lines[no - 1])
        if m:
            out.append(FeatureComment(no, m["sketch"], m["name"], m["op"], False))
        elif out and EXTENT_RE.match(lines[no - 1]) and FULL_LENGTH_RE.search(lines[no - 1]):
            last = out[-1]
            out[-1] = FeatureComment(last.line, last.sketch, last.name, last.operation, True)
    return out


# ------------------------------------------------------------------------------ importing batches


def install_ocp_shims() -> None:
    """Make the scripts' pre-OCP-8 array imports resolve to their ``OCP.collections`` successors."""
    import OCP.TColgp
    import OCP.TColStd
    from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int

    for module, name, cls in (
        (OCP.TColStd, "TColStd_Array1OfReal", Array1_double),
        (OCP.TColStd, "TColStd_Array1OfInteger", Array1_int),
        (OCP.TColgp, "TColgp_Array1OfPnt", Array1_gp_Pnt),
    ):
        if not hasattr(module, name):
            setattr(module, name, cls)


@dataclass
class _Batch:
    """An imported batch (or why it could not be imported) plus its source, parsed once."""

    path: str
    module: types.ModuleType | None
    error: str
    lines: list[str]
    spans: dict[str, tuple[int, int]]  # function name -> (first line, last line)


_BATCHES: dict[str, _Batch] = {}
_ACTIVE: list[list[RecordedCall]] = []  # the recorder of the model now running (a stack of one)


def load_batch(batch_path: str | Path) -> _Batch:
    """Import a batch once per process (cached), with ``extrude`` replaced by the recorder."""
    key = str(Path(batch_path).resolve())
    if key in _BATCHES:
        return _BATCHES[key]
    lines: list[str] = []
    spans: dict[str, tuple[int, int]] = {}
    module: types.ModuleType | None = None
    error = ""
    try:
        text = Path(key).read_text(encoding="utf-8")
        lines = text.splitlines()
        tree = ast.parse(text, filename=key)
        spans = {
            n.name: (n.lineno, n.end_lineno or n.lineno) for n in tree.body if isinstance(n, ast.FunctionDef)
        }
        install_ocp_shims()
        name = "zonegraph_b123d_" + hashlib.sha1(key.encode()).hexdigest()[:16]
        spec = importlib.util.spec_from_file_location(name, key)
        if spec is None or spec.loader is None:
            raise ImportError("no loader for this path")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        real = getattr(module, "extrude", None)
        if not callable(real):
            raise ImportError("the batch does not import build123d's extrude")
        module.extrude = _recording_extrude(real, key)  # type: ignore[attr-defined]
        _install_api_shims(module)
    except SyntaxError as exc:
        module, error = None, f"SyntaxError: {exc.msg} (line {exc.lineno})"
    except Exception as exc:  # whatever the module's top level raises
        module, error = None, f"import failed: {type(exc).__name__}: {_short(exc)}"
    batch = _Batch(key, module, error, lines, spans)
    _BATCHES[key] = batch
    return batch


def _install_api_shims(module: types.ModuleType) -> None:
    """Bridge build123d API changes the scripts predate (they were written for build123d 0.9/0.10).

    ``EllipticalCenterArc(center, rx, ry, start_angle, end_angle, rotation, angular_direction)``
    became ``EllipticalCenterArc(center, rx, ry, start_angle, *, arc_size, rotation)`` (0.13), so
    the old positional form raises. The shim maps the old arguments onto the new signature; the
    result is checked like everything else (replay vs script, script vs Fusion's volume and area).
    """
    import inspect

    original = getattr(module, "EllipticalCenterArc", None)
    if original is None or "end_angle" in inspect.signature(original).parameters:
        return

    def elliptical_center_arc(
        center: Any,
        x_radius: float,
        y_radius: float,
        start_angle: float = 0.0,
        end_angle: float | None = None,
        rotation: float = 0.0,
        angular_direction: Any = None,
        **kwargs: Any,
    ) -> Any:
        if end_angle is None:  # new-style call
            return original(center, x_radius, y_radius, start_angle, rotation=rotation, **kwargs)
        clockwise = getattr(angular_direction, "name", "") == "CLOCKWISE"
        sweep = (start_angle - end_angle) % 360 if clockwise else (end_angle - start_angle) % 360
        sweep = sweep or 360.0
        return original(
            center,
            x_radius,
            y_radius,
            start_angle,
            arc_size=-sweep if clockwise else sweep,
            rotation=rotation,
            **kwargs,
        )

    module.EllipticalCenterArc = elliptical_center_arc  # type: ignore[attr-defined]


# ------------------------------------------------------------------------------------ recording


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


@dataclass(frozen=True)
class RecordedCall:
    """One ``extrude(...)`` call, in timeline order, with everything needed to rebuild it."""

    line: int  # source line of the call inside the batch
    faces: tuple[RecordedFace, ...]
    amount: float
    both: bool
    taper: float  # build123d degrees (positive closes the profile)
    mode: str  # ADD / SUBTRACT / INTERSECT / ...
    explicit: bool  # the call named its sketch (``extrude(sk.sketch, ...)``)
    error: str = ""  # why the call cannot be expressed in our JSON (the call itself still ran)


def _recording_extrude(real: Callable[..., Any], path: str) -> Callable[..., Any]:
    """A drop-in ``extrude`` that records its faces and arguments, then runs the real one."""

    def extrude(
        to_extrude: Any = None,
        amount: float | None = None,
        dir: Any = None,  # noqa: A002
        until: Any = None,
        target: Any = None,
        both: bool = False,
        taper: float = 0.0,
        clean: bool = True,
        mode: Any = None,
    ) -> Any:
        if _ACTIVE:
            frame = sys._getframe(1)
            line = frame.f_lineno if frame.f_code.co_filename == path else -1
            _ACTIVE[-1].append(_record(to_extrude, amount, dir, until, both, taper, mode, line))
        kwargs: dict[str, Any] = dict(
            amount=amount, dir=dir, until=until, target=target, both=both, taper=taper, clean=clean
        )
        if mode is not None:
            kwargs["mode"] = mode
        return real(to_extrude, **kwargs)

    return extrude


def _record(
    to_extrude: Any,
    amount: float | None,
    direction: Any,
    until: Any,
    both: bool,
    taper: float,
    mode: Any,
    line: int,
) -> RecordedCall:
    """Snapshot the faces ``extrude`` is about to consume (it clears the pending list itself)."""
    from build123d import BuildPart, Plane

    mode_name = "ADD" if mode is None else str(getattr(mode, "name", mode))
    base = dict(
        line=line,
        amount=float(amount or 0.0),
        both=bool(both),
        taper=float(taper or 0.0),
        mode=mode_name,
        explicit=to_extrude is not None,
    )
    try:
        if amount is None or until is not None or direction is not None:
            raise UnsupportedFeatureError("", None, "extrude with until/dir (only distances)")
        if to_extrude is None:
            context = BuildPart._get_context("extrude", log=False)
            if context is None or not context.pending_faces:
                return RecordedCall(faces=(), error="extrude without pending faces", **base)  # type: ignore[arg-type]
            pairs = list(zip(context.pending_faces, context.pending_face_planes, strict=True))
        else:
            faces = list(to_extrude) if isinstance(to_extrude, (tuple, list)) else to_extrude.faces()
            pairs = [(f, Plane(f)) for f in faces]
        recorded = tuple(face_record(face, plane) for face, plane in pairs)
        return RecordedCall(faces=recorded, **base)  # type: ignore[arg-type]
    except UnsupportedFeatureError as exc:
        return RecordedCall(faces=(), error=exc.reason, **base)  # type: ignore[arg-type]
    except Exception as exc:  # a face we cannot read: say why, let the real extrude run
        reason = f"cannot read profile: {type(exc).__name__}: {_short(exc)}"
        return RecordedCall(faces=(), error=reason, **base)  # type: ignore[arg-type]


@contextlib.contextmanager
def recording() -> Iterator[list[RecordedCall]]:
    """Collect the ``extrude`` calls of the model run inside the block (batches from load_batch)."""
    calls: list[RecordedCall] = []
    _ACTIVE.append(calls)
    try:
        yield calls
    finally:
        _ACTIVE.pop()


# --------------------------------------------------------------------------- faces -> curves


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
    for outer, wire in wires:
        curves = [edge_curve(e, local) for e in wire.edges()]
        # The replay snaps end points closer than SNAP_TOL together, so such a line would collapse to
        # a point (and fail); its neighbours are joined across the gap instead, as the replay does.
        kept = [c for c in curves if not (isinstance(c, Line) and _length(c) < SNAP_TOL)]
        dropped += len(curves) - len(kept)
        loops.append(Loop(outer, tuple(kept)))
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


def face_area(face: Any) -> float | None:
    """The profile area to store in the JSON, or None where storing it would mislead.

    The replay checks each rebuilt profile against this area (1e-4 relative) with build123d's
    fixed-order Gauss measure, which is off by ~1e-4 on faces bounded by long high-degree splines
    (60730_fa513b8a_0006: 7.32759 for a face whose exact area is 7.32685). So the exact (adaptive)
    area is stored only when the quick measure agrees with it; otherwise the check is skipped.
    """
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face.wrapped, props, PRECISE_EPS, True)
    exact = float(props.Mass())
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
            reason = f"profile curve type {ad.GetType()} ({_short(exc)})"
            raise UnsupportedFeatureError("", None, reason) from None
    if curve.IsPeriodic():
        raise UnsupportedFeatureError("", None, "periodic B-spline profile curve")
    poles = tuple(local.point(_v3(curve.Pole(i))) for i in range(1, curve.NbPoles() + 1))
    knots: list[float] = []
    for i in range(1, curve.NbKnots() + 1):
        knots += [curve.Knot(i)] * curve.Multiplicity(i)
    weights = tuple(curve.Weight(i) for i in range(1, curve.NbPoles() + 1)) if curve.IsRational() else None
    return Nurbs(curve.Degree(), tuple(knots), poles, weights, False)


# ---------------------------------------------------------------------------- calls -> features


@dataclass(frozen=True)
class _Feature:
    """The recorded calls of one Fusion feature (or of calls no comment names)."""

    comment: FeatureComment | None
    calls: tuple[RecordedCall, ...]


def group_calls(calls: list[RecordedCall], comments: list[FeatureComment]) -> list[_Feature]:
    """Assign each call to the last feature comment above it (calls before any get their own)."""
    groups: list[_Feature] = []
    for call in calls:
        owner = None
        for c in comments:
            if c.line < call.line:
                owner = c
        if groups and owner is not None and groups[-1].comment is owner:
            groups[-1] = _Feature(owner, groups[-1].calls + (call,))
        else:
            groups.append(_Feature(owner, (call,)))
    return groups


@dataclass
class _Writer:
    """Builds the typed timeline (sketches, extrudes) with deterministic ids."""

    design_id: str
    timeline: list[Sketch | Extrude] = field(default_factory=list)
    counter: int = 0

    def uid(self, kind: str) -> str:
        self.counter += 1
        return str(uuid.uuid5(uuid.NAMESPACE_URL, f"fusion360_b123d/{self.design_id}/{kind}/{self.counter}"))

    def sketches(self, call: RecordedCall, name: str) -> tuple[ProfileRef, ...]:
        """One sketch per distinct face frame; every face becomes one profile."""
        refs: list[ProfileRef] = []
        groups: list[tuple[Frame, list[RecordedFace]]] = []
        for face in call.faces:
            for frame, members in groups:
                if _same_frame(frame, face.frame):
                    members.append(face)
                    break
            else:
                groups.append((face.frame, [face]))
        for i, (frame, members) in enumerate(groups):
            sid = self.uid("sketch")
            profiles: dict[str, Profile] = {}
            for face in members:
                pid = self.uid("profile")
                profiles[pid] = Profile(pid, face.loops, face.area)
                refs.append(ProfileRef(sid, pid))
            self.timeline.append(Sketch(sid, name if i == 0 else f"{name}.{i + 1}", frame, profiles))
        return tuple(refs)

    def extrude(self, refs: tuple[ProfileRef, ...], name: str, op: Operation, **extent: Any) -> None:
        self.timeline.append(Extrude(self.uid("extrude"), name, refs, op, **extent))


def _same_frame(a: Frame, b: Frame) -> bool:
    return all(
        np.allclose(u, v, atol=1e-12)
        for u, v in ((a.origin, b.origin), (a.x_axis, b.x_axis), (a.z_axis, b.z_axis))
    )


def _fusion_taper(degrees: float) -> float:
    """build123d's taper (degrees, positive inward) as Fusion's (radians, positive outward)."""
    return -math.radians(degrees)


def _single_extent(call: RecordedCall, full_length: bool) -> dict[str, Any]:
    taper = _fusion_taper(call.taper)
    if call.both:
        d = abs(call.amount)
        if full_length:
            return dict(
                extent_type=ExtentType.SYMMETRIC, extent_one=Extent(2 * d, taper), symmetric_full_length=True
            )
        return dict(
            extent_type=ExtentType.SYMMETRIC, extent_one=Extent(d, taper), symmetric_full_length=False
        )
    return dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(call.amount, taper))


def _along(first: RecordedCall, second: RecordedCall) -> float | None:
    """``second``'s amount measured along ``first``'s normal if both extrude the same faces."""
    if len(first.faces) != len(second.faces) or not first.faces:
        return None
    sign = 0.0
    for a, b in zip(first.faces, second.faces, strict=True):
        scale = max(math.sqrt(a.quick_area), 1e-9)
        if (
            abs(a.quick_area - b.quick_area) > SAME_TOL * max(a.quick_area, 1e-12)
            or np.linalg.norm(np.subtract(a.center, b.center)) > SAME_TOL * 1e3 * scale
        ):
            return None
        dot = float(np.dot(a.normal, b.normal))
        if abs(abs(dot) - 1) > 1e-9 or (sign and sign != math.copysign(1.0, dot)):
            return None
        sign = math.copysign(1.0, dot)
    return sign * second.amount


def merge_pair(first: RecordedCall, second: RecordedCall) -> dict[str, Any] | None:
    """The extent of a Fusion TwoSides feature written as two calls, or None if not a pair.

    Both calls sweep from the sketch plane, so with amounts ``a`` and ``b`` (along the first
    normal) the swept region is [0, a] U [0, b]; for the Join-then-Cut "offset" variant it is
    [0, a] minus [0, b]. TwoSides covers [-d2, d1] (our replay sweeps each tapered side from the
    profile plane, as build123d does).
    """
    if first.both or second.both or first.error or second.error:
        return None
    b = _along(first, second)
    if b is None:
        return None
    a = first.amount
    if first.mode == second.mode and first.mode in ("ADD", "SUBTRACT"):
        if a * b < 0:
            return dict(
                extent_type=ExtentType.TWO_SIDES,
                extent_one=Extent(a, _fusion_taper(first.taper)),
                extent_two=Extent(-b, _fusion_taper(second.taper)),
            )
        if first.taper == 0 and second.taper == 0:  # one side twice: the longer one wins
            return dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(a if abs(a) >= abs(b) else b))
        return None
    if (
        (first.mode, second.mode) == ("ADD", "SUBTRACT")
        and a * b > 0
        and abs(b) < abs(a)
        and first.taper == 0
        and second.taper == 0
    ):
        return dict(extent_type=ExtentType.TWO_SIDES, extent_one=Extent(a), extent_two=Extent(-b))
    return None


@dataclass(frozen=True)
class _Plan:
    """A timeline built from the recorded calls, with what was decided along the way."""

    design: Design
    operations: tuple[str, ...]
    mode_disagreements: int
    notes: tuple[str, ...]


def build_design(design_id: str, features: list[_Feature], literal: bool = False) -> _Plan:
    """Our typed design for the recorded features.

    Each Fusion feature keeps the operation of its comment. ``literal`` writes every call of a
    multi-call feature as its own extrude (the exact script) instead of merging it into one.
    """
    w = _Writer(design_id)
    ops: list[str] = []
    notes: list[str] = []
    disagreements = 0
    for k, feature in enumerate(features):
        for call in feature.calls:
            if call.error:
                raise UnsupportedFeatureError(design_id, None, f"line {call.line}: {call.error}")
        c = feature.comment
        name = c.name if c else f"Extrude{k + 1}"
        sketch_name = c.sketch if c else f"Sketch{k + 1}"
        fusion_op = c.operation if c else None
        modes = [call.mode for call in feature.calls]
        if fusion_op is not None and EXPECTED_MODE[fusion_op] != modes[0]:
            disagreements += 1
            notes.append(f"{name}: Fusion says {fusion_op}, script mode {modes[0]}")
        first_op = OPERATIONS[fusion_op] if fusion_op else MODE_OPERATION.get(modes[0], Operation.JOIN)
        if modes[0] not in MODE_OPERATION:
            raise UnsupportedFeatureError(design_id, None, f"{name}: script mode {modes[0]}")
        calls = feature.calls
        dropped = sum(f.dropped for call in calls for f in call.faces)
        if dropped:
            notes.append(f"{name}: left out {dropped} profile line(s) shorter than {SNAP_TOL:g} cm")
        extent = merge_pair(calls[0], calls[1]) if len(calls) == 2 and not literal else None
        if len(calls) == 1 or extent is not None:
            refs = w.sketches(calls[0], sketch_name)
            w.extrude(refs, name, first_op, **(extent or _single_extent(calls[0], bool(c and c.full_length))))
            ops.append(SHORT_NAMES[first_op])
            continue
        notes.append(f"{name}: {len(calls)} calls written as {len(calls)} extrudes")
        for i, call in enumerate(calls):
            op = first_op if i == 0 else MODE_OPERATION.get(call.mode)
            if op is None:
                raise UnsupportedFeatureError(design_id, None, f"{name}: script mode {call.mode}")
            suffix = "" if i == 0 else f".{i + 1}"
            refs = w.sketches(call, sketch_name + suffix)
            w.extrude(refs, name + suffix, op, **_single_extent(call, False))
            ops.append(SHORT_NAMES[op])
    if not w.timeline:
        raise UnsupportedFeatureError(design_id, None, "no extrude was recorded")
    return _Plan(Design(design_id, tuple(w.timeline)), tuple(ops), disagreements, tuple(notes))


# -------------------------------------------------------------------------------- verification


@dataclass(frozen=True)
class ConvertedDesign:
    """The outcome of converting one design: its JSON (when built) and how well it replays.

    ``volume_rel_error``/``area_rel_error``: union of our replayed bodies vs the script's part.
    ``fusion_*``: our replay (bodies summed, as Fusion's ``properties`` are) vs Fusion's MODELS;
    ``script_fusion_*``: the script's part vs Fusion's MODELS.
    """

    design_id: str
    folder: str
    design_json: dict | None
    status: str
    reason: str
    steps: int = 0
    operations: list[str] = field(default_factory=list)
    mode_disagreements: int = 0
    volume_rel_error: float | None = None
    area_rel_error: float | None = None
    fusion_volume_rel_error: float | None = None
    fusion_area_rel_error: float | None = None
    script_fusion_volume_rel_error: float | None = None
    script_fusion_area_rel_error: float | None = None
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status == "ok"


class _Timeout(Exception):
    pass


@contextlib.contextmanager
def _time_limit(seconds: float | None) -> Iterator[None]:
    """SIGALRM-based limit (main thread on Unix only; elsewhere no limit). Interrupts only between
    OCP calls, so a single endless Boolean can still overrun."""
    main = threading.current_thread() is threading.main_thread()
    usable = bool(seconds) and hasattr(signal, "SIGALRM") and main
    if not usable:
        yield
        return

    def handler(signum: int, frame: Any) -> None:
        raise _Timeout()

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, float(seconds or 0))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(abs(b), 1e-300)


def _short(exc: BaseException, limit: int = 200) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _folder_of(path: Path) -> str:
    return path.parent.name


def convert_design(
    batch_path: str | Path,
    design_id: str,
    fusion_volume: float | None = None,
    fusion_area: float | None = None,
    timeout_s: float | None = None,
) -> ConvertedDesign:
    """Run ``model_<design_id>`` of a batch, convert its extrudes to our JSON and verify the replay.

    Fusion's volume/area default to the batch's ``MODELS`` entry. Never raises for a bad design.
    """
    t0 = time.perf_counter()
    path = Path(batch_path)
    folder = _folder_of(path)

    def result(status: str, reason: str, **kw: Any) -> ConvertedDesign:
        return ConvertedDesign(
            design_id,
            folder,
            kw.pop("design_json", None),
            status,
            reason,
            seconds=time.perf_counter() - t0,
            **kw,
        )

    try:
        with _time_limit(timeout_s):
            return _convert(path, design_id, fusion_volume, fusion_area, result)
    except _Timeout:
        return result("timeout", f"took longer than {timeout_s:g} s")
    except Exception as exc:  # a bug of ours must still leave a row, not kill a corpus run
        return result("error", f"converter failed: {type(exc).__name__}: {_short(exc)}")


def _convert(
    path: Path,
    design_id: str,
    fusion_volume: float | None,
    fusion_area: float | None,
    result: Callable[..., ConvertedDesign],
) -> ConvertedDesign:
    from build123d import Shape

    from zonegraph.data.replay import replay

    batch = load_batch(path)
    if batch.module is None:
        return result("syntax_error", batch.error)
    fname = f"model_{design_id}"
    func = getattr(batch.module, fname, None)
    if not callable(func):
        return result("syntax_error", f"the batch has no function {fname}")
    if fusion_volume is None or fusion_area is None:
        info = getattr(batch.module, "MODELS", {}).get(fname, {})
        fusion_volume = fusion_volume if fusion_volume is not None else info.get("volume")
        fusion_area = fusion_area if fusion_area is not None else info.get("area")

    # 1. run the script, recording its extrudes
    try:
        with recording() as calls:
            part = func()
    except _Timeout:
        raise
    except Exception as exc:
        return result("model_raised", f"{type(exc).__name__}: {_short(exc)}")
    if not isinstance(part, Shape) or part.wrapped is None or not part.solids():
        return result("no_shape", f"the model returned {type(part).__name__} without a solid")
    script_volume, script_area = float(part.volume), float(part.area)  # build123d's own measure
    if script_volume <= 0:
        return result("no_shape", f"the model's part has volume {script_volume:.3g}")
    script_fv = _rel(script_volume, fusion_volume) if fusion_volume else None
    script_fa = _rel(script_area, fusion_area) if fusion_area else None

    # 2. the recorded calls as our timeline
    start, end = batch.spans.get(fname, (0, 0))
    comments = feature_comments(batch.lines, start, end)
    features = group_calls(calls, comments)
    notes: list[str] = []
    used = {id(f.comment) for f in features if f.comment is not None}
    idle = [f"{c.sketch} -> {c.name}" for c in comments if id(c) not in used]
    if idle:  # its sketch's faces stay pending and are extruded by the next call with the next ones
        notes.append(
            f"{len(comments)} feature comments, {len(idle)} without an extrude call: " + ", ".join(idle[:4])
        )
    unnamed = sum(1 for f in features if f.comment is None)
    if unnamed:
        notes.append(f"{unnamed} extrude call(s) before any feature comment")
    try:
        plan = build_design(design_id, features)
    except UnsupportedFeatureError as exc:
        return result(
            "unsupported",
            exc.reason,
            script_fusion_volume_rel_error=script_fv,
            script_fusion_area_rel_error=script_fa,
            notes=notes,
        )

    # 3. replay it and compare; a merged TwoSides that differs is retried call by call
    check = _verify(plan, part, replay)
    if check.status != "ok" and len(plan.operations) < len(calls):
        literal = build_design(design_id, features, literal=True)
        retry = _verify(literal, part, replay)
        if retry.status == "ok":
            plan, check = literal, retry
    notes += list(plan.notes)
    if check.status == "ok" and check.reason:
        notes.append(f"verified by {check.reason}")
    common: dict[str, Any] = dict(
        steps=len(plan.operations),
        operations=list(plan.operations),
        mode_disagreements=plan.mode_disagreements,
        script_fusion_volume_rel_error=script_fv,
        script_fusion_area_rel_error=script_fa,
        notes=notes,
    )
    if check.status == "replay_failed":
        invalid = " (the script's own part is an invalid solid too)" if not part.is_valid else ""
        check = _Check(check.status, check.reason + invalid)
        design_json = _to_json(plan, path, None, None, 0, 0)
        return result(check.status, check.reason, design_json=design_json, **common)
    fv = _rel(check.bodies_volume, fusion_volume) if fusion_volume else None
    fa = _rel(check.bodies_area, fusion_area) if fusion_area else None
    common.update(
        volume_rel_error=check.volume_rel_error,
        area_rel_error=check.area_rel_error,
        fusion_volume_rel_error=fv,
        fusion_area_rel_error=fa,
    )
    design_json = _to_json(plan, path, fusion_volume, fusion_area, check.body_count, check.face_count)
    if check.status == "mismatch":
        reason = check.reason
        if fv is not None and fa is not None and script_fv is not None and script_fa is not None:
            reason += (
                f"; vs Fusion: replay {fv:.1e}/{fa:.1e}, script {script_fv:.1e}/{script_fa:.1e} (volume/area)"
            )
        return result(check.status, reason, design_json=design_json, **common)
    if fv is not None and fa is not None and script_fv is not None and script_fa is not None:
        if min(max(fv, fa), max(script_fv, script_fa)) > FUSION_RTOL:
            return result(
                "fusion_mismatch",
                f"volume/area differ from Fusion's by {fv:.3%}/{fa:.3%} (script: "
                f"{script_fv:.3%}/{script_fa:.3%})",
                design_json=design_json,
                **common,
            )
    return result("ok", "", design_json=design_json, **common)


def precise_measures(shape: Any, eps: float = PRECISE_EPS) -> tuple[float, float]:
    """(volume, area) by adaptive integration to relative ``eps``.

    build123d's ``volume``/``area`` use OpenCASCADE's fixed-order Gauss integration, which is off
    by up to ~1e-4 relative on faces trimmed by B-spline intersection curves (two crossing
    cylinders): two identical solids built by different Boolean sequences then "differ". The
    adaptive variant agrees to ~1e-9 on them, so it decides before a design is called a mismatch.
    """
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    vol, surf = GProp_GProps(), GProp_GProps()
    BRepGProp.VolumeProperties_s(shape.wrapped, vol, eps, True)
    BRepGProp.SurfaceProperties_s(shape.wrapped, surf, eps, True)
    return abs(float(vol.Mass())), float(surf.Mass())


def symmetric_difference_rel(a: Any, b: Any) -> float:
    """vol(a - b) + vol(b - a), relative to vol(b): the last word when integration disagrees.

    On some parts bounded by many B-spline intersection curves even the adaptive integration of
    two solids the Booleans call identical differs by ~1e-6; an empty symmetric difference shows
    they are the same point set.
    """
    total = 0.0
    for x, y in ((a, b), (b, a)):
        diff = x.cut(y)
        total += sum(float(s.volume) for s in diff.solids()) if diff is not None else 0.0
    return total / max(abs(float(b.volume)), 1e-300)


@dataclass(frozen=True)
class _Check:
    """A replay compared with the script: union errors, Fusion-semantics sums, counts."""

    status: str
    reason: str
    volume_rel_error: float = math.nan
    area_rel_error: float = math.nan
    bodies_volume: float = 0.0
    bodies_area: float = 0.0
    body_count: int = 0
    face_count: int = 0


def _verify(plan: _Plan, part: Any, replay: Callable[[Design], Any]) -> _Check:
    """Replay ``plan`` and compare the union of its bodies with the script's ``part``."""
    try:
        design = parse_design(design_to_json(plan.design), plan.design.id)
        res = replay(design)
        bodies = list(res.bodies)
        union = bodies[0].fuse(*bodies[1:]).clean() if len(bodies) > 1 else bodies[0]
        dv, da = _rel(float(union.volume), float(part.volume)), _rel(float(union.area), float(part.area))
        how = ""
        if dv > VOLUME_RTOL or da > VOLUME_RTOL:
            (uv, ua), (pv, pa) = precise_measures(union), precise_measures(part)
            if uv > 0 and pv > 0:  # a broken shell (21899_d55d6c08_0024's script part) integrates to 0
                dv, da = _rel(uv, pv), _rel(ua, pa)
                how = "adaptive integration"
        if dv > VOLUME_RTOL and da <= SYMDIFF_AREA_RTOL:
            sym = symmetric_difference_rel(union, part)
            if sym <= VOLUME_RTOL:
                how = f"symmetric difference {sym:.1e} (integrated volumes differ by {dv:.1e})"
                dv = sym
    except ZoneGraphError as exc:
        return _Check("replay_failed", f"{exc.status}: {_short(exc)}")
    except _Timeout:
        raise
    except Exception as exc:
        return _Check("replay_failed", f"{type(exc).__name__}: {_short(exc)}")
    check = _Check("ok", how, dv, da, float(res.volume), float(res.area), len(bodies), int(res.face_count))
    if dv > VOLUME_RTOL or da > VOLUME_RTOL:
        reason = f"replay differs from the script: volume {dv:.2e}, area {da:.2e} relative"
        return _Check("mismatch", reason, *list(vars(check).values())[2:])
    return check


def _to_json(
    plan: _Plan, path: Path, volume: float | None, area: float | None, body_count: int, face_count: int
) -> dict:
    """Fusion-format JSON; ``properties`` carries Fusion's own volume/area and our replay's counts."""
    properties = None
    if volume is not None and area is not None:
        properties = {"volume": volume, "area": area, "body_count": body_count, "face_count": face_count}
    metadata = {
        "parent_project": plan.design.id,
        "source": "fusion360_b123d",
        "batch": f"{path.parent.name}/{path.name}",
        "function": f"model_{plan.design.id}",
        "properties_source": "volume and area: Fusion (MODELS); body_count and face_count: zonegraph replay",
    }
    return design_to_json(plan.design, properties=properties, metadata=metadata)


def convert_batch(batch_path: str | Path, timeout_s: float | None = None) -> list[ConvertedDesign]:
    """Convert every model of a batch, in file order (the batch is imported once)."""
    path = Path(batch_path)
    entries = _batch_entries(path, path.parent.name)
    return [convert_design(path, e.design_id, e.fusion_volume, e.fusion_area, timeout_s) for e in entries]


__all__ = [
    "ConvertedDesign",
    "CorpusEntry",
    "FeatureComment",
    "RecordedCall",
    "RecordedFace",
    "convert_batch",
    "convert_design",
    "edge_curve",
    "face_record",
    "feature_comments",
    "install_ocp_shims",
    "list_corpus",
    "load_batch",
    "recording",
]

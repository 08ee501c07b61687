"""Exact replay of a Fusion 360 Gallery design with build123d.

Each extrude becomes a tool solid (its profiles swept over the extent interval along the sketch
normal) and a Boolean applied with Fusion's multi-body semantics: bodies stay separate, a join
merges only the bodies the tool touches, and cuts and intersects act on each body on its own.
Results are cleaned (coplanar faces merged), as Fusion does, so face counts match its labels.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
from build123d import Compound, Face, Pos, Shape, Solid, Vector
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepExtrema import BRepExtrema_DistShapeShape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.data.design import Design, ExtentType, Extrude, Operation, Sketch
from zonegraph.data.profiles import profile_faces
from zonegraph.errors import DesignError, ReplayError, is_kernel_error
from zonegraph.geometry.cells import FUZZY_SHARES, cells_by_fuzzy
from zonegraph.geometry.occ import fuzzy_boolean, make_compound
from zonegraph.geometry.shapes import possible_volume
from zonegraph.verified import REPLAY_RTOL, Measured, disagreement, relative_difference

TOUCH_TOL = 1e-6  # cm: a join tool this close to a body merges with it
MIN_SPAN = 1e-9  # cm: a shorter extent is an empty extrusion


@dataclass(frozen=True)
class ReplayStep:
    """The state after one extrude: its tool body and every body of the design."""

    extrude: Extrude
    tool: Shape
    bodies: tuple[Solid, ...]
    seconds: float
    by_cells: bool = False  # the bodies came from the cells of all tools so far (`cells_bodies`)

    @property
    def body_count(self) -> int:
        return len(self.bodies)

    @property
    def face_count(self) -> int:
        return sum(len(b.faces()) for b in self.bodies)

    @property
    def volume(self) -> float:
        return sum(b.volume for b in self.bodies)

    @property
    def shape(self) -> Shape:
        return as_shape(self.bodies)


@dataclass(frozen=True)
class ReplayResult:
    design: Design
    steps: tuple[ReplayStep, ...]

    @property
    def bodies(self) -> tuple[Solid, ...]:
        return self.steps[-1].bodies if self.steps else ()

    @property
    def shape(self) -> Shape:
        """The final design: one solid, or a compound when Fusion would keep several bodies."""
        return self.steps[-1].shape

    @property
    def volume(self) -> float:
        return self.steps[-1].volume

    @property
    def area(self) -> float:
        return sum(b.area for b in self.bodies)

    @property
    def face_count(self) -> int:
        return self.steps[-1].face_count

    @property
    def seconds(self) -> float:
        return sum(s.seconds for s in self.steps)

    def summary(self) -> dict:
        """Plain-data description of the result (JSON and Parquet friendly)."""
        out = {
            "design": self.design.id,
            "volume": self.volume,
            "area": self.area,
            "body_count": len(self.bodies),
            "face_count": self.face_count,
            "seconds": self.seconds,
            "steps": [
                {
                    "index": i,
                    "name": s.extrude.name,
                    "operation": s.extrude.operation.name.lower(),
                    "extent_type": s.extrude.extent_type.name.lower(),
                    "tool_volume": s.tool.volume,
                    "volume": s.volume,
                    "body_count": s.body_count,
                    "face_count": s.face_count,
                    "seconds": s.seconds,
                }
                for i, s in enumerate(self.steps)
            ],
        }
        p = self.design.properties
        if p is not None:
            out["check"] = {
                "volume_rel_error": relative_difference(self.volume, p.volume),
                "area_rel_error": relative_difference(self.area, p.area),
                "body_count_expected": p.body_count,
                "face_count_expected": p.face_count,
            }
        return out

    def measured(self) -> Measured:
        return Measured(self.volume, self.area, len(self.bodies), self.face_count)

    def disagreement(self, tolerance: float = REPLAY_RTOL) -> str | None:
        """How the result differs from the file's own ``properties`` beyond ``tolerance``, or None
        (what "verified" means: `zonegraph.verified`)."""
        p = self.design.properties
        if p is None:
            return None
        return disagreement(self.measured(), p.volume, p.area, p.body_count, tolerance)


def as_shape(bodies: Iterable[Solid]) -> Shape:
    bodies = list(bodies)
    return bodies[0] if len(bodies) == 1 else Compound(bodies)


def replay(design: Design) -> ReplayResult:
    """Replay every extrude of ``design`` in timeline order, with Fusion's Boolean semantics.

    Returns:
        Every step's tool body and bodies, and the final bodies (in the design's centimetres).

    Raises:
        DesignError, UnsupportedFeatureError: a profile or extent that cannot be built exactly;
        ReplayError: an OpenCASCADE Boolean failed, and so did the cells of the tools so far.
    """
    sketches: dict[str, Sketch] = {}
    bodies: tuple[Solid, ...] = ()
    steps: list[ReplayStep] = []
    for entity in design.timeline:
        if isinstance(entity, Sketch):
            sketches[entity.id] = entity
            continue
        step = replay_extrude(bodies, entity, sketches, design.source or design.id, steps)
        steps.append(step)
        bodies = step.bodies
    if not steps:
        raise DesignError(design.source or design.id, None, "design has no extrude")
    if not bodies:
        raise ReplayError(design.source or design.id, None, "replay leaves no solid")
    return ReplayResult(design, _checked_by_cells(design, steps))


# A final volume this far (relative) from the file's own ``properties`` sends the last step to the
# cells of all tools: a join of a written program came back valid, with a volume a join allows,
# and 3% short of the part, which the cells of its tools held exactly.
CELLS_RETRY_RTOL = 1e-4


def _checked_by_cells(design: Design, steps: list[ReplayStep]) -> tuple[ReplayStep, ...]:
    """``steps``, the last one from the cells of all tools where the file's volume says the
    sequential Booleans went wrong and the cells come closer to it."""
    p, last = design.properties, steps[-1]
    if p is None or last.by_cells or relative_difference(last.volume, p.volume) <= CELLS_RETRY_RTOL:
        return tuple(steps)
    retried = cells_last(steps)
    if retried is None or relative_difference(retried[-1].volume, p.volume) >= relative_difference(
        last.volume, p.volume
    ):
        return tuple(steps)
    return retried


def cells_last(steps: Sequence[ReplayStep]) -> tuple[ReplayStep, ...] | None:
    """``steps`` with the last one's bodies from the cells of all tools (`cells_bodies`), or
    None where the cells cannot give them."""
    cells = cells_bodies(steps)
    if cells is None:
        return None
    last = steps[-1]
    return (*steps[:-1], ReplayStep(last.extrude, last.tool, cells, last.seconds, by_cells=True))


def replay_extrude(
    bodies: tuple[Solid, ...],
    extrude: Extrude,
    sketches: dict[str, Sketch],
    where: str,
    earlier: Sequence[ReplayStep] | None = None,
) -> ReplayStep:
    """Apply one extrude to ``bodies`` (which are not modified).

    ``earlier``: the steps that made ``bodies``, when known; a Boolean that fails or gives an
    invalid solid is then evaluated on the cells of all their tools (`cells_bodies`), and
    once a step came from the cells, the next ones do too where they can: a Boolean on such
    bodies can come back valid yet wrong (as in `zonegraph.sequence.program.execute`)."""
    t0 = time.perf_counter()
    try:
        tool = extrude_tool(extrude, sketches, where)
    except Exception as exc:
        if not is_kernel_error(exc):
            raise  # a ZoneGraphError already names the input; anything else is a bug of ours
        raise _kernel_failure(where, extrude, exc) from None
    history: list[ReplayStep | tuple[Extrude, Shape]] | None = (
        None if earlier is None else [*earlier, (extrude, tool)]
    )
    if earlier and earlier[-1].by_cells and history is not None:
        cells = cells_bodies(history)
        if cells is not None:
            return ReplayStep(extrude, tool, cells, time.perf_counter() - t0, by_cells=True)
    failure: ReplayError | None = None
    try:
        after = apply_operation(bodies, tool, extrude.operation)
    except Exception as exc:
        if not is_kernel_error(exc):
            raise
        failure = _kernel_failure(where, extrude, exc)
    if failure is None and not all(body.is_valid for body in after):
        failure = ReplayError(where, extrude.id, f"{extrude.operation.name.lower()} gave an invalid solid")
    if failure is None:
        return ReplayStep(extrude, tool, after, time.perf_counter() - t0)
    retried = retried_operation(bodies, tool, extrude.operation)
    if retried is not None:
        return ReplayStep(extrude, tool, retried, time.perf_counter() - t0)
    cells = cells_bodies(history) if history is not None else None
    if cells is None:
        raise failure
    return ReplayStep(extrude, tool, cells, time.perf_counter() - t0, by_cells=True)


def retried_operation(bodies: tuple[Solid, ...], tool: Shape, op: Operation) -> tuple[Solid, ...] | None:
    """A join or cut that gave an invalid solid, again with the bodies as the arguments and the
    tool as the tool, exact and then at the fuzzy values of ``FUZZY_SHARES``; the first
    valid result, else the first result repaired by OpenCASCADE's shape fixer where that is valid
    with a volume the operation allows, else None. The order matters to OpenCASCADE: a join of a
    written program whose tool-first fuse was invalid came back valid with the body first. A join
    of two pins into the round holes they fill came back invalid in every order and at every
    fuzzy value, and valid, with the volume of both, once fixed."""
    if op not in (Operation.JOIN, Operation.CUT):
        return None
    diag = float(Compound([*bodies, tool]).bounding_box().diagonal)
    first: tuple[Solid, ...] = ()
    for share in FUZZY_SHARES:
        try:
            after = _body_first(bodies, tool, op, share * diag)
        except ValueError:
            continue
        if after and all(b.is_valid for b in after):
            return after
        first = first or after
    fixed = tuple(b.fix() for b in first)
    if not fixed or not all(b.is_valid for b in fixed):
        return None
    before, held = (sum(b.volume for b in group) for group in (bodies, fixed))
    return fixed if possible_volume(op is Operation.JOIN, before, tool.volume, held) else None


def _body_first(bodies: tuple[Solid, ...], tool: Shape, op: Operation, fuzzy: float) -> tuple[Solid, ...]:
    if op is Operation.JOIN:
        touched = [b for b in bodies if touches(b, tool)]
        merged = fuzzy_boolean(
            BRepAlgoAPI_Fuse(), make_compound(t.wrapped for t in touched), tool.wrapped, fuzzy
        )
        kept = tuple(b for b in bodies if not any(b is t for t in touched))
        return kept + tuple(Shape.cast(merged).clean().solids())
    out: list[Solid] = []
    for body in bodies:
        piece = Shape.cast(fuzzy_boolean(BRepAlgoAPI_Cut(), body.wrapped, tool.wrapped, fuzzy))
        out.extend(s for s in piece.clean().solids() if s.volume > 0)
    return tuple(out)


POINT_SET_OPERATIONS = (Operation.NEW_BODY, Operation.JOIN, Operation.CUT)


def cells_bodies(steps: Sequence[ReplayStep | tuple[Extrude, Shape]]) -> tuple[Solid, ...] | None:
    """The bodies after ``steps`` from one general fuse of all their tools, each cell kept when
    the last step whose tool holds it adds material; None when that does not apply or fails.

    A chain of Booleans fails where one link does (a join of a tool sharing a cylindrical wall
    with the body comes back invalid, in the replay of a program ``zonegraph infer`` wrote,
    whose own rebuild took its cells); the cells of one fuse do not depend on the chain. They
    give the point set of new-body, join and cut steps, whatever the bodies (an intersect acts
    per body, so it is not evaluated), as one solid per connected piece: bodies that overlap
    without a join merge, which only the fallback's callers, where the Booleans failed, see."""
    pairs = [(s.extrude, s.tool) if isinstance(s, ReplayStep) else s for s in steps]
    if any(x.operation not in POINT_SET_OPERATIONS for x, _ in pairs):
        return None
    adds = [x.operation is not Operation.CUT for x, _ in pairs]
    tools = [t.wrapped for _, t in pairs]
    diag = float(Compound([t for _, t in pairs]).bounding_box().diagonal)
    for cells in cells_by_fuzzy(tools, partial(_last_adds, adds), diag):
        solids = tuple(s for s in Shape.cast(cells).solids() if s.volume > 0)
        if solids and all(s.is_valid for s in solids):
            return solids
    return None


def _last_adds(adds: list[bool], owners: frozenset[int]) -> bool:
    """Whether a cell inside the tools ``owners`` is material: the last of them adds."""
    return adds[max(owners)] if owners else False


def _kernel_failure(where: str, extrude: Extrude, exc: Exception) -> ReplayError:
    return ReplayError(where, extrude.id, f"OpenCASCADE failed: {type(exc).__name__}: {exc}")


# --------------------------------------------------------------------------------- tool bodies


def extrude_tool(extrude: Extrude, sketches: dict[str, Sketch], where: str) -> Shape:
    """The solid swept by the extrude's profiles, before any Boolean."""
    pieces: list[Solid] = []
    for ref in extrude.profiles:
        sketch = sketches[ref.sketch]
        normal = np.asarray(sketch.frame.z_axis, float)
        normal /= np.linalg.norm(normal)
        for face in profile_faces(sketch.profiles[ref.profile], sketch.frame, where):
            pieces.extend(_sweep(face, normal, extrude, where))
    # Cleaning merges the side faces of collinear profile edges, as Fusion does.
    tool = (pieces[0].fuse(*pieces[1:]) if len(pieces) > 1 else pieces[0]).clean()
    solids = tool.solids()
    if not solids:
        raise ReplayError(where, extrude.id, "extrusion produced no solid")
    return solids[0] if len(solids) == 1 else Compound(list(solids))


def _sweep(face: Face, normal: np.ndarray, x: Extrude, where: str) -> list[Solid]:
    a, b = x.interval()
    if b - a < MIN_SPAN:
        raise DesignError(where, x.id, "extrude has zero length")
    tapered = x.extent_one.taper != 0 or (x.extent_two is not None and x.extent_two.taper != 0)
    if not tapered:
        base = Pos(*(normal * a)) * face
        return [Solid.extrude(base, Vector(*(normal * (b - a))))]
    # Tapers are measured from the profile (start) plane, so each side is swept from there.
    s = x.start_offset
    if x.extent_type is ExtentType.ONE_SIDE:
        sides = [(x.extent_one.distance, x.extent_one.taper)]
    elif x.extent_type is ExtentType.SYMMETRIC:
        h = abs(x.extent_one.distance) / (2 if x.symmetric_full_length else 1)
        sides = [(h, x.extent_one.taper), (-h, x.extent_one.taper)]
    else:
        assert x.extent_two is not None
        sides = [(x.extent_one.distance, x.extent_one.taper), (-x.extent_two.distance, x.extent_two.taper)]
    base = Pos(*(normal * s)) * face
    return [_tapered(base, normal, d, t, x, where) for d, t in sides if abs(d) >= MIN_SPAN]


def _tapered(base: Face, normal: np.ndarray, distance: float, taper: float, x: Extrude, where: str) -> Solid:
    """The side swept with a taper. build123d offsets the profile with OpenCASCADE's 2D offset and
    raises a plain RuntimeError when that fails ("2D offset failed", or "Unexpected result type"
    when a steep taper splits the profile into several wires): the kernel on this geometry."""
    # Fusion's positive taper opens the profile outwards; build123d's positive taper closes it.
    try:
        return Solid.extrude_taper(base, Vector(*(normal * distance)), -math.degrees(taper))
    except RuntimeError as exc:
        raise _kernel_failure(where, x, exc) from None


# ---------------------------------------------------------------------------------- Booleans


def _copied(shape: Shape) -> Shape:
    return Shape.cast(BRepBuilderAPI_Copy(shape.wrapped).Shape())


def touches(a: Shape, b: Shape, tol: float = TOUCH_TOL) -> bool:
    box_a, box_b = a.bounding_box(), b.bounding_box()
    lo_a, hi_a = np.array(tuple(box_a.min)), np.array(tuple(box_a.max))
    lo_b, hi_b = np.array(tuple(box_b.min)), np.array(tuple(box_b.max))
    if np.any(lo_a > hi_b + tol) or np.any(lo_b > hi_a + tol):
        return False
    dist = BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    return dist.IsDone() and dist.Value() <= tol


def apply_operation(bodies: tuple[Solid, ...], tool: Shape, op: Operation) -> tuple[Solid, ...]:
    """Fusion's Boolean semantics over separate bodies.

    The Booleans take a copy of the tool: build123d's grow their operands' tolerances in place,
    and the tool goes on into the cells of later steps (`cells_bodies`). A written
    program's join gave an invalid solid, and the cells of its tools, valid when fresh, failed at
    every fuzzy value after the joins had run on them. The bodies are not copied: they are this
    step's own, and a copy changed which common a later IoU could measure. For the same reason
    the results are cleaned in place, not as `unified` does: on
    copies, the written JSON of 41125_711db4bf_0002 measured 0.9984 instead of exact."""
    tool = _copied(tool)
    tool_solids = tuple(tool.solids())
    if op is Operation.NEW_BODY:
        return bodies + tool_solids
    if op is Operation.JOIN:
        touched = [b for b in bodies if touches(b, tool)]
        if not touched:
            return bodies + tool_solids
        merged = tool.fuse(*touched).clean()
        return tuple(b for b in bodies if not any(b is t for t in touched)) + tuple(merged.solids())
    result: list[Solid] = []
    for body in bodies:
        piece = body.cut(tool) if op is Operation.CUT else body.intersect(tool)
        if piece is None:
            continue
        if not isinstance(piece, Shape):  # intersect returns a list of shapes
            piece = Compound(list(piece))
        result.extend(s for s in piece.clean().solids() if s.volume > 0)
    return tuple(result)

"""Turn a found proposal sequence into real sketch + extrude + Boolean operations.

Each step's sketch is the union of its partition faces on the start plane (merged into clean
faces with outer and inner wires), mapped back to the user's units and position; the extrude runs
along d for |d|. The program is rebuilt with build123d from those sketches, not by fusing zones,
and compared with the target by OpenCASCADE Booleans: that B-rep IoU is the honest measure.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial

import numpy as np
from build123d import Face, Shape, Solid, Vector
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.Precision import Precision
from OCP.ShapeFix import ShapeFix_Shape, ShapeFix_ShapeTolerance
from OCP.TopAbs import TopAbs_FACE, TopAbs_SHAPE, TopAbs_SOLID

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.errors import is_kernel_error
from zonegraph.geometry.cells import FUZZY_SHARES, cells_by_fuzzy, select_cells
from zonegraph.geometry.occ import (
    ancestors,
    boolean_of,
    fuzzy_boolean,
    gaps_closed,
    make_compound,
    precise_area,
    precise_volume,
    unified,
    without_internal_wires,
    without_open_shells,
)
from zonegraph.geometry.shapes import possible_volume, volume_of
from zonegraph.geometry.vec import vec3
from zonegraph.sequence.proposals import Op, Proposal, ProposalGenerator
from zonegraph.zones.model import ZoneGraph


@dataclass(frozen=True)
class ProgramStep:
    """One operation in the user's units: extrude ``faces`` by ``distance`` along ``direction``."""

    op: Op
    faces: tuple[Face, ...]  # the sketch: planar faces on the start plane, world coordinates
    origin: tuple[float, float, float]  # a point of the start plane
    direction: tuple[float, float, float]  # unit extrusion direction (the sketch normal)
    distance: float

    def tool(self) -> Shape:
        """The extruded sketch faces (fused when there are several, and cleaned as a Boolean's
        result is: merging the faces of two nested annular prisms of a corpus sketch gave an
        invalid solid of 1.6 times their volume, which build123d's fuse returned).

        A face is first turned to face the extrusion direction: a prism swept against its
        face's normal is an inside-out solid that the checker rejects and Booleans mishandle.

        Raises:
            RebuildError: a face could not be swept, or the prisms not fused.
        """
        d = Vector(*self.direction) * self.distance
        solids = [_prism(f, d) for f in self.faces]
        if len(solids) == 1:
            return solids[0]
        try:
            fused = boolean_of(BRepAlgoAPI_Fuse(), solids[0].wrapped, [s.wrapped for s in solids[1:]])
        except ValueError:
            raise RebuildError(f"the {len(solids)} prisms of a sketch did not fuse") from None
        return _cleaned(Shape.cast(fused))


def _facing(face: Face, d: Vector) -> Face:
    return face if face.normal_at().dot(d) >= 0 else Face(face.wrapped.Reversed())


def _prism(face: Face, d: Vector) -> Solid:
    """``face`` swept along ``d``; where OpenCASCADE's prism refuses the face as it is (a sketch
    face of the fuzzy partition whose wire it finds open: "Courbes non jointives"), the face
    repaired by ShapeFix, which joins such wires.

    Raises:
        RebuildError: neither face could be swept (``result.json`` says why).
    """
    try:
        return _swept_true(Solid.extrude(_facing(face, d), d), face, d)
    except Exception as exc:
        if not is_kernel_error(exc):
            raise
        first = exc
    fixed = _repaired(face).faces()
    try:
        if len(fixed) == 1:
            return Solid.extrude(_facing(fixed[0], d), d)
    except Exception as exc:
        if not is_kernel_error(exc):
            raise
    raise RebuildError(f"a sketch face could not be extruded: {type(first).__name__}: {first}")


def _swept_true(prism: Solid, face: Face, d: Vector) -> Solid:
    """``prism``, or where its volume misses the face's area times the depth by more than
    `PRISM_RTOL`, the prism of the face with its curves' gaps closed
    (`gaps_closed`) when that one is valid and sound. A prism
    missing 1.1e-4 of its volume left a zone-exact corpus program 1.3e-5 short of the target
    (21638_0a984848_0011; its written files, whose corners are shared, were not)."""
    off = _unsound(prism, face, d)
    if off <= PRISM_RTOL:
        return prism
    try:
        healed = Face(gaps_closed(face.wrapped))
        swept = Solid.extrude(_facing(healed, d), d)
        moved = abs(precise_area(healed.wrapped) / precise_area(face.wrapped) - 1)
        sound = swept.is_valid and moved <= HEAL_RTOL and _unsound(swept, healed, d) < off / 2
    except Exception as exc:
        if not is_kernel_error(exc):
            raise
        return prism
    return swept if sound else prism


def _unsound(prism: Solid, face: Face, d: Vector) -> float:
    """How far a prism's volume (integrated to 1e-9 by `volume_of`) misses its face's area
    times its depth, relative to the latter; 1 for a prism or face of no positive size (turned
    inside out). The area is integrated to 1e-9 too where the default integration, cheap but
    ~1e-4 off on spline-bounded faces, says the prism misses: read by it, a corpus spline
    profile's sound prism was healed into an inside-out one."""
    volume = volume_of(prism)
    off = _miss(volume, face.area * d.length)
    return off if off <= PRISM_RTOL else _miss(volume, precise_area(face.wrapped) * d.length)


def _miss(got: float, want: float) -> float:
    return abs(got - want) / want if want > 0 and got > 0 else 1.0


# A prism whose volume misses its sketch's area times its depth by more than this share is swept
# again from the sketch with its gaps closed; a prism of a sound face meets it to 1e-12.
PRISM_RTOL = 1e-7
# A sketch whose gaps were closed is swept only where its area moved by no more than this share:
# closing gaps within a vertex tolerance moves a region by a sliver, not by its shape.
HEAL_RTOL = 1e-3


def partition_faces(graph: ZoneGraph) -> list:
    """The OCC partition faces in the graph's face order (the order the build indexed them)."""
    if graph.solids is None:
        raise ValueError("zone graph was loaded without its zone solids")
    face_map = ancestors(make_compound(graph.solids), TopAbs_FACE, TopAbs_SOLID)
    if face_map.Size() != graph.n_faces:
        raise ValueError(f"zone solids have {face_map.Size()} faces, the graph {graph.n_faces}")
    return [face_map.FindKey(i) for i in range(1, face_map.Size() + 1)]


def merge_faces(faces: list) -> list[Face]:
    """Coplanar faces sharing edges merged into as few clean faces as possible, without the
    internal wires a merge can leave (`without_internal_wires`)."""
    shapes = [Shape.cast(f) for f in faces]
    merged = shapes[0].fuse(*shapes[1:]) if len(shapes) > 1 else shapes[0]
    return [Face(without_internal_wires(f.wrapped)) for f in _unified(merged).faces()]


def build_program(graph: ZoneGraph, steps: list[Proposal], generator: ProposalGenerator) -> list[ProgramStep]:
    """Real sketches and extrusions, in the input's units, for a found proposal sequence.

    Each sketch is the union of the proposal's partition faces (merged into clean faces), mapped
    back from the normalised frame; the extrusion runs from the start plane to the end plane.

    Raises:
        ValueError: the graph was loaded without its zone solids.
        RebuildError: OpenCASCADE failed to merge a step's faces.
    """
    faces = partition_faces(graph)
    norm = graph.normalization
    out = []
    for k, p in enumerate(steps, 1):
        with kernel_guard(f"step {k}: its sketch faces did not merge"):
            merged = merge_faces([faces[i] for i in p.faces])
        sketch = [Shape.cast(norm.apply(f.wrapped, inverse=True)) for f in merged]
        d = generator.direction(p.start, p.end) / norm.scale
        length = float(np.linalg.norm(d))
        origin = norm.to_original(graph.surface_normal[p.start] * graph.surface_offset[p.start])
        out.append(
            ProgramStep(
                p.op,
                tuple(sketch),
                vec3(origin),
                vec3(d / length),
                length,
            )
        )
    return out


class RebuildError(RuntimeError):
    """OpenCASCADE failed on the program's own sketches or tools (a robustness failure, not a
    wrong program): e.g. shapes sharing coincident curved faces it cannot resolve."""


@contextmanager
def kernel_guard(what: str) -> Iterator[None]:
    """Turns OpenCASCADE's exceptions within into a `RebuildError` naming ``what`` failed,
    so ``infer`` reports a ``rebuild_failed`` part with the reason instead of failing; anything
    else is a bug of ours and keeps its traceback."""
    try:
        yield
    except Exception as exc:
        if not is_kernel_error(exc):
            raise
        raise RebuildError(f"{what}: {type(exc).__name__}: {exc}") from None


def execute(program: list[ProgramStep]) -> list[Shape | None]:
    """The shape after each step: the first union starts the part, then unions and subtractions.

    An invalid Boolean result (a union of two prisms sharing a cylindrical wall, on the corpus)
    makes every later Boolean, and the final IoU, come back empty or wrong: each step keeps the
    first valid result of the alternatives in `_combine`, else of one general fuse of every
    tool so far (`_cells_rebuild`), else the first result it has. Once a step came from the
    cells, later steps do too where they can: a Boolean run on such a part (fuzzy, loose
    tolerances) can come back valid yet with a vertex tolerance of a few percent of the part,
    after which no common with the target holds more than a sliver of it (the measured case:
    ``docs/results/evidence.md``)."""
    shape: Shape | None = None
    states = []
    tools: list[Shape] = []
    by_cells = False
    for i, step in enumerate(program):
        with kernel_guard(f"step {i + 1}: its tool failed"):
            tools.append(step.tool())
        if shape is None:
            shape = tools[-1] if step.op is Op.UNION else None
        else:
            with kernel_guard(f"step {i + 1}: its Boolean failed"):
                shape, by_cells = _step(shape, tools, [s.op for s in program[: i + 1]], by_cells)
        states.append(shape)
    return states


# How far a program's B-rep IoU may fall below its zone IoU before its part is measured again from
# the cells: the exactness threshold's scale (zone and B-rep IoU of the corpus agree far closer).
AGREE_TOL = 1e-4


def measured(program: list[ProgramStep], part: Shape, target: Shape, zone_iou: float) -> tuple[Shape, float]:
    """The program's part and its B-rep IoU with ``target``: the sequential rebuild's, or where
    that falls short of ``zone_iou`` (the program's IoU on the zones its prisms are made of), the
    same program evaluated on the cells of one general fuse of its tools, when that measures
    higher. A diagnosis part's 15-step program rebuilt to the target's volume (to 8e-7) yet every
    common of it with the target came back empty (IoU 0, zone IoU 0.99999998); its cells measured
    0.9999999. The cells are the same program, evaluated another way."""
    iou = brep_iou(part, target)
    if iou >= zone_iou - AGREE_TOL or len(program) < 2:
        return part, iou
    try:
        tools = [step.tool() for step in program]
    except RebuildError:  # the rebuild made these tools once already; a retry that fails keeps it
        return part, iou
    diag = float(target.bounding_box().diagonal)
    cells = _cells_rebuild([step.op for step in program], tools, diag)
    again = brep_iou(cells, target) if cells is not None else 0.0
    return (cells, again) if cells is not None and again > iou else (part, iou)


def _step(shape: Shape, tools: list[Shape], ops: list[Op], by_cells: bool) -> tuple[Shape, bool]:
    """The part after the last of ``ops`` from the part before it (``shape``), and whether it came
    from the cells: first from the cells when the part before did, then from the Booleans, then
    from the cells; a valid result first (from the Booleans, one with a possible volume too),
    else one from the Booleans, else one at all.

    Raises:
        RebuildError: neither the Booleans nor the cells gave a result (``result.json`` says so).
    """
    diag = float(shape.bounding_box().diagonal)
    cells = _cells_rebuild(ops, tools, diag) if by_cells else None
    if cells is not None and cells.is_valid:
        return cells, True
    combined, accepted = _combine(shape, tools[-1], ops[-1])
    if accepted and combined is not None:
        return combined, False
    if not by_cells:
        cells = _cells_rebuild(ops, tools, diag)
    if cells is not None and (cells.is_valid or combined is None):
        return cells, True
    if combined is None:
        op = ops[-1].name.lower()
        raise RebuildError(f"step {len(ops)}: {op} failed (Booleans and cells of all tools)")
    return combined, False


def _combine(shape: Shape, tool: Shape, op: Op) -> tuple[Shape | None, bool]:
    """``shape`` fused with or cut by ``tool``, trying in turn: the operands as they are, the tool
    repaired, fuzzy values, and the part so far repaired; with whether the result is accepted.
    The first result the checker accepts with a volume the operation allows (`_possible`)
    wins, else the first result as it came: an invalid part often still takes the next Booleans,
    while repairing one in place can break the next union (``docs/results/evidence.md``). None
    when every Boolean failed."""
    diag = float(shape.bounding_box().diagonal)
    first = None
    for x, y, share in _alternatives(shape, tool):
        result = _boolean(x, y, op, share * diag)
        if result is not None and result.is_valid and _possible(shape, tool, op, result):
            return result, True
        if first is None:
            first = result
    return first, False


def _possible(shape: Shape, tool: Shape, op: Op, result: Shape) -> bool:
    return possible_volume(op is Op.UNION, shape.volume, tool.volume, result.volume)


def _cells_rebuild(ops: list[Op], tools: list[Shape], diag: float) -> Shape | None:
    """The program ``ops`` evaluated on the cells of one general fuse of its ``tools`` (at the
    fuzzy values of ``FUZZY_SHARES``): a cell is kept when the last step whose tool contains it is
    a union. It does not depend on the part so far, which earlier invalid Booleans may have made
    wrong (a cut that comes back invalid with part of the volume, a union that fails outright):
    the cells rebuild such parts exactly, in a fraction of a second per fuse on corpus parts
    (the measured cases: ``docs/results/evidence.md``). The first result the checker accepts
    wins, else the first with volume; None when every fuse failed."""
    first = None
    for cells in cells_by_fuzzy([t.wrapped for t in tools], partial(_kept, ops), diag):
        result = Shape.cast(cells)
        if not result.volume > 0:
            continue
        if result.is_valid:
            return result
        if first is None:
            first = result
    return first


def _kept(ops: list[Op], owners: frozenset[int]) -> bool:
    """Whether a cell inside the tools ``owners`` is in the part after ``ops``."""
    inside = False
    for i, op in enumerate(ops):
        if i in owners:
            inside = op is Op.UNION
    return inside


def _alternatives(shape: Shape, tool: Shape) -> Iterator[tuple[Shape, Shape, float]]:
    yield shape, tool, 0.0
    if not tool.is_valid:
        yield shape, _repaired(tool), 0.0
    for share in FUZZY_SHARES[1:]:
        yield shape, tool, share
    if not shape.is_valid:
        yield _repaired(shape), tool, 0.0


def _boolean(shape: Shape, tool: Shape, op: Op, fuzzy: float) -> Shape | None:
    """One OpenCASCADE fuse or cut, cleaned; None when it fails or comes back empty."""
    algo = BRepAlgoAPI_Fuse() if op is Op.UNION else BRepAlgoAPI_Cut()
    try:
        out = fuzzy_boolean(algo, shape.wrapped, tool.wrapped, fuzzy)
    except ValueError:
        return None
    if out.IsNull():
        return None
    result = Shape.cast(out)
    return _cleaned(result) if result.volume > 0 else None


def _cleaned(shape: Shape) -> Shape:
    """``shape`` with its same-domain faces merged (`unified`, on a
    copy, so the raw shape stays as it was), unless the merge breaks a valid shape: seen on a
    corpus part whose valid union of two prisms came back invalid from it, so every alternative
    and the cells failed with it and a program exact on zones was reported ``rebuild_failed``.
    The merged faces are cosmetic. Stray open shells are dropped
    (`without_open_shells`)."""
    cleaned = _unified(shape)
    chosen = cleaned if cleaned.is_valid or not shape.is_valid else shape
    return Shape.cast(without_open_shells(chosen.wrapped))


def _repaired(shape: Shape) -> Shape:
    fix = ShapeFix_Shape(shape.wrapped)
    fix.Perform()
    return Shape.cast(fix.Shape())


# Relative volume difference below which two solids whose commons all fell short are measured
# again with the part's tolerances limited: the IoU's own exactness threshold. Partial programs
# (most differ from the target by far more) skip those two commons.
ALIKE_RTOL = 1e-4


def brep_iou(a: Shape | None, b: Shape, fuzzy: float = 0.0) -> float:
    """vol(a and b) / vol(a or b) with OpenCASCADE Booleans, volumes by `volume_of`.

    A Boolean common of two coincident solids can come back empty although both are valid, and
    which call fails depends on the argument order (on the corpus: common(program, target) empty,
    common(target, program) whole), on a repair of one operand or on a fresh copy of the other.
    A failed common loses volume, it does not invent it, so the largest of these is the
    intersection; the next is tried only while the last fell short of the smaller solid.
    ``fuzzy`` > 0 takes faces closer than that as one: for a part meant to lie that close to the
    other (an export with snapped numbers), whose plain common of faces a hair apart can come
    back with almost no volume."""
    if a is None:
        return 0.0
    volume_a, volume_b = volume_of(a), volume_of(b)
    full = (1 - 1e-9) * min(volume_a, volume_b)
    inter = 0.0
    alike = abs(volume_a - volume_b) <= ALIKE_RTOL * max(volume_a, volume_b)
    for x, y, value in _common_operands(a, b, fuzzy, alike):
        inter = max(inter, _common_volume(x, y, value))
        if inter >= full:
            break
    if inter < full and fuzzy > 0.0:
        inter = max(inter, _cells_common(a, b, fuzzy))
    if inter < full and fuzzy > 0.0:
        inter = max(inter, _fused_common(a, b, fuzzy, volume_a, volume_b))
    inter = min(inter, volume_a, volume_b)  # volume integration error can exceed an operand's volume
    union = volume_a + volume_b - inter
    return inter / union if union > 0 else 1.0


def _common_operands(a: Shape, b: Shape, fuzzy: float, alike: bool) -> Iterator[tuple[Shape, Shape, float]]:
    """Both orders at ``fuzzy``, then (when that is not 0) both exact, then with a fuzzy value of
    1e-9 of the part (a valid program whose exact commons with the target were all empty took
    it), then a repaired part, and, for solids of the same volume (``alike``), the part with its
    tolerances limited (`_tightened`); each common takes fresh copies
    (`_common_volume`). A fuzzy value helps faces a hair apart and can itself lose the
    volume (a written file of a corpus part whose commons at every fuzzy value from 1e-9 to 1e-4
    of the part held 4% of it, and its exact common all of it). Lazy: the usual first common is
    whole, and nothing after it is computed."""
    yield a, b, fuzzy
    yield b, a, fuzzy
    if fuzzy > 0.0:
        yield a, b, 0.0
        yield b, a, 0.0
    tiny = 1e-9 * float(b.bounding_box().diagonal)
    if tiny > fuzzy:
        yield a, b, tiny
        yield b, a, tiny
    yield _repaired(_copy(a)), b, fuzzy
    tight = _tightened(a) if alike else None
    if tight is not None and tight.is_valid:
        yield tight, b, fuzzy
        yield b, tight, fuzzy


def _cells_common(a: Shape, b: Shape, fuzzy: float) -> float:
    """The common as the cells that both hold in one general fuse of the two at ``fuzzy``: the
    written JSON of a corpus part, 2e-6 off the target's volume, had every Boolean common empty
    (in both orders, at every value tried) while these cells held all of it. Only where the
    caller measures at a fuzzy value (the written files' check): exact solids rebuilt on zones
    get their commons from the Booleans."""
    try:
        cells = select_cells([_copy(a).wrapped, _copy(b).wrapped], lambda owners: len(owners) == 2, fuzzy)
    except RuntimeError:
        return 0.0
    return precise_volume(cells)


# How closely a cut must agree with the intersection a fuse implies (relative to the larger
# solid): volume integration to 1e-9 leaves the two a few 1e-7 apart on the measured cases.
FUSED_AGREE_RTOL = 1e-6


def _fused_common(a: Shape, b: Shape, fuzzy: float, volume_a: float, volume_b: float) -> float:
    """The common's volume as vol(a) + vol(b) - vol(a or b), where a cut of one by the other at
    ``fuzzy`` (or exactly) leaves what that implies; 0 where none does or the fuse fails.

    Two written files of corpus parts, each with the program's volume at every step, had every
    Boolean common with the target come back nearly empty, the cells' too, after their faces
    were unified, while their fuse with the target held what the program's own rebuild measured.
    A fuse that drops volume would overstate the common, so a second Boolean has to agree: both
    would have to fail by the same amount for a wrong common to pass."""
    try:
        union = precise_volume(fuzzy_boolean(BRepAlgoAPI_Fuse(), a.wrapped, b.wrapped, fuzzy))
    except (ValueError, RuntimeError):
        return 0.0
    inter = volume_a + volume_b - union
    tol = FUSED_AGREE_RTOL * max(volume_a, volume_b)
    if not -tol <= inter <= min(volume_a, volume_b) + tol:
        return 0.0
    for x, y, left in ((a, b, volume_a - inter), (b, a, volume_b - inter)):
        for value in (fuzzy, 0.0):
            try:
                cut = precise_volume(fuzzy_boolean(BRepAlgoAPI_Cut(), x.wrapped, y.wrapped, value))
            except (ValueError, RuntimeError):
                continue
            if abs(cut - left) <= tol:
                return max(inter, 0.0)
    return 0.0


def _unified(shape: Shape) -> Shape:
    return Shape.cast(unified(shape.wrapped))


def _copy(shape: Shape) -> Shape:
    return Shape.cast(BRepBuilderAPI_Copy(shape.wrapped).Shape())


def _tightened(shape: Shape) -> Shape:
    """A copy of ``shape`` with every tolerance limited to OpenCASCADE's confusion (1e-7).

    The program's sketches are partition faces of the zone graph's fuzzy fuse, whose tolerances
    (up to 1e-6 of the normalised part) its Booleans pass on to the rebuilt part, where they can
    grow until they swallow the target's small steps and every common with the target loses
    part of the volume; limited to 1e-7 (1e-6 is not always enough) such a part, still valid,
    measures its true IoU (the measured case: ``docs/results/evidence.md``)."""
    copy = BRepBuilderAPI_Copy(shape.wrapped).Shape()
    ShapeFix_ShapeTolerance().LimitTolerance(copy, 0.0, Precision.Confusion_s(), TopAbs_SHAPE)
    return Shape.cast(copy)


def _common_volume(a: Shape, b: Shape, fuzzy: float) -> float:
    """The volume of one common, taken of copies: a Boolean may enlarge the tolerances of its
    operands in place, after which later commons with them fail (a target measured against a
    written JSON whose commons all failed then had empty commons with every other file)."""
    a, b = _copy(a), _copy(b)
    try:
        if fuzzy <= 0.0:
            return volume_of(a.intersect(b))
        return precise_volume(fuzzy_boolean(BRepAlgoAPI_Common(), a.wrapped, b.wrapped, fuzzy))
    except ValueError:  # a null or failed Boolean result
        return 0.0

"""Reading, writing and comparing B-rep shapes, with errors that name the file.

STEP files are written with a centimetre unit declaration (Fusion 360 Gallery's unit) so readers
convert them correctly; OpenCASCADE reads every STEP file back in millimetres. BREP files are the
lossless native format used between pipeline stages (no unit: the design's centimetres).

Files are read with OCP's own readers (`read_kernel_shape`, `read_kernel_solids`):
building a zone graph needs nothing more, and importing build123d would double a short command's
start-up time and memory. `read_shape` and `read_solids` wrap the same shapes as
build123d objects for the paths that use its API (replay, programs, the exported script).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from OCP.BRep import BRep_Builder
from OCP.BRepTools import BRepTools
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_ShapeEnum, TopAbs_SOLID
from OCP.TopoDS import TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.console import captured
from zonegraph.errors import InputError, require_file
from zonegraph.geometry.occ import precise_volume, sub_shapes

if TYPE_CHECKING:
    from build123d import Shape, Solid, Unit

SHAPE_SUFFIXES = (".step", ".stp", ".brep")
KIND_NAMES = {TopAbs_FACE: "Face", TopAbs_EDGE: "Edge"}  # as build123d names them in messages


def _read_file(path: Path) -> TopoDS_Shape | None:
    """The file's shape (every STEP root in one shape, its assembly locations applied), or None
    when the reader finds nothing; OCP raises bare RuntimeError/ValueError for some corrupt files."""
    if path.suffix.lower() == ".brep":
        shape = TopoDS_Shape()
        BRepTools.Read_s(shape, str(path), BRep_Builder())
        return shape
    reader = STEPControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        return None
    reader.TransferRoots()
    return reader.OneShape()


def read_kernel_shape(path: str | Path) -> TopoDS_Shape:
    """A STEP or BREP file as one OCP shape; InputError for missing, empty or corrupt files."""
    path = Path(path)
    require_file(path)
    if path.stat().st_size == 0:
        raise InputError(str(path), "file is empty")
    suffix = path.suffix.lower()
    if suffix not in SHAPE_SUFFIXES:
        raise InputError(str(path), f"unknown shape format {suffix!r} (expected .step/.stp/.brep)")
    with captured() as console:  # the STEP reader prints its syntax errors from C++
        try:
            shape, error = _read_file(path), ""
        except Exception as exc:  # a corrupt file is the input's fault
            shape, error = None, " ".join(str(exc).split())
    if shape is None or shape.IsNull():
        said = console.kernel_errors()
        why = f": {said[0]}" if said else f" ({error})" if error else ""
        raise InputError(str(path), f"file holds no shape (corrupt or empty){why}")
    return shape


def unique_sub_shapes(shape: TopoDS_Shape, kind: TopAbs_ShapeEnum) -> list[TopoDS_Shape]:
    """Sub-shapes in exploration order, each once (build123d's ``solids()``/``faces()`` order)."""
    return list({hash(s): s for s in sub_shapes(shape, kind)}.values())


def read_kernel_solids(path: str | Path) -> list[TopoDS_Shape]:
    """The solids of a file as OCP shapes; InputError when it holds only sheets, wires or nothing."""
    shape = read_kernel_shape(path)
    solids = unique_sub_shapes(shape, TopAbs_SOLID)
    if not solids:
        kinds = [KIND_NAMES[k] for k in (TopAbs_FACE, TopAbs_EDGE) if sub_shapes(shape, k)][:1]
        raise InputError(str(path), f"not a solid (holds {', '.join(kinds) or 'nothing'})")
    return solids


def read_shape(path: str | Path) -> Shape:
    """A STEP or BREP file as one build123d shape (`read_kernel_shape`)."""
    from build123d import Compound

    return Compound.cast(read_kernel_shape(path))


def read_solids(path: str | Path) -> list[Solid]:
    """The solids of a file as build123d solids (`read_kernel_solids`)."""
    from build123d import Solid

    return [Solid(s) for s in read_kernel_solids(path)]


def write_step(shape: Shape, path: str | Path, unit: Unit | None = None) -> Path:
    """A STEP file declaring ``unit`` (the unit the shape's numbers are in; default cm, the
    designs' unit)."""
    from build123d import Unit, export_step

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not export_step(shape, str(path), unit=Unit.CM if unit is None else unit):
        raise OSError(f"{path}: STEP export failed")
    return path


def write_brep(shape: Shape, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not BRepTools.Write_s(shape.wrapped, str(path)):
        raise OSError(f"{path}: BREP export failed")
    return path


def symmetric_difference_volume(a: Shape, b: Shape) -> float:
    """vol(a - b) + vol(b - a), the B-rep distance used for every exactness check."""
    return volume_of(a.cut(b)) + volume_of(b.cut(a))


# Relative slack of `possible_volume`'s bounds, for volume integration error: a failed
# Boolean that the checker accepts loses far more (a valid union of a corpus part that held 1%).
POSSIBLE_RTOL = 1e-5


def possible_volume(union: bool, part: float, tool: float, result: float) -> bool:
    """Whether ``result`` is a volume that ``part`` fused with (``union``) or cut by ``tool`` can
    have: a union holds at least the larger operand and at most both, a cut at most the part and
    at least the part less the tool. The checker accepts some Boolean results that lose most of
    the part, and the shape fixer can make one valid by dropping what it cannot mend."""
    slack = POSSIBLE_RTOL * (part + tool)
    low, high = (max(part, tool), part + tool) if union else (part - tool, part)
    return low - slack <= result <= high + slack


def volume_of(shape: Shape | list[Shape] | None) -> float:
    """Volume of a Boolean result: a shape, a list of shapes (build123d's intersect) or None,
    integrated to 1e-9 (`precise_volume`)."""
    shapes = [] if shape is None else shape if isinstance(shape, list) else [shape]
    return sum(precise_volume(s.wrapped) for s in shapes)

"""Reading, writing and comparing B-rep shapes, with errors that name the file.

STEP files are written with a centimetre unit declaration (Fusion 360 Gallery's unit) so readers
convert them correctly; OpenCASCADE reads every STEP file back in millimetres. BREP files are the
lossless native format used between pipeline stages (no unit: the design's centimetres).
"""

from __future__ import annotations

from pathlib import Path

from build123d import Shape, Solid, Unit, export_step, import_brep, import_step
from OCP.BRepTools import BRepTools

from zonegraph.console import captured
from zonegraph.errors import InputError, require_file
from zonegraph.geometry.occ import precise_volume


def read_shape(path: str | Path) -> Shape:
    """A STEP or BREP file as one shape; InputError for missing, empty or corrupt files."""
    path = Path(path)
    require_file(path)
    if path.stat().st_size == 0:
        raise InputError(str(path), "file is empty")
    suffix = path.suffix.lower()
    if suffix not in (".step", ".stp", ".brep"):
        raise InputError(str(path), f"unknown shape format {suffix!r} (expected .step/.stp/.brep)")
    with captured() as console:  # the STEP reader prints its syntax errors from C++
        try:
            shape = import_brep(str(path)) if suffix == ".brep" else import_step(str(path))
        except Exception as exc:  # OCP raises bare RuntimeError/ValueError for corrupt files
            shape, error = None, " ".join(str(exc).split())
        else:
            error = ""
    if shape is None or shape.is_null:
        said = console.kernel_errors()
        why = f": {said[0]}" if said else f" ({error})" if error else ""
        raise InputError(str(path), f"file holds no shape (corrupt or empty){why}")
    return shape


def read_solids(path: str | Path) -> list[Solid]:
    """The solids of a file; InputError when it holds only sheets, wires or nothing."""
    shape = read_shape(path)
    solids = list(shape.solids())
    if not solids:
        kinds = ", ".join(sorted({type(s).__name__ for s in (shape.faces() or shape.edges())})) or "nothing"
        raise InputError(str(path), f"not a solid (holds {kinds})")
    return solids


def write_step(shape: Shape, path: str | Path, unit: Unit = Unit.CM) -> Path:
    """A STEP file declaring ``unit`` (the unit the shape's numbers are in; designs use cm)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not export_step(shape, str(path), unit=unit):
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


def volume_of(shape: Shape | list[Shape] | None) -> float:
    """Volume of a Boolean result: a shape, a list of shapes (build123d's intersect) or None,
    integrated to 1e-9 (:func:`~zonegraph.geometry.occ.precise_volume`)."""
    shapes = [] if shape is None else [shape] if isinstance(shape, Shape) else shape
    return sum(precise_volume(s.wrapped) for s in shapes)

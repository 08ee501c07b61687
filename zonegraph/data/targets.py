"""Load a reconstruction target from a user's file: a STEP/BREP solid or a design JSON.

A STEP or BREP file is read by OCP alone (:func:`load_kernel_target`), so building its zone
graph never imports build123d; a design JSON is replayed, which needs build123d's API.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from zonegraph.geometry.shapes import read_kernel_solids

if TYPE_CHECKING:
    from build123d import Solid
    from OCP.TopoDS import TopoDS_Shape


def _replayed(path: Path) -> list[Solid]:
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay

    return list(replay(load_design(path)).bodies)


def load_target(path: str | Path) -> list[Solid]:
    """The target solids; a design JSON stands for its final shape (all its bodies)."""
    from build123d import Solid

    path = Path(path)
    if path.suffix.lower() == ".json":
        return _replayed(path)
    return [Solid(s) for s in read_kernel_solids(path)]


def load_kernel_target(path: str | Path) -> list[TopoDS_Shape]:
    """The target solids as OCP shapes (the same solids as :func:`load_target`)."""
    path = Path(path)
    if path.suffix.lower() == ".json":
        return [s.wrapped for s in _replayed(path)]
    return read_kernel_solids(path)

"""Load a reconstruction target from a user's file: a STEP/BREP solid or a design JSON."""

from __future__ import annotations

from pathlib import Path

from build123d import Solid

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.shapes import read_solids


def load_target(path: str | Path) -> list[Solid]:
    """The target solids; a design JSON stands for its final shape (all its bodies)."""
    path = Path(path)
    if path.suffix.lower() == ".json":
        return list(replay(load_design(path)).bodies)
    return read_solids(path)

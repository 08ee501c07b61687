"""The solid a replay must equal: the script's part, or its repair where the part is invalid.

build123d's Booleans sometimes leave the script's part an invalid solid (a face of the shell
reversed, an edge left unshared); its integrated volume is then wrong even where every face is
right, so no correct replay could match it. ShapeFix repairs such a shell without moving a face;
the repaired part is the reference only when it is a valid solid, and the row says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Reference:
    """The shape verification compares with, and why it is not the script's own part."""

    shape: Any
    note: str = ""


def reference_part(part: Any) -> Reference:
    """``part`` itself when valid, else its ShapeFix repair when that is a valid solid."""
    from build123d import Shape
    from OCP.ShapeFix import ShapeFix_Shape

    if part.is_valid:
        return Reference(part)
    fix = ShapeFix_Shape(part.wrapped)
    fix.Perform()
    repaired = Shape.cast(fix.Shape())
    if repaired.is_valid and repaired.solids() and float(repaired.volume) > 0:
        return Reference(repaired, "the script's part is an invalid solid: verified against its repair")
    return Reference(part, "the script's part is an invalid solid (ShapeFix cannot repair it)")

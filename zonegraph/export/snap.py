"""Simpler numbers for the exported program: each value snapped to the shortest decimal nearby.

A found program's numbers come out of OpenCASCADE and the zone graph's normalisation carrying
float noise: 0.4499999866 for a designer's 0.45, 0.750000011176 for a float32 0.75, 1e-14 for 0.
People edit the script, so each length is written as the value with the fewest decimals within a
tolerance relative to the part (``REL_TOL`` of its bounding-box diagonal: far below anything a
designer means, far above float noise). A unit vector keeps its components (0.7071067811865476 is
no noise) except those next to 0 or +-1 (closer than a turn that moves the part by no more than a
length may move), and is renormalised. Snapping alone proves
nothing about the part: `zonegraph.export.verify` rebuilds what is written and falls back to
the raw numbers when the snapped ones lose exactness.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

REL_TOL = 1e-6  # a length may move this fraction of the part's bounding-box diagonal
MAX_DECIMALS = 15  # beyond this a double has no shorter decimal to offer
ZERO = 1e-9  # a raw written value this close to zero is written as 0 (OpenCASCADE's tolerance is 1e-7)


def written(x: float) -> str:
    """A number as the script writes it: at most 12 significant digits, positional (0.00003, not
    3e-05), never ``-0``, noise below 1e-9 as 0."""
    x = float(x)
    if abs(x) < ZERO:
        return "0"
    return str(np.format_float_positional(x, precision=12, fractional=False, trim="-"))


def simplest(x: float, tol: float) -> float:
    """The value with the fewest decimals within ``tol`` of ``x`` (``x`` itself when none is).

    ``+ 0.0`` turns a negative zero into zero, so ``-0`` is never written."""
    x = float(x)
    for decimals in range(MAX_DECIMALS + 1):
        candidate = round(x, decimals)
        if abs(candidate - x) <= tol:
            return candidate + 0.0
    return x + 0.0


def _unit_component(c: float, tol: float) -> float:
    """A direction component: 0 or +-1 when that close, else unchanged."""
    if abs(c) <= tol:
        return 0.0
    if abs(abs(c) - 1.0) <= tol:
        return float(np.sign(c))
    return float(c) + 0.0


@dataclass
class Snapper:
    """Snaps a program's lengths and directions as they are written, counting what it changed.

    ``tol`` is in the input's units; ``unit_tol`` applies to direction components (chosen so that
    the turn it allows moves the part no more than ``tol``). A snapper with both tolerances zero
    writes the raw numbers.
    """

    tol: float
    unit_tol: float
    changed: int = 0  # numbers whose written text differs from the raw number's

    @classmethod
    def for_part(cls, diagonal: float, reach: float, rel: float = REL_TOL) -> Snapper:
        """Tolerances for a part of bounding-box ``diagonal`` whose farthest point lies ``reach``
        from the input's origin (both in the input's units). Sketch coordinates are measured from
        the plane's point nearest that origin, so turning a plane by an angle moves the part by
        at most the angle times twice ``reach``: ``unit_tol`` keeps that within ``tol`` too."""
        tol = rel * diagonal
        return cls(tol=tol, unit_tol=tol / max(diagonal, 2.0 * reach))

    @classmethod
    def raw(cls) -> Snapper:
        """The identity: the fallback when snapped numbers do not rebuild the part as well."""
        return cls(tol=0.0, unit_tol=0.0)

    def _count(self, raw: Sequence[float] | np.ndarray, new: Sequence[float] | np.ndarray) -> None:
        self.changed += sum(written(a) != written(b) for a, b in zip(raw, new, strict=True))

    def length(self, x: float) -> float:
        new = simplest(x, self.tol)
        self._count([x], [new])
        return new

    def point(self, p: Sequence[float] | np.ndarray) -> np.ndarray:
        raw = np.asarray(p, float)
        new = np.array([simplest(c, self.tol) for c in raw])
        self._count(raw, new)
        return new

    def direction(self, v: Sequence[float] | np.ndarray) -> np.ndarray:
        """A unit vector with near-0/+-1 components snapped, renormalised (still unit length)."""
        raw = np.asarray(v, float)
        new = np.array([_unit_component(c, self.unit_tol) for c in raw])
        new = new / np.linalg.norm(new) + 0.0
        self._count(raw / np.linalg.norm(raw), new)
        return new

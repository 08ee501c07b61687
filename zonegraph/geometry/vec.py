"""Plain 3-vectors: the typed tuples the design model and programs store (hashable, JSON-ready)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Vec3 = tuple[float, float, float]


def vec3(v: Sequence[float] | np.ndarray) -> Vec3:
    """Any 3-sequence (a numpy row, a list) as a tuple of three Python floats."""
    return float(v[0]), float(v[1]), float(v[2])

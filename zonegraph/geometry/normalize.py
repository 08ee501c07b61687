"""Centre a target on its bounding box and scale it to a unit diagonal.

Every absolute tolerance of the zone graph (fuzzy value, de-duplication, sliver sizes) is stated in
these normalised units, so the same numbers work for a 1 mm bracket and a 10 m beam. The transform
is kept so results can be mapped back into the user's units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Trsf
from OCP.TopoDS import TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import bounds, pnt, vec
from zonegraph.geometry.vec import vec3


@dataclass(frozen=True)
class Normalization:
    """normalised = (original - center) * scale."""

    center: tuple[float, float, float]
    scale: float

    @classmethod
    def of(cls, shape: TopoDS_Shape) -> Normalization:
        b = bounds(shape)
        lo, hi = b[:3], b[3:]
        diag = float(np.linalg.norm(hi - lo))
        return cls(vec3((lo + hi) / 2), 1.0 / diag)

    def trsf(self, inverse: bool = False) -> gp_Trsf:
        move, scale = gp_Trsf(), gp_Trsf()
        move.SetTranslation(vec(-np.asarray(self.center)))
        scale.SetScale(pnt((0, 0, 0)), self.scale)
        t = scale.Multiplied(move)
        return t.Inverted() if inverse else t

    def apply(self, shape: TopoDS_Shape, inverse: bool = False) -> TopoDS_Shape:
        return BRepBuilderAPI_Transform(shape, self.trsf(inverse), True).Shape()

    def to_original(self, points: np.ndarray) -> np.ndarray:
        return np.asarray(points) / self.scale + np.asarray(self.center)

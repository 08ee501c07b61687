"""The Booleans of the rebuild, the replay and the IoU leave their operands as they were."""

from __future__ import annotations

import pytest
from build123d import Box, Pos, Shape
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance

from zonegraph.geometry.occ import fuzzy_boolean


def _max_tolerance(shape: Shape) -> float:
    return ShapeAnalysis_ShapeTolerance().Tolerance(shape.wrapped, 1)


@pytest.mark.parametrize("operation", [BRepAlgoAPI_Fuse, BRepAlgoAPI_Cut, BRepAlgoAPI_Common])
def test_a_fuzzy_boolean_does_not_enlarge_its_operands_tolerances(operation):
    """A fuzzy value bridges a gap by growing the tolerances of the sub-shapes it joins; done on
    the operands themselves, a part kept from an earlier step changes under the next Boolean
    (a rebuilt part after a cut that then held 2e-4 less of itself)."""
    a = Box(1, 1, 1)
    b = Pos(0.5, 0.3, 1e-5) * Box(1, 1, 1)  # its top face 1e-5 above a's
    before = _max_tolerance(a), _max_tolerance(b)
    result = Shape.cast(fuzzy_boolean(operation(), a.wrapped, b.wrapped, 1e-4))
    assert result.volume > 0
    assert (_max_tolerance(a), _max_tolerance(b)) == before

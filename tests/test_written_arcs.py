"""Arcs as the files write them (export.writers._arc_through): through the loop's corners, on the
circle nearest the edge's own curve wherever the corners lie off it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from build123d import ThreePointArc

from zonegraph.export.writers import _arc_through


def _along(centre: np.ndarray, radius: float, first: float, last: float, count: int = 9) -> np.ndarray:
    angles = np.linspace(first, last, count)
    return centre + radius * np.stack([np.cos(angles), np.sin(angles), np.zeros(count)], axis=1)


def test_a_half_circle_whose_corners_lie_off_it_keeps_its_centre():
    # A corpus semicircle (136473_1a062e83_0000): radius 4 about (4, -6.488091), its corners on
    # the lines it meets, 1.8e-5 off the circle, so the chord is longer than the diameter.
    centre = np.array([4.0, -6.488091, 0.0])
    start, end = np.array([0.0, -6.5, 0.0]), np.array([8.0, -6.488091, 0.0])
    curve = _along(centre, 4.0, math.pi + 0.002977, 2 * math.pi)
    new_centre, radius, mid = _arc_through(start, end, centre, curve)
    assert np.linalg.norm(new_centre - centre) < 1e-4
    assert radius == pytest.approx(4.0, abs=1e-4)
    arc = ThreePointArc(tuple(start), tuple(mid), tuple(end))
    assert np.array(tuple(arc.arc_center)) == pytest.approx(new_centre, abs=1e-9)
    assert arc.radius == pytest.approx(radius, abs=1e-9)


def test_a_short_arc_whose_corner_lies_off_it_keeps_its_bulge():
    # A 0.008 cm arc of radius 2.6 with a corner 1.3e-5 outside its circle: through the edge's
    # own mid point the three points are collinear to OpenCASCADE.
    half = math.asin(0.004 / 2.6)
    centre = np.zeros(3)
    start = 2.6 * np.array([math.cos(-half), math.sin(-half), 0.0])
    end = (2.6 + 1.3e-5) * np.array([math.cos(half), math.sin(half), 0.0])
    new_centre, radius, mid = _arc_through(start, end, centre, _along(centre, 2.6, -half, half))
    assert np.linalg.norm(new_centre - start) == pytest.approx(radius, abs=1e-12)
    assert np.linalg.norm(new_centre - end) == pytest.approx(radius, abs=1e-12)
    assert radius == pytest.approx(2.6, abs=1e-4)
    arc = ThreePointArc(tuple(start), tuple(mid), tuple(end))
    assert arc.position_at(0.5).X > (start[0] + end[0]) / 2  # bulging away from the centre


@pytest.mark.parametrize("sweep", [0.3, 1.5, 3.0, 4.5, 6.0])
def test_an_arc_whose_corners_lie_on_it_is_written_as_it_is(sweep):
    centre = np.array([1.0, 2.0, 0.0])
    curve = _along(centre, 3.0, 0.2, 0.2 + sweep)
    new_centre, radius, mid = _arc_through(curve[0], curve[-1], centre, curve)
    assert new_centre == pytest.approx(centre, abs=1e-9)
    assert radius == pytest.approx(3.0, abs=1e-9)
    assert mid == pytest.approx(curve[len(curve) // 2], abs=1e-9)

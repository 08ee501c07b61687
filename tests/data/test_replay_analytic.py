"""Replay semantics checked against closed-form volumes and positions on hand-written designs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.testing import fusion_json as fj

SQUARE = [(True, fj.rect(0, 0, 2, 2))]  # area 4


def run(tmp_path, *entities):
    return replay(load_design(fj.write(tmp_path, fj.design(*entities))))


def z_range(result):
    """The solid's extent along z, to 1e-6 (bounding boxes of lofted faces carry slack)."""
    box = result.shape.bounding_box()
    return round(box.min.Z, 6) + 0.0, round(box.max.Z, 6) + 0.0


@pytest.mark.parametrize(
    "kind, one, two, offset, expected",
    [
        ("OneSideFeatureExtentType", fj.extent(3.0), None, None, (0.0, 3.0)),
        ("OneSideFeatureExtentType", fj.extent(-3.0), None, None, (-3.0, 0.0)),
        ("TwoSidesFeatureExtentType", fj.extent(2.0), fj.extent(1.0), None, (-1.0, 2.0)),
        ("TwoSidesFeatureExtentType", fj.extent(3.0), fj.extent(-1.0), None, (1.0, 3.0)),
        ("SymmetricFeatureExtentType", fj.extent(4.0, full=True), None, None, (-2.0, 2.0)),
        ("SymmetricFeatureExtentType", fj.extent(2.0, full=False), None, None, (-2.0, 2.0)),
        ("OneSideFeatureExtentType", fj.extent(2.0), None, 1.0, (1.0, 3.0)),
        ("SymmetricFeatureExtentType", fj.extent(1.0, full=False), None, -0.5, (-1.5, 0.5)),
    ],
    ids=[
        "one-side",
        "one-side-negative",
        "two-sides",
        "two-sides-same-side",
        "symmetric-full",
        "symmetric-half",
        "offset-start",
        "symmetric-offset",
    ],
)
def test_extent_intervals(tmp_path, kind, one, two, offset, expected):
    result = run(tmp_path, fj.sketch(SQUARE), fj.extrude("s0", kind=kind, one=one, two=two, offset=offset))
    assert z_range(result) == expected
    assert result.volume == pytest.approx(4 * (expected[1] - expected[0]), rel=1e-9)


@pytest.mark.parametrize("degrees", [10.0, -10.0])
def test_taper_sign_positive_opens_outward(tmp_path, degrees):
    theta = math.radians(degrees)
    result = run(tmp_path, fj.sketch(SQUARE), fj.extrude("s0", one=fj.extent(1.0, taper=theta)))
    top = 2 + 2 * math.tan(theta)  # Fusion: a positive taper widens the far end
    expected = (4 + top * top + 2 * top) / 3  # frustum: h/3 (A1 + A2 + sqrt(A1 A2)), h = 1
    assert result.volume == pytest.approx(expected, rel=1e-6)


def test_taper_on_negative_direction(tmp_path):
    theta = math.radians(5)
    result = run(tmp_path, fj.sketch(SQUARE), fj.extrude("s0", one=fj.extent(-1.0, taper=theta)))
    top = 2 + 2 * math.tan(theta)
    assert z_range(result) == (-1.0, 0.0)
    assert result.volume == pytest.approx((4 + top * top + 2 * top) / 3, rel=1e-6)


def test_arc_over_180_degrees_keeps_the_major_segment(tmp_path):
    sweep = 1.5 * math.pi
    a = fj.arc((0, 0), 1.0, -sweep / 2, sweep / 2)
    chord = fj.line(
        (a["end_point"]["x"], a["end_point"]["y"]), (a["start_point"]["x"], a["start_point"]["y"])
    )
    result = run(tmp_path, fj.sketch([(True, [chord, a])]), fj.extrude("s0", one=fj.extent(1.0)))
    assert result.volume == pytest.approx((sweep - math.sin(sweep)) / 2, rel=1e-9)


def test_ellipse_profile(tmp_path):
    result = run(
        tmp_path, fj.sketch([(True, [fj.ellipse((1, 1), 2.0, 0.5)])]), fj.extrude("s0", one=fj.extent(2.0))
    )
    assert result.volume == pytest.approx(2 * math.pi * 2.0 * 0.5, rel=1e-7)


def test_nurbs_edge_profile(tmp_path):
    # Quadratic Bezier top (a parabola with sagitta 0.5 over a chord of 2): area 2 + 2/3.
    top = fj.nurbs([(1, 1), (0, 2), (-1, 1)], 2, [0, 0, 0, 1, 1, 1])
    loop = [fj.line((-1, 1), (-1, 0)), fj.line((-1, 0), (1, 0)), fj.line((1, 0), (1, 1)), top]
    result = run(tmp_path, fj.sketch([(True, loop)]), fj.extrude("s0", one=fj.extent(1.0)))
    assert result.volume == pytest.approx(8 / 3, rel=1e-7)


def test_rotated_sketch_frame_places_the_solid(tmp_path):
    c, s = math.cos(0.4), math.sin(0.4)
    x = np.array([c, s, 0.0])
    z = np.array([-s, c, 1.0]) / math.sqrt(2)
    z -= x * (x @ z)
    z /= np.linalg.norm(z)
    y = np.cross(z, x)
    frame = {"origin": (1.0, -2.0, 3.0), "x_axis": tuple(x), "y_axis": tuple(y), "z_axis": tuple(z)}
    result = run(
        tmp_path, fj.sketch([(True, fj.rect(0, 0, 2, 1))], frame), fj.extrude("s0", one=fj.extent(0.5))
    )
    expected = np.array([1.0, -2.0, 3.0]) + x * 1.0 + y * 0.5 + z * 0.25  # centre of the 2 x 1 x 0.5 box
    assert np.allclose(tuple(result.shape.center()), expected, atol=1e-9)
    assert result.volume == pytest.approx(1.0, rel=1e-9)


def test_left_handed_frame_extrudes_along_its_z_axis(tmp_path):
    frame = {"origin": (0, 0, 0), "x_axis": (1, 0, 0), "y_axis": (0, 1, 0), "z_axis": (0, 0, -1)}
    result = run(tmp_path, fj.sketch(SQUARE, frame), fj.extrude("s0", one=fj.extent(1.0)))
    assert z_range(result) == (-1.0, 0.0)


def test_inner_loop_makes_a_hole(tmp_path):
    loops = [(False, [fj.circle((2, 2), 1.0)]), (True, list(reversed(fj.rect(0, 0, 4, 4))))]
    result = run(tmp_path, fj.sketch(loops), fj.extrude("s0", one=fj.extent(1.0)))
    assert result.volume == pytest.approx(16 - math.pi, rel=1e-9)
    assert result.face_count == 7  # 4 sides, top, bottom, the hole's cylinder


def test_shuffled_and_reversed_loop_edges_still_close(tmp_path):
    edges = fj.rect(0, 0, 2, 2)
    first = edges[0]
    reversed_first = fj.line(
        (first["end_point"]["x"], first["end_point"]["y"]),
        (first["start_point"]["x"], first["start_point"]["y"]),
    )
    loop = [edges[2], reversed_first, edges[3], edges[1]]
    result = run(tmp_path, fj.sketch([(True, loop)]), fj.extrude("s0", one=fj.extent(1.0)))
    assert result.volume == pytest.approx(4.0, rel=1e-9)


def two_boxes(op, gap):
    """A 2x2x1 body, then a second square profile ``gap`` away along x, with operation ``op``."""
    second = fj.sketch([(True, fj.rect(2 + gap, 0, 4 + gap, 2))], name="Sketch2")
    return (fj.sketch(SQUARE), fj.extrude("s0"), second, fj.extrude("s2", op=op))


@pytest.mark.parametrize("gap, bodies", [(0.0, 1), (0.5, 2)], ids=["touching", "apart"])
def test_join_merges_only_touching_bodies(tmp_path, gap, bodies):
    result = run(tmp_path, *two_boxes("JoinFeatureOperation", gap))
    assert len(result.bodies) == bodies
    assert result.volume == pytest.approx(8.0, rel=1e-9)
    if bodies == 1:
        assert result.face_count == 6  # coplanar faces merged, as Fusion does


def test_new_body_keeps_bodies_separate(tmp_path):
    result = run(tmp_path, *two_boxes("NewBodyFeatureOperation", 0.0))
    assert len(result.bodies) == 2


def test_cut_can_split_a_body_and_intersect_keeps_the_overlap(tmp_path):
    bar = fj.sketch([(True, fj.rect(0, 0, 6, 2))])
    slot = fj.sketch([(True, fj.rect(2, -1, 3, 3))], name="Sketch2")
    cut = run(tmp_path, bar, fj.extrude("s0"), slot, fj.extrude("s2", op="CutFeatureOperation"))
    assert len(cut.bodies) == 2 and cut.volume == pytest.approx(10.0)
    inter = run(tmp_path, bar, fj.extrude("s0"), slot, fj.extrude("s2", op="IntersectFeatureOperation"))
    assert len(inter.bodies) == 1 and inter.volume == pytest.approx(2.0)


def test_multi_profile_extrude_fuses_touching_profiles(tmp_path):
    sk = fj.sketch(SQUARE)
    sk["profiles"]["q"] = {"loops": [{"is_outer": True, "profile_curves": fj.rect(2, 0, 4, 2)}]}
    ex = fj.extrude("s0")
    ex["profiles"].append({"profile": "q", "sketch": "s0"})
    result = run(tmp_path, sk, ex)
    assert len(result.bodies) == 1 and result.face_count == 6

"""Profiles the corpus conversion used to lose, and the script parts it could not verify against.

Built edges check the slit-profile rule itself; real corpus designs (skipped when
``../shared/data/fusion360_b123d`` is absent) check that each kind now converts and verifies.
"""

from __future__ import annotations

import math

import pytest
from build123d import Edge, Plane, Vector

from zonegraph.data.b123d import convert_design
from zonegraph.data.b123d.faces import NotAProfile, slit_profile_faces
from zonegraph.testing import CORPUS, requires_corpus


def _line(a: tuple[float, float], b: tuple[float, float]) -> Edge:
    return Edge.make_line(Vector(*a), Vector(*b))


def _circle(center: tuple[float, float], r: float) -> Edge:
    return Edge.make_circle(r, Plane(origin=(*center, 0)))


def test_a_slit_to_a_hole_is_dropped_and_the_hole_kept() -> None:
    # 21638's shape: a rectangle whose left side is split where a line runs into a circle.
    edges = [
        _line((0, 0), (9, 0)),
        _line((9, 0), (9, 11.5)),
        _line((9, 11.5), (0, 11.5)),
        _line((0, 11.5), (0, 5)),
        _line((0, 5), (0, 0)),
        _line((0, 5), (2.45, 5)),  # ends on the circle, not at its vertex: a bridge
        _circle((3, 5), 0.55),
    ]
    (face,) = slit_profile_faces(edges)
    assert len(face.inner_wires()) == 1
    assert face.area == pytest.approx(9 * 11.5 - math.pi * 0.55**2, rel=1e-12)


def test_two_holes_joined_by_a_slit_are_two_holes() -> None:
    edges = [_circle((0, 0), 10), _circle((0, 0), 1), _line((1, 0), (5, 0)), _circle((6, 0), 1)]
    (face,) = slit_profile_faces(edges)
    assert len(face.inner_wires()) == 2
    assert face.area == pytest.approx(math.pi * (100 - 2), rel=1e-12)


def test_a_float_gap_is_joined_and_an_open_chain_refused() -> None:
    gap = 2e-6  # Fusion's float32 noise at this size; build123d joins only 1e-9
    square = [_line((0, 0), (1, 0)), _line((1, 0), (1, 1)), _line((1, 1), (0, 1)), _line((0, 1), (0, gap))]
    (face,) = slit_profile_faces(square)
    assert face.area == pytest.approx(1.0, rel=1e-5)
    with pytest.raises(NotAProfile):
        slit_profile_faces(square[:3])


# Real designs, one per cause, each lost by the whole-corpus conversion at 15fd216:
# (batch, design id, status then, what it shows).
RECOVERED = {
    "slit_between_holes": ("01_2ops/batch_010.py", "33607_c6f31fa6_0010"),  # model_raised
    "hole_touching_outer": ("01_2ops/batch_016.py", "56459_7b640aed_0005"),  # replay_failed
    "invalid_script_part": ("03_4to5ops/batch_014.py", "57854_7f40fb28_0000"),  # mismatch
}


@requires_corpus
@pytest.mark.parametrize("cause", sorted(RECOVERED))
def test_a_design_lost_before_converts_and_verifies(cause: str) -> None:
    batch, design_id = RECOVERED[cause]
    r = convert_design(CORPUS / batch, design_id)
    assert r.status == "ok", f"{design_id}: {r.status}: {r.reason}"
    assert r.volume_rel_error is not None and r.volume_rel_error <= 1e-6
    assert r.area_rel_error is not None and r.area_rel_error <= 1e-6
    # the converted design is Fusion's (the repair of an invalid script part is not a loophole)
    assert r.fusion_volume_rel_error is not None and r.fusion_volume_rel_error < 1e-9
    assert r.fusion_area_rel_error is not None and r.fusion_area_rel_error < 1e-9
    repaired = any("invalid solid" in n for n in r.notes)
    assert repaired == (cause == "invalid_script_part")


@requires_corpus
def test_a_hole_below_the_snap_tolerance_is_a_clear_one_line_reason() -> None:
    r = convert_design(CORPUS / "01_2ops/batch_007.py", "22228_1c82530b_0010")
    assert r.status == "unsupported"
    assert "each shorter than 1e-05 cm" in r.reason and "\n" not in r.reason

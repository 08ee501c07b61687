"""What an engineer gets back from ``zg.infer``: the program as a Part, and a reason when it is not
exact, on parts made here with build123d (STEP in, as a user's file would be)."""

from __future__ import annotations

import json
import math

import pytest
from build123d import (
    Axis,
    Box,
    BuildPart,
    BuildSketch,
    Cylinder,
    Locations,
    Mode,
    Part,
    Plane,
    Polygon,
    Sphere,
    chamfer,
    export_step,
    fillet,
    revolve,
)

import zonegraph as zg

# Bounded by work, not seconds (the filleted box exhausts its space in 1,199 expansions, 0.5 s
# idle, which a 2 s budget did not always buy on a loaded 2-core machine).
FAST = zg.InferConfig(budget_s=math.inf, max_expansions=5000)


def _infer(tmp_path, shape, name):
    path = tmp_path / f"{name}.step"
    export_step(shape, str(path))
    return zg.infer(path, tmp_path / name, FAST, render=False)


def _revolved():
    with BuildPart() as p:
        with BuildSketch(Plane.XZ):
            Polygon((0, 0), (20, 0), (20, 5), (10, 15), (0, 15), align=None)
        revolve(axis=Axis.Z)
    return p.part


def test_the_python_example_gives_the_part(tmp_path):
    target = Box(40, 30, 10) - Cylinder(5, 10)
    result = _infer(tmp_path, target, "plate")
    assert result.exact and not result.reason
    part = result.to_part()
    assert isinstance(part, Part)
    assert part.volume == pytest.approx(target.volume, rel=1e-6)
    assert (tmp_path / "plate" / "sequence.py").read_text() == result.to_script()
    assert json.loads(result.to_json())["entities"]
    written = json.loads((tmp_path / "plate" / "result.json").read_text())
    assert "script" not in written and written["diagnosis"]["unmakeable"] == []  # every key, always


def test_a_box_chamfered_along_its_top_is_exact(tmp_path):
    """Each chamfer is a plane that a cut of a triangular prism leaves (the proposals' cut groups)."""
    part = chamfer(Box(40, 30, 20).edges().group_by(Axis.Z)[-1], 4)
    result = _infer(tmp_path, part, "chamfered")
    assert result.status == "exact" and result.iou_brep >= zg.reconstruction.EXACT_IOU


@pytest.mark.parametrize(
    ("name", "make", "named"),
    [
        ("revolved", _revolved, "no extrusion can make 1 cone ("),
        ("sphere", lambda: Sphere(10), "no extrusion can make 1 sphere (100.0% of the area)"),
    ],
)
def test_a_partial_result_names_its_faces_and_keeps_its_program(tmp_path, name, make, named):
    result = _infer(tmp_path, make(), name)
    assert result.status == "partial" and 0 < result.iou_brep < zg.reconstruction.EXACT_IOU
    assert named in result.reason
    assert "exhausted its space" in result.reason
    assert result.steps >= 1 and result.files == ["sequence.py", "sequence.json"]
    assert result.script_iou == pytest.approx(result.iou_brep, abs=1e-6)  # the files are the program
    written = json.loads((tmp_path / name / "result.json").read_text())
    assert written["reason"] == result.reason and written["script_iou"] == pytest.approx(result.iou_brep)


def test_a_box_with_every_edge_filleted_names_its_fillets_and_keeps_its_best_program(tmp_path):
    result = _infer(tmp_path, fillet(Box(20, 16, 12).edges(), 2), "filleted")
    assert (
        result.status == "partial" and result.steps >= 1 and result.files == ["sequence.py", "sequence.json"]
    )
    assert "8 spheres (fillets, " in result.reason and "exhausted its space" in result.reason


def test_a_search_with_no_step_says_so_and_writes_no_program(tmp_path):
    step = tmp_path / "box.step"
    export_step(Box(20, 16, 12), str(step))
    result = zg.infer(step, tmp_path / "out", zg.InferConfig(budget_s=1e-9))  # spent before one expansion
    assert result.steps == 0 and result.files == []
    assert result.reason.startswith("no step found, so no program was written")
    assert "budget" in result.reason
    assert not (tmp_path / "out" / "sequence.py").exists()
    with pytest.raises(ValueError, match="no program was found: no step found"):
        result.to_part()


def test_dir_shows_the_public_api_only():
    names = dir(zg)
    assert "infer" in names and "InferResult" in names and "__version__" in names
    assert not {"TYPE_CHECKING", "Any", "importlib", "lazy_exports", "annotations"} & set(names)


def test_a_hole_across_every_direction_is_named(tmp_path):
    with BuildPart() as p:
        Box(30, 30, 10)
        with Locations(Plane.XY.rotated((0, 35, 0))):
            Cylinder(3, 40, mode=Mode.SUBTRACT)
    result = _infer(tmp_path, p.part, "slanted")
    assert not result.exact
    assert result.reason.startswith("no extrusion can make ") and "cylinder" in result.reason.split(";")[0]

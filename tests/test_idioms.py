"""The written script is what a build123d user writes, and still rebuilds the part exactly.

Programs are made here from build123d faces (a plate with a hexagon pocket, a slot and a hole; a
cut down from z = 22; a boss along -y), written through the exporter, and the written script is
run and measured against the program's own rebuild.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from build123d import Circle, Face, Plane, Pos, Rectangle, RegularPolygon, SlotCenterToCenter, Unit

from zonegraph.export.verify import verified_export
from zonegraph.export.writers import LITERAL, profile_counts, program_script, written_steps
from zonegraph.reconstruction import EXACT_IOU
from zonegraph.sequence.program import ProgramStep, execute
from zonegraph.sequence.proposals import Op


def face(plane: Plane, sketch: object) -> Face:
    return (plane * sketch).face()  # type: ignore[operator]


def export(program: list[ProgramStep], name: str = "part"):  # type: ignore[no-untyped-def]
    target = execute(program)[-1]
    assert target is not None
    return verified_export(program, name, Unit.MM, target, 1.0, EXACT_IOU)


PLATE = ProgramStep(
    Op.UNION,
    (face(Plane.XY, Pos(10, 5) * Rectangle(40, 20)) - face(Plane.XY, Pos(0, 5) * Circle(3)),),
    (0.0, 0.0, 0.0),
    (0.0, 0.0, 1.0),
    6.0,
)


def test_a_rectangle_with_a_hole_is_written_as_objects_and_rebuilds_exactly() -> None:
    result = export([PLATE])
    assert "with BuildSketch(Plane.XY):" in result.script
    assert "with Locations((10, 5)):\n            Rectangle(40, 20)" in result.script
    assert "with Locations((0, 5)):\n            Circle(3, mode=Mode.SUBTRACT)" in result.script
    assert "BuildLine" not in result.script and profile_counts(result.script) == (2, 2)
    assert result.check.script_iou >= EXACT_IOU and result.check.json_iou >= EXACT_IOU


def test_polygons_slots_and_holes_are_written_as_build123d_objects() -> None:
    top = Plane.XY.offset(6)
    pocket = ProgramStep(
        Op.SUBTRACT,
        (
            face(top, Pos(15, 5) * RegularPolygon(4, 6, rotation=30)),
            face(top, Pos(24, 5) * SlotCenterToCenter(6, 3, rotation=90)),
        ),
        (0.0, 0.0, 6.0),
        (0.0, 0.0, -1.0),
        2.0,
    )
    hole = ProgramStep(
        Op.SUBTRACT, (face(top, Pos(-6, 5) * Circle(1.5)),), (0.0, 0.0, 6.0), (0.0, 0.0, -1.0), 4.0
    )
    result = export([PLATE, pocket, hole])
    assert "RegularPolygon(4, 6, rotation=30)" in result.script
    assert "SlotCenterToCenter(6, 3, rotation=90)" in result.script
    assert "with Locations(Plane.XY.offset(6)):" in result.script and "Hole(1.5, depth=4)" in result.script
    assert "extrude(amount=-2, mode=Mode.SUBTRACT)" in result.script  # down from z = 6, not a mirrored frame
    assert profile_counts(result.script) == (5, 5) and result.style.holes
    assert result.check.script_iou >= EXACT_IOU and result.check.json_iou >= EXACT_IOU


def test_a_hole_that_would_cut_above_its_plane_falls_back_to_a_sketch() -> None:
    """Hole(r, depth=d) cuts d either side of its plane: from z = 3 inside the plate it is not exact."""
    mid = ProgramStep(
        Op.SUBTRACT, (face(Plane.XY.offset(3), Pos(20, 5) * Circle(2)),), (0, 0, 3.0), (0, 0, -1.0), 2.0
    )
    result = export([PLATE, mid])
    assert "Hole(" not in result.script and not result.style.holes and result.style.objects
    assert "with Locations((20, 5)):\n            Circle(2)" in result.script
    assert result.check.script_iou >= EXACT_IOU


def test_reversed_normals_read_in_global_coordinates() -> None:
    """A cut down from z = 22 and a boss along -y from y = -4: no z_dir=(0, 0, -1) frame whose local
    y runs along -y, no local y along -z."""
    block = ProgramStep(
        Op.UNION, (face(Plane.XY, Pos(20, 0) * Rectangle(20, 10)),), (0, 0, 0), (0, 0, 1.0), 22.0
    )
    cut = ProgramStep(
        Op.SUBTRACT,
        (face(Plane.XY.offset(22), Pos(20, 2) * Rectangle(4, 2)),),
        (0, 0, 22.0),
        (0, 0, -1.0),
        5.0,
    )
    boss = ProgramStep(
        Op.UNION, (face(Plane.XZ.offset(5), Pos(20, 11) * Circle(2)),), (0, -5.0, 0), (0, -1.0, 0), 3.0
    )
    result = export([block, cut, boss])
    lines = result.script.splitlines()
    assert (
        "with BuildSketch(Plane.XY.offset(22)):"
        in lines[
            lines.index("    # Step 2: subtract: sketch on the plane z = 22 mm, extruded 5 mm along -z") + 1
        ]
    )
    assert "with Locations((20, 2)):\n            Rectangle(4, 2)" in result.script  # x, y as in the input
    assert "with BuildSketch(Plane.XZ.offset(5)):" in result.script  # the plane y = -5
    assert "with Locations((20, 11)):\n            Circle(2)" in result.script  # x, z as in the input
    assert "extrude(amount=3, mode=Mode.ADD)" in result.script  # Plane.XZ's normal is -y already
    assert "z_dir" not in result.script
    assert result.check.script_iou >= EXACT_IOU and result.check.json_iou >= EXACT_IOU
    literal = program_script(written_steps([block, cut, boss]), "part", Unit.MM, LITERAL)
    assert "Line((18, 3), (18, 1))" in literal or "Line((18, 1), (18, 3))" in literal  # global x, y


def test_the_script_run_without_an_argument_writes_its_step_beside_it(tmp_path: Path) -> None:
    script = tmp_path / "sequence.py"
    script.write_text(export([PLATE]).script)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300, check=True
    )
    assert (tmp_path / "sequence.step").stat().st_size > 0 and "sequence.step" in done.stdout


def _blob(plane: Plane, seam: int, shift: float = 0.0) -> Face:
    """One closed free-form loop through eight points, its seam moved to knot ``seam``."""
    import math

    from build123d import Edge, Wire
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.Geom import Geom_BSplineCurve

    points = [
        plane.from_local_coords((10 * math.cos(a) + 2 * math.cos(3 * a) + shift, 6 * math.sin(a)))
        for a in (2 * math.pi * i / 8 for i in range(8))
    ]
    curve = BRep_Tool.Curve_s(Edge.make_spline(points, periodic=True).wrapped, 0.0, 1.0)
    spline = curve.Copy()
    assert isinstance(spline, Geom_BSplineCurve)
    spline.SetOrigin(seam)
    return Face(Wire([Edge(BRepBuilderAPI_MakeEdge(spline).Edge())]))


def test_one_closed_spline_sketched_by_two_steps_is_written_as_one_curve() -> None:
    """Two steps sketch the same closed free-form loop, each from its own seam and 3e-6 mm apart
    (a corpus part's two faces on one side face): written alike, their union holds in both files."""
    lower = ProgramStep(Op.UNION, (_blob(Plane.XY, 1),), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 10.0)
    top = Plane.XY.offset(12)
    upper = ProgramStep(Op.UNION, (_blob(top, 4, 3e-6),), (0.0, 0.0, 12.0), (0.0, 0.0, -1.0), 8.0)
    result = export([lower, upper])
    splines = [line.strip() for line in result.script.splitlines() if line.strip().startswith("Spline(")]
    assert len(splines) == 2 and splines[0] == splines[1]
    assert result.check.script_iou >= EXACT_IOU and result.check.json_iou >= EXACT_IOU


def test_a_point_set_script_makes_the_part_from_one_fuse_of_its_tools() -> None:
    """The last style tried: no Boolean per step, the cells of all tools that the last tool holding
    them adds (a union, a cut through it, a union refilling part of the cut)."""
    from zonegraph.export.verify import run_script
    from zonegraph.export.writers import ScriptStyle

    cut = ProgramStep(
        Op.SUBTRACT, (face(Plane.XY.offset(6), Pos(0, 5) * Rectangle(10, 4)),), (0, 0, 6.0), (0, 0, -1.0), 6.0
    )
    refill = ProgramStep(Op.UNION, (face(Plane.XY, Pos(0, 5) * Circle(1)),), (0, 0, 0), (0, 0, 1.0), 3.0)
    program = [PLATE, cut, refill]
    style = ScriptStyle(holes=False, fuzzy=(0.0, 1e-6), cells=True)
    script = program_script(written_steps(program), "part", Unit.MM, style)
    assert "result = point_set(steps)" in script and "steps.append((extrude(" in script
    expected = execute(program)[-1]
    assert expected is not None
    built = run_script(script)
    assert built.is_valid and abs(built.volume - expected.volume) < 1e-6 * expected.volume

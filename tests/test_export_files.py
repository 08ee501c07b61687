"""The written files of a zone-exact program rebuild the part: real corpus geometry.

41737_b6724677_0000's sketch faces come from the fuzzy partition with curves that end 1.3e-5 cm
apart at a vertex: written edge by edge from the curves, neither the script (make_face: "Face can
only be created with closed wires") nor the JSON ("a profile loop does not close") rebuilt.
24650_dad8c8ee_0000's loop has a free-form edge whose samples run against the loop: written from
the wrong corner, the script's spline crossed itself ("TopoDS::Face" type mismatch).
69456_81a21eaf_0000's corners lie 1.1e-6 cm off the sketch plane (their vertices' tolerance):
written there, the JSON's hole was not coplanar and the reader built the profile without it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from build123d import Box, Pos

from zonegraph.configs import InferConfig
from zonegraph.data.design import Extent, ExtentType, Extrude, Operation
from zonegraph.data.replay import cells_bodies
from zonegraph.reconstruction import EXACT_IOU, infer
from zonegraph.testing import CORPUS, requires_corpus

EXACT_FILE_DESIGNS = [
    ("01_2ops/batch_012.py", "41737_b6724677_0000"),
    ("02_3ops/batch_003.py", "24650_dad8c8ee_0000"),
    pytest.param(
        "06_11to15ops/batch_005.py",
        "69456_81a21eaf_0000",
        # Known failure, tracked in issue 23: since the sweep passes dangling faces the search finds
        # another 20-step zone-exact program; its B-rep and JSON are exact, its script's
        # sequential Booleans give 0.9712, its checked fuzzy Booleans 0.99974 (strict: the test
        # says so when it passes again).
        marks=pytest.mark.xfail(strict=True, reason="script of the 20-step program rebuilds to 0.99974"),
    ),
    # a 94 cm spline side: the script's 24-point interpolation strayed 3e-4 of it (IoU 0.99988)
    ("02_3ops/batch_007.py", "87564_c58c72e9_0002"),
    # a merged sketch face with a 2e-5 cm stray of a neighbouring circle: the JSON's profile area
    # was the face's, which the written arcs differ from by 1.8e-4, and the reader refused it
    ("05_8to10ops/batch_009.py", "54285_76f37095_0003"),
    # pins joined into the round holes they fill: invalid at every fuzzy value in both files
    # (script 0.0046, JSON refused) until the shape fixer mends the join
    ("06_11to15ops/batch_002.py", "22305_5b45cdb3_0002"),
    # one closed spline sketched by two steps, cut from the side face at both ends 8e-6 cm apart:
    # sampled from each face's seam and snapped apart, the union failed (script 0, JSON 0.988)
    ("03_4to5ops/batch_007.py", "25364_b3985755_0002"),
    # the written tools' sixth cut fails in every chain of Booleans, at every fuzzy value (script
    # 0.73); one general fuse of all seven tools gives the part (the point-set style)
    ("06_11to15ops/batch_002.py", "21638_0a984848_0011"),
    # the JSON replay's joins grew its tools' tolerances in place, after which the cells of the
    # tools, valid when fresh, failed at every fuzzy value (JSON refused: an invalid join)
    ("06_11to15ops/batch_002.py", "23137_e55b73cb_0007"),
]


@requires_corpus
@pytest.mark.parametrize(("batch", "design_id"), EXACT_FILE_DESIGNS)
def test_the_files_of_a_zone_exact_program_rebuild_the_part(
    batch: str, design_id: str, tmp_path: Path
) -> None:
    from zonegraph.data.b123d import convert_design

    converted = convert_design(CORPUS / batch, design_id)
    assert converted.ok and converted.design_json is not None, converted.reason
    path = tmp_path / f"{design_id}.json"
    path.write_text(json.dumps(converted.design_json))
    result = infer(path, tmp_path / "out", InferConfig(budget_s=20), render=False)
    saved = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result.exact and not saved["export_error"], saved["export_error"]
    assert saved["script_iou"] >= EXACT_IOU and saved["json_iou"] >= EXACT_IOU


@requires_corpus
def test_written_files_whose_boolean_commons_with_the_part_are_empty_measure_exact(tmp_path: Path) -> None:
    """43928_6ca53538_0025: its JSON replays 2e-6 off the part's volume, yet every Boolean common
    of the two came back empty (IoU 3e-7), which the cells of one fuse of both measure; its
    fuzzy-style script has the program's volume at all 20 steps, yet every common with it comes
    back empty, the cells' too (0.994 was the best script), which the intersection its fuse with
    the part implies, checked by a cut, measures."""
    from zonegraph.data.b123d import convert_design

    design_id = "43928_6ca53538_0025"
    converted = convert_design(CORPUS / "07_16to20ops/batch_002.py", design_id)
    assert converted.ok and converted.design_json is not None, converted.reason
    path = tmp_path / f"{design_id}.json"
    path.write_text(json.dumps(converted.design_json))
    result = infer(path, tmp_path / "out", InferConfig(budget_s=math.inf, max_expansions=200), render=False)
    saved = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result.exact and saved["json_iou"] >= EXACT_IOU and saved["script_iou"] >= EXACT_IOU


@requires_corpus
def test_a_written_json_whose_unified_join_fails_its_commons_measures_exact(tmp_path: Path) -> None:
    """41125_711db4bf_0002's written JSON: the last join has the program's volume, but once its
    faces are unified every common with the part holds 3% of it, so the writer had recorded the
    cells' figures, 1.6e-3 short (JSON IoU 0.9984). Measured by the intersection its fuse with the
    part implies, the sequential join is exact, and the file replays and verifies by default."""
    from zonegraph.data.b123d import convert_design
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay

    design_id = "41125_711db4bf_0002"
    converted = convert_design(CORPUS / "07_16to20ops/batch_002.py", design_id)
    assert converted.ok and converted.design_json is not None, converted.reason
    path = tmp_path / f"{design_id}.json"
    path.write_text(json.dumps(converted.design_json))
    infer(path, tmp_path / "out", InferConfig(budget_s=math.inf, max_expansions=200), render=False)
    saved = json.loads((tmp_path / "out" / "result.json").read_text())
    replayed = replay(load_design(tmp_path / "out" / "sequence.json"))
    assert replayed.disagreement() is None
    assert saved["json_iou"] >= EXACT_IOU and saved["script_iou"] >= EXACT_IOU


def _extrude(name: str, op: Operation) -> Extrude:
    return Extrude(name, name, (), op, ExtentType.ONE_SIDE, Extent(1.0))


def test_the_cells_of_all_tools_give_the_point_set_of_joins_and_cuts() -> None:
    steps = [
        (_extrude("a", Operation.NEW_BODY), Box(2, 2, 2)),
        (_extrude("b", Operation.JOIN), Pos(1.5, 0, 0) * Box(2, 2, 2)),
        (_extrude("c", Operation.CUT), Pos(0, 0, 1) * Box(1, 1, 1)),
    ]
    bodies = cells_bodies(steps)
    assert bodies is not None and len(bodies) == 1 and bodies[0].is_valid
    assert abs(bodies[0].volume - (8 + 8 - 2 - 0.5)) < 1e-9  # overlap 2; the cut takes half its cube
    intersect = [*steps[:1], (_extrude("d", Operation.INTERSECT), Box(1, 1, 1))]
    assert cells_bodies(intersect) is None  # per-body semantics: not a point set of the tools

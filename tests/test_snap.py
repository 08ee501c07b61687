"""Snapped numbers in the exported script and JSON: short where the part stays exact, raw where not.

The parts are real: the Couch sample (its design JSON carries float32 noise such as 0.750000011176)
and a corpus design whose converted JSON carries 3.49999999979 for 3.5 (skipped when ../shared
is absent).
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest
from build123d import Unit

from zonegraph.configs import InferConfig
from zonegraph.data.replay import as_shape
from zonegraph.data.targets import load_target
from zonegraph.export.snap import Snapper, simplest, written
from zonegraph.export.verify import export_texts, verified_export
from zonegraph.geometry.shapes import read_solids
from zonegraph.reconstruction import EXACT_IOU, infer, reconstruct
from zonegraph.sequence.program import ProgramStep, brep_iou, build_program, execute
from zonegraph.testing import CORPUS, requires_corpus, requires_samples

NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
NOISY_CORPUS_DESIGN = ("01_2ops/batch_001.py", "100798_1efa7e4b_0000")  # 3.49999999979 for 3.5


def significant_digits(token: str) -> int:
    return len(token.lstrip("-").split("e")[0].replace(".", "").lstrip("0"))


def script_numbers(text: str) -> list[str]:
    """The numbers of the program's body (after ``with BuildPart``), not of its docstring."""
    body = text[text.index("with BuildPart") :]
    return NUMBER.findall(body.split("result = part.part")[0])


def assert_clean(text: str, longest: int) -> None:
    assert not re.search(r"\de-?\d", text.split('"""')[2]), "an exponent in the script"
    assert not re.search(r"[(, =]-0(?:\.0+)?[,)]", text), "a negative zero in the script"
    digits = max(significant_digits(t) for t in script_numbers(text))
    assert digits <= longest, f"a number with {digits} significant digits"


def program_of(target: Path) -> tuple[list[ProgramStep], float]:
    """The found program of a target and the B-rep IoU of its own rebuild."""
    rec = reconstruct(target, InferConfig(budget_s=10))
    program = build_program(rec.graph, rec.result.steps, rec.generator)
    return program, brep_iou(execute(program)[-1], as_shape(rec.solids))


# ------------------------------------------------------------------------------------ numbers


def test_simplest_takes_the_fewest_decimals_within_tolerance() -> None:
    assert simplest(0.4499999866, 1e-6) == 0.45
    assert simplest(0.750000011176, 1e-6) == 0.75
    assert simplest(-58.2782013783, 1e-7) == -58.2782014  # a designer's long number stays long
    assert simplest(3.25, 0.0) == 3.25 and simplest(0.1 + 0.2, 0.0) == 0.1 + 0.2  # no tolerance
    zero = simplest(-3.99680288865e-14, 1e-6)
    assert zero == 0.0 and math.copysign(1.0, zero) == 1.0  # never -0
    assert written(zero) == "0" and written(-0.0) == "0"
    assert written(3e-05) == "0.00003" and written(0.4499999866) == "0.4499999866"  # no exponents


def test_directions_snap_only_to_zero_and_one_and_stay_unit() -> None:
    snap = Snapper(tol=1e-6, unit_tol=1e-6)
    z = snap.direction((2e-13, -0.0, -1.0))
    assert [written(c) for c in z] == ["0", "0", "-1"] and math.copysign(1.0, z[1]) == 1.0
    slanted = snap.direction((0.7071067811865476, 3e-8, -0.7071067811865475))
    assert slanted[0] == pytest.approx(0.7071067811865476, abs=1e-15) and slanted[1] == 0.0
    assert math.isclose(float(slanted @ slanted), 1.0, rel_tol=1e-15)
    assert snap.changed == 1  # 3e-8 became 0; 2e-13 was written as 0 already


def test_a_snapper_counts_the_numbers_whose_text_it_changed() -> None:
    snap = Snapper(tol=1e-5, unit_tol=1e-6)
    assert list(snap.point((0.4499999866, 2.0, 1e-12))) == [0.45, 2.0, 0.0]
    assert snap.length(1.20000001788) == 1.2
    assert snap.changed == 2
    raw = Snapper.raw()
    assert raw.length(0.4499999866) == 0.4499999866 and raw.changed == 0


# ------------------------------------------------------------------------------- real parts


@requires_samples
def test_couch_exports_short_numbers_that_rebuild_it_exactly(samples_dir: Path, tmp_path: Path) -> None:
    """The Couch design is stored in float32 (0.750000011176, 1.50000002235, -3.25000004843)."""
    program, _ = program_of(samples_dir / "Couch.json")
    raw_script, _ = export_texts(program, "Couch", Unit.CM, Snapper.raw())
    assert max(significant_digits(t) for t in script_numbers(raw_script)) >= 10  # the noise is there

    result = infer(samples_dir / "Couch.json", tmp_path / "out", InferConfig(budget_s=10), render=False)
    text = (tmp_path / "out" / "sequence.py").read_text()
    assert_clean(text, longest=2)  # -2.5, 2.2, 0.5, ...: the numbers the designer typed
    assert "extrude(amount=2.2, mode=Mode.ADD)" in text and "Line((-2.5, 1), (-2.5, 3))" in text
    saved = json.loads((tmp_path / "out" / "result.json").read_text())
    assert saved["script_snapped"] and saved["snapped_numbers"] >= 20 and not saved["export_error"]
    assert min(result.script_iou, result.json_iou) >= EXACT_IOU and result.exact

    subprocess.run(  # the written script on its own, in a fresh interpreter
        [sys.executable, str(tmp_path / "out" / "sequence.py"), str(tmp_path / "couch.step")],
        check=True,
        capture_output=True,
        timeout=300,
    )
    rebuilt = as_shape(read_solids(tmp_path / "couch.step")).scale(0.1)  # STEP reads in mm
    assert brep_iou(rebuilt, as_shape(load_target(samples_dir / "Couch.json"))) >= EXACT_IOU


@requires_corpus
def test_a_corpus_design_with_noise_exports_short_numbers(tmp_path: Path) -> None:
    from zonegraph.data.b123d import convert_design

    batch, design_id = NOISY_CORPUS_DESIGN
    converted = convert_design(CORPUS / batch, design_id)
    assert converted.ok and converted.design_json is not None, converted.reason
    path = tmp_path / f"{design_id}.json"
    path.write_text(json.dumps(converted.design_json))
    program, iou = program_of(path)
    target = as_shape(load_target(path))

    raw_script, raw_design = export_texts(program, design_id, Unit.CM, Snapper.raw())
    assert "3.49999999979" in raw_script and "3.4999999" in raw_design  # the raw program's noise
    export = verified_export(program, design_id, Unit.CM, target, iou, EXACT_IOU)
    assert export.snapped and export.snapped_numbers >= 10
    assert export.check.iou >= EXACT_IOU and not export.check.error
    assert_clean(export.script, longest=7)
    assert "3.49999999979" not in export.script and "Line((1, 2.4), (3.5, 2.4))" in export.script
    assert "3.4999999" not in export.design


@requires_samples
def test_a_snap_that_breaks_exactness_falls_back_to_the_raw_numbers(samples_dir: Path) -> None:
    """Snapping by 5% of the part rounds the Couch's 2.2 high extrusion to 2: the written files
    would no longer be the part, so the raw numbers are written, and their IoU recorded."""
    program, iou = program_of(samples_dir / "Couch.json")
    target = as_shape(load_target(samples_dir / "Couch.json"))
    coarse = verified_export(program, "Couch", Unit.CM, target, iou, EXACT_IOU, rel_tol=0.05)
    raw_script, raw_design = export_texts(program, "Couch", Unit.CM, Snapper.raw())
    assert not coarse.snapped and coarse.snapped_numbers == 0
    assert coarse.script == raw_script
    written = json.loads(coarse.design)
    assert written.pop("properties")["body_count"] == 1  # the file's own replay's figures
    assert written == json.loads(raw_design)
    assert coarse.check.iou >= EXACT_IOU

    snapped_script, _ = export_texts(program, "Couch", Unit.CM, Snapper.for_part(8.0, 8.0, rel=0.05))
    assert "extrude(amount=2, mode=Mode.ADD)" in snapped_script  # what was refused

"""``zonegraph replay`` end to end, through the installed console script."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from zonegraph.cli import main
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.shapes import read_solids

SCRIPT = Path(sys.executable).parent / "zonegraph"


@pytest.mark.skipif(
    not SCRIPT.exists(), reason=f"console script not installed at {SCRIPT} (pip install -e .)"
)
def test_replay_writes_steps_and_summary(samples_dir, tmp_path):
    out = tmp_path / "out"
    proc = subprocess.run(
        [str(SCRIPT), "replay", str(samples_dir / "Pattern2_6c40bf33_0000.json"), "--out", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "2 extrudes" in proc.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert [s["operation"] for s in summary["steps"]] == ["new_body", "cut"]
    assert summary["check"]["volume_rel_error"] < 1e-9
    for name in ("final.step", "steps/00.step", "steps/01.step", "steps/01_tool.step"):
        assert (out / name).stat().st_size > 0
    # STEP is written with a centimetre unit; OpenCASCADE reads it back in millimetres.
    final = read_solids(out / "final.step")
    assert sum(s.volume for s in final) == pytest.approx(summary["volume"] * 1000, rel=1e-6)


BATCH = """
from build123d import *

def model_1_a_0000():
    with BuildPart() as part:
        # Sketch1 -> Extrude1 (NewBody)
        with BuildSketch(Plane.XY):
            Rectangle(4, 2)
        extrude(amount=1)
        # Sketch2 -> Extrude2 (Cut)
        with BuildSketch(Plane(origin=(0, 0, 1), x_dir=(1, 0, 0), z_dir=(0, 0, 1))):
            Circle(0.5)
        extrude(amount=-1, mode=Mode.SUBTRACT)
    return part.part

def model_1_b_0000():
    raise RuntimeError("broken model")

MODELS = {
    "model_1_a_0000": {"func": model_1_a_0000, "volume": 7.2146018366, "area": 29.5707963268},
    "model_1_b_0000": {"func": model_1_b_0000, "volume": 1.0, "area": 1.0},
}
"""


def test_convert_writes_verified_json_and_a_summary(tmp_path):
    batch = tmp_path / "01_2ops" / "batch_001.py"
    batch.parent.mkdir()
    batch.write_text(BATCH)
    assert main(["convert", str(tmp_path), "--out", str(tmp_path / "out")]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    status = {d["design_id"]: d["status"] for d in summary["designs"]}
    assert status == {"1_a_0000": "ok", "1_b_0000": "model_raised"}
    design = load_design(tmp_path / "out" / "1_a_0000.json")
    assert [e.operation.name for e in design.extrudes] == ["NEW_BODY", "CUT"]
    assert replay(design).volume == pytest.approx(8 - 0.25 * math.pi, rel=1e-9)
    assert main(["convert", str(tmp_path / "missing"), "--out", str(tmp_path / "o2")]) == 2

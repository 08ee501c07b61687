"""``zonegraph replay`` end to end, through the installed console script."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

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

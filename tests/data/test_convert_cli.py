"""``zonegraph convert`` on hostile batches: each design in its own killable child, one row each.

Run as a user runs it (a fresh ``python -m zonegraph.cli``): a model that exits, kills its process
or never returns stops only itself; the outputs are those of the last run; exit 2 when nothing
converted. The files ``convert`` calls ok replay with ``zonegraph replay``'s default check.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from zonegraph.testing.batches import plate_model

ROOT = Path(__file__).resolve().parents[2]

OK_MODEL = plate_model("good")

HOSTILE_MODELS = """
def model_exits():
    os._exit(0)


def model_sys_exit():
    sys.exit(3)


def model_segfault():
    ctypes.string_at(0)


def model_spins():
    while True:
        pass
"""


def _batch(tmp_path: Path, name: str, *models: str) -> Path:
    folder = tmp_path / name / "01_2ops"
    folder.mkdir(parents=True)
    path = folder / "batch_001.py"
    path.write_text("import ctypes, os, sys\nfrom build123d import *\n" + "\n".join(models))
    return path


def _convert(source: Path, out: Path, timeout: float = 5) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "zonegraph.cli",
            "convert",
            str(source),
            "--out",
            str(out),
            "--timeout",
            str(timeout),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )


def _rows(out: Path) -> dict[str, dict]:
    return {d["design_id"]: d for d in json.loads((out / "summary.json").read_text())["designs"]}


def test_each_hostile_model_is_one_row_and_the_rest_converts(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = _convert(_batch(tmp_path, "mixed", OK_MODEL, HOSTILE_MODELS), out)
    assert proc.returncode == 0, proc.stderr
    rows = _rows(out)
    assert {k: r["status"] for k, r in rows.items()} == {
        "good": "ok",
        "exits": "crash",
        "sys_exit": "model_raised",
        "segfault": "crash",
        "spins": "timeout",
    }
    assert rows["exits"]["reason"] == "worker exited without a result (exit code 0)"
    assert rows["segfault"]["reason"] == "worker died (exit code -11, SIGSEGV)"
    assert rows["sys_exit"]["reason"] == "SystemExit: 3"
    assert rows["spins"]["reason"] == "no result after 5 s"
    assert sorted(p.name for p in out.glob("[!.]*")) == ["good.json", "summary.json"]

    replayed = subprocess.run(  # what convert calls ok, replay accepts with its default check
        [
            sys.executable,
            "-m",
            "zonegraph.cli",
            "replay",
            str(out / "good.json"),
            "--out",
            str(tmp_path / "r"),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert replayed.returncode == 0, replayed.stderr


def test_nothing_converted_exits_2_and_leaves_no_earlier_output(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert _convert(_batch(tmp_path, "good", OK_MODEL), out).returncode == 0
    assert (out / "good.json").is_file()
    proc = _convert(_batch(tmp_path, "hostile", HOSTILE_MODELS), out, timeout=2)
    assert proc.returncode == 2
    assert not (out / "good.json").exists()  # the earlier run's design is not current any more
    assert {r["status"] for r in _rows(out).values()} == {"crash", "model_raised", "timeout"}


def test_a_batch_whose_top_level_exits_is_a_row_per_design(tmp_path: Path) -> None:
    path = _batch(tmp_path, "top", OK_MODEL)
    path.write_text(path.read_text() + "\nsys.exit(1)\n")
    out = tmp_path / "out"
    assert _convert(path, out).returncode == 2
    row = _rows(out)["good"]
    assert row["status"] == "syntax_error" and row["reason"] == "import failed: SystemExit: 1"

"""``zonegraph replay``, ``convert``, and batches of ``infer`` and ``build``, end to end."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import zonegraph
from zonegraph.batch import collect_parts
from zonegraph.cli import main
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.shapes import read_solids
from zonegraph.testing.batches import PLATE_AREA, PLATE_VOLUME, plate_model

SCRIPT = Path(sys.executable).parent / "zonegraph"
ROOT = Path(__file__).resolve().parents[1]  # run as ``python -m zonegraph.cli`` from here: this checkout
KERNEL = ("build123d", "OCP", "scipy", "sklearn")


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


BATCH = f"""
from build123d import *
{plate_model("1_a_0000")}
def model_1_b_0000():
    raise RuntimeError("broken model")

MODELS = {{
    "model_1_a_0000": {{"func": model_1_a_0000, "volume": {PLATE_VOLUME}, "area": {PLATE_AREA}}},
    "model_1_b_0000": {{"func": model_1_b_0000, "volume": 1.0, "area": 1.0}},
}}
"""


def test_convert_writes_verified_json_and_a_summary(tmp_path):
    batch = tmp_path / "01_2ops" / "batch_001.py"
    batch.parent.mkdir()
    batch.write_text(BATCH)
    # a fresh process, as a user runs it: forking this one after earlier tests ran OpenCASCADE
    # in it can deadlock the design's child
    proc = _cli("convert", str(tmp_path), "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    status = {d["design_id"]: d["status"] for d in summary["designs"]}
    assert status == {"1_a_0000": "ok", "1_b_0000": "model_raised"}
    design = load_design(tmp_path / "out" / "1_a_0000.json")
    assert [e.operation.name for e in design.extrudes] == ["NEW_BODY", "CUT"]
    assert replay(design).volume == pytest.approx(8 - 0.25 * math.pi, rel=1e-9)
    assert main(["convert", str(tmp_path / "missing"), "--out", str(tmp_path / "o2")]) == 2


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "zonegraph.cli", *args], cwd=ROOT, capture_output=True, text=True
    )


def test_batch_infer_writes_a_folder_per_part_and_a_summary(samples_dir, tmp_path):
    parts = tmp_path / "parts"
    parts.mkdir()
    for name in ("SingleSketchExtrude.json", "Pattern2_6c40bf33_0000.json", "Couch.json", "Couch.step"):
        shutil.copy(samples_dir / name, parts / name)
    (parts / "corrupt.step").write_text("ISO-10303-21;\nnot a STEP file\n")
    (parts / "notes.txt").write_text("not a part")
    out = tmp_path / "out"
    proc = _cli("infer", str(parts), "--out", str(out), "--budget", "1")
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    names = ["Couch.json", "Couch.step", "Pattern2_6c40bf33_0000", "SingleSketchExtrude", "corrupt"]
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == names  # stems; a shared one: file names
    summary = json.loads((out / "summary.json").read_text())
    rows = {r["name"]: r for r in summary["parts"]}
    assert [r["name"] for r in summary["parts"]] == names  # sorted files, in order
    assert {n: rows[n]["status"] for n in names[:4]} == dict.fromkeys(names[:4], "exact")
    assert rows["Couch.step"]["target"].endswith("Couch.step") and rows["Couch.step"]["iou_brep"] > 0.9999
    assert rows["corrupt"]["status"] == "invalid_input" and not rows["corrupt"]["ok"]
    assert rows["corrupt"]["reason"] and "\n" not in rows["corrupt"]["reason"]
    assert summary["totals"]["by_status"] == {"exact": 4, "invalid_input": 1}
    for name in names[:4]:
        assert json.loads((out / name / "result.json").read_text())["steps"] == rows[name]["steps"]
    assert json.loads((out / "corrupt" / "error.json").read_text())["status"] == "invalid_input"
    table = proc.stdout.splitlines()
    assert table[0].split()[:3] == ["part", "status", "steps"] and len(table) == 1 + len(names) + 1
    assert "5 parts: 4 ran, 1 failed" in table[-1]


def test_one_target_keeps_its_layout_and_several_files_make_a_batch(samples_dir, tmp_path):
    """In subprocesses: the test process has run OpenCASCADE's thread pool, which a fork cannot use."""
    one = tmp_path / "one"
    proc = _cli("build", str(samples_dir / "SingleSketchExtrude.json"), "--out", str(one), "--samples", "0")
    assert proc.returncode == 0, proc.stderr
    assert (one / "zones.parquet").is_file()  # --out is the part's own folder, as before batches
    files = [str(samples_dir / n) for n in ("SingleSketchExtrude.json", "Pattern2_6c40bf33_0000.json")]
    several = tmp_path / "several"
    proc = _cli("build", *files, "--out", str(several), "--samples", "0")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((several / "summary.json").read_text())
    assert [(r["name"], r["status"], r["zones"]) for r in summary["parts"]] == [
        ("SingleSketchExtrude", "ok", 1),
        ("Pattern2_6c40bf33_0000", "ok", 12),
    ]
    assert (several / "Pattern2_6c40bf33_0000" / "zones.parquet").is_file()


def test_a_folder_stands_for_its_part_files_and_equal_stems_keep_their_extensions(tmp_path):
    for name in ("b.step", "a.json", "a.STEP", "readme.md"):
        (tmp_path / name).write_text("")
    (tmp_path / "sub").mkdir()
    parts = collect_parts([str(tmp_path), str(tmp_path / "b.step"), str(tmp_path / "absent.brep")])
    assert [(p.name, p.path.name) for p in parts] == [
        ("a.STEP", "a.STEP"),
        ("a.json", "a.json"),
        ("b.step", "b.step"),
        ("b_2.step", "b.step"),  # the same file twice
        ("absent", "absent.brep"),  # kept, to fail as its own row
    ]


def test_help_and_argument_errors_load_no_geometry_kernel(tmp_path):
    code = (
        "import sys\n"
        "from zonegraph.cli import main\n"
        "for argv in (['--help'], ['infer', '--help'], ['infer'], ['build', 'x.step']):\n"
        "    try:\n"
        "        main(argv)\n"
        "    except SystemExit:\n"
        "        pass\n"
        f"assert main(['infer', {str(tmp_path / 'absent.step')!r}, '--out', 'o']) == 2\n"
        "assert main(['infer', 'x.step', '--out', 'o', '--guide', 'nope']) == 2\n"
        f"print([m for m in {KERNEL!r} if m in sys.modules])\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"
    assert "no such file" in proc.stderr and "unknown guide 'nope'" in proc.stderr


@pytest.mark.parametrize(
    ("flag", "value"), [("--budget", "0"), ("--budget", "-1"), ("--budget", "nan"), ("--expansions", "0")]
)
def test_a_bound_that_is_not_positive_is_a_user_error(samples_dir, tmp_path, flag, value):
    proc = _cli("infer", str(samples_dir / "Couch.json"), "--out", str(tmp_path / "o"), f"{flag}={value}")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    shown = float(value) if flag == "--budget" else int(value)
    message = f"zonegraph: error: {flag} {shown}: must be a positive number"
    assert proc.stderr.strip().splitlines() == [message]
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("command", ["replay", "build", "infer"])
def test_an_out_that_is_a_file_or_cannot_be_created_is_named_up_front(samples_dir, tmp_path, command):
    design = str(samples_dir / "Couch.json")
    existing = tmp_path / "existing"
    existing.write_text("keep me")
    proc = _cli(command, design, "--out", str(existing))
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip() == f"zonegraph: error: --out {existing}: exists and is not a folder"
    assert existing.read_text() == "keep me"
    below_file = existing / "sub"
    proc = _cli(command, design, "--out", str(below_file))
    assert proc.returncode == 2 and f"--out {below_file}: cannot be created" in proc.stderr


def test_a_folder_given_as_a_design_is_named_as_a_folder(tmp_path):
    proc = _cli("replay", str(tmp_path), "--out", str(tmp_path / "o"))
    assert proc.returncode == 2
    assert proc.stderr.strip() == f"zonegraph: error: {tmp_path}: invalid_input: is a folder, not a file"


def test_help_lists_commands_in_use_order_with_defaults_choices_and_examples(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    top = capsys.readouterr().out
    assert "{infer,build,replay,convert,server}" in top and "examples:" in top and "``" not in top
    with pytest.raises(SystemExit):
        main(["infer", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--guide {heuristic,random,net}" in text and "(default: heuristic)" in text
    assert "(default: 10.0)" in text and "(default: 5)" in text and "(default: None)" not in text
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"zonegraph {zonegraph.__version__}"


def test_a_model_for_a_guide_that_uses_none_is_refused(samples_dir, tmp_path, capsys):
    target = str(samples_dir / "SingleSketchExtrude.json")
    assert main(["infer", target, "--out", str(tmp_path / "o"), "--model", "m.pt"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    refusal = "zonegraph: error: --model m.pt: the heuristic guide uses no model (only --guide net does)"
    assert lines == [refusal]
    assert not (tmp_path / "o").exists()


def test_a_model_that_is_not_a_checkpoint_is_one_line_before_any_work(samples_dir, tmp_path, capsys):
    target = str(samples_dir / "SingleSketchExtrude.json")
    junk = tmp_path / "junk.npz"
    junk.write_text("not a zip")
    assert main(["infer", target, "--out", str(tmp_path / "o"), "--guide", "net", "--model", str(junk)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"zonegraph: error: {junk}: not a folded scorer")
    assert not (tmp_path / "o").exists()


def test_a_part_past_its_memory_limit_is_one_out_of_memory_line(samples_dir, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["build", str(samples_dir / "Couch.step"), "--out", str(out), "--samples", "1000000"]
    assert main([*argv, "--memory", "300"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"zonegraph: error: {samples_dir / 'Couch.step'}: out_of_memory: "
        "out of memory (MemoryError) past the 300 MiB memory limit"
    ]
    assert not out.exists()
    assert main([*argv, "--memory", "0"]) == 2
    assert capsys.readouterr().err.strip() == "zonegraph: error: --memory 0: must be a positive number"

"""Issue 14's seven cases of hostile input, each through the CLI as a user runs it: a one-line user
error with exit 2 (or a bug's traceback with exit 1), and no partial or stale output."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from OCP.gp import gp_Dir

from zonegraph.cli import EXIT_BUG, _fail
from zonegraph.isolation import classify, run_isolated
from zonegraph.status import Status

ROOT = Path(__file__).resolve().parents[1]


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "zonegraph.cli", *args], cwd=ROOT, capture_output=True, text=True
    )


def _one_line_error(proc: subprocess.CompletedProcess) -> str:
    """The message of a user error, after checking that it is one: exit 2, one line, no stdout."""
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == "", proc.stdout
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("zonegraph: error: "), proc.stderr
    return lines[0]


def _design(samples_dir: Path, tmp_path: Path, edit, name: str = "edited.json") -> Path:
    """SingleSketchExtrude.json with ``edit(design, sketch, extrude)`` applied, written as JSON
    (``json.dump`` writes NaN and Infinity as the tokens ``NaN`` and ``Infinity``)."""
    design = json.loads((samples_dir / "SingleSketchExtrude.json").read_text())
    sketch = next(e for e in design["entities"].values() if e["type"] == "Sketch")
    extrude = next(e for e in design["entities"].values() if e["type"] == "ExtrudeFeature")
    edit(design, sketch, extrude)
    path = tmp_path / name
    path.write_text(json.dumps(design))
    return path


def _distance(value: float):
    return lambda d, s, e: e["extent_one"]["distance"].__setitem__("value", value)


def _leftovers(folder: Path) -> list[str]:
    """Scratch folders a run left beside its --out (they are named ``.<out>.partial-*``)."""
    return sorted(p.name for p in folder.iterdir() if ".partial-" in p.name)


# ------------------------------------------------------------------- 1: replay hangs on Infinity


def test_an_infinite_distance_is_named_before_any_geometry(samples_dir, tmp_path):
    """This design kept OpenCASCADE busy for over 10 minutes; the schema now rejects it at once."""
    path = _design(samples_dir, tmp_path, _distance(math.inf))
    message = _one_line_error(_cli("replay", str(path), "--out", str(tmp_path / "o")))
    assert message.endswith("extent_one.distance.value: input should be a finite number (got inf)")
    assert not (tmp_path / "o").exists() and _leftovers(tmp_path) == []


def test_replay_runs_under_a_timeout_and_leaves_nothing(samples_dir, tmp_path):
    design = samples_dir / "Couch.json"
    message = _one_line_error(_cli("replay", str(design), "--out", str(tmp_path / "o"), "--timeout", "0.001"))
    assert message == f"zonegraph: error: {design}: timeout: no result after 0.001 s"
    assert not (tmp_path / "o").exists() and _leftovers(tmp_path) == []


# ------------------------------------------------- 2 and 3: malformed designs, in all three commands


@pytest.mark.parametrize("command", ["replay", "build", "infer"])
def test_a_timeline_that_is_a_number_is_named(samples_dir, tmp_path, command):
    path = tmp_path / "five.json"
    path.write_text(json.dumps({"timeline": 5, "entities": {}}))
    message = _one_line_error(_cli(command, str(path), "--out", str(tmp_path / "o")))
    assert (
        message == f"zonegraph: error: {path}: invalid_design: timeline: input should be a valid list (got 5)"
    )


def test_an_entity_that_is_a_string_is_named(samples_dir, tmp_path):
    def edit(d, s, e):
        d["entities"][next(iter(d["entities"]))] = "a string"

    path = _design(samples_dir, tmp_path, edit)
    message = _one_line_error(_cli("replay", str(path), "--out", str(tmp_path / "o")))
    uuid = next(iter(json.loads(path.read_text())["entities"]))
    assert message.endswith(f"[{uuid}] the entity: must be an object with a string 'type' (got 'a string')")


def test_an_absurd_distance_is_named_by_infer(samples_dir, tmp_path):
    """It used to end in ``Standard_DomainError:  (partition.py:135)``, an empty reason."""
    path = _design(samples_dir, tmp_path, _distance(1e12))
    message = _one_line_error(_cli("infer", str(path), "--out", str(tmp_path / "o")))
    assert "extent_one.distance.value: input should be less than or equal to 1000000" in message


def test_replay_exits_non_zero_when_the_file_disagrees_with_its_own_properties(samples_dir, tmp_path):
    def edit(d, s, e):
        d["properties"]["volume"] *= 1.01

    path = _design(samples_dir, tmp_path, edit)
    message = _one_line_error(_cli("replay", str(path), "--out", str(tmp_path / "o")))
    assert "replay_mismatch: replay disagrees with the file's properties: volume differs by 9.9e-03" in (
        message
    )
    assert not (tmp_path / "o").exists()
    proc = _cli("replay", str(path), "--out", str(tmp_path / "o"), "--no-check")
    assert proc.returncode == 0 and (tmp_path / "o" / "summary.json").is_file()


def test_a_bug_keeps_its_traceback_and_exits_1(capsys):
    """An exception of our own code is not the user's fault: traceback and exit 1. An
    OpenCASCADE exception on the input's geometry is a one-line status."""
    outcome = run_isolated(int, ("not a number",), timeout=30)
    assert outcome.status == Status.BUG and outcome.reason.startswith("ValueError: invalid literal")
    assert _fail("part.step", outcome) == EXIT_BUG
    err = capsys.readouterr().err
    assert err.startswith("Traceback") and "ValueError" in err
    assert err.splitlines()[-1] == "zonegraph: internal error on part.step (a bug: please report it)"
    try:
        gp_Dir(0, 0, 0)
    except Exception as exc:  # a real kernel exception, raised by OCP
        status, reason, detail = classify(exc)
    assert status == Status.KERNEL_ERROR and not detail
    assert reason.startswith("OpenCASCADE Standard_ConstructionError")


# ---------------------------------------------------------------------- 4: misleading messages


@pytest.mark.parametrize(
    ("edit", "field", "old"),
    [
        (_distance(math.nan), "extent_one.distance.value", "extrude has zero length"),
        (
            lambda d, s, e: s["transform"]["origin"].__setitem__("x", math.nan),
            "transform.origin.x",
            "does not close",
        ),
    ],
)
def test_a_nan_is_named_by_its_field(samples_dir, tmp_path, edit, field, old):
    path = _design(samples_dir, tmp_path, edit)
    message = _one_line_error(_cli("replay", str(path), "--out", str(tmp_path / "o")))
    assert f"{field}: input should be a finite number (got nan)" in message and old not in message


# ------------------------------------------------------ 6: atomic outputs, stale results removed


def test_a_failed_infer_leaves_no_partial_files_and_removes_the_stale_result(samples_dir, tmp_path):
    out = tmp_path / "o"
    (out).mkdir()
    (out / "mine.txt").write_text("the user's own file")
    design = str(samples_dir / "Couch.json")
    proc = _cli("infer", design, "--out", str(out), "--budget", "2")
    assert proc.returncode == 0, proc.stderr
    assert (out / "result.json").is_file() and (out / "sequence.py").is_file()
    message = _one_line_error(_cli("infer", design, "--out", str(out), "--timeout", "0.02"))
    assert message.endswith("timeout: no result after 0.02 s")
    assert sorted(p.name for p in out.iterdir()) == ["mine.txt"]
    assert _leftovers(tmp_path) == []


# --------------------------------------------------------- 7: the kernel's console stays quiet


def test_a_corrupt_step_prints_one_line_and_no_kernel_messages(samples_dir, tmp_path):
    """OpenCASCADE printed ``**** ERR StepFile : ... Incorrect syntax`` to stdout from C++."""
    truncated = tmp_path / "truncated.step"
    truncated.write_bytes((samples_dir / "Couch.step").read_bytes()[:3000])
    for command in ("build", "infer"):
        message = _one_line_error(_cli(command, str(truncated), "--out", str(tmp_path / command)))
        assert "invalid_input: file holds no shape (corrupt or empty): ERR StepFile" in message
        assert "Incorrect syntax" in message  # the kernel's own reason, moved into the one line
        assert not (tmp_path / command).exists()

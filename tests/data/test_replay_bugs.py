"""A failure inside a replay step is the input's fault (exit 2) only when OpenCASCADE raised it;
an exception of our own code is a bug: its traceback and exit 1, never "OpenCASCADE failed"."""

from __future__ import annotations

import json

import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
from OCP.gp import gp_Dir, gp_Pnt

from zonegraph.cli import EXIT_BUG, EXIT_USER_ERROR, main
from zonegraph.data import replay as replay_module
from zonegraph.errors import ReplayError, is_kernel_error

SAMPLE = "Pattern2_6c40bf33_0000.json"


def _our_bug(extrude, sketches, where):
    return extrude.profiles + 1  # a genuine TypeError: a tuple plus an int


def _construction_error(extrude, sketches, where):
    return gp_Dir(0, 0, 0)  # OCP raises Standard_ConstructionError: no direction


def _not_done(extrude, sketches, where):
    # OCP raises StdFail_NotDone, which OCP does not derive from Standard_Failure
    return BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(0, 0, 0)).Edge()


def test_a_bug_in_replay_exits_1_with_its_traceback(samples_dir, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(replay_module, "extrude_tool", _our_bug)
    design = str(samples_dir / SAMPLE)
    assert main(["replay", design, "--out", str(tmp_path / "o")]) == EXIT_BUG
    err = capsys.readouterr().err
    assert err.startswith("Traceback") and "TypeError" in err and "OpenCASCADE" not in err
    assert err.splitlines()[-1] == f"zonegraph: internal error on {design} (a bug: please report it)"
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("step", "name"),
    [(_construction_error, "Standard_ConstructionError"), (_not_done, "StdFail_NotDone")],
)
def test_a_kernel_failure_in_replay_exits_2(samples_dir, tmp_path, monkeypatch, capsys, step, name):
    monkeypatch.setattr(replay_module, "extrude_tool", step)
    design = str(samples_dir / SAMPLE)
    assert main(["replay", design, "--out", str(tmp_path / "o")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.splitlines() == [err.strip()] and "Traceback" not in err
    assert err.startswith(f"zonegraph: error: {design}: {ReplayError.status}: [")
    assert f"OpenCASCADE failed: {name}" in err
    assert not (tmp_path / "o").exists()


def test_a_taper_the_kernel_cannot_offset_exits_2(samples_dir, tmp_path, capsys):
    """build123d raises a plain RuntimeError when OpenCASCADE's 2D offset of a tapered profile
    fails: the geometry's fault (a taper of -1 rad splits this profile), not ours."""
    design = json.loads((samples_dir / "SingleSketchExtrude_RootComponent.json").read_text())
    extrude = next(e for e in design["entities"].values() if e["type"] == "ExtrudeFeature")
    extrude["extent_one"]["taper_angle"]["value"] = -1.0
    path = tmp_path / "steep.json"
    path.write_text(json.dumps(design))
    assert main(["replay", str(path), "--out", str(tmp_path / "o")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.endswith("OpenCASCADE failed: RuntimeError: Unexpected result type")


def test_every_ocp_exception_is_a_kernel_error_and_nothing_else_is():
    for step in (_construction_error, _not_done):
        with pytest.raises(Exception) as caught:
            step(None, None, "")
        assert is_kernel_error(caught.value), caught.value
    with pytest.raises(TypeError) as bug:
        _our_bug(type("X", (), {"profiles": ()})(), None, "")
    assert not is_kernel_error(bug.value)

"""What ``pip install`` gives a user: one top-level name, the shipped checkpoint, and a core-only
install (no torch) that runs every guide, the network's shipped weights folded to numpy, and
turns a PyTorch checkpoint into one line naming the extra it needs.

The core-only venv is an honest install: a fresh venv without system site packages, the built
wheel and its core dependencies installed by pip from the configured indexes (a couple of
minutes), so these tests are marked slow.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from importlib.util import find_spec
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# Checkout folders the build never reads: data and outputs (large), other environments.
NOT_SOURCE = {".git", ".venv", ".dvc", "data", "models", "mlruns", "build", "dist", "bench_out", "results"}
TORCH_FREE = "import importlib.util as u; print([m for m in ('torch', 'torch_geometric') if u.find_spec(m)])"

pytestmark = pytest.mark.slow
# The core venv's processes see only what the wheel installed: with a checkout on PYTHONPATH pip
# would find zonegraph "already installed" there and skip the wheel.
CORE_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def _source_copy(dest: Path) -> Path:
    """The checkout without its data, so the build's scratch files stay out of the checkout."""

    def ignore(folder: str, names: list[str]) -> set[str]:
        skipped = {n for n in names if n == "__pycache__" or n.endswith(".egg-info")}
        return skipped | (NOT_SOURCE & set(names) if Path(folder) == ROOT else set())

    shutil.copytree(ROOT, dest, ignore=ignore)
    return dest


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("wheel")
    source = _source_copy(tmp / "src")
    cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-w", str(tmp), "."]
    subprocess.run(cmd, cwd=source, check=True, capture_output=True, text=True)
    (found,) = tmp.glob("zonegraph-*.whl")
    return found


@pytest.fixture(scope="module")
def core_venv(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh venv holding the wheel and its core dependencies only; returns its bin folder."""
    venv = tmp_path_factory.mktemp("core") / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    install = [str(venv / "bin" / "python"), "-m", "pip", "install", "-q", str(wheel)]
    proc = subprocess.run(install, capture_output=True, text=True, env=CORE_ENV)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return venv / "bin"


def test_the_wheel_installs_one_top_level_name_and_ships_the_checkpoint(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        (top_level,) = [n for n in names if n.endswith(".dist-info/top_level.txt")]
        assert archive.read(top_level).decode().split() == ["zonegraph"]
    assert {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")} == {"zonegraph"}
    assert "zonegraph/network/checkpoints/scorer.pt" in names
    assert "zonegraph/network/checkpoints/scorer.npz" in names
    assert "zonegraph/network/checkpoints/MODEL_CARD.md" in names
    assert "zonegraph/network/ranker.py" in names


def test_a_core_install_runs_every_guide_and_names_the_extra_for_a_pytorch_checkpoint(
    core_venv, samples_dir, tmp_path
):
    python, zonegraph = str(core_venv / "python"), str(core_venv / "zonegraph")
    found = subprocess.run([python, "-c", TORCH_FREE], capture_output=True, text=True, env=CORE_ENV)
    assert found.stdout.split() == ["[]"]
    guides = "import zonegraph.plugins as p; print(p.available_guides())"
    listed = subprocess.run(
        [python, "-c", guides], capture_output=True, text=True, check=True, cwd=tmp_path, env=CORE_ENV
    )
    assert listed.stdout.strip() == "['heuristic', 'random', 'net']"
    part = samples_dir / "Couch.step"
    for guide in ("heuristic", "net"):
        cmd = [zonegraph, "infer", str(part), "--out", str(tmp_path / guide), "--budget", "5"]
        cmd += ["--guide", guide]
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path, env=CORE_ENV)
        assert proc.returncode == 0, proc.stderr
        assert json.loads((tmp_path / guide / "result.json").read_text())["status"] == "exact"
    checkpoint = tmp_path / "scorer.pt"
    checkpoint.write_bytes(b"not read: torch is missing")
    cmd = [zonegraph, "infer", str(part), "--out", str(tmp_path / "pt"), "--model", str(checkpoint)]
    proc = subprocess.run(
        [*cmd, "--guide", "net"], capture_output=True, text=True, cwd=tmp_path, env=CORE_ENV
    )
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"zonegraph: error: {checkpoint}: a PyTorch checkpoint needs torch and torch_geometric: "
        "pip install 'zonegraph[train]' (the shipped weights need neither)"
    ]
    assert not (tmp_path / "pt").exists()


@pytest.mark.skipif(find_spec("torch") is None, reason="the network guide needs torch (the train extra)")
def test_with_the_train_extra_a_pytorch_checkpoint_guides_infer(samples_dir, tmp_path):
    from zonegraph.network.checkpoint import SHIPPED

    part = str(samples_dir / "Couch.json")
    cmd = [sys.executable, "-m", "zonegraph.cli", "infer", part, "--out", str(tmp_path), "--guide", "net"]
    cmd += ["--model", str(SHIPPED)]
    proc = subprocess.run([*cmd, "--budget", "10"], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "result.json").read_text())["status"] == "exact"  # a box and a cut

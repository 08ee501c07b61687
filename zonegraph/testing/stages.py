"""Run a pipeline stage the way DVC does: its ``dvc.yaml`` command in a fresh interpreter."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import yaml


def stage_command(module: str, project: Path) -> list[str]:
    """The words of the ``dvc.yaml`` command that runs ``python -m module``, paths included."""
    stages = yaml.safe_load((project / "dvc.yaml").read_text())["stages"]
    commands = [shlex.split(s["cmd"]) for s in stages.values()]
    return next(c for c in commands if c[:3] == ["python", "-m", module])


def run_stage(module: str, cwd: Path | str, project: Path | None = None) -> str:
    """Run the stage of the checkout ``project`` (default: the current folder) whose command runs
    ``module``, in ``cwd`` (which holds its ``params.yaml``); assert it exits 0 (its stderr's tail
    is the message when not) and return its stdout. The stage scripts are the checkout's, not
    installed, so the checkout goes on ``PYTHONPATH``."""
    project = (project or Path.cwd()).resolve()
    words = stage_command(module, project)
    path = os.pathsep.join(p for p in (str(project), os.environ.get("PYTHONPATH")) if p)
    proc = subprocess.run(
        [sys.executable, *words[1:]],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": path},
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout

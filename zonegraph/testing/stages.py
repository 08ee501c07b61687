"""Run a pipeline stage the way DVC does: ``python -m <module>`` in a fresh interpreter."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def run_stage(module: str, cwd: Path | str) -> str:
    """Run ``module`` in ``cwd`` (which holds its ``params.yaml``), assert it exits 0 (its stderr's
    tail is the message when not) and return its stdout."""
    proc = subprocess.run(
        [sys.executable, "-m", module], cwd=cwd, capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout

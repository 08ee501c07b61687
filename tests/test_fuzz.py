"""Issue 14's fast fuzz slice: 100 mutated real inputs through ``zonegraph replay|build|infer``.

Every input must end in success, a one-line user error (exit 2) or a timeout: no hang, traceback,
noise or partial output (``bench/fuzz.py`` defines the inputs and the classes). The harness runs in
a fresh interpreter: it forks a child per input, and this pytest process may already have run
OpenCASCADE Booleans, after which a forked child can hang.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from bench.fuzz import SAMPLES, SKIP_REASON, VIOLATIONS

ROOT = Path(__file__).resolve().parents[1]
INPUTS, SEED, TIMEOUT_S = 100, 0, 10


@pytest.mark.skipif(not SAMPLES.is_dir(), reason=SKIP_REASON)
def test_fuzz_slice_keeps_the_cli_contract(tmp_path):
    argv = ["--inputs", str(INPUTS), "--seed", str(SEED), "--timeout", str(TIMEOUT_S), "--out", str(tmp_path)]
    proc = subprocess.run(
        [sys.executable, "-m", "bench.fuzz_bench", *argv],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert (tmp_path / "rows.json").is_file(), proc.stderr[-3000:]
    rows = json.loads((tmp_path / "rows.json").read_text())
    assert len(rows) == INPUTS
    bad = [r for r in rows if r["outcome"] in VIOLATIONS]
    shown = "\n".join(
        f"#{r['index']} {r['command']} {r['mutation']}: {r['outcome']}: {r['detail']}" for r in bad[:20]
    )
    assert not bad, f"{len(bad)} of {INPUTS} inputs broke the contract:\n{shown}\n\n{proc.stdout[-4000:]}"

"""The start-up benchmark's measurement: a child's CPU, wall and peak memory come from its own
``wait4`` record, so a process that allocates shows it and a failing one keeps its status."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from bench.startup_bench import _warm_out, original_problem, table

MEASURE = """
import json, sys
from pathlib import Path
from bench.startup_bench import measure
cmds = {
    "big": [sys.executable, "-c", "b = bytearray(200 * 2**20); b[::4096] = b'x' * len(b[::4096])"],
    "small": [sys.executable, "-c", "pass"],
    "failing": [sys.executable, "-c", "raise SystemExit(3)"],
}
print(json.dumps({k: measure(c, Path(sys.argv[1])).__dict__ for k, c in cmds.items()}))
"""


def test_measure_sees_the_childs_memory_and_cpu_and_exit_status(tmp_path):
    # Measured from a fresh interpreter: a child's peak memory starts at its parent's resident size
    # (fork copies it before exec), and the test process has imported half the project.
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run(
        [sys.executable, "-c", MEASURE, str(tmp_path)], cwd=root, capture_output=True, text=True, check=True
    )
    runs = json.loads(out.stdout)
    big, small = runs["big"], runs["small"]
    assert big["rc"] == 0 and big["peak_mb"] > small["peak_mb"] + 150 and big["cpu_s"] > 0
    assert runs["failing"]["rc"] == 3


def test_the_original_is_skipped_with_a_reason_and_the_table_has_medians(tmp_path):
    assert "no --original" in original_problem(None, sys.executable, [])
    assert "not a brownvc/zone-graphs checkout" in original_problem(tmp_path, sys.executable, [])
    run = {"rc": 0, "cpu_s": 1.0, "wall_s": 2.0, "peak_mb": 250.0}
    rows = [{"part": p, "step_bytes": n, "build": run} for p, n in (("a", 10), ("b", 5))]
    text = table(rows, ["build"], "because")
    assert "| **median of 2** | 1.00 | 2.00 | 250 |" in text and "smallest part (b" in text


def test_a_warm_run_writes_to_its_own_out_folder_whatever_follows_it():
    cmd = ["python", "-m", "zonegraph", "infer", "p.step", "--out", "o/p", "--budget", "1", "--guide", "net"]
    assert _warm_out(cmd) == [*cmd[:6], "o/p_warm", *cmd[7:]]

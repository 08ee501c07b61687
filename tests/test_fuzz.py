"""Issue 14's fast fuzz slice: 100 mutated real inputs through ``zonegraph replay|build|infer``.

Every input must end in success, a one-line user error (exit 2) or a timeout: no hang, traceback,
noise or partial output (``zonegraph/testing/fuzz.py`` defines the inputs and the classes). The
harness runs in a fresh interpreter: it forks a child per input, and this pytest process may
already have run OpenCASCADE Booleans, after which a forked child can hang.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from zonegraph.testing import requires_samples
from zonegraph.testing.fuzz import VIOLATIONS, Row, classify

ROOT = Path(__file__).resolve().parents[1]
INPUTS, SEED, TIMEOUT_S = 100, 0, 10


@pytest.mark.slow
@requires_samples
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


def _classified(tmp_path, command="build", rc=2, stdout="", stderr="", result=None, beside=(), inside=()):
    """A run's classification from made-up outputs (no geometry, no fork)."""
    parent, out = tmp_path / "parent", tmp_path / "parent" / "out"
    parent.mkdir(parents=True)
    for name in beside:
        (parent / name).write_text("x")
    if inside:
        out.mkdir()
        for name in inside:
            (out / name).write_text("x")
    row = Row(0, command, "json", "s", "m", [], stdout=stdout, stderr=stderr)
    classify(row, {"rc": rc} if result is None else result, parent, out)
    return row.outcome, row.violations


ERR = "zonegraph: error: d.json: invalid_design: extrude has zero length\n"
KERNEL = "\x1b[31;1m**** ERR StepFile : Undefined Parsing: Line 2: Incorrect syntax ****\n"


def test_classes_of_made_up_runs(tmp_path):
    """Each class on the smallest run that shows it, and precedence when several apply."""
    cases = {
        "user": dict(stderr=ERR),
        "timeout": dict(stderr="zonegraph: error: d.json: timeout: no result after 20 s\n"),
        "ok": dict(
            command="infer",
            rc=0,
            stdout="d.json: exact, 1 steps (union), B-rep IoU 1\n",
            inside=["result.json"],
        ),
        "incomplete": dict(command="infer", rc=0, inside=["sequence.py"]),
        "kernel": dict(stderr=KERNEL + ERR),
        "stdout": dict(stdout=KERNEL, stderr=ERR),
        "exit1": dict(rc=1, stderr="Traceback (most recent call last):\nValueError: x\n"),
        "escaped": dict(result={"exception": "ValueError: x"}),
        "two_lines": dict(stderr=ERR + ERR),
        "internal": dict(stderr="zonegraph: error: d.json: error: TypeError: x (design.py:280)\n"),
        "hang": dict(result={"hang": True}, inside=["steps.json"]),
        "left_in_out": dict(stderr=ERR, inside=["sequence.py"]),
        "left_beside": dict(stderr=ERR, beside=[".out.tmp-1"]),
        "all_at_once": dict(stderr=KERNEL + "Traceback (most recent call last):\n", rc=1, inside=["a"]),
    }
    expected = {
        "user": "user_error",
        "timeout": "timeout",
        "ok": "success",
        "incomplete": "partial_output",
        "kernel": "noise",
        "stdout": "noise",
        "exit1": "traceback",
        "escaped": "traceback",
        "two_lines": "traceback",
        "internal": "traceback",
        "hang": "hang",
        "left_in_out": "partial_output",
        "left_beside": "partial_output",
        "all_at_once": "traceback",
    }
    got = {name: _classified(tmp_path / name, **kw) for name, kw in cases.items()}
    assert {name: outcome for name, (outcome, _) in got.items()} == expected
    assert got["all_at_once"][1] == ["traceback", "noise", "partial_output"]


PROBE = """
PROBE = ("a-literal-no-module-had", 987654, 31337, 7, 12, b"zz", -3, 2.5)
"""

DRAW = """
import hashlib, sys
sys.path.insert(0, sys.argv[1])
if len(sys.argv) > 2:
    import probe  # a local module with literals of its own
from zonegraph.testing import fuzz
cases = fuzz.draw_cases(200, 0, fuzz.fuzz_cases({}))
print(hashlib.sha1("\\n".join(c.label() for c in cases).encode()).hexdigest())
"""


@requires_samples
def test_the_drawn_inputs_depend_on_the_seed_alone(tmp_path):
    """Hypothesis mixes the literals of every loaded local module into its draws; the harness must
    not, so that a change of the project's code never changes the fuzz inputs (a before/after pair
    of runs compares input by input)."""
    (tmp_path / "probe.py").write_text(PROBE)

    def digest(*extra: str) -> str:
        proc = subprocess.run(
            [sys.executable, "-c", DRAW, str(tmp_path), *extra],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=300,
            check=True,
        )
        return proc.stdout.strip()

    assert digest() == digest("with the probe module")


def test_convert_runs_are_classed_by_their_design_rows(tmp_path):
    """``convert`` says why in one row line per failed design, prints its progress whatever the
    outcome, and keeps a failed run's summary.json."""
    row = "zonegraph: b/batch_001.py: 123_ab_0000: timeout: no result after 10 s\n"
    progress = "io/batch_001.py: 0/1 converted\nconverted 0 of 1 designs -> out (by status {})\n"
    kept = ["summary.json", ".zonegraph-outputs.json"]
    cases = {
        "timeout": dict(stdout=progress, stderr=row, inside=kept),
        "user": dict(stderr=row.replace("timeout", "syntax_error")),
        "internal": dict(stderr=row.replace("no result after 10 s", "TypeError: x (convert.py:12)")),
        "none": dict(stdout=progress),
        "left": dict(stderr=row, inside=[*kept, "123_ab_0000.json"]),
        "ok": dict(rc=0, stdout=progress.replace("0/1", "1/1"), inside=["summary.json", "1.json"]),
        "no_json": dict(rc=0, stdout=progress, inside=["summary.json"]),
    }
    got = {name: _classified(tmp_path / name, command="convert", **kw)[0] for name, kw in cases.items()}
    assert got == {
        "timeout": "timeout",
        "user": "user_error",
        "internal": "traceback",
        "none": "traceback",
        "left": "partial_output",
        "ok": "success",
        "no_json": "partial_output",
    }

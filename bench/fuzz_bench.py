"""The fuzz benchmark of issue 14: mutated real inputs through ``zonegraph replay|build|infer|convert``.

Inputs: mutated sample designs (replay, build, infer), STEP files replayed from them (build,
infer) and, a share of them, mutated one-model batches of the build123d corpus (convert, with
hostile statements such as endless loops, ``os._exit``, signals and unbounded allocation under
``--memory``); see ``zonegraph/testing/fuzz.py``.

    python -m bench.fuzz_bench --inputs 1000 --seed 0 --out DIR [--timeout 20]

Prints progress lines, then a table: inputs tried, outcomes by class and by command, the slowest
input and the distinct violations; writes ``DIR/rows.json`` (one row per input), ``DIR/table.md``
and, under ``DIR/violations/``, the input file of every violation (named by its row index) to
reproduce it. Run it in a fresh interpreter: the harness forks a child per input, and a process
that already ran an OpenCASCADE Boolean may not fork safely. Exit status 1 if any input broke the
contract (a hang, a traceback, noise or partial output).
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

from zonegraph.testing.fuzz import GOOD, OUTCOMES, SAMPLES, SKIP_REASON, VIOLATIONS, Row, fuzz


def progress(every: int, t0: float) -> Callable[[int, int, list[Row]], None]:
    """A callback printing one line per ``every`` inputs: how far, how long, outcomes so far."""

    def report(done: int, total: int, rows: list[Row]) -> None:
        if done % every and done != total:
            return
        counts = Counter(r.outcome for r in rows)
        shown = ", ".join(f"{k} {counts[k]}" for k in OUTCOMES if counts[k])
        print(f"[{done:5d}/{total}] {time.perf_counter() - t0:7.1f} s  {shown}", flush=True)

    return report


def cause(row: Row) -> str:
    """A violation's cause with the run's own paths, numbers and colours blanked, and a kernel
    message cut to its source and kind, to group alike violations."""
    text = re.sub(r"/\S*zg-fuzz-\S*?/(io|parent)/", "", row.detail)
    text = re.sub(r"\\x1b\[[\d;]*m", "", text)
    text = re.sub(r"\d+(\.\d+)?(e[+-]?\d+)?", "N", text)
    if row.outcome == "noise" and "***" in text:
        text = ":".join(text.lstrip("'\"").split(":")[:2]) + ": ..."
    return f"{row.outcome}: {text[:160]}"


def table(rows: list[Row], seconds: float) -> str:
    """The markdown table of a run."""
    counts = Counter(r.outcome for r in rows)
    commands = sorted({r.command for r in rows})
    by = Counter((r.command, r.outcome) for r in rows)
    good, bad = sum(counts[k] for k in GOOD), sum(counts[k] for k in VIOLATIONS)
    lines = [
        f"Fuzz run: {len(rows)} inputs tried in {seconds:.1f} s ({good} kept the contract, {bad} violations)",
        "",
        "| outcome | inputs | " + " | ".join(commands) + " |",
        "|---|---:|" + "---:|" * len(commands),
    ]
    for k in OUTCOMES:
        lines.append(f"| {k} | {counts[k]} | " + " | ".join(str(by[c, k]) for c in commands) + " |")
    lines.append(
        "| all | "
        + f"{len(rows)} | "
        + " | ".join(str(sum(by[c, k] for k in OUTCOMES)) for c in commands)
        + " |"
    )
    if rows:
        slow = max(rows, key=lambda r: r.seconds)
        lines += [
            "",
            f"Slowest input: #{slow.index} `{slow.command}` {slow.mutation} ({slow.kind} {slow.source}): "
            f"{slow.seconds:.2f} s, {slow.outcome}",
        ]
    causes = Counter(cause(r) for r in rows if r.outcome in VIOLATIONS)
    if causes:
        first: dict[str, int] = {}
        for r in rows:
            first.setdefault(cause(r), r.index)
        lines += ["", "| violation cause | inputs | first |", "|---|---:|---:|"]
        lines += [f"| {c.replace('|', '/')} | {n} | #{first[c]} |" for c, n in causes.most_common()]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--inputs", type=int, default=1000, help="how many mutated inputs to run")
    parser.add_argument(
        "--seed", type=int, default=0, help="Hypothesis seed: the same inputs for the same seed"
    )
    parser.add_argument("--timeout", type=float, default=20.0, help="each command's --timeout in seconds")
    parser.add_argument(
        "--out", type=Path, default=Path("data/fuzz"), help="rows.json, table.md, violations/"
    )
    args = parser.parse_args()
    if not SAMPLES.is_dir():
        print(f"fuzz_bench: {SKIP_REASON}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    shutil.rmtree(args.out / "violations", ignore_errors=True)  # an earlier run's inputs
    t0 = time.perf_counter()
    rows = fuzz(args.inputs, args.seed, args.timeout, args.out / "violations", progress(25, t0))
    text = table(rows, time.perf_counter() - t0)
    (args.out / "rows.json").write_text(json.dumps([asdict(r) for r in rows], indent=1))
    (args.out / "table.md").write_text(text + "\n")
    print(text)
    return 1 if any(r.outcome in VIOLATIONS for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())

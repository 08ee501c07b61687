"""Wall time per part: one batch ``zonegraph infer FOLDER`` against one CLI process per part.

    python -m bench.batch_bench [--parts 100] [--budget 1] [--source FOLDER] [--singles N]
                                [--out bench_out/batch]

The parts are ``--source``'s part files (default: the real Fusion 360 Gallery JSON samples in
``../shared``), copied round-robin into one folder until there are ``--parts`` of them. The batch is
one ``python -m zonegraph.cli infer FOLDER --out OUT --budget B``; the singles are ``python -m
zonegraph.cli infer PART --out OUT --budget B``, one process each, for the first ``--singles`` parts
(default: all). Both run this checkout's code. Prints the wall seconds per part of each, their
ratio, and whether both ways gave every part the same status.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

from zonegraph.batch import PART_SUFFIXES
from zonegraph.testing import SAMPLES

ROOT = Path(__file__).resolve().parents[1]


def stage_parts(source: Path, count: int, folder: Path) -> list[Path]:
    """``count`` copies of ``source``'s part files, round-robin, named ``NNN_<stem>`` in order."""
    files = sorted(p for p in source.iterdir() if p.suffix.lower() in PART_SUFFIXES)
    if not files:
        sys.exit(f"no {', '.join(PART_SUFFIXES)} files in {source}")
    folder.mkdir(parents=True)
    parts = []
    for i in range(count):
        src = files[i % len(files)]
        parts.append(folder / f"{i:03d}_{src.name}")
        shutil.copy(src, parts[-1])
    return parts


def cli(*args: str) -> float:
    """Wall seconds of one ``python -m zonegraph.cli`` process (its output is discarded)."""
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "zonegraph.cli", *args], cwd=ROOT, capture_output=True)
    return time.perf_counter() - t0


def status_of(folder: Path) -> str:
    """A part's status from its output folder: ``result.json``, else the batch's ``error.json``."""
    for name in ("result.json", "error.json"):
        if (folder / name).is_file():
            return str(json.loads((folder / name).read_text())["status"])
    return "no output"


def run_batch(parts: Path, out: Path, budget: float) -> tuple[float, float, dict[str, str]]:
    """The batch's wall seconds, the seconds its parts took (the imports excluded), the statuses."""
    wall = cli("infer", str(parts), "--out", str(out), "--budget", str(budget))
    summary = json.loads((out / "summary.json").read_text())
    return wall, summary["totals"]["part_seconds"], {r["name"]: r["status"] for r in summary["parts"]}


def run_singles(parts: list[Path], out: Path, budget: float) -> tuple[list[float], dict[str, str]]:
    walls, status = [], {}
    for part in parts:
        walls.append(cli("infer", str(part), "--out", str(out / part.stem), "--budget", str(budget)))
        status[part.stem] = status_of(out / part.stem)
    return walls, status


def report(batch: tuple[float, float, dict[str, str]], singles: tuple[list[float], dict[str, str]]) -> None:
    """Seconds per part both ways, their ratio, and whether the statuses agree."""
    (wall, part_seconds, batch_status), (walls, single_status) = batch, singles
    n = len(batch_status)
    per_batch, per_single = wall / n, sum(walls) / len(walls)
    print(
        f"  batch:  1 process, {wall:.1f} s wall, {per_batch:.3f} s per part "
        f"({part_seconds / n:.3f} s in the part's own child, start-up excluded)"
    )
    print(
        f"  single: {len(walls)} processes, {sum(walls):.1f} s wall, {per_single:.3f} s per part "
        f"(median {statistics.median(walls):.3f}, min {min(walls):.3f}, max {max(walls):.3f})"
    )
    print(f"  single / batch per part: {per_single / per_batch:.1f}x")
    same = sum(batch_status[p] == s for p, s in single_status.items())
    counts = dict(Counter(batch_status.values()))
    print(f"  same status both ways: {same} of {len(single_status)}; batch statuses {counts}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", type=int, default=100, help="parts in the batch")
    parser.add_argument("--budget", type=float, default=1.0, help="search seconds per part")
    parser.add_argument("--source", type=Path, default=SAMPLES, help="folder of part files to copy")
    parser.add_argument("--singles", type=int, default=None, help="single calls (default: every part)")
    parser.add_argument("--out", type=Path, default=ROOT / "bench_out" / "batch", help="work folder")
    args = parser.parse_args()
    if not args.source.is_dir():
        sys.exit(f"no part folder at {args.source} (clone ../shared beside the repo, or pass --source)")
    shutil.rmtree(args.out, ignore_errors=True)
    parts = stage_parts(args.source, args.parts, args.out / "parts")
    batch = run_batch(args.out / "parts", args.out / "batch", args.budget)
    singles = run_singles(parts[: args.singles], args.out / "singles", args.budget)
    print(f"{len(parts)} parts from {args.source}, --budget {args.budget:g}")
    report(batch, singles)


if __name__ == "__main__":
    main()

"""No silent regressions: corpus designs with the status they are expected to keep.

    python -m bench.regressions [--list bench/regressions.csv] [--budget 20] [--workers 2]
                                [--corpus ../shared/data/fusion360_b123d] [--out bench_out/regressions]

``bench/regressions.csv`` names a few designs per timeline folder of the tuning sample (seed 0 of
``bench.corpus_bench``) with the status they had when the list was made: ``exact`` (B-rep exact,
and the written JSON and script too) or ``partial`` (a known miss). Each goes through what
``bench.corpus_bench`` runs (convert, then ``infer`` in its own process), and the table marks every
design whose outcome is worse than expected (an exact design that turned partial, or whose files
stopped rebuilding the part) and every known miss that became exact, so the list can be raised.
Exits 1 when any design regressed. Known misses stay on the list so that a fix shows up here.
"""

from __future__ import annotations

import argparse
import csv
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from bench.corpus import CORPUS, require_corpus, run_designs, write_results
from bench.corpus_bench import _job
from zonegraph.configs import InferConfig
from zonegraph.data.b123d import CorpusEntry, list_corpus
from zonegraph.reconstruction import EXACT_IOU

LIST = Path(__file__).with_name("regressions.csv")


@dataclass(frozen=True)
class Expected:
    design_id: str
    folder: str
    expected: str  # "exact" or "partial"


def read_list(path: Path) -> list[Expected]:
    with path.open(newline="") as fh:
        return [Expected(r["design_id"], r["folder"], r["expected"]) for r in csv.DictReader(fh)]


def outcome(row: dict) -> str:
    """``exact`` only when the B-rep and both written files rebuild the part."""
    files = min(row.get("json_iou", 0.0), row.get("script_iou", 0.0))
    if row.get("exact") and files >= EXACT_IOU:
        return "exact"
    return "partial" if row.get("status") in ("exact", "partial") else str(row.get("status"))


def verdict(expected: str, got: str) -> str:
    if got == expected:
        return "as expected"
    return "improved" if got == "exact" else "REGRESSED"


def table(expected: list[Expected], rows: list[dict]) -> tuple[str, int]:
    """The Markdown table and the number of regressions."""
    lines = ["| design | folder | expected | now | B-rep IoU | verdict |", "|---|---|---|---|---|---|"]
    regressed = 0
    for e, row in zip(expected, rows, strict=True):
        got = outcome(row)
        v = verdict(e.expected, got)
        regressed += v == "REGRESSED"
        lines.append(
            f"| {e.design_id} | {e.folder} | {e.expected} | {got} | {row.get('iou_brep', 0.0):.6f} | {v} |"
        )
    lines += ["", f"{regressed} of {len(expected)} designs regressed"]
    return "\n".join(lines), regressed


def entries(corpus: Path, expected: list[Expected]) -> list[CorpusEntry]:
    found = {e.design_id: e for e in list_corpus(corpus)}
    missing = [e.design_id for e in expected if e.design_id not in found]
    if missing:
        raise SystemExit(f"{corpus}: the regression list names designs it lacks: {', '.join(missing)}")
    return [found[e.design_id] for e in expected]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", type=Path, default=LIST)
    parser.add_argument("--corpus", type=Path, default=CORPUS)
    parser.add_argument("--budget", type=float, default=20.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("bench_out/regressions"))
    args = parser.parse_args()
    require_corpus(args.corpus)
    expected = read_list(args.list)
    config = InferConfig(guide="heuristic", budget_s=args.budget)
    print(f"{len(expected)} designs from {args.list}, heuristic, budget {args.budget:g} s")
    with tempfile.TemporaryDirectory() as work:
        jobs = [(e, config, work) for e in entries(args.corpus, expected)]
        rows = run_designs(_job, jobs, args.workers)
    text, regressed = table(expected, rows)
    write_results(rows, text, args.out)
    sys.exit(1 if regressed else 0)


if __name__ == "__main__":
    main()

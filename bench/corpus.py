"""What the corpus benchmarks share: where the corpus is, running designs side by side, results."""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from zonegraph.testing import CORPUS

__all__ = ["CORPUS", "require_corpus", "run_designs", "write_results"]


def require_corpus(path: Path) -> None:
    if not path.is_dir():
        raise SystemExit(f"corpus not found at {path} (clone Fusion360GalleryDataset-build123d there)")


def run_designs(
    job: Callable[[Any], dict],
    jobs: Sequence[Any],
    workers: int,
    note: Callable[[list[dict]], str] = lambda r: "",
) -> list[dict]:
    """``job`` over ``jobs`` on ``workers`` processes, in order, with a progress line every 10."""
    rows: list[dict] = []
    with ProcessPoolExecutor(workers) as pool:
        for i, row in enumerate(pool.map(job, jobs), 1):
            rows.append(row)
            if i % 10 == 0 or i == len(jobs):
                print(f"  {i}/{len(jobs)} designs{note(rows)}", flush=True)
    return rows


def write_results(rows: list[dict], table: str, out: Path) -> None:
    """Print the table and write ``results.json`` (every row) and ``results.md`` under ``out``."""
    print(table)
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(rows, indent=1, default=str))
    (out / "results.md").write_text(table + "\n")

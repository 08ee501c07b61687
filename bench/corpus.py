"""What the corpus benchmarks share: where the corpus is, running designs side by side, results."""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from zonegraph.testing import CORPUS

__all__ = ["CORPUS", "closest_graphs", "replayed", "require_corpus", "run_designs", "write_results"]


def require_corpus(path: Path) -> None:
    if not path.is_dir():
        raise SystemExit(f"corpus not found at {path} (clone Fusion360GalleryDataset-build123d there)")


def replayed(batch: str, design_id: str, work: str | Path) -> tuple[Any, dict]:
    """A corpus design converted (in a killable child, as the ``generate`` stage does), written
    under ``work`` and replayed: the replay and an empty row, or None and the failure's row."""
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay
    from zonegraph.jobs import convert_isolated

    converted = convert_isolated(batch, design_id, timeout=120)
    if not converted.ok or converted.design_json is None:
        return None, {"status": f"convert_{converted.status}", "reason": converted.reason}
    path = Path(work) / f"{design_id}.json"
    path.write_text(json.dumps(converted.design_json))
    return replay(load_design(path)), {}


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


def closest_graphs(folder: Path, targets: list[int]) -> dict[int, Path]:
    """The saved graph whose zone count is closest to each target (read from the zone tables)."""
    from zonegraph.zones.storage import saved_zone_count

    counts = {g: saved_zone_count(g) for g in sorted(folder.iterdir())}
    return {t: min(counts, key=lambda g: abs(counts[g] - t)) for t in targets}

"""The heaviest parts: zone graph build, first expansion and labels, CPU seconds each.

    python -m bench.heavy_bench --ids ID [ID ...] [--timeout 1800] [--level 1] [--seed 0]
                                [--corpus ../shared/data/fusion360_b123d] [--out bench_out/heavy]

The cost of the shared mechanism is set by a few parts: a graph of thousands of zones is most of
a sample's labelling time and a search that cannot expand within its budget. Each design runs in
its own process under ``--timeout`` (conversion and replay untimed): the simplified zone graph as
the ``zonegraphs`` stage builds it (no surface samples), the first expansion (a fresh proposal
generator and the proposals of the empty canvas, where every plane pair's sweeps are new), the
ground truth, then the labeller exactly as the ``labels`` stage runs it. Each stage's CPU seconds
(``process_time``: core-seconds, robust to a busy machine) and wall seconds are written as soon as
the stage ends, so a design that runs out of time still reports the stages it finished. The file
imports only names that have not moved since the start-up work of issue 27, so the same file
measures an older checkout (copy it and ``bench/corpus.py`` into a worktree there) against this
one.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from bench.corpus import CORPUS, replayed, require_corpus, run_designs, write_results
from zonegraph.data.b123d import CorpusEntry, list_corpus
from zonegraph.isolation import run_isolated
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.sequence.labels import GTOperation, label_design
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.status import Status
from zonegraph.zones.build import build_zone_graph

STAGES = ("build", "expansion", "ground_truth", "labels")


def _timed(progress: Path, row: dict, stage: str, fn: Callable[[], Any]) -> Any:
    """Run one stage, add its CPU and wall seconds to ``row`` and write the row at once."""
    t0, c0 = time.perf_counter(), time.process_time()
    value = fn()
    row[f"{stage}_s"] = round(time.process_time() - c0, 3)
    row[f"{stage}_wall_s"] = round(time.perf_counter() - t0, 3)
    progress.write_text(json.dumps(row))
    return value


def _measure(entry: CorpusEntry, work: str, level: int, seed: int) -> dict:
    progress = Path(work) / f"{entry.design_id}.progress.json"
    r, failed = replayed(entry.batch, entry.design_id, work)
    if r is None:
        return failed
    row: dict = {"faces_in": sum(len(b.faces()) for b in r.bodies)}
    graph = _timed(progress, row, "build", lambda: build_zone_graph(list(r.bodies), samples=0))
    row["zones"] = graph.n_zones
    empty = np.zeros(graph.n_zones, bool)
    first = _timed(progress, row, "expansion", lambda: ProposalGenerator(graph, level=level).proposals(empty))
    row["first_proposals"] = len(first)
    operations = [s["operation"] for s in r.summary()["steps"]]
    tools = [s.tool.wrapped for s in r.steps]
    gt = _timed(progress, row, "ground_truth", lambda: ground_truth(graph, tools, operations, (level,)))
    if not gt.reaches_target:
        return {**row, "status": "gt_off_target", "reason": gt.reason}
    ops = [GTOperation(s.zones, s.op, s.captured[level], s.operation, s.reason) for s in gt.steps]
    steps = _timed(
        progress, row, "labels", lambda: label_design(graph, ops, entry.design_id, seed=seed, level=level)
    )
    row["steps"] = len(steps)
    row["proposals"] = sum(len(st.proposals) for st in steps)
    row["completions"] = sum(x.completions for st in steps for x in st.proposals)
    return {**row, "status": Status.OK.value}


def _job(args: tuple) -> dict:
    entry, work, timeout, level, seed = args
    outcome = run_isolated(_measure, (entry, work, level, seed), timeout=timeout)
    row = {"design_id": entry.design_id, "folder": entry.folder, "seconds": round(outcome.seconds, 1)}
    if outcome.ok:
        return {**row, **outcome.value}
    progress = Path(work) / f"{entry.design_id}.progress.json"
    done = json.loads(progress.read_text()) if progress.exists() else {}
    return {**row, **done, "status": outcome.status, "reason": outcome.reason}


def _cell(row: dict, stage: str) -> str:
    if f"{stage}_s" in row:
        return f"{row[f'{stage}_s']:.2f}"
    return f"> {row['seconds']:.0f} (not finished)" if row["status"] == Status.TIMEOUT else "-"


def summarise(rows: list[dict]) -> str:
    lines = [
        "| design | folder | faces | zones | build CPU s | first expansion CPU s | proposals | "
        "ground truth CPU s | labels CPU s | completions | status |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        cells = " | ".join(_cell(r, stage) for stage in STAGES[:2])
        lines.append(
            f"| {r['design_id']} | {r['folder']} | {r.get('faces_in', '-')} | {r.get('zones', '-')} | "
            f"{cells} | {r.get('first_proposals', '-')} | {_cell(r, 'ground_truth')} | "
            f"{_cell(r, 'labels')} | {r.get('completions', '-')} | {r['status']} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ids", nargs="+", required=True, help="corpus design ids")
    parser.add_argument("--corpus", type=Path, default=CORPUS)
    parser.add_argument("--timeout", type=float, default=1800.0, help="per design, every stage")
    parser.add_argument("--level", type=int, default=1)
    parser.add_argument("--seed", type=int, default=0, help="the labeller's seed (with the design id)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("bench_out/heavy"))
    args = parser.parse_args()
    require_corpus(args.corpus)
    by_id = {e.design_id: e for e in list_corpus(args.corpus)}
    missing = [i for i in args.ids if i not in by_id]
    if missing:
        raise SystemExit(f"heavy_bench: not in the corpus at {args.corpus}: {', '.join(missing)}")
    entries = [by_id[i] for i in args.ids]
    print(f"{len(entries)} designs, {args.workers} workers, timeout {args.timeout:g} s", flush=True)
    with tempfile.TemporaryDirectory() as work:
        jobs = [(e, work, args.timeout, args.level, args.seed) for e in entries]
        rows = run_designs(_job, jobs, args.workers)
    write_results(rows, summarise(rows), args.out)


if __name__ == "__main__":
    main()

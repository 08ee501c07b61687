"""Cost of ternary labels on real training designs, and what it means for the whole corpus.

    python -m bench.labels_bench [--designs 100] [--seed 0] [--timeout 300] [--workers 2]
                                 [--multiplier 1] [--slack 2] [--level 1]
                                 [--corpus ../shared/data/fusion360_b123d] [--out bench_out/labels]

A seeded sample of the corpus's training designs (the project-grouped split of ``params.yaml``),
stratified by timeline folder in proportion to the folders' sizes, so that the mean is an estimate
for the corpus. Each design runs in its own process under ``--timeout``: conversion, replay, zone
graph and ground truth (timed apart as preparation), then the labeller exactly as the ``labels``
stage runs it. Prints labelling CPU seconds (core-seconds, so that other work on the machine does
not inflate them) per design (median, p90, max) and per labelled step,
completions per second, label counts, the slowest designs, and the extrapolation to all 7,483
designs on a 16-core cluster (a design that timed out counts as ``--timeout`` seconds, so the
estimate is a lower bound when any did); writes ``results.json`` and ``results.md``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.corpus import CORPUS, replayed, require_corpus, run_designs, write_results
from zonegraph.data.b123d import CorpusEntry, list_corpus
from zonegraph.data.dataset import stratified_sample, test_ids
from zonegraph.isolation import run_isolated
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.sequence.labels import NEGATIVE, NEUTRAL, POSITIVE, GTOperation, label_design
from zonegraph.status import Status
from zonegraph.zones.build import build_zone_graph

CORPUS_SIZE, CLUSTER_CORES = 7483, 16


def training_sample(corpus: Path, count: int, seed: int) -> list[CorpusEntry]:
    """A seeded, folder-stratified sample of the training designs (split as ``params.yaml``)."""
    entries = list_corpus(corpus)
    test = test_ids([e.design_id for e in entries], seed=0, test_fraction=0.35)
    train = [e for e in entries if e.design_id not in test]
    return [train[i] for i in stratified_sample([e.folder for e in train], count, seed)]


def _label(entry: CorpusEntry, work: str, seed: int, level: int, multiplier: float, slack: int) -> dict:
    t0 = time.perf_counter()
    r, failed = replayed(entry.batch, entry.design_id, work)
    if r is None:
        return failed
    graph = build_zone_graph(list(r.bodies), samples=0)
    operations = [s["operation"] for s in r.summary()["steps"]]
    gt = ground_truth(graph, [s.tool.wrapped for s in r.steps], operations, (level,))
    if not gt.reaches_target:
        return {"status": "gt_off_target", "reason": gt.reason, "zones": graph.n_zones}
    ops = [GTOperation(s.zones, s.op, s.captured[level], s.operation, s.reason) for s in gt.steps]
    prepare = time.perf_counter() - t0
    t1, c1 = time.perf_counter(), time.process_time()
    steps = label_design(
        graph, ops, entry.design_id, seed=seed, level=level, multiplier=multiplier, slack=slack
    )
    labels = [x.label for st in steps for x in st.proposals]
    return {
        "status": Status.OK.value,
        "zones": graph.n_zones,
        "steps": len(steps),
        "labelled_steps": sum(bool(st.proposals) for st in steps),
        "proposals": len(labels),
        "positives": labels.count(POSITIVE),
        "neutrals": labels.count(NEUTRAL),
        "negatives": labels.count(NEGATIVE),
        "completions": sum(x.completions for st in steps for x in st.proposals),
        "prepare_s": prepare,
        "label_wall_s": time.perf_counter() - t1,
        "label_s": time.process_time() - c1,  # CPU seconds: core-seconds, robust to a busy machine
    }


def _job(args: tuple) -> dict:
    entry, work, timeout, *settings = args
    outcome = run_isolated(_label, (entry, work, *settings), timeout=timeout)
    row = {"design_id": entry.design_id, "folder": entry.folder, "seconds": outcome.seconds}
    row.update(outcome.value if outcome.ok else {"status": outcome.status, "reason": outcome.reason})
    return row


def corpus_mean(rows: list[dict], timeout: float, population: dict[str, int]) -> float:
    """Mean labelling seconds per corpus design: each folder's mean weighted by its share of the
    corpus (small folders are over-sampled); timeouts count as ``timeout``, failures as 0."""
    total, weight = 0.0, 0
    for folder, size in population.items():
        rs = [r for r in rows if r["folder"] == folder]
        if rs:
            cost = [
                r["label_s"] if r["status"] == Status.OK else timeout * (r["status"] == Status.TIMEOUT)
                for r in rs
            ]
            total, weight = total + size * float(np.mean(cost)), weight + size
    return total / max(weight, 1)


def summarise(rows: list[dict], timeout: float, population: dict[str, int]) -> str:
    ok = [r for r in rows if r["status"] == Status.OK]
    timed_out = [r for r in rows if r["status"] == Status.TIMEOUT]
    lines = [
        "| folder | designs | labelled | median s | p90 s | max s | s per labelled step | proposals | "
        "completions/s | + / 0 / - |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for folder in sorted({r["folder"] for r in rows}) + ["all"]:
        rs = [r for r in ok if folder in ("all", r["folder"])]
        n = sum(folder in ("all", r["folder"]) for r in rows)
        if not rs:
            lines.append(f"| {folder} | {n} | 0 | - | - | - | - | - | - | - |")
            continue
        s = np.array([r["label_s"] for r in rs])
        steps = sum(r["labelled_steps"] for r in rs)
        rate = sum(r["completions"] for r in rs) / max(s.sum(), 1e-9)
        counts = " / ".join(str(sum(r[k] for r in rs)) for k in ("positives", "neutrals", "negatives"))
        lines.append(
            f"| {folder} | {n} | {len(rs)} | {np.median(s):.2f} | {np.percentile(s, 90):.2f} | "
            f"{s.max():.1f} | {s.sum() / max(steps, 1):.2f} | {sum(r['proposals'] for r in rs)} | "
            f"{rate:.0f} | {counts} |"
        )
    mean = corpus_mean(rows, timeout, population)
    hours = mean * CORPUS_SIZE / CLUSTER_CORES / 3600
    bound = " (a lower bound: timeouts counted at the timeout)" if timed_out else ""
    lines += [
        "",
        f"Mean labelling cost (folders weighted by size) {mean:.2f} core-s per design -> all "
        f"{CORPUS_SIZE} designs on {CLUSTER_CORES} cores: {hours:.2f} h{bound}; "
        "goal < 1 h (7.7 core-s per design).",
        f"Preparation (convert, replay, zone graph, GT) median "
        f"{np.median([r['prepare_s'] for r in ok]) if ok else float('nan'):.2f} s, not counted above.",
        "",
        "Slowest designs:",
    ]
    for r in sorted(ok, key=lambda r: -r["label_s"])[:5]:
        lines.append(
            f"- {r['design_id']} ({r['folder']}): {r['label_s']:.1f} s, {r['zones']} zones, "
            f"{r['steps']} steps, {r['proposals']} proposals, {r['completions']} completions"
        )
    for r in rows:
        if r["status"] != Status.OK:
            lines.append(
                f"- {r['design_id']} ({r['folder']}): {r['status']}: {str(r.get('reason', ''))[:160]}"
            )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=CORPUS)
    parser.add_argument("--designs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=300.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--level", type=int, default=1)
    parser.add_argument("--multiplier", type=float, default=1.0)
    parser.add_argument("--slack", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("bench_out/labels"))
    args = parser.parse_args()
    require_corpus(args.corpus)
    entries = training_sample(args.corpus, args.designs, args.seed)
    population: dict[str, int] = {}
    for e in list_corpus(args.corpus):
        population[e.folder] = population.get(e.folder, 0) + 1
    print(f"{len(entries)} training designs, {args.workers} workers, timeout {args.timeout:g} s", flush=True)
    settings = (args.seed, args.level, args.multiplier, args.slack)
    with tempfile.TemporaryDirectory() as work:
        rows = run_designs(_job, [(e, work, args.timeout, *settings) for e in entries], args.workers)
    write_results(rows, summarise(rows, args.timeout, population), args.out)


if __name__ == "__main__":
    main()

"""Proposal coverage and cost on the ground-truth path of real designs.

    python -m bench.proposal_bench [--per-folder 4] [--seed 7] [--ids ID ...] [--level 1]
                                   [--timeout 120] [--cache /tmp/proposal_bench]
                                   [--designs /work/corpus_run/data/designs/json]
                                   [--exclude /work/wt/validation_ids.txt] [--out bench_out/proposals]

A seeded draw of converted designs, ``--per-folder`` per timeline folder (the designs whose ids are
in ``--exclude`` are never drawn: that sample only measures). Each design is prepared once in its
own killable process (replay, simplified zone graph, ground-truth tools mapped onto zones) and the
prepared zone graph and GT steps are cached under ``--cache``, so that a change of the proposal
rules is measured on the same geometry without rebuilding it. Then, for each design, a fresh
`ProposalGenerator` walks the GT path: at every C_{i-1} it times ``proposals`` and checks
whether the GT step (its zone set and operation) is among them. Prints, by folder: GT steps
captured / mappable steps (the steps a proposal could have: mapped, not an intersect, changing the
canvas), first steps captured, designs with every step captured, proposals per state (mean, max)
and generation seconds, wall and CPU (setup, per state mean and max; wall is contended on a shared
machine, CPU is not); writes ``results.json`` and ``results.md``.
"""

from __future__ import annotations

import argparse
import pickle
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from bench.corpus import write_results
from zonegraph.isolation import run_isolated
from zonegraph.sequence.ground_truth import MAPPING_RTOL, apply_operation, map_tool, search_op
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.status import Status
from zonegraph.zones.model import ZoneGraph

DESIGNS = Path("/work/corpus_run/data/designs/json")
EXCLUDE = Path("/work/wt/validation_ids.txt")


@dataclass
class Prepared:
    """A design's zone graph (no solids) and its GT steps on it, ready to test proposals on."""

    graph: ZoneGraph
    zones: list[np.ndarray]  # (Z,) bool per GT step
    operations: list[str]
    mapped: list[bool]


def prepare(path: str) -> dict:
    """Replay ``path``, build its simplified zone graph and map every GT tool onto it.

    Returns `Prepared`'s fields as a dict: the cache must unpickle whichever module runs."""
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay
    from zonegraph.zones.build import build_zone_graph

    r = replay(load_design(Path(path)))
    graph = build_zone_graph(list(r.bodies), samples=0, keep_solids=False)
    operations = [s["operation"] for s in r.summary()["steps"]]
    zones, mapped = [], []
    for step in r.steps:
        z, error = map_tool(graph, step.tool.wrapped)
        zones.append(z)
        mapped.append(bool(error <= MAPPING_RTOL))
    return dict(graph=replace(graph, solids=None), zones=zones, operations=operations, mapped=mapped)


def prepared(design_id: str, designs: Path, cache: Path, timeout: float) -> Prepared | str:
    """The cached preparation of ``design_id``, or why it failed (also cached)."""
    file = cache / f"{design_id}.pkl"
    if not file.exists():
        out = run_isolated(prepare, (str(designs / f"{design_id}.json"),), timeout=timeout)
        value = out.value if out.status == Status.OK else f"{out.status}: {out.reason}"[:200]
        cache.mkdir(parents=True, exist_ok=True)
        file.write_bytes(pickle.dumps(value))
    value = pickle.loads(file.read_bytes())
    return value if isinstance(value, str) else Prepared(**value)


def measure(p: Prepared, level: int) -> dict:
    """Walk the GT path with a fresh generator: capture, proposal counts and times per state."""
    t0, c0 = time.perf_counter(), time.process_time()
    gen = ProposalGenerator(p.graph, level=level)
    setup, setup_cpu = time.perf_counter() - t0, time.process_time() - c0
    canvas = np.zeros(p.graph.n_zones, bool)
    steps = []
    for i, (zones, operation, mapped) in enumerate(zip(p.zones, p.operations, p.mapped, strict=True)):
        after = apply_operation(operation, canvas, zones)
        t1, c1 = time.perf_counter(), time.process_time()
        props = gen.proposals(canvas)
        seconds, cpu = time.perf_counter() - t1, time.process_time() - c1
        op = search_op(operation)
        mappable = mapped and op is not None and not np.array_equal(after, canvas)
        key = (np.packbits(zones).tobytes(), int(op)) if op is not None else None
        captured = mappable and any(q.key == key for q in props)
        effect = mappable and any(np.array_equal(q.apply(canvas), after) for q in props)
        steps.append(dict(index=i, mappable=mappable, captured=captured, effect=effect))
        steps[-1].update(proposals=len(props), seconds=seconds, cpu_s=cpu)
        canvas = after
    return dict(
        zones=p.graph.n_zones,
        setup_s=setup,
        setup_cpu_s=setup_cpu,
        reaches=bool(np.array_equal(canvas, p.graph.zone_inside)),
        steps=steps,
    )


def draw(designs: Path, exclude: Path, per_folder: int, seed: int) -> list[tuple[str, str]]:
    """(design id, folder) of a seeded draw of ``per_folder`` designs per folder, none excluded."""
    index = pd.read_parquet(designs.parent / "index.parquet")
    banned = set(exclude.read_text().split()) if exclude.exists() else set()
    have = {f.stem for f in designs.glob("*.json")}
    index = index[index.design_id.isin(have) & ~index.design_id.isin(banned)].sort_values("design_id")
    rng = np.random.default_rng(seed)
    out = []
    for folder, rows in index.groupby("folder", sort=True):
        picks = rng.choice(len(rows), size=min(per_folder, len(rows)), replace=False)
        out += [(rows.design_id.iloc[i], folder) for i in sorted(picks)]
    return out


def table(rows: list[dict]) -> str:
    """Markdown figures by folder and overall."""
    lines = [
        "| folder | designs | GT steps captured | effect-captured | first steps | all steps "
        "| proposals/state mean, max | setup s (CPU) | s/state mean, max | CPU s/state mean, max |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    folders = sorted({r["folder"] for r in rows}) + ["all"]
    for folder in folders:
        rs = [r for r in rows if "steps" in r and folder in (r["folder"], "all")]
        failed = sum(1 for r in rows if "steps" not in r and folder in (r["folder"], "all"))
        st = [s for r in rs for s in r["steps"]]
        mp = [s for s in st if s["mappable"]]
        first = [r["steps"][0] for r in rs if r["steps"] and r["steps"][0]["mappable"]]
        whole = sum(r["reaches"] and all(s["captured"] for s in r["steps"]) for r in rs)
        props = [s["proposals"] for s in st] or [0]
        secs = [s["seconds"] for s in st] or [0.0]
        cpus = [s["cpu_s"] for s in st] or [0.0]
        setup = sum(r["setup_s"] for r in rs)
        setup_cpu = sum(r["setup_cpu_s"] for r in rs)
        lines.append(
            f"| {folder} | {len(rs)} (+{failed} failed) | {sum(s['captured'] for s in mp)} / {len(mp)} "
            f"| {sum(s['effect'] for s in mp)} | {sum(s['captured'] for s in first)} / {len(first)} "
            f"| {whole} | {np.mean(props):.0f}, {max(props)} | {setup:.2f} ({setup_cpu:.2f}) "
            f"| {np.mean(secs):.4f}, {max(secs):.3f} | {np.mean(cpus):.4f}, {max(cpus):.3f} |"
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--per-folder", type=int, default=4)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--ids", nargs="*", help="these designs instead of a draw")
    ap.add_argument("--level", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--max-zones", type=int, default=3000, help="skip larger graphs (time)")
    ap.add_argument("--cache", type=Path, default=Path("/tmp/proposal_bench"))
    ap.add_argument("--designs", type=Path, default=DESIGNS)
    ap.add_argument("--exclude", type=Path, default=EXCLUDE)
    ap.add_argument("--out", type=Path, default=Path("bench_out/proposals"))
    args = ap.parse_args()
    banned = set(args.exclude.read_text().split()) if args.exclude.exists() else set()
    index = pd.read_parquet(args.designs.parent / "index.parquet").set_index("design_id")
    if args.ids:
        if banned & set(args.ids):
            raise SystemExit("--ids names validation designs: they only measure, never steer")
        jobs = [(i, str(index.folder.get(i, "?"))) for i in args.ids]
    else:
        jobs = draw(args.designs, args.exclude, args.per_folder, args.seed)
    rows = []
    for design_id, folder in jobs:
        p = prepared(design_id, args.designs, args.cache, args.timeout)
        row: dict = dict(design_id=design_id, folder=folder)
        if isinstance(p, str):
            row["failed"] = p
        elif p.graph.n_zones > args.max_zones:
            row["failed"] = f"{p.graph.n_zones} zones > --max-zones"
        else:
            row.update(measure(p, args.level))
        rows.append(row)
        print(f"  {design_id} {row.get('failed') or _line(row)}", flush=True)
    write_results(rows, table(rows), args.out)


def _line(row: dict) -> str:
    mp = [s for s in row["steps"] if s["mappable"]]
    return (
        f"{row['zones']} zones, {sum(s['captured'] for s in mp)}/{len(mp)} captured, "
        f"{sum(s['seconds'] for s in row['steps']):.2f} s ({sum(s['cpu_s'] for s in row['steps']):.2f} CPU s)"
    )


if __name__ == "__main__":
    main()

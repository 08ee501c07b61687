"""DVC stage ``ground_truth``: every design's GT sequence on its zone graphs, and the coverage.

For each design whose zone graph was built, the replay's tool bodies are mapped onto the saved
(simplified) graph and onto the full graph, replayed on zones, and each step is tested for capture
at proposal levels 1 and 3 (``zonegraph.sequence.ground_truth``); a design whose GT is not
captured gets a heuristic search (``ground_truth.budget_s``) to tell "another sequence"
from "not reconstructed". Outputs: ``data/gt/steps.parquet`` (design, graph, step, operation, GT
zone ids, captured and proposal count at each level, mapping check, reason),
``data/gt/designs.parquet`` (one row per design of the run, failures of earlier stages included),
``data/gt/coverage.md``, ``data/plots/coverage.png``, ``data/metrics/coverage.json`` and every
variant's categories in ``data/details/coverage.json``.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from eval.coverage import CATEGORIES, coverage_table, plot_coverage, to_markdown
from eval.dvc_metrics import headline, write_json
from zonegraph.jobs import ground_truth_and_coverage
from zonegraph.status import Status

from .cluster import dask_client
from .params import DaskParams, GroundTruthParams, section
from .paths import stage_paths
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs


def designs_table(designs: Path, replayed: Path, zonegraphs: Path) -> pd.DataFrame:
    """Every design of the run with the status of each earlier stage (conversion when present)."""
    index = pd.read_parquet(designs / "index.parquet")[["design_id", "split", "folder"]]
    replay = pd.read_parquet(replayed / "manifest.parquet")
    replay = replay[["design_id", "status", "reason", "steps", "operations", "brep_dir"]]
    replay = replay.rename(columns={"status": "replay_status", "reason": "replay_reason"})
    graphs = pd.read_parquet(zonegraphs / "manifest.parquet")[["design_id", "status", "reason", "zones"]]
    graphs = graphs.rename(
        columns={"status": "graph_status", "reason": "graph_reason", "zones": "graph_zones"}
    )
    table = index.merge(replay, on="design_id", how="left").merge(graphs, on="design_id", how="left")
    conversion = designs / "conversion.parquet"
    if conversion.is_file():  # corpus runs: designs that never became JSON count too
        conv = pd.read_parquet(conversion)[["design_id", "folder", "status", "reason"]]
        conv = conv.rename(columns={"status": "convert_status", "reason": "convert_reason"})
        failed = conv[conv["convert_status"] != Status.OK].assign(split="none")
        table = pd.concat(
            [table.assign(convert_status=Status.OK.value, convert_reason=""), failed], ignore_index=True
        )
    return table


def main() -> None:
    args = stage_paths(
        __doc__,
        ("designs", "replay", "zonegraphs"),
        out="the ground truth folder",
        plot="the coverage plot (PNG)",
        metrics="the coverage metrics JSON",
        details="the coverage categories of every graph and level, JSON",
    )
    cfg = section(GroundTruthParams, "ground_truth")
    levels = cfg.levels
    table = designs_table(args.designs, args.replay, args.zonegraphs)
    todo = table[table["graph_status"] == Status.OK]
    code = code_fingerprint("ground_truth")
    settings = (levels, cfg.budget_s, cfg.full_graph)
    jobs = []
    for row in todo.itertuples():
        graph = args.zonegraphs / "graphs" / row.design_id
        ops = row.operations.split(",")
        jobs.append(
            Job(
                row.design_id,
                fingerprint(code, settings, ops, files=(row.brep_dir, graph)),
                (row.brep_dir, str(graph), ops, *settings),
                cost=float(row.graph_zones),
                inputs=(row.brep_dir, str(graph)),
            )
        )
    dask = section(DaskParams, "dask")
    with dask_client(dask) as client:
        records = run_jobs(
            ground_truth_and_coverage,
            jobs,
            args.out / "records",
            client,
            cfg.timeout_s,
            "ground_truth",
            memory_mb=dask.memory_mb,
        )
    steps = [dict(step, design_id=r["design_id"]) for r in records for step in r.get("steps", [])]
    args.out.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(steps).to_parquet(args.out / "steps.parquet", index=False)
    results = graph_results(records_frame([{k: v for k, v in r.items() if k != "steps"} for r in records]))
    designs = table.merge(results, on="design_id", how="left")
    designs.to_parquet(args.out / "designs.parquet", index=False)
    write_coverage(designs, levels, args.out, args.plot, args.metrics, args.details, cfg.full_graph)


def graph_results(results: pd.DataFrame) -> pd.DataFrame:
    """The records' rows with a failed job's status and reason (it timed out, crashed, or its
    graph would not load) as each graph's, so a design's row says why it has no ground truth."""
    failed = results["status"] != Status.OK
    results = results.copy()
    for graph in ("simplified", "full"):
        for field in ("status", "reason"):
            column = f"{graph}_{field}"
            if column not in results:
                results[column] = None
            results[column] = results[column].astype(object)
            results.loc[failed, column] = results.loc[failed, field]
    return results.drop(columns=["status", "reason"]).rename(columns={"seconds": "gt_seconds"})


def write_coverage(
    designs: pd.DataFrame,
    levels: tuple[int, ...],
    out: Path,
    plot: Path,
    metrics_file: Path,
    details_file: Path,
    full_graph: bool = True,
) -> None:
    """The coverage tables and plot; the metrics' ``ok`` counts the designs whose simplified
    graph's ground truth was computed; the share of all designs whose GT the first variant
    captures and every variant's categories go to the details. The full graph's variants only
    where the stage built it (``full_graph``): unmeasured, every design would read as a failure."""
    graphs = ("simplified", "full") if full_graph else ("simplified",)
    variants = {f"{graph} graph, level {level}": (graph, level) for graph in graphs for level in levels}
    tables = {name: coverage_table(designs, graph, level) for name, (graph, level) in variants.items()}
    (out / "coverage.md").write_text(to_markdown(tables))
    first = next(iter(tables))
    plot_coverage(tables[first], plot, f"Coverage ({first}), {len(designs)} designs")
    n = len(designs)
    ok = int((designs["simplified_status"] == Status.OK).sum()) if "simplified_status" in designs else 0
    write_json(metrics_file, headline(n, ok, designs["gt_seconds"]))
    seconds = designs["gt_seconds"].dropna()
    details = {
        "captured": int(tables[first].loc["gt_captured", "all"]) / n if n else None,
        "seconds_per_design_mean": float(seconds.mean()) if len(seconds) else None,
        **{name: {c: int(t.loc[c, "all"]) for c in CATEGORIES} for name, t in tables.items()},
    }
    write_json(details_file, details)
    t = tables[first]
    share = t["all"] / max(int(t["all"].sum()), 1)
    print(
        f"ground_truth: {len(designs)} designs; {first}: "
        + ", ".join(f"{c} {share[c]:.1%}" for c in CATEGORIES)
    )


if __name__ == "__main__":
    main()

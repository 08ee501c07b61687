"""Zone copies per training state: where a training's memory and time go, and what a bound cuts.

    python -m bench.copies_bench [--labels data/labels] [--graphs data/zonegraphs/graphs]
                                 [--split train] [--max-proposals 32] [--max-nodes 50000 100000 200000]
                                 [--out bench_out/copies]

Training copies a design's Z zones once per proposal it keeps (``training.data``, up to
``train.max_proposals``), and every layer's activations, BatchNorm included, and the backward pass
hold every copy, so a state costs its P x Z copies. Zone counts span four orders of magnitude, so
a few designs' states can hold a large share of an epoch's copies and set its peak memory.
Reads the label shards training reads (`training.shards.label_shards`: proposal labels only) and
the saved graphs' zone counts (Parquet footers, no geometry); prints the distribution of copies
per state, the designs that hold most, and for each ``--max-nodes`` (``train.max_nodes``) the
states it would cut, their designs, and the share of all copies they hold before and after the
cut (`training.data.kept_proposals`, as training applies it). Writes results.json and results.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd
import pyarrow.dataset as ds

from bench.corpus import write_results
from training.data import kept_proposals
from training.shards import label_shards
from zonegraph.zones.storage import saved_zone_count


def training_states(labels: Path, graphs: Path, split: str) -> pd.DataFrame:
    """One row per labelled state of ``split``: its design, zones, proposals and positives."""
    shards = label_shards(labels).proposals
    table = ds.dataset(shards, format="parquet").to_table(
        columns=["design_id", "step", "label"], filter=ds.field("split") == split
    )
    rows = table.to_pandas()
    states = rows.groupby(["design_id", "step"], sort=True)["label"].agg(
        proposals="size", positives=lambda labels: int((labels == 1).sum())
    )
    states = states.reset_index()
    zones = {d: saved_zone_count(graphs / d) for d in states["design_id"].unique()}
    return states.assign(zones=states["design_id"].map(zones))


def copies(states: pd.DataFrame, max_proposals: int | None, max_nodes: int | None) -> pd.Series:
    """Zone copies each state holds in training under the two bounds."""
    kept = [
        min(p, kept_proposals(z, pos, max_proposals, max_nodes) or p)
        for p, pos, z in zip(states["proposals"], states["positives"], states["zones"], strict=True)
    ]
    return pd.Series(kept, index=states.index) * states["zones"]


def summary(states: pd.DataFrame, max_proposals: int | None, bounds: list[int]) -> dict:
    """The distribution of copies per state, the heaviest designs, and what each bound cuts."""
    held = copies(states, max_proposals, None)
    total = int(held.sum())
    by_design = held.groupby(states["design_id"]).sum().sort_values(ascending=False)
    zones = states.groupby("design_id")["zones"].first()
    cuts = []
    for bound in bounds:
        over = held > bound
        after = copies(states, max_proposals, bound)
        cuts.append(
            {
                "max_nodes": bound,
                "states": int(over.sum()),
                "designs": int(states.loc[over, "design_id"].nunique()),
                "share_before": float(held[over].sum() / total),
                "share_after": float(after[over].sum() / after.sum()),
                "copies_after": int(after.sum()),
                "largest_after": int(after.max()),
            }
        )
    return {
        "states": len(states),
        "designs": int(states["design_id"].nunique()),
        "copies": total,
        "quantiles": {str(q): float(held.quantile(q)) for q in (0.5, 0.9, 0.99, 0.999)},
        "largest": int(held.max()),
        "heaviest": [
            {"design_id": d, "zones": int(zones[d]), "share": c / total} for d, c in by_design.head(5).items()
        ],
        "cuts": cuts,
    }


def markdown(result: dict, max_proposals: int | None) -> str:
    q = result["quantiles"]
    lines = [
        f"{result['states']} states of {result['designs']} designs, up to {max_proposals} proposals each: "
        f"{result['copies']:,} zone copies; per state median {q['0.5']:,.0f}, p90 {q['0.9']:,.0f}, "
        f"p99 {q['0.99']:,.0f}, p99.9 {q['0.999']:,.0f}, largest {result['largest']:,}",
        "",
        "| design | zones | share of all copies |",
        "|---|---|---|",
        *(f"| {h['design_id']} | {h['zones']:,} | {h['share']:.3f} |" for h in result["heaviest"]),
        "",
        "| max_nodes | states over it | their designs | their share of copies | after the cut | "
        "copies after | largest state after |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in result["cuts"]:
        lines.append(
            f"| {c['max_nodes']:,} | {c['states']} | {c['designs']} | {c['share_before']:.3f} | "
            f"{c['share_after']:.3f} | {c['copies_after']:,} | {c['largest_after']:,} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=Path, default=Path("data/labels"))
    parser.add_argument("--graphs", type=Path, default=Path("data/zonegraphs/graphs"))
    parser.add_argument("--split", default="train")
    parser.add_argument("--max-proposals", type=int, default=32)
    parser.add_argument("--max-nodes", type=int, nargs="*", default=[50_000, 100_000, 200_000])
    parser.add_argument("--out", type=Path, default=Path("bench_out/copies"))
    args = parser.parse_args(argv)
    states = training_states(args.labels, args.graphs, args.split)
    if states.empty:
        raise SystemExit(f"copies_bench: {args.labels}: no labelled states of the {args.split} split")
    result = summary(states, args.max_proposals, args.max_nodes)
    write_results([result], markdown(result, args.max_proposals), args.out)


if __name__ == "__main__":
    main()

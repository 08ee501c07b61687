"""Issue 29 on a whole pipeline run: where our replay and Fusion's figures part, and whether those
designs fail later stages more often.

    python -m bench.fusion_diff [--project .] [--out bench_out/fusion_diff]

Reads what the stages wrote under ``--project``: ``data/designs/conversion.parquet`` (every design
of a ``data.source: b123d`` run, with both relative differences of our replay from Fusion's
published volume and area), and, where those stages have run, the replay and zone-graph
manifests. Prints and writes (``results.md``, ``results.json``) the difference table by decade
over the designs that converted, how many differ by more than 1e-6, and each later stage's
failure rate for the designs above 1e-6 against the rest (denominators: the converted designs
that reached that stage's manifest).
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import pandas as pd

from bench.verify_bench import THRESHOLD, decade, decade_rows

STAGES = {"replay": "data/replay/manifest.parquet", "zonegraphs": "data/zonegraphs/manifest.parquet"}


def failure_rates(converted: pd.DataFrame, project: Path) -> list[dict]:
    """Per later stage and group (above the threshold or not): designs, failed, rate."""
    rows = []
    for stage, manifest in STAGES.items():
        path = project / manifest
        if not path.is_file():
            continue
        status = pd.read_parquet(path, columns=["design_id", "status"]).set_index("design_id")["status"]
        for above, group in converted.groupby("above"):
            reached = group[group["design_id"].isin(status.index)]
            failed = int((status.loc[reached["design_id"]] != "ok").sum())
            rows.append(
                {
                    "stage": stage,
                    "group": f"> {THRESHOLD:g}" if above else f"<= {THRESHOLD:g}",
                    "designs": int(len(reached)),
                    "failed": failed,
                    "rate": failed / len(reached) if len(reached) else None,
                }
            )
    return rows


def summarise(table: pd.DataFrame, project: Path) -> tuple[str, dict]:
    converted = table[table["status"] == "ok"].copy()
    largest = converted[["fusion_volume_rel_error", "fusion_area_rel_error"]].fillna(0).max(axis=1)
    converted["above"] = largest > THRESHOLD
    volume = Counter(decade(x) for x in converted["fusion_volume_rel_error"])
    area = Counter(decade(x) for x in converted["fusion_area_rel_error"])
    rates = failure_rates(converted, project)
    lines = [
        f"{len(table)} designs, {len(converted)} converted; {int(converted['above'].sum())} of the "
        f"converted differ from Fusion by more than {THRESHOLD:g} in volume or area",
        "",
        "| relative difference, our replay vs Fusion | volume | area |",
        "|---|---|---|",
        *decade_rows(volume, area),
        "",
        "| later stage | group | designs | failed | rate |",
        "|---|---|---|---|---|",
        *(
            f"| {r['stage']} | {r['group']} | {r['designs']} | {r['failed']} | "
            f"{'-' if r['rate'] is None else format(r['rate'], '.1%')} |"
            for r in rates
        ),
    ]
    values = {
        "designs": int(len(table)),
        "converted": int(len(converted)),
        "above": int(converted["above"].sum()),
        "volume_decades": dict(volume),
        "area_decades": dict(area),
        "failure_rates": rates,
    }
    return "\n".join(lines), values


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--project", type=Path, default=Path("."))
    parser.add_argument("--out", type=Path, default=Path("bench_out/fusion_diff"))
    args = parser.parse_args()
    conversion = args.project / "data/designs/conversion.parquet"
    if not conversion.is_file():
        raise SystemExit(f"{conversion}: no such file (run the generate stage with data.source: b123d)")
    text, values = summarise(pd.read_parquet(conversion), args.project)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.md").write_text(text + "\n")
    (args.out / "results.json").write_text(json.dumps(values, indent=2))


if __name__ == "__main__":
    main()

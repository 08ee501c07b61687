"""DVC stage ``reconstruct``: search programs for the test split, heuristic and random alike.

Every test design whose replay succeeded is reconstructed from its final B-rep with each guide at
the same budget (``params.yaml: reconstruct``), starting from the zone graph the ``zonegraphs``
stage saved (zone-graph build time is excluded from the budget, as in the paper). Results:
``data/reconstruct/results.parquet`` (one row per design and guide), each program under
``data/reconstruct/<guide>/<id>/`` and the metrics
(exact rate, mean B-rep IoU per guide) in ``data/metrics/reconstruct/<guide>.json``, with the median
time to exact and the failures in ``data/details/reconstruct.json``.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from eval.dvc_metrics import headline, median, write_guides, write_json
from zonegraph.configs import InferConfig
from zonegraph.reconstruction import infer
from zonegraph.status import Status

from .cluster import dask_client
from .params import DaskParams, ReconstructParams, section
from .paths import stage_paths
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs

SEARCHED = (Status.EXACT, Status.PARTIAL, Status.REBUILD_FAILED)  # a search ran and gave a program


def reconstruct_design(target: str, out: str, config: InferConfig, saved_graph: str) -> dict:
    """Job body: infer without rendering, reusing the zonegraphs stage's graph; plain data."""
    result = infer(target, out, config, render=False, saved_graph=saved_graph).to_dict()
    result.pop("config")
    result["operations"] = ",".join(result["operations"])
    return result


def summarise(results: pd.DataFrame) -> dict[str, dict]:
    """Per guide: the designs, those searched, the exact rate and mean B-rep IoU of all of them,
    the median time to exact and the failures by status."""
    metrics = {}
    for guide, rows in results.groupby("guide"):
        ok = rows[rows["status"].isin([s.value for s in SEARCHED])]
        exact = ok[ok["exact"].astype(bool)]
        metrics[guide] = {
            "designs": int(len(rows)),
            "searched": int(len(ok)),
            "exact_rate": float(len(exact) / len(rows)) if len(rows) else 0.0,
            "mean_iou_brep": float(ok["iou_brep"].fillna(0).sum() / len(rows)) if len(rows) else 0.0,
            "median_time_to_exact_s": float(np.median(exact["time_to_best_s"])) if len(exact) else None,
            "median_seconds": median(rows["seconds"]),
            "failures": {
                k: int(v) for k, v in rows.loc[~rows.index.isin(ok.index), "status"].value_counts().items()
            },
        }
    return metrics


def write_metrics(summary: dict[str, dict], metrics_dir: Path, details_file: Path) -> None:
    """One metrics file per guide (a row of ``dvc metrics show``), the summary as the details."""
    write_guides(
        metrics_dir,
        {
            guide: headline(
                m["designs"],
                m["searched"],
                (m["median_seconds"],),
                exact=m["exact_rate"],
                iou=m["mean_iou_brep"],
            )
            for guide, m in summary.items()
        },
    )
    write_json(details_file, summary)


def main() -> None:
    args = stage_paths(
        __doc__,
        ("replay", "zonegraphs"),
        out="the reconstructions folder",
        metrics="the reconstruction metrics folder (one JSON per guide)",
        details="the reconstruction's per-guide summary JSON (time to exact, failures by status)",
    )
    cfg = section(ReconstructParams, "reconstruct")
    replayed = pd.read_parquet(args.replay / "manifest.parquet")
    test = replayed[(replayed["split"] == "test") & (replayed["status"] == Status.OK)]
    graphs = pd.read_parquet(args.zonegraphs / "manifest.parquet").set_index("design_id")
    built = test["design_id"].isin(graphs.index[graphs["status"] == Status.OK])
    unbuilt = graphs.loc[test.loc[~built, "design_id"], ["status", "reason"]].reset_index()
    test = test[built]  # a graph folder the current zonegraphs run did not build is stale: never searched
    zones = graphs["zones"].fillna(0)
    code = code_fingerprint("reconstruct")
    jobs = []
    for guide in cfg.guides:
        config = InferConfig.from_mapping({**asdict(cfg), "guide": guide})
        model = (cfg.model,) if guide == "net" and cfg.model else ()  # its weights count too
        for row in test.itertuples():
            brep = f"{row.brep_dir}/final.brep"
            graph = args.zonegraphs / "graphs" / row.design_id
            out = str(args.out / guide / row.design_id)
            jobs.append(
                Job(
                    f"{guide}__{row.design_id}",
                    fingerprint(code, repr(config), files=(brep, graph, *model)),
                    (brep, out, config, str(graph)),
                    cost=float(zones.get(row.design_id, 0)),
                    outputs=(out,),
                    inputs=(brep, str(graph)),
                )
            )
    dask = section(DaskParams, "dask")
    with dask_client(dask) as client:
        records = run_jobs(
            reconstruct_design,
            jobs,
            args.out / "records",
            client,
            cfg.timeout_s,
            "reconstruct",
            memory_mb=dask.memory_mb,
        )
    results = records_frame(records, ("exact", "iou_brep", "time_to_best_s"))
    if len(results):
        results[["guide", "design_id"]] = results["design_id"].str.split("__", n=1, expand=True)
    else:
        results["guide"] = None
    skipped = [unbuilt.assign(guide=guide) for guide in cfg.guides if len(unbuilt)]
    results = pd.concat([results, *skipped], ignore_index=True)
    results.to_parquet(args.out / "results.parquet", index=False)
    metrics = summarise(results)
    write_metrics(metrics, args.metrics, args.details)
    for guide, m in metrics.items():
        print(
            f"reconstruct [{guide}]: exact {m['exact_rate']:.1%} of {m['designs']}, mean B-rep IoU "
            f"{m['mean_iou_brep']:.4f}, median time to exact {m['median_time_to_exact_s']} s, "
            f"failures {m['failures']}"
        )


if __name__ == "__main__":
    main()

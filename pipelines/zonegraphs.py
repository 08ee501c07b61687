"""DVC stage ``zonegraphs``: every replayed design's final solid -> its zone graph.

Graphs go to ``graphs/<id>/`` of the output folder (see ``zonegraph.zones.storage``); the manifest
``manifest.parquet`` beside them has one row per design (status, reason, target faces, zones,
edges, build seconds, simplified), designs that failed to replay included with their status.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from eval.dvc_metrics import headline, write_json
from zonegraph.configs import BuildConfig
from zonegraph.jobs import build_and_save
from zonegraph.status import Status

from .cluster import dask_client
from .params import DaskParams, ZoneGraphParams, section
from .paths import stage_paths
from .records import retry_summary
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs


def main() -> None:
    args = stage_paths(
        __doc__,
        ("replay",),
        out="the zone graphs folder (manifest, graphs)",
        metrics="the zone graph metrics JSON",
        details="the zone graphs' breakdowns JSON (by status, build seconds, zones, retries)",
    )
    cfg = section(ZoneGraphParams, "zonegraph")
    replayed = pd.read_parquet(args.replay / "manifest.parquet")
    ok = replayed[replayed["status"] == Status.OK]
    code = code_fingerprint("zonegraphs")
    config = BuildConfig.from_mapping(asdict(cfg))  # the section less the stage's timeout
    jobs = []
    for row in ok.itertuples():
        brep, graph = f"{row.brep_dir}/final.brep", str(args.out / "graphs" / row.design_id)
        jobs.append(
            Job(
                row.design_id,
                fingerprint(code, repr(config), files=(brep,)),
                (brep, graph, config),
                cost=row.faces,
                outputs=(graph,),
                inputs=(brep,),
            )
        )
    dask = section(DaskParams, "dask")
    with dask_client(dask) as client:
        records = run_jobs(
            build_and_save,
            jobs,
            args.out / "records",
            client,
            cfg.timeout_s,
            "zonegraphs",
            memory_mb=dask.memory_mb,
        )
    built = records_frame(records, ("target_faces", "faces", "zones", "edges", "build_s"))
    skipped = replayed.loc[replayed["status"] != Status.OK, ["design_id", "status", "reason"]]
    manifest = pd.concat([built, skipped], ignore_index=True)
    manifest = manifest.merge(replayed[["design_id", "split"]], on="design_id")
    manifest = manifest.rename(
        columns={"target_faces": "faces_in", "faces": "partition_faces", "seconds": "job_seconds"}
    )
    manifest["simplified"] = config.simplify
    manifest.to_parquet(args.out / "manifest.parquet", index=False)
    write_metrics(manifest, args.metrics, args.details, retry_summary(records))


def write_metrics(
    manifest: pd.DataFrame, metrics_file: Path, details_file: Path, retries: dict | None = None
) -> None:
    """The shared metrics keys (as every stage: seconds is the median job, build and saving) and
    the breakdowns."""
    ok = manifest["status"] == Status.OK
    build = manifest.loc[ok, "build_s"].to_numpy(float) if "build_s" in manifest else np.zeros(0)
    seconds = manifest["job_seconds"] if "job_seconds" in manifest else ()
    write_json(metrics_file, headline(len(manifest), int(ok.sum()), seconds))
    details = {
        "by_status": {k: int(v) for k, v in manifest["status"].value_counts().items()},
        "median_build_s": float(np.median(build)) if len(build) else None,
        "p90_build_s": float(np.percentile(build, 90)) if len(build) else None,
        "median_zones": float(manifest.loc[ok, "zones"].median()) if ok.any() else None,
        "runner": retries or {},
    }
    write_json(details_file, details)
    print(
        f"zonegraphs: {int(ok.sum())}/{len(manifest)} ok, median build {details['median_build_s']} s, "
        f"by status {details['by_status']}"
    )
    for row in manifest.loc[~ok].itertuples():
        print(f"  {row.design_id}: {row.status}: {row.reason}")


if __name__ == "__main__":
    main()

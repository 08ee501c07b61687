"""DVC stage ``replay``: every design -> final and per-step B-reps plus a Parquet manifest.

B-reps are BREP files in the design's centimetres: ``breps/<id>/final.brep`` of the output folder,
``NN.brep`` (all bodies after extrude NN) and ``NN_tool.brep`` (that extrude's tool body).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from eval.dvc_metrics import headline, write_json
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.shapes import write_brep
from zonegraph.status import Status
from zonegraph.verified import REPLAY_RTOL

from .cluster import dask_client
from .params import DaskParams, ReplayParams, section
from .paths import stage_paths
from .records import retry_summary
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs


def replay_design(path: str, out_dir: str) -> dict:
    """Job body: replay one design and write its B-reps; returns the manifest fields."""
    result = replay(load_design(path))
    out = Path(out_dir)
    write_brep(result.shape, out / "final.brep")
    for i, step in enumerate(result.steps):
        write_brep(step.shape, out / f"{i:02d}.brep")
        write_brep(step.tool, out / f"{i:02d}_tool.brep")
    s = result.summary()
    check = s.get("check", {})
    return {
        "steps": len(result.steps),
        "operations": ",".join(st["operation"] for st in s["steps"]),
        "extents": ",".join(st["extent_type"] for st in s["steps"]),
        "volume": s["volume"],
        "area": s["area"],
        "faces": s["face_count"],
        "bodies": s["body_count"],
        "volume_rel_error": check.get("volume_rel_error"),
        "area_rel_error": check.get("area_rel_error"),
        "verified": result.disagreement(REPLAY_RTOL) is None,  # zonegraph.verified's definition
        "replay_seconds": s["seconds"],
        "brep_dir": str(out),
    }


def main() -> None:
    args = stage_paths(
        __doc__,
        ("designs",),
        out="the replay folder (manifest, breps)",
        metrics="the replay metrics JSON",
        details="the replay's breakdowns JSON (failures by status, volume error, retries)",
    )
    cfg = section(ReplayParams, "replay")
    index = pd.read_parquet(args.designs / "index.parquet")
    code = code_fingerprint("replay")
    jobs = []
    for row in index.itertuples():
        design, breps = str(Path(row.path).resolve()), str(args.out / "breps" / row.design_id)
        jobs.append(
            Job(
                row.design_id,
                fingerprint(code, files=(design,)),
                (design, breps),
                outputs=(breps,),
                inputs=(design,),
            )
        )
    dask = section(DaskParams, "dask")
    with dask_client(dask) as client:
        records = run_jobs(
            replay_design,
            jobs,
            args.out / "records",
            client,
            cfg.timeout_s,
            "replay",
            memory_mb=dask.memory_mb,
        )
    manifest = records_frame(records, ("volume_rel_error", "brep_dir"))
    manifest["brep_dir"] = [str(args.out / "breps" / d) for d in manifest["design_id"]]  # where they are now
    manifest.insert(1, "split", index["split"].to_numpy())
    manifest.to_parquet(args.out / "manifest.parquet", index=False)
    ok = write_metrics(manifest, retry_summary(records), args.metrics, args.details)
    for row in manifest.loc[~ok].itertuples():
        print(f"  {row.design_id}: {row.status}: {row.reason}")


def write_metrics(manifest: pd.DataFrame, retries: dict, metrics_file: Path, details_file: Path) -> pd.Series:
    """The shared metrics keys and the breakdowns; returns which designs replayed."""
    ok = manifest["status"] == Status.OK
    write_json(metrics_file, headline(len(manifest), int(ok.sum()), manifest["seconds"]))
    failed = {k: int(v) for k, v in manifest.loc[~ok, "status"].value_counts().items()}
    details = {
        "failed_by_status": failed,
        "max_volume_rel_error": float(manifest.loc[ok, "volume_rel_error"].max()) if ok.any() else None,
        "runner": retries,
    }
    write_json(details_file, details)
    print(f"replay: {int(ok.sum())}/{len(manifest)} designs ok, failures {failed}")
    return ok


if __name__ == "__main__":
    main()

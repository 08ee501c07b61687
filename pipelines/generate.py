"""DVC stage ``generate``: the design index, from one of three sources (``params.yaml: data``).

- ``synthetic`` (the offline default): ``synthetic.count`` seeded designs generated in parallel;
- ``fusion_json``: a folder of Fusion 360 Gallery reconstruction JSON (r1.0.1), indexed in place;
- ``b123d``: the build123d corpus (a clone of Fusion360GalleryDataset-build123d): each design's
  script is run, its extrudes converted to our JSON and verified against the script's part and
  Fusion's volume (``zonegraph.data.b123d``), one killable Dask task per design, resumable.

``data.limit`` keeps a seeded sample, stratified by timeline folder. Either way the stage writes
``data/designs/index.parquet`` (design id, path, split, folder: the timeline-length bucket),
``stats.json``/``stats.txt`` beside the published statistics and, for the corpus,
``conversion.parquet`` (every design with its status and reason), ``data/metrics/conversion.json``
(`eval.dvc_metrics`' shared keys) and its breakdowns in ``data/details/conversion.json``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pandas as pd

from eval.dvc_metrics import headline, write_json
from zonegraph.data.b123d import convert_design, list_corpus
from zonegraph.data.dataset import DesignRecord, read_dataset, stratified_sample, test_ids
from zonegraph.data.design import load_design
from zonegraph.data.stats import design_statistics, format_comparison, timeline_folder
from zonegraph.data.synthetic import design_seed, generate_design, synthetic_id
from zonegraph.status import Status

from .cluster import dask_client
from .params import PARAMS_FILE, DaskParams, DataParams, SyntheticParams, section
from .paths import stage_paths
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs


def write_design(design_id: str, seed: int, path: str) -> dict[str, Any]:
    """Job body: one synthetic design written to ``path``."""
    data = generate_design(design_id, seed)
    Path(path).write_text(json.dumps(data))
    return {"extrudes": sum(e["type"] == "ExtrudeFeature" for e in data["entities"].values())}


def convert_to_json(batch: str, design_id: str, path: str) -> dict[str, Any]:
    """Job body (in a killable child): one corpus design converted and verified; its JSON written
    when it is ok. Both relative differences of our replay from Fusion's figures are kept, so the
    replay-vs-Fusion table of the whole corpus comes from ``conversion.parquet``."""
    result = convert_design(batch, design_id)
    if result.ok and result.design_json is not None:
        Path(path).write_text(json.dumps(result.design_json))
    return {
        "convert_status": str(result.status),
        "convert_reason": result.reason,
        "folder": result.folder,
        "steps": result.steps,
        "operations": ",".join(result.operations),
        "mode_disagreements": result.mode_disagreements,
        "volume_rel_error": result.volume_rel_error,
        "area_rel_error": result.area_rel_error,
        "fusion_volume_rel_error": result.fusion_volume_rel_error,
        "fusion_area_rel_error": result.fusion_area_rel_error,
        "script_fusion_volume_rel_error": result.script_fusion_volume_rel_error,
        "script_fusion_area_rel_error": result.script_fusion_area_rel_error,
    }


def generate(count: int, seed: int, dask_cfg: DaskParams, timeout: float, out: Path) -> Path:
    json_dir = out / "json"
    json_dir.mkdir(parents=True, exist_ok=True)
    code = code_fingerprint("generate")
    jobs = []
    for i in range(count):
        name, s = synthetic_id(i), design_seed(seed, i)
        path = str(json_dir / f"{name}.json")
        jobs.append(Job(name, fingerprint(code, s), (name, s, path), outputs=(path,)))
    with dask_client(dask_cfg) as client:
        records = run_jobs(
            write_design, jobs, out / "records", client, timeout, "generate", memory_mb=dask_cfg.memory_mb
        )
    for r in records:
        if r["status"] != Status.OK:
            print(f"generate: {r['design_id']} failed ({r['status']}): {r['reason']}")
            (json_dir / f"{r['design_id']}.json").unlink(missing_ok=True)
    return json_dir


def convert_corpus(
    root: Path, limit: int | None, seed: int, dask_cfg: DaskParams, timeout: float, out: Path
) -> pd.DataFrame:
    """Convert (a stratified sample of) the corpus; returns one row per design, failures included."""
    entries = list_corpus(root)
    entries = [entries[i] for i in stratified_sample([e.folder for e in entries], limit, seed)]
    json_dir = out / "json"
    json_dir.mkdir(parents=True, exist_ok=True)
    code = code_fingerprint("generate")
    jobs = [
        Job(
            e.design_id,
            fingerprint(code, timeout, files=(e.batch,)),
            (str(e.batch), e.design_id, str(json_dir / f"{e.design_id}.json")),
            outputs=(str(json_dir / f"{e.design_id}.json"),),
            inputs=(str(e.batch),),
            outputs_optional=True,  # a design that does not convert writes no JSON
        )
        for e in entries
    ]
    with dask_client(dask_cfg) as client:  # each design in a child killed at its timeout
        records = run_jobs(
            convert_to_json,
            jobs,
            out / "convert_records",
            client,
            timeout,
            "convert",
            memory_mb=dask_cfg.memory_mb,
        )
    table = records_frame(records, ("convert_status", "convert_reason", "folder"))
    table["folder"] = [e.folder for e in entries]
    failed = table["status"] != Status.OK  # the child timed out, crashed or met a bug of ours
    table.loc[failed, "convert_status"] = table.loc[failed, "status"]
    table.loc[failed, "convert_reason"] = table.loc[failed, "reason"]
    for row in table.itertuples():
        if row.convert_status != Status.OK:
            (json_dir / f"{row.design_id}.json").unlink(missing_ok=True)
    return table.drop(columns=["status", "reason"]).rename(
        columns={"convert_status": "status", "convert_reason": "reason"}
    )


def write_conversion(table: pd.DataFrame, out: Path, metrics_file: Path, details_file: Path) -> None:
    table.to_parquet(out / "conversion.parquet", index=False)
    ok = table["status"] == Status.OK
    write_json(metrics_file, headline(len(table), int(ok.sum()), table["seconds"]))
    details = {
        "source": "b123d",
        "by_status": {k: int(v) for k, v in table["status"].value_counts().items()},
        "by_folder": {
            f: {"designs": int(len(g)), "converted": int((g["status"] == Status.OK).sum())}
            for f, g in table.groupby("folder")
        },
    }
    write_json(details_file, details)
    print(
        f"convert: {int(ok.sum())}/{len(table)} converted and verified "
        f"({ok.mean() if len(table) else 0.0:.2%}), by status {details['by_status']}"
    )


def main() -> None:
    args = stage_paths(
        __doc__,
        (),
        out="the designs folder (index.parquet, json/)",
        metrics="the conversion metrics JSON",
        details="the conversion's breakdowns JSON (by status, by folder)",
    )
    data, dask = section(DataParams, "data"), section(DaskParams, "dask")
    source, limit = data.source, data.limit
    seed, fraction = data.split_seed, data.test_fraction
    if source == "fusion_json":
        folder = _folder(data.fusion_json_dir, "fusion_json_dir")
    elif source == "b123d":
        root = _folder(data.b123d_dir, "b123d_dir")
        table = convert_corpus(root, limit, data.limit_seed, dask, data.convert_timeout_s, args.out)
        write_conversion(table, args.out, args.metrics, args.details)
        folder = args.out / "json"
    elif source == "synthetic":
        syn = section(SyntheticParams, "synthetic")
        folder = generate(syn.count, syn.seed, dask, syn.timeout_s, args.out)
    else:
        raise SystemExit(f"generate: unknown data.source {source!r} (synthetic, fusion_json or b123d)")
    if source == "b123d":  # this run's converted designs (the folder may hold earlier runs' too)
        ids = sorted(table.loc[table["status"] == Status.OK, "design_id"])
        test = test_ids(ids, seed, fraction)
        records = [DesignRecord(i, folder / f"{i}.json", "test" if i in test else "train") for i in ids]
    else:
        records = read_dataset(folder, seed=seed, test_fraction=fraction)
    if source == "fusion_json" and limit is not None:
        records = [records[i] for i in stratified_sample(["all"] * len(records), limit, seed)]
    write_index(records, table if source == "b123d" else None, args.out)
    if source != "b123d":  # nothing converted: every design is one as read
        write_json(args.metrics, headline(len(records), len(records), ()))
        write_json(args.details, {"source": source})
    print(f"generate: {len(records)} designs from {folder} ({source})")


def _folder(value: str | None, key: str) -> Path:
    """The source folder ``data.<key>`` names, resolved from the run's folder (the one holding
    ``params.yaml``, where DVC runs the stage): a missing one is a user's error, said in one line."""
    if value is None:
        raise SystemExit(f"{PARAMS_FILE}: data: this source needs data.{key}")
    folder = Path(value).expanduser().resolve()
    if not folder.is_dir():
        raise SystemExit(
            f"{PARAMS_FILE}: data.{key}: no folder {folder} (a relative path is read from {Path.cwd()})"
        )
    return folder


def write_index(records: list[DesignRecord], table: pd.DataFrame | None, out: Path) -> None:
    designs, folders = [], []
    for r in records:
        try:
            design = load_design(r.path)
        except Exception:  # unreadable designs are reported by the replay stage
            folders.append("unreadable")
            continue
        designs.append(design)
        folders.append(timeline_folder(len(design.timeline)))
    index = pd.DataFrame(
        {
            "design_id": [r.design_id for r in records],
            "path": [str(r.path) for r in records],
            "split": [r.split for r in records],
            "folder": folders,
        }
    )
    if table is not None:  # the corpus's own timeline folders
        index["folder"] = index["design_id"].map(table.set_index("design_id")["folder"])
    out.mkdir(parents=True, exist_ok=True)
    index.to_parquet(out / "index.parquet", index=False)
    stats = design_statistics(designs)
    (out / "stats.json").write_text(json.dumps(stats, indent=2))
    (out / "stats.txt").write_text(format_comparison(stats) + "\n")
    print(f"generate: splits {index['split'].value_counts().to_dict()}")


if __name__ == "__main__":
    main()

"""DVC stage ``generate``: the design index (and, by default, the synthetic designs themselves).

With ``data.fusion_dir`` set, the stage indexes that folder (the r1.0.1 reconstruction data or any
folder of design JSONs) and copies nothing. Otherwise it generates ``synthetic.count`` seeded
designs in parallel. Either way it writes ``data/designs/index.parquet`` (design id, path, split)
and ``stats.json``/``stats.txt`` comparing the designs with the published statistics.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from zonegraph.data.dataset import read_dataset
from zonegraph.data.design import load_design
from zonegraph.data.stats import design_statistics, format_comparison
from zonegraph.data.synthetic import design_seed, generate_design, synthetic_id

from .cluster import dask_client
from .params import load_params
from .runner import Job, code_fingerprint, fingerprint, run_jobs

OUT = Path("data/designs")


def write_design(design_id: str, seed: int, path: str) -> dict:
    """Job body: one synthetic design written to ``path``."""
    data = generate_design(design_id, seed)
    Path(path).write_text(json.dumps(data))
    return {"extrudes": sum(e["type"] == "ExtrudeFeature" for e in data["entities"].values())}


def generate(count: int, seed: int, dask_cfg: dict, timeout: float) -> Path:
    json_dir = OUT / "json"
    json_dir.mkdir(parents=True, exist_ok=True)
    code = code_fingerprint("generate")
    jobs = []
    for i in range(count):
        name, s = synthetic_id(i), design_seed(seed, i)
        jobs.append(Job(name, fingerprint(code, s), (name, s, str(json_dir / f"{name}.json"))))
    with dask_client(dask_cfg) as client:
        records = run_jobs(write_design, jobs, OUT / "records", client, timeout, "generate")
    failed = [r for r in records if r["status"] != "ok"]
    for r in failed:
        print(f"generate: {r['design_id']} failed ({r['status']}): {r['reason']}")
        (json_dir / f"{r['design_id']}.json").unlink(missing_ok=True)
    return json_dir


def main() -> None:
    params = load_params()
    data = params["data"]
    if data.get("fusion_dir"):
        folder = Path(data["fusion_dir"]).expanduser().resolve()
    else:
        syn = params["synthetic"]
        folder = generate(int(syn["count"]), int(syn["seed"]), params["dask"], float(syn["timeout_s"]))
    records = read_dataset(folder, seed=int(data["split_seed"]), test_fraction=float(data["test_fraction"]))
    OUT.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(
        [{"design_id": r.design_id, "path": str(r.path), "split": r.split} for r in records]
    ).to_parquet(OUT / "index.parquet", index=False)
    designs = []
    for r in records:
        try:
            designs.append(load_design(r.path))
        except Exception:  # unreadable designs are reported by the replay stage
            continue
    stats = design_statistics(designs)
    (OUT / "stats.json").write_text(json.dumps(stats, indent=2))
    (OUT / "stats.txt").write_text(format_comparison(stats) + "\n")
    splits = pd.Series([r.split for r in records]).value_counts().to_dict()
    print(f"generate: {len(records)} designs from {folder} ({splits})")


if __name__ == "__main__":
    main()

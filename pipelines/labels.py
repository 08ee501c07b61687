"""DVC stage ``labels``: ternary labels for every captured ground-truth step (paper sec. 4.2).

For each design of the chosen splits whose GT replays to its target on the saved zone graph, the
labeller (``zonegraph.sequence.labels``) runs random completions from every proposal at every GT
step. Each design is one killable Dask task that writes its own shards,
``data/labels/proposals/<id>.parquet`` and ``data/labels/steps/<id>.parquet`` (schemas in the
README; read the folders with ``pyarrow.dataset``), so one bad design never loses the others and
an interrupted run resumes. ``data/metrics/labels.json`` counts designs, steps and labels.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from zonegraph.data.dataset import stratified_sample
from zonegraph.jobs import label_and_save

from .cluster import dask_client
from .params import load_params
from .runner import Job, code_fingerprint, fingerprint, run_jobs

OUT = Path("data/labels")
GRAPHS = Path("data/zonegraphs/graphs")
METRICS = Path("data/metrics/labels.json")


def saved_graph_rows(steps: pd.DataFrame) -> pd.DataFrame:
    """Each design's GT rows on its saved graph: the simplified one when simplification ran."""
    has_simplified = steps.groupby("design_id")["graph"].transform(lambda g: (g == "simplified").any())
    keep = (steps["graph"] == "simplified") | ~has_simplified
    return steps[keep].sort_values(["design_id", "step"])


def candidates(designs: pd.DataFrame, splits: list[str], limit: int | None, seed: int) -> pd.DataFrame:
    """Designs to label: the chosen splits, GT replayed to the target; a seeded stratified sample."""
    reaches = designs["simplified_reaches_target"].where(
        designs["simplified_status"] == "ok", designs["full_reaches_target"]
    )
    chosen = designs[designs["split"].isin(splits) & (reaches == True)]  # noqa: E712 (nullable)
    chosen = chosen.sort_values("design_id").reset_index(drop=True)
    return chosen.iloc[stratified_sample(chosen["folder"].astype(str).tolist(), limit, seed)]


def main() -> None:
    params = load_params()
    cfg = params["labels"]
    level, seed = int(cfg["level"]), int(cfg["seed"])
    settings = (seed, level, float(cfg["multiplier"]), int(cfg["slack"]))
    designs = pd.read_parquet("data/gt/designs.parquet")
    steps = saved_graph_rows(pd.read_parquet("data/gt/steps.parquet"))
    column = f"captured_l{level}"
    if column not in steps:
        raise SystemExit(f"labels: level {level} is not among ground_truth.levels ({column} missing)")
    todo = candidates(designs, list(cfg["splits"]), cfg.get("limit"), int(cfg.get("limit_seed", 0)))
    gt_of = {
        d: [
            {
                "operation": r.operation,
                "gt_zones": [int(z) for z in r.gt_zones],
                "captured": bool(getattr(r, column)),
                "reason": r.reason if isinstance(r.reason, str) else "",
            }
            for r in g.itertuples()
        ]
        for d, g in steps[steps["design_id"].isin(todo["design_id"])].groupby("design_id")
    }
    code = code_fingerprint("labels")
    jobs = [
        Job(
            row.design_id,
            fingerprint(code, settings, row.split, gt_of[row.design_id], files=(GRAPHS / row.design_id,)),
            (
                str(GRAPHS / row.design_id),
                gt_of[row.design_id],
                row.design_id,
                row.split,
                str(OUT),
                *settings,
            ),
            cost=float(row.graph_zones),
        )
        for row in todo.itertuples()
        if row.design_id in gt_of
    ]
    with dask_client(params["dask"]) as client:
        records = run_jobs(label_and_save, jobs, OUT / "records", client, float(cfg["timeout_s"]), "labels")
    keep = {r["design_id"] for r in records if r["status"] == "ok"}
    for shard in [*OUT.glob("proposals/*.parquet"), *OUT.glob("steps/*.parquet")]:
        if shard.stem not in keep:  # a failed design or one of an earlier, different run
            shard.unlink()
    write_metrics(pd.DataFrame(records))


def write_metrics(records: pd.DataFrame) -> None:
    ok = records[records["status"] == "ok"] if len(records) else records
    counts = ("steps", "labelled_steps", "proposals", "positives", "negatives", "neutrals", "completions")
    metrics = {
        "designs": int(len(records)),
        "labelled": int(len(ok)),
        "by_status": {k: int(v) for k, v in records["status"].value_counts().items()} if len(records) else {},
        **{c: int(ok[c].sum()) if len(ok) else 0 for c in counts},
        "seconds": float(records["seconds"].sum()) if len(records) else 0.0,
        "seconds_per_design_median": float(ok["seconds"].median()) if len(ok) else None,
    }
    METRICS.parent.mkdir(parents=True, exist_ok=True)
    METRICS.write_text(json.dumps(metrics, indent=2))
    print(
        f"labels: {metrics['labelled']}/{metrics['designs']} designs, {metrics['labelled_steps']} steps, "
        f"{metrics['proposals']} proposals (+{metrics['positives']} / 0 {metrics['neutrals']} / "
        f"-{metrics['negatives']}), {metrics['seconds']:.0f} s"
    )
    for row in records[records["status"] != "ok"].itertuples():
        print(f"  {row.design_id}: {row.status}: {row.reason}")


if __name__ == "__main__":
    main()

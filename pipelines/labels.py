"""DVC stage ``labels``: ternary labels for every captured ground-truth step (paper sec. 4.2).

For each design of the chosen splits whose GT replays to its target on the saved zone graph, the
labeller (``zonegraph.sequence.labels``) runs random completions from every proposal at every GT
step. Designs of ``labels.rank_splits`` (the test split) get rank-only labels instead: every
proposal of every captured step with the GT flagged and no completions (multiplier 0), which is
what the relative GT rank of ``eval`` needs at a small part of the cost. Each design is one
killable Dask task that writes its own shards, ``data/labels/proposals/<id>.parquet`` and
``data/labels/steps/<id>.parquet`` (schemas in docs/pipeline.md; read the folders with
``pyarrow.dataset``), so one bad design never loses the others and an interrupted run resumes.
``data/metrics/labels.json`` has the shared metrics keys (every design, training and rank-only);
``data/details/labels.json`` counts designs, steps and labels (rank-only designs apart).
"""

from __future__ import annotations

import pandas as pd

from eval.dvc_metrics import headline, write_json
from zonegraph.data.dataset import stratified_sample
from zonegraph.jobs import label_and_save
from zonegraph.status import Status

from .cluster import dask_client
from .params import DaskParams, LabelsParams, section
from .paths import stage_paths
from .records import retry_summary
from .runner import Job, code_fingerprint, fingerprint, records_frame, run_jobs


def saved_graph_rows(steps: pd.DataFrame) -> pd.DataFrame:
    """Each design's GT rows on its saved graph: the simplified one when simplification ran."""
    has_simplified = steps.groupby("design_id")["graph"].transform(lambda g: (g == "simplified").any())
    keep = (steps["graph"] == "simplified") | ~has_simplified
    return steps[keep].sort_values(["design_id", "step"])


def candidates(designs: pd.DataFrame, splits: list[str], limit: int | None, seed: int) -> pd.DataFrame:
    """Designs to label: the chosen splits, GT replayed to the target; a seeded stratified sample."""
    full = designs["full_reaches_target"] if "full_reaches_target" in designs else None  # full_graph: false
    reaches = designs["simplified_reaches_target"].where(designs["simplified_status"] == Status.OK, full)
    chosen = designs[designs["split"].isin(splits) & (reaches == True)]  # noqa: E712 (nullable)
    chosen = chosen.sort_values("design_id").reset_index(drop=True)
    return chosen.iloc[stratified_sample(chosen["folder"].astype(str).tolist(), limit, seed)]


def main() -> None:
    args = stage_paths(
        __doc__,
        ("gt", "zonegraphs"),
        out="the labels folder (shards, records)",
        metrics="the label metrics JSON",
        details="the labels' counts JSON (designs, steps and labels; rank-only designs apart)",
    )
    out, graphs = args.out, args.zonegraphs / "graphs"
    cfg = section(LabelsParams, "labels")
    level, seed = cfg.level, cfg.seed
    splits = list(cfg.splits)
    rank_splits = [s for s in cfg.rank_splits if s not in splits]
    designs = pd.read_parquet(args.gt / "designs.parquet")
    steps = saved_graph_rows(pd.read_parquet(args.gt / "steps.parquet"))
    column = f"captured_l{level}"
    if column not in steps:
        raise SystemExit(f"labels: level {level} is not among ground_truth.levels ({column} missing)")
    limit, limit_seed = cfg.limit, cfg.limit_seed
    todo = pd.concat(
        [candidates(designs, splits, limit, limit_seed), candidates(designs, rank_splits, limit, limit_seed)]
    )

    def settings(split: str) -> tuple[int, int, float, int]:
        multiplier = 0.0 if split in rank_splits else cfg.multiplier
        return seed, level, multiplier, cfg.slack

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
            fingerprint(
                code, settings(row.split), row.split, gt_of[row.design_id], files=(graphs / row.design_id,)
            ),
            (
                str(graphs / row.design_id),
                gt_of[row.design_id],
                row.design_id,
                row.split,
                str(out),
                *settings(row.split),
            ),
            cost=float(row.graph_zones),
            outputs=(
                str(out / "proposals" / f"{row.design_id}.parquet"),
                str(out / "steps" / f"{row.design_id}.parquet"),
            ),
            inputs=(str(graphs / row.design_id),),
        )
        for row in todo.itertuples()
        if row.design_id in gt_of
    ]
    dask = section(DaskParams, "dask")
    with dask_client(dask) as client:
        records = run_jobs(
            label_and_save, jobs, out / "records", client, cfg.timeout_s, "labels", memory_mb=dask.memory_mb
        )
    keep = {r["design_id"] for r in records if r["status"] == Status.OK}
    for shard in [*out.glob("proposals/*.parquet"), *out.glob("steps/*.parquet")]:
        if shard.stem not in keep:  # a failed design or one of an earlier, different run
            shard.unlink()
    split_of = dict(zip(todo["design_id"], todo["split"], strict=True))
    table = records_frame(records)
    ranked = table["design_id"].map(split_of).isin(rank_splits) if len(table) else pd.Series(dtype=bool)
    metrics = {**count(table[~ranked]), "rank_only": count(table[ranked]), "runner": retry_summary(records)}
    ok = int((table["status"] == Status.OK).sum()) if len(table) else 0
    write_json(args.metrics, headline(len(table), ok, table["seconds"] if len(table) else ()))
    write_json(args.details, metrics)
    print(
        f"labels: {metrics['labelled']}/{metrics['designs']} designs, {metrics['labelled_steps']} steps, "
        f"{metrics['proposals']} proposals (+{metrics['positives']} / 0 {metrics['neutrals']} / "
        f"-{metrics['negatives']}), {metrics['seconds']:.0f} s; rank-only "
        f"{metrics['rank_only']['labelled']}/{metrics['rank_only']['designs']} designs "
        f"({', '.join(rank_splits) or 'none'}), {metrics['rank_only']['labelled_steps']} steps"
    )
    for row in table[table["status"] != Status.OK].itertuples():
        print(f"  {row.design_id}: {row.status}: {row.reason}")


def count(records: pd.DataFrame) -> dict:
    """Designs, steps and labels of a set of job records, with the time they took."""
    ok = records[records["status"] == Status.OK] if len(records) else records
    counts = ("steps", "labelled_steps", "proposals", "positives", "negatives", "neutrals", "completions")
    return {
        "designs": int(len(records)),
        "labelled": int(len(ok)),
        "by_status": {k: int(v) for k, v in records["status"].value_counts().items()} if len(records) else {},
        **{c: int(ok[c].sum()) if len(ok) else 0 for c in counts},
        "seconds": float(records["seconds"].sum()) if len(records) else 0.0,
        "seconds_per_design_median": float(ok["seconds"].median()) if len(ok) else None,
    }


if __name__ == "__main__":
    main()

"""An evaluation as an MLflow run (experiment ``evaluation``), linked to the runs that trained its models.

The tracking store is ``MLFLOW_TRACKING_URI`` when set (a team's server), else the project's
``sqlite:///mlflow.db``, the same store the training runs use, so ``make ui`` shows both. Metric
names are grouped by a ``/`` (``rank/heuristic``, ``exact_at_1s/net``), which the dashboard draws
as one section per group, and the IoU curves are stepped by search milliseconds.

A local store records absolute artifact paths (MLflow resolves ``./mlruns`` when a run starts),
so a project moved or copied to another folder would point at the old one:
``python -m eval.tracking relocate`` (``make ui`` runs it) rewrites them to this folder.
"""

from __future__ import annotations

import argparse
import os
import sqlite3
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd

DEFAULT_TRACKING = "sqlite:///mlflow.db"
EXPERIMENT = "evaluation"
ARTIFACTS = "mlruns"  # beside mlflow.db, as MLflow's own default


def training_run(model: str | Path) -> str | None:
    """The MLflow run that trained a checkpoint (stored in it by ``training.train``), if known."""
    try:
        import torch

        checkpoint = torch.load(model, map_location="cpu", weights_only=True)
    except Exception:  # an unreadable checkpoint has no known origin; the ranker reports it
        return None
    return checkpoint.get("provenance", {}).get("run_id")


def metric_name(key: str) -> str:
    """``rank.heuristic`` -> ``rank/heuristic``: the group before the first dot becomes a section."""
    return key.replace(":", "_").replace(".", "/", 1)


def run_name(params: dict[str, Any]) -> str:
    """What the dashboard lists: the designs evaluated, the budget and the widths searched."""
    designs = Path(str(params.get("designs", "test"))).name or "designs"
    k = params.get("k", "")
    widths = "-".join(str(x) for x in k) if isinstance(k, list | tuple) else str(k)
    budget = params.get("budget_s", params.get("budget", "?"))  # eval.report's name for --budget
    return f"evaluate {designs} {budget}s k{widths} seed{params.get('seed', 0)}"


def _description(models: Sequence[str | Path], runs: dict[str, str]) -> str:
    """Markdown for the run's description: a link to each model's training run."""
    lines = ["Evaluation of random, heuristic and network guidance (`eval.report`)."]
    for m in models:
        run = runs.get(Path(m).stem)
        link = f"[training run {run[:8]}](#/runs/{run})" if run else "trained outside this store"
        lines.append(f"- `{m}`: {link}")
    return "\n".join(lines)


def log_evaluation(
    params: dict[str, Any],
    metrics: dict[str, float],
    curves: pd.DataFrame | None,
    artifacts: Path,
    models: Sequence[str | Path] = (),
) -> str:
    """One run: parameters, metrics, the IoU curves as step metrics, the files of ``artifacts``
    (its top level: the report, tables and plots, not the per-search records)."""
    import mlflow

    mlflow.set_tracking_uri(os.environ.get("MLFLOW_TRACKING_URI", DEFAULT_TRACKING))
    mlflow.set_experiment(EXPERIMENT)
    runs = {Path(m).stem: run for m in models if (run := training_run(m))}
    tags = {f"training_run.{stem}": run for stem, run in runs.items()}
    tags["mlflow.note.content"] = _description(models, runs)
    with mlflow.start_run(run_name=run_name(params), tags=tags) as run:
        mlflow.log_params({k: str(v)[:500] for k, v in params.items()})
        mlflow.log_metrics(
            {metric_name(k): float(v) for k, v in metrics.items() if v == v}
        )  # NaN: not measured
        if curves is not None:
            for (guide, k), group in curves.groupby(["guide", "k"], sort=False):
                name = f"{guide.replace(':', '_')}_k{k}"
                for row in group.itertuples():
                    step = int(round(1000 * row.seconds))  # search milliseconds: steps must be integers
                    mlflow.log_metric(f"iou_vs_ms/{name}", row.mean_iou, step=step)
                    mlflow.log_metric(f"exact_vs_ms/{name}", row.exact_rate, step=step)
        for path in sorted(p for p in Path(artifacts).iterdir() if p.is_file()):
            mlflow.log_artifact(str(path))
        return run.info.run_id


def relocate(db: Path = Path("mlflow.db")) -> int:
    """Point a local store's artifact paths at the ``mlruns`` folder beside ``db``; returns how
    many experiments and runs it rewrote. Paths already there, and remote ones, are left alone."""
    root = (db.resolve().parent / ARTIFACTS).as_uri()
    con = sqlite3.connect(db)
    changed = 0
    with con:
        for table, column, key in (
            ("experiments", "artifact_location", "experiment_id"),
            ("runs", "artifact_uri", "run_uuid"),
        ):
            for ident, uri in con.execute(f"SELECT {key}, {column} FROM {table}").fetchall():
                moved = _moved(uri, root)
                if moved:
                    con.execute(f"UPDATE {table} SET {column} = ? WHERE {key} = ?", (moved, ident))
                    changed += 1
    con.close()
    return changed


def _moved(uri: str | None, root: str) -> str | None:
    """``uri`` under ``root`` when it is a local path into some other ``mlruns`` folder."""
    marker = f"/{ARTIFACTS}/"
    if not uri or not uri.startswith(("file:", "/")) or marker not in uri or uri.startswith(root + "/"):
        return None
    return root + "/" + uri.split(marker, 1)[1]


def main() -> None:
    ap = argparse.ArgumentParser(
        prog="python -m eval.tracking", description="Maintain the project's MLflow store."
    )
    sub = ap.add_subparsers(dest="command", required=True)
    cmd = sub.add_parser("relocate", help="point artifact paths at the mlruns folder beside the store")
    cmd.add_argument("--db", type=Path, default=Path("mlflow.db"))
    args = ap.parse_args()
    if not args.db.is_file():
        print(f"{args.db}: no MLflow store here yet (nothing to relocate)")
        return
    print(f"{args.db}: {relocate(args.db)} artifact paths now under {args.db.resolve().parent / ARTIFACTS}")


if __name__ == "__main__":
    main()

"""An evaluation as an MLflow run (experiment ``evaluation``), linked to the runs that trained its models.

The tracking store is ``MLFLOW_TRACKING_URI`` when set (a team's server), else the project's
``sqlite:///mlflow.db``, the same store the training runs use, so ``make ui`` shows both.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd

DEFAULT_TRACKING = "sqlite:///mlflow.db"
EXPERIMENT = "evaluation"


def training_run(model: str | Path) -> str | None:
    """The MLflow run that trained a checkpoint (stored in it by ``training.train``), if known."""
    try:
        import torch

        checkpoint = torch.load(model, map_location="cpu", weights_only=True)
    except Exception:  # an unreadable checkpoint has no known origin; the ranker reports it
        return None
    return checkpoint.get("provenance", {}).get("run_id")


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
    tags = {f"training_run.{Path(m).stem}": run for m in models if (run := training_run(m))}
    with mlflow.start_run(tags=tags) as run:
        mlflow.log_params({k: str(v)[:500] for k, v in params.items()})
        mlflow.log_metrics({k: float(v) for k, v in metrics.items() if v == v})  # NaN: not measured
        if curves is not None:
            for (guide, k), group in curves.groupby(["guide", "k"], sort=False):
                for step, row in enumerate(group.itertuples()):
                    name = f"{guide.replace(':', '_')}_k{k}"
                    mlflow.log_metric(f"iou_curve.{name}", row.mean_iou, step=step)
                    mlflow.log_metric(f"exact_curve.{name}", row.exact_rate, step=step)
        for path in sorted(p for p in Path(artifacts).iterdir() if p.is_file()):
            mlflow.log_artifact(str(path))
        return run.info.run_id

"""Train the proposal scorer on the ``labels`` stage's shards, tracked in MLflow.

    python -m training.train [--params params.yaml] [--device cpu|cuda]

Designs of the labelled training split are split again by project into training and validation
(``train.val_fraction``). Every epoch logs the training and validation focal loss and the
validation relative GT rank (the rank of the GT among all of a step's proposals over their count,
averaged; lower is better). The checkpoint with the best validation rank is written to
``models/scorer.pt`` with ``models/metrics.json``; ``models/curve.csv`` and ``models/curve.png``
hold the learning curves. The run logs its parameters, metrics, the data version (a hash of the
label shards), the git commit and the checkpoint to MLflow: ``MLFLOW_TRACKING_URI`` when set,
else ``sqlite:///mlflow.db`` in the working directory (``mlflow ui --backend-store-uri
sqlite:///mlflow.db`` shows it).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import signal
import socket
import subprocess
import threading
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.dataset as ds
import torch
from torch_geometric.loader import DataLoader

from training.data import LabelDataset
from training.loss import focal_loss
from zonegraph.configs import Config, ConfigError, load_section
from zonegraph.data.dataset import project_of, test_ids
from zonegraph.network.model import ModelConfig, ProposalScorer
from zonegraph.network.scoring import score_state
from zonegraph.sequence.rankers import relative_rank

DEFAULT_TRACKING = "sqlite:///mlflow.db"


@dataclass(frozen=True)
class TrainConfig(Config):
    """Everything a run depends on (``params.yaml: train``).

    The defaults are what ``make run`` trains (``params.yaml`` repeats them, so that DVC tracks
    each); the shipped checkpoint's own settings are in ``training/checkpoints/MODEL_CARD.md``.
    """

    labels_dir: str = "data/labels"
    graphs_dir: str = "data/zonegraphs/graphs"
    out_dir: str = "models"
    fusion: str = "late"
    rounds: int = 3
    use_points: bool = True
    epochs: int = 3
    lr: float = 1e-3
    batch_states: int = 8  # states per batch (each with up to max_proposals proposals)
    max_proposals: int = 32
    points_per_zone: int = 64
    gamma: float = 0.5
    val_fraction: float = 0.15
    max_designs: int | None = None  # a seeded sample of the training designs (quick runs, costly fusions)
    seed: int = 0
    device: str = "auto"
    experiment: str = "zonegraph-scorer"

    @property
    def model(self) -> ModelConfig:
        return ModelConfig(fusion=self.fusion, rounds=self.rounds, use_points=self.use_points)


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def forward(model: ProposalScorer, batch: Any) -> torch.Tensor:
    """Logits (P, 2) for a PyG batch of states, in any fusion."""
    return model(batch)


def mean_loss(model: ProposalScorer, loader: DataLoader, device: torch.device, gamma: float) -> float:
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for batch in loader:
            batch = batch.to(device)
            logits = forward(model, batch)
            total += float(focal_loss(logits, batch.y, gamma)) * len(batch.y)
            count += len(batch.y)
    return total / max(count, 1)


def rank_scores(model: ProposalScorer, dataset: LabelDataset, device: torch.device) -> list[float]:
    """Relative GT rank of every state of a rank-mode dataset (states with a GT and others)."""
    ranks = []
    for state in dataset.states:
        if int(state.is_gt.sum()) != 1 or len(state.is_gt) < 2:
            continue
        scores = score_state(
            model,
            dataset.geometry[state.design_id],
            torch.from_numpy(state.canvas),
            torch.from_numpy(state.zones),
            torch.from_numpy(state.ops),
            device,
        )
        ranks.append(relative_rank(scores, state.is_gt))
    return ranks


def data_version(labels_dir: str | Path) -> str:
    """A short hash of the label shards' names and sizes: which labels a run saw."""
    h = hashlib.sha1()
    for path in sorted(Path(labels_dir).glob("*/*.parquet")):
        h.update(f"{path.parent.name}/{path.name}:{path.stat().st_size}".encode())
    return h.hexdigest()[:12]


def git_commit() -> str:
    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True)
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def labelled_designs(labels_dir: str | Path, split: str) -> list[str]:
    """The designs of one split that have label shards."""
    steps = ds.dataset(Path(labels_dir) / "steps", format="parquet").to_table(columns=["design_id", "split"])
    chosen = steps.filter(ds.field("split") == split).column("design_id").to_pylist()
    return sorted(set(chosen))


def split_designs(labels_dir: str | Path, seed: int, fraction: float) -> tuple[list[str], list[str]]:
    """Training-split designs with labels, split by project into training and validation."""
    ids = labelled_designs(labels_dir, "train")
    val = test_ids(ids, seed, fraction)
    return [i for i in ids if i not in val], sorted(val)


def _terminated(signum: int, frame: Any) -> None:
    raise SystemExit(f"training stopped by signal {signum}")  # mlflow's run context ends it FAILED


def fail_dead_runs(experiment_id: str) -> None:
    """End as FAILED the runs still RUNNING whose training process on this host is gone: a
    ``kill -9`` (or a lost machine) leaves no chance to end them, so the next training does."""
    import mlflow

    client = mlflow.MlflowClient()
    host = socket.gethostname()
    for run in client.search_runs([experiment_id], "attributes.status = 'RUNNING'"):
        tags = run.data.tags
        pid = tags.get("zonegraph.pid", "")
        if tags.get("zonegraph.host") == host and pid.isdigit() and not _alive(int(pid)):
            client.set_terminated(run.info.run_id, status="FAILED")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def train(config: TrainConfig) -> dict[str, Any]:
    """One training run; returns the best epoch's metrics (also in ``out_dir/metrics.json``)."""
    import mlflow  # a heavy import: only when training

    torch.manual_seed(config.seed)
    np.random.seed(config.seed)
    device = pick_device(config.device)
    train_ids, val_ids = split_designs(config.labels_dir, config.seed, config.val_fraction)
    if config.max_designs is not None and config.max_designs < len(train_ids):
        keep = np.random.default_rng(config.seed).choice(len(train_ids), config.max_designs, replace=False)
        train_ids = [train_ids[i] for i in sorted(keep)]
    common = dict(points_per_zone=config.points_per_zone, seed=config.seed)
    sets = {
        "train": LabelDataset(
            config.labels_dir, config.graphs_dir, train_ids, "train", config.max_proposals, **common
        ),
        "val": LabelDataset(
            config.labels_dir, config.graphs_dir, val_ids, "train", config.max_proposals, **common
        ),
        "rank": LabelDataset(config.labels_dir, config.graphs_dir, val_ids, "rank", **common),
    }
    generator = torch.Generator().manual_seed(config.seed)
    train_loader = DataLoader(
        sets["train"], batch_size=config.batch_states, shuffle=True, generator=generator
    )
    val_loader = DataLoader(sets["val"], batch_size=config.batch_states)
    model = ProposalScorer(config.model).to(device)
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    out = Path(config.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    mlflow.set_tracking_uri(os.environ.get("MLFLOW_TRACKING_URI", DEFAULT_TRACKING))
    experiment = mlflow.set_experiment(config.experiment)
    fail_dead_runs(experiment.experiment_id)
    curve, best = [], {"val_rank": float("inf")}
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminated)  # a killed training's run ends FAILED, not RUNNING
    with mlflow.start_run(
        tags={"zonegraph.host": socket.gethostname(), "zonegraph.pid": str(os.getpid())}
    ) as run:
        sizes = {
            "train_designs": len(train_ids),
            "val_designs": len(val_ids),
            "train_states": len(sets["train"]),
        }
        mlflow.log_params({**asdict(config), **sizes, "device": str(device)})
        tags = {"data_version": data_version(config.labels_dir), "git_commit": git_commit()}
        mlflow.set_tags(tags)
        seen = sorted({project_of(d) for d in [*train_ids, *val_ids]})  # evaluation must skip these
        provenance = {**sizes, **tags, "run_id": run.info.run_id, "train_projects": seen}
        for epoch in range(1, config.epochs + 1):
            t0 = time.perf_counter()
            model.train()
            losses = []
            for batch in train_loader:
                batch = batch.to(device)
                if len(batch.y) < 2:  # BatchNorm needs two examples
                    continue
                loss = focal_loss(forward(model, batch), batch.y, config.gamma)
                optimiser.zero_grad()
                loss.backward()
                optimiser.step()
                losses.append(loss.item())
            ranks = rank_scores(model, sets["rank"], device)
            row = {
                "epoch": epoch,
                "train_loss": float(np.mean(losses)) if losses else float("nan"),
                "val_loss": mean_loss(model, val_loader, device, config.gamma),
                "val_rank": float(np.mean(ranks)) if ranks else float("nan"),
                "seconds": time.perf_counter() - t0,
            }
            if not np.isfinite(row["train_loss"]):
                print(f"epoch {epoch}: the training loss is not finite; stopping", flush=True)
                break
            curve.append(row)
            mlflow.log_metrics({k: v for k, v in row.items() if k != "epoch"}, step=epoch)
            print(
                f"epoch {epoch}: " + ", ".join(f"{k} {v:.4f}" for k, v in row.items() if k != "epoch"),
                flush=True,
            )
            if row["val_rank"] <= best["val_rank"] or not np.isfinite(best["val_rank"]):
                best = {**row, "val_steps": len(ranks)}
                save_checkpoint(model, config, best, out / "scorer.pt", provenance)
        if not curve:
            raise SystemExit("train: no epoch finished with a finite loss; no checkpoint written")
        write_curves(curve, out)
        (out / "metrics.json").write_text(json.dumps({**best, "run_id": run.info.run_id}, indent=2))
        mlflow.log_metrics({f"best_{k}": v for k, v in best.items() if k != "epoch"})
        mlflow.log_artifact(str(out / "scorer.pt"))
        mlflow.log_artifact(str(out / "curve.png"))
    return best


def save_checkpoint(
    model: ProposalScorer, config: TrainConfig, metrics: dict, path: Path, provenance: dict | None = None
) -> None:
    """Weights with everything a model card needs: configs, best metrics, data and code versions
    (read back by :func:`zonegraph.network.checkpoint.scorer_from`)."""
    torch.save(
        {
            "model": asdict(config.model),
            "state_dict": model.state_dict(),
            "train": asdict(config),
            "metrics": metrics,
            "provenance": provenance or {},
        },
        path,
    )


def write_curves(curve: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(out / "curve.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(curve[0]))
        writer.writeheader()
        writer.writerows(curve)
    epochs = [r["epoch"] for r in curve]
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.5))
    a.plot(epochs, [r["train_loss"] for r in curve], label="train")
    a.plot(epochs, [r["val_loss"] for r in curve], label="validation")
    a.set(xlabel="epoch", ylabel="focal loss")
    a.legend()
    b.plot(epochs, [r["val_rank"] for r in curve], color="C2")
    b.set(xlabel="epoch", ylabel="validation relative GT rank")
    fig.tight_layout()
    fig.savefig(out / "curve.png", dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--device", default=None, help="cpu, cuda or auto (default: params)")
    parser.add_argument("--labels", default=None, help="the labels folder (default: params)")
    parser.add_argument("--graphs", default=None, help="the saved zone graphs folder (default: params)")
    parser.add_argument("--out", default=None, help="the folder for the model (default: params)")
    args = parser.parse_args()
    try:
        config = load_section(TrainConfig, "train", args.params)
    except ConfigError as exc:
        raise SystemExit(str(exc)) from None
    paths = {"labels_dir": args.labels, "graphs_dir": args.graphs, "out_dir": args.out}
    overrides = {k: v for k, v in paths.items() if v}  # the train stage's, from dvc.yaml
    if args.device:
        overrides["device"] = args.device
    best = train(replace(config, **overrides))
    print(f"train: best epoch {best['epoch']}, validation relative GT rank {best['val_rank']:.4f}")


if __name__ == "__main__":
    main()

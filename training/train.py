"""Train the proposal scorer on the ``labels`` stage's shards, tracked in MLflow.

    python -m training.train [--params params.yaml] [--device cpu|cuda|auto] [--fresh]

Designs of the labelled training split are split again by project into training and validation
(``train.val_fraction``). The objective is ``train.loss``: the paper's focal loss per proposal or
a listwise softmax over each state's proposals with the GT as target (``train.neutral_credit``
gives neutral proposals partial credit); ``train.features`` names the proposal features the
scorer reads beside the zones (`zonegraph.sequence.features`). Every epoch logs the
training and validation loss and the validation GT rank on every scale (rank / P, its floor,
the normalised rank, top-1 and top-5; ``docs/evaluation.md``). The checkpoint with the best
validation normalised rank is written to ``models/scorer.pt``, its every figure to
``models/best.json``; ``models/metrics.json`` holds the few keys ``dvc metrics show`` shares with
the stages (`dvc_metrics`); ``models/curve.csv`` and ``models/curve.png`` hold the learning
curves.

A run resumes: every epoch also writes ``models/last.pt`` (weights, optimiser, the shuffle's
random state, the curve so far, the MLflow run), and a run started with the same settings and
labels (the epoch count and device aside, so raising ``epochs`` continues a finished run) goes on
from its last epoch in the same MLflow run; ``--fresh`` starts over. The run logs its
parameters, metrics, the data version (a hash of the label shards), the git commit and the
checkpoint to MLflow: ``MLFLOW_TRACKING_URI`` when set, else ``sqlite:///mlflow.db`` in the
working directory (``mlflow ui --backend-store-uri sqlite:///mlflow.db`` shows it).
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
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.dataset as ds
import torch
from torch.optim.lr_scheduler import ConstantLR, CosineAnnealingLR, LRScheduler
from torch_geometric.loader import DataLoader
from tqdm import tqdm

from training.data import LabelDataset
from training.loss import LOSSES, distilled_weight, focal_loss, listwise_loss
from training.shards import label_shards
from zonegraph.configs import Config, ConfigError, load_section
from zonegraph.data.dataset import project_of, test_ids
from zonegraph.network.checkpoint import fold, read_checkpoint, scorer_from
from zonegraph.network.encoding import Geometry
from zonegraph.network.folded import CodeMemo, FoldedScorer, State
from zonegraph.network.model import HIDDEN, ModelConfig, ProposalScorer
from zonegraph.network.scoring import score_state
from zonegraph.sequence.rankers import GTPlace, gt_place

DEFAULT_TRACKING = "sqlite:///mlflow.db"
LAST = "last.pt"  # the resumable state, beside the best checkpoint
SELECT = "val_normalised"  # the validation metric that picks the best epoch (lower is better)
SCHEDULES = ("constant", "cosine")
RANK_ROWS = 2_000_000  # proposals x zones per numpy call when validation ranks a state
Teachers = tuple[ProposalScorer, ...]


@dataclass(frozen=True)
class TrainConfig(Config):
    """Everything a run depends on (``params.yaml: train``).

    The defaults are the paper's network and objective; ``params.yaml`` sets what ``make run``
    trains (DVC tracks each key there); the shipped checkpoint's own settings are in
    ``zonegraph/network/checkpoints/MODEL_CARD.md``.
    """

    labels_dir: str = "data/labels"
    graphs_dir: str = "data/zonegraphs/graphs"
    out_dir: str = "models"
    fusion: str = "late"
    rounds: int = 3
    use_points: bool = True
    hidden: int = HIDDEN  # width of every layer: a search pays for it at every state
    features: tuple[str, ...] = ()  # proposal features the scorer reads (zonegraph.sequence.features)
    context: bool = False  # the readout also reads the max over the state's proposals' codes
    loss: str = "focal"  # focal (per proposal) or listwise (softmax over a state's proposals)
    neutral_credit: float | None = None  # listwise: None leaves neutrals out, else their target weight
    # listwise: trained checkpoints whose mean log-odds share the target (one, or an ensemble)
    teacher: tuple[str, ...] = ()
    distill: float = 0.5  # the teacher's share of each state's target (with a teacher)
    temperature: float = 2.0  # of the teacher's softmax
    epochs: int = 3
    lr: float = 1e-3
    # constant, or cosine: decayed to 0 over every batch of every epoch, so the run ends at rest
    # instead of wherever its last steps at the full rate left it
    lr_schedule: str = "constant"
    batch_states: int = 8  # states per batch (each with up to max_proposals proposals)
    max_proposals: int | None = 32  # None: every proposal of a state, the set its rank is judged on
    # zone copies (proposals x zones) per training state at most (None: no bound): 256 proposals of
    # a 16,500-zone graph are 4.2M copies, and batches of such states exhausted 24 GB
    max_nodes: int | None = None
    points_per_zone: int = 64
    gamma: float = 0.5
    val_fraction: float = 0.15
    # a seeded share of the training split's projects neither trained nor validated on: designs to
    # evaluate on once the test split is used up (listed in the checkpoint, `eval.heldout`)
    holdout_fraction: float = 0.0
    holdout_seed: int = 0
    max_designs: int | None = None  # a seeded sample of the training designs (quick runs, costly fusions)
    seed: int = 0
    device: str = "cpu"  # cpu, cuda, or auto (cuda when available)
    experiment: str = "zonegraph-scorer"

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any], strict: bool = False) -> TrainConfig:
        """As `Config.from_mapping`, with ``teacher`` one checkpoint's path or a list of them."""
        if isinstance(values.get("teacher"), str):
            values = {**values, "teacher": [values["teacher"]]}
        return super().from_mapping(values, strict)

    @property
    def model(self) -> ModelConfig:
        return ModelConfig(
            fusion=self.fusion,
            rounds=self.rounds,
            use_points=self.use_points,
            hidden=self.hidden,
            features=self.features,
            context=self.context,
        )

    def check(self) -> None:
        """One line naming what is wrong with the settings (SystemExit), before any data is read."""
        if self.loss not in LOSSES:
            raise SystemExit(f"train: unknown loss {self.loss!r} (one of {', '.join(LOSSES)})")
        if self.lr_schedule not in SCHEDULES:
            choices = ", ".join(SCHEDULES)
            raise SystemExit(f"train: unknown lr_schedule {self.lr_schedule!r} (one of {choices})")
        if self.neutral_credit is not None and (self.loss != "listwise" or self.neutral_credit < 0):
            raise SystemExit("train: neutral_credit is a non-negative weight of the listwise loss")
        try:
            self.model.feature_columns()
        except ValueError as exc:
            raise SystemExit(f"train: {exc}") from None
        if self.teacher and (self.loss != "listwise" or not 0.0 <= self.distill <= 1.0):
            raise SystemExit("train: a teacher shares the listwise target: loss listwise, distill in [0, 1]")
        for path in self.teacher:
            if not Path(path).is_file():
                raise SystemExit(f"train: {path}: no teacher checkpoint")
        if not 0.0 <= self.holdout_fraction < 1.0:
            raise SystemExit("train: holdout_fraction is a share of the training projects, in [0, 1)")
        if self.device == "cuda" and not torch.cuda.is_available():
            raise SystemExit("train: --device cuda, but torch finds no CUDA device (use cpu or auto)")


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(name)


def forward(model: ProposalScorer, batch: Any) -> torch.Tensor:
    """Logits (P, 2) for a PyG batch of states, in any fusion."""
    return model(batch)


def objective(
    config: TrainConfig, logits: torch.Tensor, batch: Any, teacher: Teachers = ()
) -> torch.Tensor:
    """The configured loss of one batch (with teachers, their mean logits share the listwise
    target: the mean of each column, so their mean log-odds)."""
    if config.loss == "focal":
        keep = batch.label != 0  # neutrals kept for a listwise loss carry no focal signal
        return focal_loss(logits[keep], batch.y[keep], config.gamma)
    weight = (batch.label == 1).float()
    if config.neutral_credit:
        weight = weight + config.neutral_credit * (batch.label == 0).float()
    if teacher:
        taught = teach(teacher, batch)
        weight = distilled_weight(weight, taught, batch.state, config.distill, config.temperature)
    return listwise_loss(logits, batch.state, weight)


def teach(teachers: Teachers, batch: Any) -> torch.Tensor:
    """(P, 2) the teachers' mean logits: their difference is the mean of the teachers' log-odds,
    an ensemble's score (one teacher: its own logits)."""
    with torch.no_grad():
        return torch.stack([forward(t, batch) for t in teachers]).mean(dim=0)


def load_teacher(config: TrainConfig, device: torch.device) -> tuple[Teachers, list[str]]:
    """The teachers in eval mode and every project one of them trained on (a student has seen
    them too: evaluation leaves them out); none and no projects without a teacher."""
    teachers, projects = [], set()
    for path in config.teacher:
        checkpoint = read_checkpoint(path, str(device))
        teacher = scorer_from(checkpoint, str(device))
        if teacher.config.use_points and not config.use_points:
            raise SystemExit(f"train: {path}: the teacher reads point geometry; train with use_points")
        teachers.append(teacher)
        projects |= set(checkpoint.get("provenance", {}).get("train_projects", []))
    return tuple(teachers), sorted(projects)


def mean_loss(
    model: ProposalScorer,
    loader: DataLoader,
    device: torch.device,
    config: TrainConfig,
    teacher: Teachers = (),
) -> float:
    model.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for batch in loader:
            batch = batch.to(device)
            logits = forward(model, batch)
            total += float(objective(config, logits, batch, teacher)) * len(batch.y)
            count += len(batch.y)
    return total / max(count, 1)


def rank_places(
    model: ProposalScorer, dataset: LabelDataset, device: torch.device, numpy: bool = True
) -> list[GTPlace]:
    """The GT's place in every state of a rank-mode dataset (states with a GT and others).

    On the CPU a late-fusion model is scored folded to numpy, as the guide runs it: a proposal's
    codes are computed only within its reach (`zonegraph.network.folded`), where the PyTorch
    forward computes every zone of every proposal, which on a large graph with thousands of
    proposals costs more than an epoch's training (docs/CHANGELOG.md). The same scores either way
    (tests compare the two forwards); ``numpy`` False keeps the PyTorch forward."""
    late_on_cpu = model.config.fusion == "late" and device.type == "cpu"
    folded = fold(model) if numpy and late_on_cpu else None
    design, graph = "", None  # the states come design by design: one design's graph at a time
    places = []
    for state in dataset.states:
        if int(state.is_gt.sum()) != 1 or len(state.is_gt) < 2:
            continue
        geometry = dataset.geometry[state.design_id]
        if folded is None:
            scores = score_state(
                model,
                geometry,
                torch.from_numpy(state.canvas),
                torch.from_numpy(state.zones),
                torch.from_numpy(state.ops),
                device,
                features=torch.from_numpy(state.features),
            )
        else:
            if graph is None or state.design_id != design:
                design, graph = state.design_id, _numpy_graph(folded, geometry)
            scores = _numpy_scores(folded, *graph, state)
        places.append(gt_place(scores, state.is_gt))
    return places


def _numpy_scores(folded: FoldedScorer, graph: State, codes: np.ndarray | None, state: Any) -> np.ndarray:
    """(P,) one state's scores, in chunks of proposals of at most `RANK_ROWS` zone copies (a
    state of a 16,500-zone graph has had 16,800 proposals: 277 million copies); the state's own
    zone codes are computed once and kept for the later chunks (`CodeMemo`), and the chunks are
    read together (a scorer with a context reads the whole state's)."""
    p, z = state.zones.shape
    size, memo = max(1, RANK_ROWS // max(z, 1)), CodeMemo()
    at = graph.with_canvas(state.canvas)
    ops = state.ops.astype(np.float32)
    chunks = [slice(i, i + size) for i in range(0, p, size)]
    embedded = [folded.embed(at, state.zones[c], ops[c], codes, state.features[c], memo) for c in chunks]
    return folded.read(np.concatenate(embedded))


def _numpy_graph(folded: FoldedScorer, geometry: Geometry) -> tuple[State, np.ndarray | None]:
    """A design's adjacency and zone geometry codes as the folded scorer reads them."""
    inside = geometry.inside.numpy()
    codes = folded.encode_geometry(geometry.points.numpy()) if folded.points else None
    return State.of(inside, np.zeros(len(inside), bool), geometry.edges), codes


def rank_metrics(places: list[GTPlace], prefix: str = "val_") -> dict[str, float]:
    """Means over steps of every scale of the GT's rank (``docs/evaluation.md``)."""
    if not places:
        return {f"{prefix}{k}": float("nan") for k in ("rank", "normalised", "floor", "top1", "top5")}
    return {
        f"{prefix}rank": float(np.mean([p.relative for p in places])),
        f"{prefix}normalised": float(np.mean([p.normalised for p in places])),
        f"{prefix}floor": float(np.mean([p.floor for p in places])),
        f"{prefix}top1": float(np.mean([p.hit(1) for p in places])),
        f"{prefix}top5": float(np.mean([p.hit(5) for p in places])),
    }


def data_version(labels_dir: str | Path) -> str:
    """A short hash of the names and sizes of the label shards read: which labels a run saw."""
    h = hashlib.sha1()
    shards = label_shards(labels_dir)
    for path in sorted(shards.proposals + shards.steps):
        h.update(f"{path.parent.name}/{path.name}:{path.stat().st_size}".encode())
    return h.hexdigest()[:12]


def metric_name(key: str) -> str:
    """The dashboard's groups: ``train_loss`` -> ``loss/train``, ``val_rank`` -> ``val/rank``,
    ``best_val_rank`` -> ``best/val_rank``, ``seconds`` -> ``time/epoch_s``."""
    if key.startswith("best_"):
        return f"best/{key[5:]}"
    if key.endswith("_loss"):
        return f"loss/{key[:-5]}"
    if key.startswith("val_"):
        return f"val/{key[4:]}"
    return {"seconds": "time/epoch_s"}.get(key, key)


def run_name(config: TrainConfig, train_designs: int) -> str:
    """What the dashboard lists: the fusion, the objective, the data and the seed."""
    features = " +features" if config.features else ""
    width = f" hidden{config.hidden}" if config.hidden != HIDDEN else ""
    width += " +context" if config.context else ""
    many = f"x{len(config.teacher)}" if len(config.teacher) > 1 else ""
    taught = f" +teacher{many}{config.distill:g}" if config.teacher else ""
    return f"{config.fusion} {config.loss}{features}{width}{taught} {train_designs} designs seed{config.seed}"


def log_labels(labels_dir: str | Path, version: str) -> None:
    """The label shards as the run's training dataset: one row per labelled step."""
    import mlflow

    steps = label_shards(labels_dir).steps
    if not steps:
        return
    table = ds.dataset(steps, format="parquet").to_table(
        columns=["design_id", "split", "step", "proposals", "captured"]
    )
    dataset = mlflow.data.from_pandas(
        table.to_pandas(), source=str(Path(labels_dir).resolve()), name=f"labels-{version}"
    )
    mlflow.log_input(dataset, context="training")


def log_scorer(path: Path) -> None:
    """The best checkpoint as an MLflow PyTorch model with the signature of a batch of states
    (``zonegraph.network.encoding.StateData``: S surface samples per zone), beside the raw ``.pt``
    that the ``net`` guide loads."""
    import mlflow
    from mlflow.models import ModelSignature
    from mlflow.types.schema import Schema, TensorSpec

    from zonegraph.network.checkpoint import load_scorer

    inputs = Schema(
        [
            TensorSpec(np.dtype(np.float32), (-1, 4), "x"),
            TensorSpec(np.dtype(np.int64), (2, -1), "edge_index"),
            TensorSpec(np.dtype(np.int64), (-1,), "proposal"),
            TensorSpec(np.dtype(np.int64), (-1,), "zone_of"),
            TensorSpec(np.dtype(np.float32), (-1, 6, -1), "points"),
        ]
    )
    outputs = Schema([TensorSpec(np.dtype(np.float32), (-1, 2), "logits")])
    mlflow.pytorch.log_model(
        load_scorer(path),
        name="scorer",
        signature=ModelSignature(inputs=inputs, outputs=outputs),
        pip_requirements=["torch", "torch-geometric", "zonegraph"],
        serialization_format="pickle",  # pt2 traces forward() on tensors; it takes a PyG batch
    )


def git_commit() -> str:
    """The commit of the training code, wherever training runs from (a run in a folder outside
    the repository recorded ``unknown``); ``unknown`` outside a git checkout."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True, cwd=here
        )
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def labelled_designs(labels_dir: str | Path, split: str) -> list[str]:
    """The designs of one split that have label shards (those training reads)."""
    shards = label_shards(labels_dir).steps
    steps = ds.dataset(shards, format="parquet").to_table(columns=["design_id", "split"])
    chosen = steps.filter(ds.field("split") == split).column("design_id").to_pylist()
    return sorted(set(chosen))


@dataclass(frozen=True)
class DesignSplit:
    """The labelled training-split designs of one run, by project: trained on, validated on (the
    best epoch's pick) and held out of both (for evaluation)."""

    train: list[str]
    val: list[str]
    holdout: list[str]


def split_designs(config: TrainConfig) -> DesignSplit:
    """The labelled training-split designs split by project: the holdout first, then validation
    from the rest."""
    ids = labelled_designs(config.labels_dir, "train")
    held = {i for i in ids if held_out_project(project_of(i), config.holdout_seed, config.holdout_fraction)}
    rest = [i for i in ids if i not in held]
    val = test_ids(rest, config.seed, config.val_fraction)
    return DesignSplit([i for i in rest if i not in val], sorted(val), sorted(held))


def held_out_project(project: str, seed: int, fraction: float) -> bool:
    """Whether ``project`` is in the holdout drawn with ``seed``: a seeded hash of its name, so a
    project is held out or not whatever labels it is read from, and a teacher and its student
    trained on different label sets hold out the same projects. SHA-256, since a CRC is linear:
    two seeds' CRCs of a name differ by a constant, so their draws were not independent (two 15%
    holdouts shared no project)."""
    digest = hashlib.sha256(f"{seed}/{project}".encode()).digest()
    return int.from_bytes(digest[:8], "big") < fraction * 2**64


def resume_key(config: TrainConfig, version: str) -> dict[str, Any]:
    """What a resumed run must share with the one it continues: every setting but the device,
    and the labels; the epoch count too under a schedule, which it shapes (a constant-rate run
    can be given more epochs and go on)."""
    free = ("epochs", "device") if config.lr_schedule == "constant" else ("device",)
    settings = {k: v for k, v in asdict(config).items() if k not in free}
    lists = {"features": list(config.features), "teacher": list(config.teacher)}
    return {**settings, **lists, "data_version": version}


def lr_scheduler(optimiser: torch.optim.Optimizer, config: TrainConfig, batches: int) -> LRScheduler:
    """The rate per optimiser step: constant, or a cosine from ``lr`` to 0 over ``epochs`` x
    ``batches`` steps."""
    if config.lr_schedule == "cosine":
        return CosineAnnealingLR(optimiser, T_max=max(config.epochs * batches, 1))
    return ConstantLR(optimiser, factor=1.0, total_iters=0)


def load_last(path: Path, key: dict[str, Any], epochs: int) -> dict[str, Any] | None:
    """The resumable state at ``path`` when it continues a run of these settings, else None."""
    if not path.is_file():
        return None
    last: dict[str, Any] = torch.load(path, map_location="cpu", weights_only=True)
    if last.get("key") != key or last["epoch"] >= epochs:
        return None
    return last


def datasets(config: TrainConfig, train_ids: list[str], val_ids: list[str]) -> dict[str, LabelDataset]:
    common = dict(points_per_zone=config.points_per_zone, seed=config.seed)
    neutrals = config.loss == "listwise" and config.neutral_credit is not None
    args = (config.labels_dir, config.graphs_dir)
    train = dict(neutrals=neutrals, max_nodes=config.max_nodes, **common)
    sets = {
        "train": LabelDataset(*args, train_ids, "train", config.max_proposals, **train),
        "val": LabelDataset(*args, val_ids, "train", config.max_proposals, **train),
        "rank": LabelDataset(*args, val_ids, "rank", **common),
    }
    if config.features and not sets["train"].has_features:
        raise SystemExit(
            f"train: {config.labels_dir}: the label shards have no proposal features "
            "(written before them): relabel, or train with features: []"
        )
    return sets


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


def train(config: TrainConfig, fresh: bool = False) -> dict[str, Any]:
    """One training run, or the rest of an interrupted one; returns the best epoch's metrics
    (also in ``out_dir/best.json``)."""
    import mlflow  # a heavy import: only when training

    config.check()
    torch.manual_seed(config.seed)
    np.random.seed(config.seed)
    device = pick_device(config.device)
    split = split_designs(config)
    train_ids, val_ids = split.train, split.val
    if config.max_designs is not None and config.max_designs < len(train_ids):
        keep = np.random.default_rng(config.seed).choice(len(train_ids), config.max_designs, replace=False)
        train_ids = [train_ids[i] for i in sorted(keep)]
    sets = datasets(config, train_ids, val_ids)
    generator = torch.Generator().manual_seed(config.seed)
    train_loader = DataLoader(
        sets["train"], batch_size=config.batch_states, shuffle=True, generator=generator
    )
    val_loader = DataLoader(sets["val"], batch_size=config.batch_states)
    model = ProposalScorer(config.model).to(device)
    teacher, taught = load_teacher(config, device)
    holdout = sorted({project_of(d) for d in split.holdout})
    if overlap := set(taught) & set(holdout):
        raise SystemExit(
            f"train: {', '.join(config.teacher)}: the teacher trained on {len(overlap)} of the held-out "
            "projects: train it with the same holdout_fraction and holdout_seed"
        )
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    scheduler = lr_scheduler(optimiser, config, len(train_loader))
    out = Path(config.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    version = data_version(config.labels_dir)
    key = resume_key(config, version)
    last = None if fresh else load_last(out / LAST, key, config.epochs)
    curve: list[dict[str, Any]] = []
    best: dict[str, Any] = {SELECT: float("inf")}
    first = 1
    if last is not None:
        model.load_state_dict(last["model"])
        optimiser.load_state_dict(last["optimiser"])
        scheduler.load_state_dict(last["scheduler"])
        generator.set_state(last["generator"])
        torch.set_rng_state(last["torch_rng"])
        curve, best, first = last["curve"], last["best"], last["epoch"] + 1
        print(f"train: resuming at epoch {first} of {config.epochs}, MLflow run {last['run_id']}", flush=True)
    mlflow.set_tracking_uri(os.environ.get("MLFLOW_TRACKING_URI", DEFAULT_TRACKING))
    experiment = mlflow.set_experiment(config.experiment)
    fail_dead_runs(experiment.experiment_id)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminated)  # a killed training's run ends FAILED, not RUNNING
    tags = {"zonegraph.host": socket.gethostname(), "zonegraph.pid": str(os.getpid())}
    name = None if last else run_name(config, len(train_ids))
    with mlflow.start_run(run_id=last["run_id"] if last else None, run_name=name, tags=tags) as run:
        sizes = {
            "train_designs": len(train_ids),
            "val_designs": len(val_ids),
            "holdout_designs": len(split.holdout),
            "train_states": len(sets["train"]),
        }
        tags = {"data_version": version, "git_commit": git_commit()}
        if last is None:
            mlflow.log_params({**asdict(config), **sizes, "device": str(device)})
            mlflow.set_tags(tags)
            log_labels(config.labels_dir, version)
        else:
            resumed = {f"resumed_at_epoch_{first}": str(device), "git_commit_resumed": tags["git_commit"]}
            mlflow.set_tags(resumed)
        seen = sorted({project_of(d) for d in [*train_ids, *val_ids]} | set(taught))  # evaluation skips these
        provenance = {**sizes, **tags, "run_id": run.info.run_id, "train_projects": seen}
        if holdout:
            provenance["holdout_projects"] = holdout
        for epoch in range(first, config.epochs + 1):
            t0 = time.perf_counter()
            model.train()
            losses = []
            desc = f"train: epoch {epoch}/{config.epochs}"
            for batch in tqdm(train_loader, desc=desc, unit="batch", mininterval=5):
                batch = batch.to(device)
                if len(batch.y) < 2:  # BatchNorm needs two examples
                    continue
                loss = objective(config, forward(model, batch), batch, teacher)
                optimiser.zero_grad()
                loss.backward()
                optimiser.step()
                scheduler.step()
                losses.append(loss.item())
            places = rank_places(model, sets["rank"], device)
            row = {
                "epoch": epoch,
                "train_loss": float(np.mean(losses)) if losses else float("nan"),
                "val_loss": mean_loss(model, val_loader, device, config, teacher),
                **rank_metrics(places),
                "seconds": time.perf_counter() - t0,
            }
            if not np.isfinite(row["train_loss"]):
                print(f"epoch {epoch}: the training loss is not finite; stopping", flush=True)
                break
            curve.append(row)
            mlflow.log_metrics({metric_name(k): v for k, v in row.items() if k != "epoch"}, step=epoch)
            print(
                f"epoch {epoch}: " + ", ".join(f"{k} {v:.4f}" for k, v in row.items() if k != "epoch"),
                flush=True,
            )
            if row[SELECT] <= best[SELECT] or not np.isfinite(best[SELECT]):
                best = {**row, "val_steps": len(places)}
                save_checkpoint(model, config, best, out / "scorer.pt", provenance)
            save_last(
                out / LAST, model, optimiser, scheduler, generator, key, epoch, curve, best, run.info.run_id
            )
        if not curve:
            raise SystemExit("train: no epoch finished with a finite loss; no checkpoint written")
        write_curves(curve, out)
        (out / "best.json").write_text(json.dumps({**best, "run_id": run.info.run_id}, indent=2))
        (out / "metrics.json").write_text(json.dumps(dvc_metrics(best, curve, len(train_ids)), indent=2))
        mlflow.log_metrics({metric_name(f"best_{k}"): v for k, v in best.items() if k != "epoch"})
        mlflow.log_artifact(str(out / "scorer.pt"))
        log_scorer(out / "scorer.pt")
        mlflow.log_artifact(str(out / "curve.png"))
    return best


def save_last(
    path: Path,
    model: ProposalScorer,
    optimiser: torch.optim.Optimizer,
    scheduler: LRScheduler,
    generator: torch.Generator,
    key: dict[str, Any],
    epoch: int,
    curve: list[dict[str, Any]],
    best: dict[str, Any],
    run_id: str,
) -> None:
    """Everything the next epoch needs (the optimiser's, the rate schedule's and the data order's
    states among it), written atomically (a kill mid-write keeps the last one)."""
    state = {
        "key": key,
        "epoch": epoch,
        "model": model.state_dict(),
        "optimiser": optimiser.state_dict(),
        "scheduler": scheduler.state_dict(),
        "generator": generator.get_state(),
        "torch_rng": torch.get_rng_state(),
        "curve": curve,
        "best": best,
        "run_id": run_id,
    }
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)


def save_checkpoint(
    model: ProposalScorer, config: TrainConfig, metrics: dict, path: Path, provenance: dict | None = None
) -> None:
    """Weights with everything a model card needs: configs, best metrics, data and code versions
    (read back by `zonegraph.network.checkpoint.scorer_from`)."""
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


def dvc_metrics(best: dict[str, Any], curve: list[dict], designs: int) -> dict[str, Any]:
    """The training's row of ``dvc metrics show``: only keys the stages' files also use
    (``eval/dvc_metrics.py``: designs, seconds, rank), so the unfiltered table gains no column;
    ``seconds`` is the median epoch, ``rank`` the best epoch's validation rank / P."""
    seconds = sorted(r["seconds"] for r in curve)
    mid = len(seconds) // 2
    median = seconds[mid] if len(seconds) % 2 else (seconds[mid - 1] + seconds[mid]) / 2
    rank = best["val_rank"] if np.isfinite(best["val_rank"]) else None
    return {"designs": designs, "seconds": round(median, 3), "rank": None if rank is None else round(rank, 3)}


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
    a.set(xlabel="epoch", ylabel="loss")
    a.legend()
    b.plot(epochs, [r["val_rank"] for r in curve], color="C2", label="rank / P")
    b.plot(epochs, [r["val_floor"] for r in curve], color="C2", linestyle=":", label="floor of rank / P")
    b.plot(epochs, [r["val_normalised"] for r in curve], color="C1", label="normalised rank")
    b.axhline(0.5, color="C3", linestyle="--", label="random (normalised)")
    b.set(xlabel="epoch", ylabel="validation GT rank")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "curve.png", dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument(
        "--device",
        default=None,
        choices=["cpu", "cuda", "auto"],
        help="auto: cuda when available (default: params)",
    )
    parser.add_argument("--fresh", action="store_true", help="start over instead of resuming models/last.pt")
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
    best = train(replace(config, **overrides), fresh=args.fresh)
    print(
        f"train: best epoch {best['epoch']}: validation normalised GT rank {best['val_normalised']:.4f}, "
        f"rank / P {best['val_rank']:.4f} (floor {best['val_floor']:.4f}), top-1 {best['val_top1']:.3f}"
    )


if __name__ == "__main__":
    main()

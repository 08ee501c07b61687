"""Loading a trained scorer, and the one zonegraph ships.

A checkpoint holds the model's configuration beside its weights (``training.train`` writes them,
with the training configuration, metrics and provenance its model card reads), so loading needs
nothing but the file. The shipped checkpoint is package data, beside its numpy fold
(`fold_checkpoint`, ``scorer.npz``) which ``--guide net`` loads, so the guide works
without a checkout and without torch.
"""

from __future__ import annotations

from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from zonegraph.network.folded import SLOPE, Affine, FoldedScorer
from zonegraph.network.model import ModelConfig, PointNet, ProposalScorer

SHIPPED = Path(__file__).resolve().parent / "checkpoints" / "scorer.pt"


def read_checkpoint(path: str | Path, device: str = "cpu") -> dict[str, Any]:
    """A checkpoint's contents (tensors only: ``weights_only``, so loading runs no pickled code)."""
    checkpoint: dict[str, Any] = torch.load(path, map_location=device, weights_only=True)
    return checkpoint


def load_scorer(path: str | Path, device: str = "cpu") -> ProposalScorer:
    """A trained scorer in eval mode."""
    return scorer_from(read_checkpoint(path, device), device)


def scorer_from(checkpoint: dict[str, Any], device: str = "cpu") -> ProposalScorer:
    """The scorer a loaded checkpoint holds, in eval mode."""
    model = ProposalScorer(ModelConfig.from_mapping(checkpoint["model"], strict=True))
    model.load_state_dict(checkpoint["state_dict"])
    return model.eval().to(device)


def guide_settings(checkpoint: dict[str, Any]) -> tuple[int | None, dict[str, Any]]:
    """The surface samples per zone it trained with, and the search defaults stored beside its
    weights (``top_m``, ``blend``)."""
    samples = checkpoint.get("train", {}).get("points_per_zone")
    return None if samples is None else int(samples), dict(checkpoint.get("search", {}))


def fold_checkpoint(checkpoint: dict[str, Any]) -> FoldedScorer:
    """A late-fusion checkpoint's scorer as numpy arrays, with its `guide_settings`, the projects
    it trained on and those it held out."""
    samples, search = guide_settings(checkpoint)
    provenance = checkpoint.get("provenance", {})
    return replace(
        fold(scorer_from(checkpoint)),
        points_per_zone=samples,
        search=search,
        train_projects=tuple(provenance.get("train_projects", ())),
        holdout_projects=tuple(provenance.get("holdout_projects", ())),
    )


def fold(model: ProposalScorer) -> FoldedScorer:
    """The model in eval mode as numpy arrays (`zonegraph.network.folded`): every BatchNorm
    folded into the Linear or 1x1 convolution beside it. Late fusion only."""
    if model.config.fusion != "late":
        raise ValueError(f"only late fusion folds to numpy (this model: {model.config.fusion})")
    encoder = model.encoder
    return FoldedScorer(
        config={**asdict(model.config), "features": list(model.config.features)},
        columns=tuple(model.columns),
        zone_in=_chain(model.zone_in),
        rounds=tuple(_chain(layer.mlp) for layer in model.rounds),  # type: ignore[arg-type]
        readout=_chain(model.readout),
        points=_chain(encoder.points) if isinstance(encoder, PointNet) else (),
        head=_chain(encoder.head) if isinstance(encoder, PointNet) else (),
        features=_chain(model.features_in) if model.columns else (),
    )


def _leaves(module: nn.Module) -> list[nn.Module]:
    if isinstance(module, nn.Sequential):
        return [leaf for child in module for leaf in _leaves(child)]
    return [module]


def _bn(norm: nn.BatchNorm1d) -> tuple[np.ndarray, np.ndarray]:
    """A BatchNorm in eval mode as ``x * scale + shift``."""
    assert norm.running_var is not None and norm.running_mean is not None
    scale = (norm.weight / torch.sqrt(norm.running_var + norm.eps)).detach().double().numpy()
    shift = norm.bias.detach().double().numpy() - norm.running_mean.double().numpy() * scale
    return scale, shift


@torch.no_grad()
def _chain(module: nn.Module) -> tuple[Affine, ...]:
    """A Sequential of Linear/Conv1d, BatchNorm1d and LeakyReLU layers as folded affine maps."""
    layers: list[Affine] = []
    before: tuple[np.ndarray, np.ndarray] | None = None  # a BatchNorm in front of the first Linear
    for leaf in _leaves(module):
        if isinstance(leaf, (nn.Linear, nn.Conv1d)):
            weight = leaf.weight.detach().double().numpy().reshape(leaf.weight.shape[0], -1).T
            assert leaf.bias is not None  # every layer of the scorer has one
            bias = leaf.bias.detach().double().numpy()
            if before is not None:
                bias, weight = bias + before[1] @ weight, weight * before[0][:, None]
                before = None
            layers.append(Affine(weight, bias, False))
        elif isinstance(leaf, nn.BatchNorm1d) and not layers:
            before = _bn(leaf)
        elif isinstance(leaf, nn.BatchNorm1d):
            scale, shift = _bn(leaf)
            last = layers[-1]
            layers[-1] = Affine(last.weight * scale, last.bias * scale + shift, False)
        elif isinstance(leaf, nn.LeakyReLU) and leaf.negative_slope == SLOPE:
            layers[-1] = Affine(layers[-1].weight, layers[-1].bias, True)
        else:
            raise ValueError(f"cannot fold {type(leaf).__name__} into numpy")
    return tuple(Affine(a.weight.astype(np.float32), a.bias.astype(np.float32), a.activation) for a in layers)

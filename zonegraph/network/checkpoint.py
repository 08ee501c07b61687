"""Loading a trained scorer, and the one zonegraph ships.

A checkpoint holds the model's configuration beside its weights (``training.train`` writes them,
with the training configuration, metrics and provenance its model card reads), so loading needs
nothing but the file. The shipped checkpoint is package data: ``--guide net`` works after
``pip install 'zonegraph[train]'``, without a checkout.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import torch

from zonegraph.network.model import ModelConfig, ProposalScorer

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

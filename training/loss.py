"""Focal loss (Lin et al. 2017) on two-class logits, as the paper trains the scorer."""

from __future__ import annotations

import torch
from torch import Tensor


def focal_loss(logits: Tensor, target: Tensor, gamma: float = 0.5) -> Tensor:
    """Mean of -(1 - p_t)^gamma log p_t over the examples (gamma 0: cross-entropy).

    Only positives and negatives reach it: neutral proposals carry no training signal.

    Shapes:
        logits: (P, 2); target: (P,) int64 in {0, 1}.
    """
    log_p = torch.log_softmax(logits, dim=1).gather(1, target[:, None]).squeeze(1)
    # (1 - p)^gamma has an infinite slope at p = 1 for gamma < 1: a confident, correct example
    # (p rounds to 1 in float32) turned every gradient into NaN. Below 1e-12 the factor is flat.
    modulating = (-torch.expm1(log_p)).clamp_min(1e-12) ** gamma
    return (-modulating * log_p).mean()

"""The scorer's objectives: focal loss per proposal (the paper's), or a listwise softmax per state.

Both read the same two logits per proposal, and the network guide ranks by P(positive) =
softmax(logits)[1], which is monotonic in the log-odds ``logits[1] - logits[0]``; the listwise
loss is a softmax of those log-odds over each state's proposals, so either objective trains the
one score the search sorts by. The focal loss judges each proposal alone, while the metric the
guide is judged by (where the GT lands among a state's proposals) is a property of the whole
list; the listwise loss trains that directly.

A trained scorer can also teach another (knowledge distillation, Hinton et al. 2015): the listwise
target of a state then mixes the GT with the teacher's softmax over the same proposals
(`distilled_weight`), so a narrower student, cheaper in search, learns the teacher's whole
ordering and not only its first place, from fewer designs than the teacher saw.
"""

from __future__ import annotations

import torch
from torch import Tensor
from torch_geometric.utils import scatter

LOSSES = ("focal", "listwise")


def state_softmax(score: Tensor, state: Tensor) -> Tensor:
    """Each proposal's share of its state's softmax over ``score``.

    Shapes:
        score: (P,); state: (P,) int64, the state of each proposal (0..S-1); returns (P,).
    """
    states = int(state.max()) + 1 if len(state) else 0
    top = scatter(score, state, dim=0, dim_size=states, reduce="max")
    exp = (score - top[state]).exp()
    return exp / scatter(exp, state, dim=0, dim_size=states, reduce="sum")[state]


def distilled_weight(
    weight: Tensor, teacher: Tensor, state: Tensor, share: float, temperature: float
) -> Tensor:
    """A listwise target that gives the teacher ``share`` of each state: ``(1 - share)`` times the
    GT's normalised ``weight`` plus ``share`` times the teacher's softmax of its log-odds at
    ``temperature`` (above 1 it shows more of the teacher's order below its first choice).

    Shapes:
        weight: (P,) >= 0; teacher: (P, 2) the teacher's logits; state: (P,) int64; returns (P,).
    """
    states = int(state.max()) + 1 if len(state) else 0
    total = scatter(weight, state, dim=0, dim_size=states, reduce="sum")
    truth = weight / total[state].clamp_min(1e-12)
    taught = state_softmax((teacher[:, 1] - teacher[:, 0]) / temperature, state)
    return (1.0 - share) * truth + share * taught


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


def listwise_loss(logits: Tensor, state: Tensor, weight: Tensor) -> Tensor:
    """Cross-entropy between each state's softmax over its proposals and a target distribution.

    The target of a state is ``weight`` normalised over its proposals: the GT alone (weight 1,
    the others 0) is ListNet's top-one loss with the GT as the answer; neutral proposals given a
    partial weight share the target with it. States whose weights sum to 0 are left out.

    Shapes:
        logits: (P, 2); state: (P,) int64, the state of each proposal (0..S-1); weight: (P,) >= 0.
    """
    score = logits[:, 1] - logits[:, 0]
    states = int(state.max()) + 1 if len(state) else 0
    top = scatter(score.detach(), state, dim=0, dim_size=states, reduce="max")
    log_z = scatter((score - top[state]).exp(), state, dim=0, dim_size=states, reduce="sum").log() + top
    log_p = score - log_z[state]
    total = scatter(weight, state, dim=0, dim_size=states, reduce="sum")
    target = weight / total[state].clamp_min(1e-12)
    per_state = -scatter(target * log_p, state, dim=0, dim_size=states, reduce="sum")
    used = total > 0
    return per_state[used].mean() if bool(used.any()) else score.sum() * 0.0

"""The network guide at inference: the proposal scorer, its input encoding, checkpoint loading,
the ranker and the shipped checkpoint (paper sec. 4.2).

Layout: everything a user of ``--guide net`` needs lives here, inside the one installed
package. The shipped weights run folded to numpy (`zonegraph.network.folded`), so the core
install runs the guide; ``pip install 'zonegraph[train]'`` adds PyTorch checkpoints. The
training loop, the loss, the label dataset and the model card writer stay in the checkout's
``training/`` folder, run with ``python -m`` like the pipeline's stages. This is the one layer
that imports torch and torch_geometric (``folded`` and ``ranker`` do not); nothing outside it
imports it eagerly (`zonegraph.plugins` names the ranker by reference), and this
``__init__`` imports its names on first use, so ``import zonegraph.network`` alone loads no
torch either.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "ModelConfig": "zonegraph.network.model",
    "ProposalScorer": "zonegraph.network.model",
    "Geometry": "zonegraph.network.encoding",
    "StateData": "zonegraph.network.encoding",
    "geometry_of": "zonegraph.network.encoding",
    "state_data": "zonegraph.network.encoding",
    "score_state": "zonegraph.network.scoring",
    "SHIPPED": "zonegraph.network.checkpoint",
    "load_scorer": "zonegraph.network.checkpoint",
    "scorer_from": "zonegraph.network.checkpoint",
    "NetworkRanker": "zonegraph.network.ranker",
    "FoldedScorer": "zonegraph.network.folded",
    "SHIPPED_FOLDED": "zonegraph.network.folded",
    "fold": "zonegraph.network.checkpoint",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.network.checkpoint import SHIPPED, fold, load_scorer, scorer_from
    from zonegraph.network.encoding import Geometry, StateData, geometry_of, state_data
    from zonegraph.network.folded import SHIPPED_FOLDED, FoldedScorer
    from zonegraph.network.model import ModelConfig, ProposalScorer
    from zonegraph.network.ranker import NetworkRanker
    from zonegraph.network.scoring import score_state


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)

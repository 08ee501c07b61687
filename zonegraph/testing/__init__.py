"""Test support shipped with the package (as ``torch_geometric.testing`` is with PyG).

What the tests and the benchmarks share, defined once:

- `zonegraph.testing.locations`: where the real samples and the corpus are
  (``SAMPLES``, ``CORPUS``, `sample_paths`), looked for beside the checkout;
- ``requires_samples`` / ``requires_corpus``: pytest skip markers, from
  `zonegraph.testing.markers`, loaded on first use: pytest is in the ``test`` extra, and this
  package must stay importable without it (the benchmarks read the locations);
- `gt_rows`: the ground-truth stage's rows of in-memory ``GTStep`` objects;
- `zonegraph.testing.fuzz`: the fuzz harness (mutated real inputs through the CLI, each run
  classified), shared by ``bench/fuzz_bench.py`` and the fuzz tests (needs hypothesis);
- `zonegraph.testing.corpus` (real corpus designs replayed),
  `zonegraph.testing.fusion_json` (hand-written design JSON),
  `zonegraph.testing.mlflow_server` (a real tracking server) and
  `zonegraph.testing.stages` (a pipeline stage in a fresh interpreter).

Nothing below `zonegraph.testing` imports it: it is a top layer.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports
from zonegraph.testing.locations import (
    CORPUS,
    CORPUS_SKIP_REASON,
    SAMPLES,
    SKIP_REASON,
    corpus_root,
    sample_paths,
    samples_root,
    shared_root,
)

_LAZY = {
    "requires_samples": "zonegraph.testing.markers",
    "requires_corpus": "zonegraph.testing.markers",
    "gt_rows": "zonegraph.testing.ground_truth",
}

__all__ = [
    "CORPUS",
    "CORPUS_SKIP_REASON",
    "SAMPLES",
    "SKIP_REASON",
    "corpus_root",
    "gt_rows",
    "requires_corpus",
    "requires_samples",
    "sample_paths",
    "samples_root",
    "shared_root",
]

if TYPE_CHECKING:
    from zonegraph.testing.ground_truth import gt_rows
    from zonegraph.testing.markers import requires_corpus, requires_samples


__getattr__, __dir__ = lazy_exports(__name__, _LAZY, __all__)

"""Shared fixtures: the real Fusion 360 Gallery samples and the build123d script corpus from ../shared
(skipped when absent)."""

from __future__ import annotations

from pathlib import Path

import pytest

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "fusion360_samples"
SKIP_REASON = f"real Fusion 360 Gallery samples not found at {SAMPLES} (clone with ../shared beside the repo)"


def sample_paths() -> list[Path]:
    return sorted(SAMPLES.glob("*.json")) if SAMPLES.is_dir() else []


@pytest.fixture(scope="session")
def samples_dir() -> Path:
    if not SAMPLES.is_dir():
        pytest.skip(SKIP_REASON)
    return SAMPLES


requires_samples = pytest.mark.skipif(not SAMPLES.is_dir(), reason=SKIP_REASON)

CORPUS = SAMPLES.parent / "fusion360_b123d"
CORPUS_SKIP_REASON = f"build123d script corpus not found at {CORPUS} (clone with ../shared beside the repo)"
requires_corpus = pytest.mark.skipif(not CORPUS.is_dir(), reason=CORPUS_SKIP_REASON)


def gt_rows(steps, level: int = 1) -> list[dict]:
    """The ground-truth stage's per-step rows (what the labels stage reads) of ``GTStep`` objects."""
    import numpy as np

    return [
        {
            "operation": s.operation,
            "gt_zones": np.flatnonzero(s.zones).tolist(),
            "captured": s.captured[level],
            "reason": s.reason,
        }
        for s in steps
    ]

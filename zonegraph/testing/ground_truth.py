"""The ground-truth stage's per-step rows, built in memory for tests that skip the stage."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from zonegraph.sequence.ground_truth import GTStep


def gt_rows(steps: Iterable[GTStep], level: int = 1) -> list[dict[str, Any]]:
    """The rows the labels stage reads, one per ``GTStep``: its operation, the indices of its
    zones, whether proposals of ``level`` capture it, and why not."""
    return [
        {
            "operation": s.operation,
            "gt_zones": np.flatnonzero(s.zones).tolist(),
            "captured": s.captured[level],
            "reason": s.reason,
        }
        for s in steps
    ]

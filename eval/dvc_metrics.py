"""The shape of a stage's DVC metrics: the same few top-level keys in every file.

``dvc metrics show`` draws one column per key of every metrics file, so a stage that writes its
own flat or nested keys widens every row by a column that is a dash for all the other stages
(before this, 82 columns). Each stage's file in ``data/metrics/`` (one per guide for ``evaluate``
and ``reconstruct``) therefore holds only `SHARED`, plus a stage's one or two headline
figures from `HEADLINE`; its breakdowns (by status, by folder, by coverage category, the
runner's retries) go to ``data/details/<stage>.json``, declared in ``dvc.yaml`` as a plain
output, not as a metric, and outside ``data/metrics`` so that ``dvc metrics show data/metrics``
shows the metrics alone. ``docs/pipeline.md`` lists which key went where.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from pathlib import Path

SHARED = ("designs", "ok", "failed", "seconds")  # seconds: the median per design
HEADLINE = ("exact", "iou", "rank")  # in [0, 1], per guide; each more key is a column of every row
DIGITS = 3  # three decimals keep a column 5 characters wide; the details keep every digit


def rounded(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else round(float(value), DIGITS)


def median(values: Iterable[float | None]) -> float | None:
    finite = sorted(float(v) for v in values if v is not None and math.isfinite(float(v)))
    if not finite:
        return None
    mid = len(finite) // 2
    return finite[mid] if len(finite) % 2 else (finite[mid - 1] + finite[mid]) / 2


def headline(designs: int, ok: int, seconds: Iterable[float | None], **figures: float | None) -> dict:
    """The shared keys of a metrics file, and the ``figures`` (names of `HEADLINE`)."""
    unknown = set(figures) - set(HEADLINE)
    if unknown:
        raise ValueError(f"not headline metrics: {sorted(unknown)} (known: {', '.join(HEADLINE)})")
    return {
        "designs": int(designs),
        "ok": int(ok),
        "failed": int(designs) - int(ok),
        "seconds": rounded(median(seconds)),
        **{k: rounded(v) for k, v in figures.items()},
    }


def write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2) + "\n")


def write_guides(folder: Path, by_guide: dict[str, dict]) -> None:
    """One metrics file per guide (``net:shipped`` -> ``net_shipped.json``): a guide is a row of
    ``dvc metrics show``, not a column per figure; files of guides no longer run are removed."""
    folder.mkdir(parents=True, exist_ok=True)
    names = {guide.replace(":", "_"): m for guide, m in by_guide.items()}
    for stale in folder.glob("*.json"):
        if stale.stem not in names:
            stale.unlink()
    for name, metrics in names.items():
        write_json(folder / f"{name}.json", metrics)

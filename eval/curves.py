"""IoU vs search time: each guide's anytime search traces, averaged on a log time grid.

Every ``infer`` result carries its anytime trace, ``(search seconds, best zone IoU so far)`` over
both zone graphs, zone-graph build excluded (as in the paper's figure). A design's curve is a step
function: at time t, the best IoU found by t; after the search ends it stays at the final value.
The final value is replaced by the rebuilt program's B-rep IoU, so a curve ends where the real
geometry does (a zone-exact program that rebuilds wrongly does not count as exact). The exact
rate at t is the share of designs whose B-rep-exact program was found by t.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd


def time_grid(budget_s: float, points: int = 40, start_s: float = 1e-3) -> np.ndarray:
    """Log-spaced times from ``start_s`` to the budget."""
    return np.geomspace(start_s, budget_s, points)


def iou_at(trace: Sequence[Sequence[float]], times: np.ndarray, final_iou: float | None = None) -> np.ndarray:
    """The best IoU found by each time of ``times`` (0 before the first point of the trace).

    ``final_iou`` (the B-rep IoU of the returned program) replaces the trace's last value from the
    moment that program was found."""
    if len(trace) == 0:
        return np.zeros(len(times))
    t = np.asarray([p[0] for p in trace], float)
    iou = np.asarray([p[1] for p in trace], float)
    if final_iou is not None:
        iou[-1] = final_iou
    found = np.searchsorted(t, times, side="right") - 1
    return np.where(found >= 0, iou[np.clip(found, 0, None)], 0.0)


def curves(results: pd.DataFrame, times: np.ndarray) -> pd.DataFrame:
    """Mean IoU and exact rate per guide at each time.

    ``results``: one row per (guide, design) with ``trace``, ``iou_brep``, ``exact`` and
    ``time_to_best_s``; a failed search (no trace) counts as IoU 0, never exact."""
    rows = []
    for guide, group in results.groupby("guide", sort=False):
        ious = np.stack(
            [
                iou_at(_trace(r.trace), times, float(r.iou_brep) if _trace(r.trace) else None)
                for r in group.itertuples()
            ]
        )
        exact_at = np.asarray(
            [float(r.time_to_best_s) if bool(r.exact) else np.inf for r in group.itertuples()]
        )
        for i, t in enumerate(times):
            rows.append(
                {
                    "guide": guide,
                    "seconds": float(t),
                    "mean_iou": float(ious[:, i].mean()),
                    "exact_rate": float((exact_at <= t).mean()),
                    "designs": len(group),
                }
            )
    return pd.DataFrame(rows)


def at_time(curve: pd.DataFrame, seconds: float) -> pd.Series:
    """The row of one guide's curve (`curves`) whose time is nearest ``seconds``: how the
    report and its figures read a curve at a mark."""
    return curve.iloc[int(np.argmin(np.abs(curve["seconds"].to_numpy() - seconds)))]


def _trace(value: object) -> list:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return []
    return [list(p) for p in value]  # type: ignore[union-attr]


def plot_curves(table: pd.DataFrame, path: Path, title: str = "") -> Path:
    """Mean IoU and exact rate against log search time, one line per guide."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.8))
    for guide, group in table.groupby("guide", sort=False):
        a.plot(group["seconds"], group["mean_iou"], label=guide)
        b.plot(group["seconds"], group["exact_rate"], label=guide)
    a.set(xscale="log", xlabel="search seconds", ylabel="mean IoU (final point: B-rep)", ylim=(0, 1.02))
    b.set(xscale="log", xlabel="search seconds", ylabel="exact (B-rep) rate", ylim=(0, 1.02))
    a.legend()
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path

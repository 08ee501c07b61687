"""How the inferred programs compare with the designers' own (beyond the paper's perceptual study).

Two measures per guide, over its searches of designs whose ground truth was mapped onto the zone
graph the search returned its program on: the share of inferred steps that equal a GT step (the
same extrusion zones and the same Boolean), and program length over GT length.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

BOOLEAN = {"new_body": "union", "join": "union", "cut": "subtract"}


def gt_steps(steps: pd.DataFrame) -> dict[tuple[str, str], set[tuple[frozenset[int], str]]]:
    """(design, graph) -> its GT steps as (zones, union|subtract), from ``data/gt/steps.parquet``."""
    out: dict[tuple[str, str], set[tuple[frozenset[int], str]]] = {}
    for row in steps.itertuples():
        if row.operation not in BOOLEAN or not bool(row.mapped):
            continue
        key = (str(row.design_id), str(row.graph))
        out.setdefault(key, set()).add((frozenset(int(z) for z in row.gt_zones), BOOLEAN[row.operation]))
    return out


def program_measures(results: pd.DataFrame, steps: pd.DataFrame) -> pd.DataFrame:
    """Per guide: searched designs with a GT, share of steps equal to a GT step, mean length ratio."""
    truth = gt_steps(steps)
    rows = []
    for guide, group in results.groupby("guide", sort=False):
        equal = total = 0
        ratios = []
        for r in group.itertuples():
            ops, zones = getattr(r, "operations", None), getattr(r, "step_zones", None)
            if not isinstance(ops, list | np.ndarray) or zones is None or not r.gt_length:
                continue
            key = (r.design_id, "simplified" if bool(r.simplified) else "full")
            if key not in truth:
                continue
            inferred = [(frozenset(int(z) for z in zs), op) for zs, op in zip(zones, ops, strict=True)]
            equal += sum(step in truth[key] for step in inferred)
            total += len(inferred)
            ratios.append(len(inferred) / int(r.gt_length))
        rows.append(
            {
                "guide": guide,
                "designs": len(ratios),
                "steps": total,
                "gt_step_share": equal / total if total else float("nan"),
                "length_ratio": float(np.mean(ratios)) if ratios else float("nan"),
            }
        )
    return pd.DataFrame(rows)

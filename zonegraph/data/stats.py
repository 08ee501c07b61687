"""Statistics of a set of designs, comparable with the published r1.0.1 figures."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable

import numpy as np

from zonegraph.data.design import Design, Operation

# Published figures for r1.0.1 (../shared/docs/FUSION_JSON.md).
PUBLISHED = {
    "designs": 8625,
    "sequence_length_mean": 4.74,
    "sequence_length_median": 4,
    "sequence_length_mode": 2,
    "sequence_length_max": 61,
    "share_single_extrude": 0.527,
    "share_with_cut": 0.259,
    "share_with_join": 0.315,
    "designs_with_intersect": 11,
    "operations": {"new_body": 10304, "join": 4711, "cut": 4299, "intersect": 19},
    "extents": {"one_side": 16900, "symmetric": 1900, "two_sides": 600, "tapered": 150},
    "share_with_other_curves": 0.076,
}

BASIC_CURVES = {"Line", "Arc", "Circle"}


TIMELINE_FOLDERS = (
    (2, "01_2ops"),
    (3, "02_3ops"),
    (5, "03_4to5ops"),
    (7, "04_6to7ops"),
    (10, "05_8to10ops"),
    (15, "06_11to15ops"),
    (20, "07_16to20ops"),
)


def timeline_folder(length: int) -> str:
    """The corpus's timeline folder for a timeline of ``length`` entities (sketches + extrudes)."""
    for most, name in TIMELINE_FOLDERS:
        if length <= most:
            return name
    return "08_21plus"


def design_statistics(designs: Iterable[Design]) -> dict:
    designs = list(designs)
    lengths = np.array([len(d.timeline) for d in designs])
    ops: Counter = Counter()
    extents: Counter = Counter()
    curves: Counter = Counter()
    other_curves = 0
    for d in designs:
        for x in d.extrudes:
            ops[x.operation.name.lower()] += 1
            extents[x.extent_type.name.lower()] += 1
            if x.extent_one.taper or (x.extent_two and x.extent_two.taper):
                extents["tapered"] += 1
        kinds = {
            type(c).__name__
            for s in d.sketches.values()
            for p in s.profiles.values()
            for lp in p.loops
            for c in lp.curves
        }
        for s in d.sketches.values():
            for p in s.profiles.values():
                for lp in p.loops:
                    curves.update(type(c).__name__ for c in lp.curves)
        other_curves += bool(kinds - BASIC_CURVES)
    n = max(len(designs), 1)
    has = lambda op: sum(any(x.operation is op for x in d.extrudes) for d in designs) / n  # noqa: E731
    values, counts = np.unique(lengths, return_counts=True) if len(lengths) else ([0], [0])
    return {
        "designs": len(designs),
        "sequence_length_mean": float(lengths.mean()) if len(lengths) else 0.0,
        "sequence_length_median": float(np.median(lengths)) if len(lengths) else 0.0,
        "sequence_length_mode": int(values[int(np.argmax(counts))]),
        "sequence_length_max": int(lengths.max()) if len(lengths) else 0,
        "extrude_count_histogram": {
            int(k): int(v) for k, v in Counter(len(d.extrudes) for d in designs).items()
        },
        "share_single_extrude": sum(len(d.extrudes) == 1 for d in designs) / n,
        "share_with_cut": has(Operation.CUT),
        "share_with_join": has(Operation.JOIN),
        "designs_with_intersect": sum(
            any(x.operation is Operation.INTERSECT for x in d.extrudes) for d in designs
        ),
        "operations": dict(ops),
        "extents": dict(extents),
        "curves": dict(curves),
        "share_with_other_curves": other_curves / n,
    }


def format_comparison(stats: dict, published: dict = PUBLISHED) -> str:
    """A two-column text table: our figures beside the published ones."""
    rows = []
    for key, ref in published.items():
        ours = stats.get(key)
        if isinstance(ref, dict):
            for k, v in ref.items():
                rows.append((f"{key}.{k}", (ours or {}).get(k, 0), v))
        else:
            rows.append((key, ours, ref))
    rows.append(
        ("curves", stats.get("curves"), "Line 129552, Circle 25677, Arc 20778, splines 7969, ellipses 278")
    )
    fmt = lambda v: f"{v:.3f}" if isinstance(v, float) else str(v)  # noqa: E731
    width = max(len(r[0]) for r in rows)
    lines = [f"{'statistic':{width}}  {'synthetic':>12}  published r1.0.1"]
    lines += [f"{name:{width}}  {fmt(ours):>12}  {fmt(ref)}" for name, ours, ref in rows]
    return "\n".join(lines)


__all__ = ["PUBLISHED", "design_statistics", "format_comparison"]

"""Sequence strips: the designer's sequence beside each guide's, one row each, for a few designs.

In place of the paper's perceptual study, a reader compares the sequences themselves: green is a
union, red a subtraction, grey the shape before the step. Every row is a Fusion-format design
replayed by `zonegraph.data.replay.replay`: the ground truth's own JSON and the
``sequence.json`` each search wrote, so all rows are drawn by the same code at one scale.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from zonegraph.data.design import Operation, load_design
from zonegraph.data.replay import replay
from zonegraph.errors import DesignError, ReplayError
from zonegraph.export.render import StripStep, render_strips


def design_strip(path: str | Path) -> list[StripStep]:
    """Panels of a design JSON's extrude timeline, replayed."""
    steps, before = [], None
    for i, step in enumerate(replay(load_design(path)).steps):
        cut = step.extrude.operation is Operation.CUT
        steps.append(StripStep(before, step.tool, cut, f"{i + 1}: {'subtract' if cut else 'union'}"))
        before = step.shape
    return steps


def pick_designs(results: pd.DataFrame, guides: list[str], max_steps: int = 6) -> list[str]:
    """Designs every guide reconstructed exactly in at most ``max_steps``, longest GT first."""
    main = results[(results["k"] == 5) & results["guide"].isin(guides)].copy()
    main["gt_length"] = main["gt_length"].fillna(0)
    exact = main.groupby("design_id").agg(
        solved=("exact", "sum"), longest=("steps", "max"), gt=("gt_length", "first")
    )
    exact = exact[(exact["solved"] == len(guides)) & (exact["longest"] <= max_steps)]
    return list(exact.sort_values(["gt", "longest"], ascending=False, kind="stable").index)


def write_strips(
    designs: list[str], gt_json: dict[str, Path], records: Path, guides: list[str], out: Path, count: int
) -> list[Path]:
    """Up to ``count`` PNGs, one per design: rows GT, then each guide's k 5 program.

    A design is passed over (with a line saying why) when a sequence does not replay."""
    written: list[Path] = []
    for design in designs:
        if len(written) == count:
            break
        sequences = [gt_json[design]] + [
            records / "programs" / f"{guide.replace(':', '_')}_k5" / design / "sequence.json"
            for guide in guides
        ]
        try:
            rows = {name: design_strip(path) for name, path in zip(["GT", *guides], sequences, strict=True)}
        except (DesignError, ReplayError, OSError) as exc:
            print(f"strips: {design} left out: {exc}", flush=True)
            continue
        written.append(render_strips(rows, out / f"strip_{design}.png"))
    return written

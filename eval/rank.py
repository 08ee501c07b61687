"""Relative rank of the ground truth: how high a guide puts the GT among a state's proposals.

The paper's ranking metric (sec. 5.2): at every captured GT step of a test design, a guide scores
all proposals of the state C_{i-1}; the GT's rank divided by the proposal count is averaged over
steps (1/P is perfect, about 0.5 is random). The states come from the ``labels`` stage's Parquet
shards (rank-only labels suffice: every proposal, the GT flagged), the zone graphs from the
``zonegraphs`` stage, and every guide is reached through ``make_ranker``, so a network is scored
exactly as the search would call it (``net`` with a checkpoint path).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow.dataset as ds

from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.sequence.rankers import Ranker, make_ranker, relative_rank
from zonegraph.zones.model import ZoneGraph
from zonegraph.zones.storage import load_zone_graph


@dataclass(frozen=True)
class RankState:
    """One captured GT step: its canvas, every proposal, which one is the GT.

    Shapes:
        canvas: (Z,) bool; is_gt: (P,) bool with exactly one true.
    """

    design_id: str
    step: int
    canvas: np.ndarray
    proposals: list[Proposal]
    is_gt: np.ndarray


def _mask(ids: Sequence[int], n: int) -> np.ndarray:
    out = np.zeros(n, bool)
    out[np.asarray(ids, dtype=np.int64)] = True
    return out


def _read(
    labels_dir: str | Path, kind: str, split: str | None, designs: Sequence[str] | None
) -> pd.DataFrame:
    dataset = ds.dataset(Path(labels_dir) / kind, format="parquet")
    condition = None
    if split is not None:
        condition = ds.field("split") == split
    if designs is not None:
        chosen = ds.field("design_id").isin(sorted(designs))
        condition = chosen if condition is None else condition & chosen
    return dataset.to_table(filter=condition).to_pandas()


def rank_states(
    labels_dir: str | Path,
    graphs_dir: str | Path,
    split: str | None = "test",
    designs: Sequence[str] | None = None,
) -> Iterator[tuple[ZoneGraph, list[RankState]]]:
    """Each design's zone graph with its rankable states (exactly one GT and another proposal)."""
    steps = _read(labels_dir, "steps", split, designs)
    proposals = _read(labels_dir, "proposals", split, designs)
    canvas_of: dict[tuple[Any, Any], Any] = {
        (r.design_id, r.step): r.canvas_zones for r in steps.itertuples()
    }
    for design_id, rows in proposals.groupby("design_id", sort=True):
        graph = load_zone_graph(Path(graphs_dir) / str(design_id), solids=False)
        states = []
        for step, group in rows.groupby("step", sort=True):
            is_gt = group["is_gt"].to_numpy(bool)
            if is_gt.sum() != 1 or len(group) < 2:
                continue
            states.append(
                RankState(
                    str(design_id),
                    int(step),
                    _mask(canvas_of[(design_id, step)], graph.n_zones),
                    [_proposal(r, graph.n_zones) for r in group.itertuples()],
                    is_gt,
                )
            )
        if states:
            yield graph, states


def _proposal(row: Any, n_zones: int) -> Proposal:
    op = Op.UNION if row.operation == "union" else Op.SUBTRACT
    faces = tuple(int(f) for f in row.sketch_faces)
    return Proposal(int(row.start_plane), int(row.end_plane), faces, _mask(row.zones, n_zones), op)


def guide_ranks(
    labels_dir: str | Path,
    graphs_dir: str | Path,
    guides: dict[str, Ranker],
    split: str | None = "test",
    designs: Sequence[str] | None = None,
) -> pd.DataFrame:
    """One row per (guide, design, step): the GT's relative rank and the proposal count."""
    rows = []
    for graph, states in rank_states(labels_dir, graphs_dir, split, designs):
        for name, ranker in guides.items():
            for state in states:
                scores = np.asarray(ranker.score(graph, state.canvas, state.proposals), float)
                rows.append(
                    {
                        "guide": name,
                        "design_id": state.design_id,
                        "step": state.step,
                        "proposals": len(state.proposals),
                        "rank": relative_rank(scores, state.is_gt),
                    }
                )
    return pd.DataFrame(rows, columns=["guide", "design_id", "step", "proposals", "rank"])


def make_guides(names: Sequence[str], models: Sequence[str | Path] = (), seed: int = 0) -> dict[str, Ranker]:
    """Rankers by guide name, plus one network guide per model checkpoint (named by its file)."""
    guides = {name: make_ranker(name, seed) for name in names}
    for model in models:
        path = Path(model)
        label = path.stem if path.stem != "scorer" else f"net:{path.parent.name or path.stem}"
        guides[label] = make_ranker("net", seed, str(path))
    return guides


def bootstrap_mean(
    ranks: pd.DataFrame, level: float = 0.9, samples: int = 2000, seed: int = 0
) -> tuple[float, float, float]:
    """Mean rank over steps and its ``level`` confidence interval, resampling whole designs.

    Designs, not steps, are the independent units: the steps of a design share one zone graph."""
    per_design = ranks.groupby("design_id")["rank"].agg(["sum", "count"]).to_numpy()
    mean = float(per_design[:, 0].sum() / per_design[:, 1].sum())
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, len(per_design), size=(samples, len(per_design)))
    sums = per_design[picks].sum(axis=1)  # (samples, 2)
    means = sums[:, 0] / sums[:, 1]
    tail = (1 - level) / 2
    low, high = np.quantile(means, [tail, 1 - tail])
    return mean, float(low), float(high)


def summarise(ranks: pd.DataFrame, level: float = 0.9, seed: int = 0) -> pd.DataFrame:
    """Per guide: designs, steps, mean relative rank with its bootstrap interval."""
    rows = []
    for guide, group in ranks.groupby("guide", sort=False):
        mean, low, high = bootstrap_mean(group, level, seed=seed)
        rows.append(
            {
                "guide": guide,
                "designs": group["design_id"].nunique(),
                "steps": len(group),
                "rank": mean,
                "ci_low": low,
                "ci_high": high,
            }
        )
    return pd.DataFrame(rows)


def markdown(table: pd.DataFrame) -> str:
    """The summary as a Markdown table: rank with its interval per guide."""
    lines = ["| guide | designs | steps | relative GT rank | 90% CI |", "|---|---|---|---|---|"]
    lines += [
        f"| {r.guide} | {r.designs} | {r.steps} | {r.rank:.4f} | {r.ci_low:.4f} - {r.ci_high:.4f} |"
        for r in table.itertuples()
    ]
    return "\n".join(lines) + "\n"


def plot_ranks(table: pd.DataFrame, path: Path) -> Path:
    """Bars of the mean relative rank per guide with their confidence intervals."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(1.2 * len(table) + 2, 3.2))
    errors = [table["rank"] - table["ci_low"], table["ci_high"] - table["rank"]]
    ax.bar(table["guide"], table["rank"], yerr=errors, capsize=4, color="C0")
    for x, value in enumerate(table["rank"]):
        ax.text(x, value / 2, f"{value:.3f}", ha="center", color="white")
    ax.set(
        ylabel="relative GT rank (lower is better)", ylim=(0, max(0.7, float(table["ci_high"].max()) + 0.05))
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main() -> None:
    import argparse
    import json

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=Path, default=Path("data/labels"))
    parser.add_argument("--graphs", type=Path, default=Path("data/zonegraphs/graphs"))
    parser.add_argument("--split", default="test")
    parser.add_argument("--guides", nargs="*", default=["random", "heuristic"])
    parser.add_argument("--model", nargs="*", default=[], help="network checkpoints to rank with")
    parser.add_argument("--limit", type=int, default=None, help="the first N designs (by id) only")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("eval_out/rank"))
    args = parser.parse_args()
    designs = None
    if args.limit is not None:
        steps = _read(args.labels, "steps", args.split, None)
        designs = sorted(set(steps["design_id"]))[: args.limit]
    ranks = guide_ranks(
        args.labels, args.graphs, make_guides(args.guides, args.model, args.seed), args.split, designs
    )
    table = summarise(ranks, seed=args.seed)
    args.out.mkdir(parents=True, exist_ok=True)
    ranks.to_parquet(args.out / "ranks.parquet", index=False)
    (args.out / "rank.json").write_text(json.dumps(table.to_dict(orient="records"), indent=2))
    (args.out / "rank.md").write_text(markdown(table))
    plot_ranks(table, args.out / "rank.png")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4f}"))


if __name__ == "__main__":
    main()

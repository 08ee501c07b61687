"""Relative rank of the ground truth: how high a guide puts the GT among a state's proposals.

The paper's ranking metric (sec. 5.2): at every captured GT step of a test design, a guide scores
all proposals of the state C_{i-1}; the GT's rank divided by the proposal count is averaged over
steps. That ratio's best value is 1/P and its random value (P + 1) / 2P, so it mixes the guide
with the proposal counts; beside it every table carries the normalised rank (rank - 1) / (P - 1)
(0: the GT first, 0.5: random, at any P), the oracle floor (mean 1/P, the best rank / P any guide
could reach on these steps) and the top-1 / top-5 hit rates (``docs/evaluation.md``). Steps with
a single proposal rank nothing: they are left out of every mean and counted (``single``).

Each step also carries its ``kind`` (`STEP_KINDS`): whether the GT completes the target, or
another proposal does and the GT does not (there the designer took a longer way than the state
offers, and a guide that puts the finishing proposal first is right for reconstruction while
the GT's rank counts it wrong), or none does. `by_kind` breaks every guide's rank down by it.

The states come from the ``labels`` stage's Parquet shards (rank-only labels suffice: every
proposal, the GT flagged), the zone graphs from the ``zonegraphs`` stage, and every guide is
reached through ``make_ranker``, so a network is scored exactly as the search would call it
(``net`` with a checkpoint path).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow.dataset as ds

from eval.guides import GuideSpec
from eval.heldout import (
    HOLDOUT,
    PARTS,
    add_exclude,
    excluded,
    held_out_labelled,
    holdout_projects,
    labels_split,
    of_projects,
    part_of,
    trained_projects,
)
from zonegraph.sequence.proposals import Op, Proposal
from zonegraph.sequence.rankers import GTPlace, Ranker, gt_place, make_ranker, score_step
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
    target: np.ndarray  # (Z,) bool, the zones inside the design

    @cached_property
    def kind(self) -> str:
        """Which proposals complete the target (`STEP_KINDS`), once per state for every guide."""
        completes = np.array([np.array_equal(p.apply(self.canvas), self.target) for p in self.proposals])
        if completes[self.is_gt].any():
            return "gt_completes"
        return "other_completes" if completes.any() else "none_completes"


# the GT completes the target; another proposal does and the GT does not; no proposal does
STEP_KINDS = ("gt_completes", "other_completes", "none_completes")


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
    singles: bool = False,
) -> Iterator[tuple[ZoneGraph, list[RankState]]]:
    """Each design's zone graph with its rankable states (exactly one GT and another proposal;
    ``singles``: also the states whose GT is the only proposal)."""
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
            if is_gt.sum() != 1 or len(group) < (1 if singles else 2):
                continue
            states.append(
                RankState(
                    str(design_id),
                    int(step),
                    _mask(canvas_of[(design_id, step)], graph.n_zones),
                    [_proposal(r, graph.n_zones) for r in group.itertuples()],
                    is_gt,
                    graph.zone_inside.astype(bool),
                )
            )
        if states:
            yield graph, states


def _proposal(row: Any, n_zones: int) -> Proposal:
    op = Op.UNION if row.operation == "union" else Op.SUBTRACT
    faces = tuple(int(f) for f in row.sketch_faces)
    return Proposal(int(row.start_plane), int(row.end_plane), faces, _mask(row.zones, n_zones), op)


METRICS = ("rank", "normalised", "floor", "top1", "top5")  # the per-step columns of guide_ranks
COLUMNS = ["guide", "design_id", "step", "kind", "proposals", "above", "ties", *METRICS]


def place_row(guide: str, state: RankState, place: GTPlace) -> dict[str, Any]:
    """One ranked step: the GT's place and every scale of it (`METRICS`)."""
    return {
        "guide": guide,
        "design_id": state.design_id,
        "step": state.step,
        "kind": state.kind,
        "proposals": place.proposals,
        "above": place.above,
        "ties": place.ties,
        "rank": place.relative,
        "normalised": place.normalised,
        "floor": place.floor,
        "top1": place.hit(1),
        "top5": place.hit(5),
    }


def guide_ranks(
    labels_dir: str | Path,
    graphs_dir: str | Path,
    guides: dict[str, Ranker],
    split: str | None = "test",
    designs: Sequence[str] | None = None,
) -> pd.DataFrame:
    """One row per (guide, design, step): the GT's place on every scale (`COLUMNS`).

    A step whose GT is the only proposal gets a row (``proposals`` 1) without asking the guide:
    `summarise` counts it and leaves it out of the means."""
    rows = []
    for graph, states in rank_states(labels_dir, graphs_dir, split, designs, singles=True):
        for name, ranker in guides.items():
            for state in states:
                if len(state.proposals) == 1:
                    rows.append(place_row(name, state, GTPlace(0, 0, 1)))
                    continue
                scores = score_step(ranker, graph, state.canvas, state.proposals, state.step)
                rows.append(place_row(name, state, gt_place(scores, state.is_gt)))
    return pd.DataFrame(rows, columns=COLUMNS)


def make_guides(names: Sequence[str], models: Sequence[str | Path] = (), seed: int = 0) -> dict[str, Ranker]:
    """Rankers by guide name, plus one network guide per model checkpoint (named by its file),
    which may carry the guide's knobs: ``PATH@top_m=8,blend=0.3`` (`eval.guides`)."""
    guides = {name: make_ranker(name, seed) for name in names}
    for model in models:
        spec = GuideSpec.parse(f"net={model}")
        path = Path(spec.model or "")
        label = path.stem if path.stem != "scorer" else f"net:{path.parent.name or path.stem}"
        knobs = str(model).partition("@")[2]
        guides[label + (f"@{knobs}" if knobs else "")] = spec.ranker(seed)
    return guides


def _design_sums(ranks: pd.DataFrame, columns: Sequence[str]) -> tuple[list[str], np.ndarray]:
    """Per design: the sums of ``columns`` and the step count, (D, len(columns) + 1)."""
    grouped = ranks.groupby("design_id", sort=True)
    sums = grouped[list(columns)].sum().join(grouped.size().rename("_count"))
    return list(sums.index), sums.to_numpy(float)


def _picks(designs: int, samples: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, designs, size=(samples, designs))


def _interval(values: np.ndarray, level: float) -> tuple[float, float]:
    tail = (1 - level) / 2
    low, high = np.quantile(values, [tail, 1 - tail])
    return float(low), float(high)


def bootstrap_means(
    ranks: pd.DataFrame, columns: Sequence[str], level: float = 0.9, samples: int = 2000, seed: int = 0
) -> dict[str, tuple[float, float, float]]:
    """Per column: the mean over steps and its ``level`` interval, resampling whole designs (one
    draw of designs for every column, so the intervals describe the same resamples).

    Designs, not steps, are the independent units: the steps of a design share one zone graph."""
    _, sums = _design_sums(ranks, columns)
    resampled = sums[_picks(len(sums), samples, seed)].sum(axis=1)  # (samples, C + 1)
    out = {}
    for i, column in enumerate(columns):
        means = resampled[:, i] / resampled[:, -1]
        out[column] = (float(sums[:, i].sum() / sums[:, -1].sum()), *_interval(means, level))
    return out


def bootstrap_mean(
    ranks: pd.DataFrame, level: float = 0.9, samples: int = 2000, seed: int = 0, column: str = "rank"
) -> tuple[float, float, float]:
    """The mean of one column over steps with its interval (see `bootstrap_means`)."""
    return bootstrap_means(ranks, [column], level, samples, seed)[column]


def ranked(ranks: pd.DataFrame) -> pd.DataFrame:
    """The steps that rank something: more than one proposal (all, when counts are not known)."""
    return ranks[ranks["proposals"] > 1] if "proposals" in ranks else ranks


def summarise(ranks: pd.DataFrame, level: float = 0.9, seed: int = 0) -> pd.DataFrame:
    """Per guide: designs, ranked steps, single-proposal steps left out, and every metric of
    `METRICS` with its bootstrap interval (``rank``, ``ci_low``, ``ci_high`` for rank / P;
    ``<metric>``, ``<metric>_ci_low``, ``<metric>_ci_high`` for the others)."""
    rows = []
    for guide, group in ranks.groupby("guide", sort=False):
        steps = ranked(group)
        row: dict[str, Any] = {
            "guide": guide,
            "designs": steps["design_id"].nunique(),
            "steps": len(steps),
            "single": int((group["proposals"] == 1).sum()) if "proposals" in group else 0,
        }
        if len(steps):
            present = [m for m in METRICS if m in steps]
            for metric, (mean, low, high) in bootstrap_means(steps, present, level, seed=seed).items():
                prefix = "" if metric == "rank" else f"{metric}_"
                row.update({metric: mean, f"{prefix}ci_low": low, f"{prefix}ci_high": high})
        rows.append(row)
    return pd.DataFrame(rows)


def pooled(ranks: pd.DataFrame, members: Sequence[str], name: str) -> pd.DataFrame:
    """``ranks`` with one more guide, ``name``: the step-by-step mean of ``members``' metrics.

    A training recipe is a distribution over its seeds, and one training per side cannot tell
    two recipes apart by less than the seeds' spread; the mean over each recipe's seeds, paired
    by `ratios` over the same resampled designs, can. The members must have ranked the same
    steps (ValueError otherwise)."""
    group = ranks[ranks["guide"].isin(members)]
    if missing := sorted(set(members) - set(group["guide"])):
        raise ValueError(f"no ranks of {', '.join(missing)}")
    keys = ["design_id", "step"]
    if (group.groupby(keys).size() != len(set(members))).any():
        raise ValueError(f"{name}: its members ranked different steps")
    metrics = [m for m in METRICS if m in group]
    means = group.groupby(keys)[metrics].mean()
    first = group[group["guide"] == members[0]].set_index(keys).drop(columns=metrics)
    mean = first.join(means).reset_index().assign(guide=name)
    return pd.concat([ranks, mean[list(ranks.columns)]], ignore_index=True)


def ratios(
    ranks: pd.DataFrame,
    base: str = "heuristic",
    metric: str = "normalised",
    level: float = 0.9,
    samples: int = 2000,
    seed: int = 0,
) -> pd.DataFrame:
    """Per guide: its mean ``metric`` over the base guide's, with a paired bootstrap interval
    (the same designs resampled for both; the issue's test: net <= 0.5 x heuristic)."""
    steps = ranked(ranks)
    if base not in set(steps["guide"]):
        return pd.DataFrame(columns=["guide", "base", "ratio", "ci_low", "ci_high"])
    _, base_sums = _design_sums(steps[steps["guide"] == base], [metric])
    picks = _picks(len(base_sums), samples, seed)
    base_means = base_sums[picks, 0].sum(axis=1) / base_sums[picks, 1].sum(axis=1)
    rows = []
    for guide, group in steps.groupby("guide", sort=False):
        if guide == base:
            continue
        _, sums = _design_sums(group, [metric])
        if len(sums) != len(base_sums):  # not the same designs: no pairing
            continue
        means = sums[picks, 0].sum(axis=1) / sums[picks, 1].sum(axis=1)
        mean, base_mean = sums[:, 0].sum() / sums[:, 1].sum(), base_sums[:, 0].sum() / base_sums[:, 1].sum()
        with np.errstate(divide="ignore", invalid="ignore"):  # a base that ranks every GT first
            ratio = float(mean / base_mean)
            resampled = means / base_means
        finite = resampled[np.isfinite(resampled)]  # a resample where the base ranks every GT first
        low, high = _interval(finite, level) if len(finite) else (float("nan"), float("nan"))
        rows.append({"guide": guide, "base": base, "ratio": ratio, "ci_low": low, "ci_high": high})
    return pd.DataFrame(rows, columns=["guide", "base", "ratio", "ci_low", "ci_high"])


def by_folder(
    ranks: pd.DataFrame, folders: dict[str, str], level: float = 0.9, seed: int = 0
) -> pd.DataFrame:
    """Per timeline folder and guide: designs and ranked steps, the mean normalised rank, top-1
    and top-5, and the normalised rank over the heuristic's with its paired interval (`ratios`
    within the folder; NaN where the heuristic ranks every GT of the folder first)."""
    steps = ranked(ranks).assign(folder=lambda f: f["design_id"].map(folders).fillna(""))
    rows = []
    for folder, group in steps.groupby("folder", sort=True):
        paired = ratios(group, level=level, seed=seed).set_index("guide")
        for guide, at in group.groupby("guide", sort=False):
            row = {
                "folder": folder,
                "guide": guide,
                "designs": at["design_id"].nunique(),
                "steps": len(at),
                **{m: float(at[m].mean()) for m in ("normalised", "top1", "top5")},
            }
            rows.append(row | _paired(paired, guide))
    return pd.DataFrame(rows)


def by_kind(ranks: pd.DataFrame, level: float = 0.9, seed: int = 0) -> pd.DataFrame:
    """Per kind of step (`STEP_KINDS`) and guide: ranked steps, the guide's share of its own
    normalised-rank sum there, the mean normalised rank and top-1, and its normalised rank over
    the heuristic's with the paired interval (`ratios` within the kind). Empty for ranks written
    before steps had a kind."""
    if "kind" not in ranks:
        return pd.DataFrame()
    steps = ranked(ranks)
    totals = steps.groupby("guide", sort=False)["normalised"].sum()
    rows = []
    for kind in STEP_KINDS:
        group = steps[steps["kind"] == kind]
        paired = ratios(group, level=level, seed=seed).set_index("guide")
        for guide, at in group.groupby("guide", sort=False):
            total = float(totals[guide])
            row = {
                "kind": kind,
                "guide": guide,
                "steps": len(at),
                "share": float(at["normalised"].sum()) / total if total else float("nan"),
                "normalised": float(at["normalised"].mean()),
                "top1": float(at["top1"].mean()),
            }
            rows.append(row | _paired(paired, guide))
    return pd.DataFrame(rows)


def _paired(paired: pd.DataFrame, guide: str) -> dict[str, float]:
    """A guide's ratio to the heuristic and its interval from `ratios` by guide (NaN for the
    heuristic itself, and where the heuristic ranks every GT first)."""
    fields = (("vs_heuristic", "ratio"), ("ci_low", "ci_low"), ("ci_high", "ci_high"))
    return {key: float(paired.at[guide, f]) if guide in paired.index else float("nan") for key, f in fields}


def _ratio_text(row: Any) -> str:
    """A table row's ratio to the heuristic with its interval, empty where it has none."""
    if np.isnan(row.vs_heuristic):
        return ""
    return f"{row.vs_heuristic:.3f} ({row.ci_low:.3f} - {row.ci_high:.3f})"


def kind_markdown(table: pd.DataFrame) -> str:
    """`by_kind` as a Markdown table."""
    lines = [
        "| step | guide | steps | share of its sum | normalised rank | top-1 | / heuristic's (90% CI) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in table.itertuples():
        ratio = _ratio_text(r)
        cells = f"{r.steps} | {r.share:.3f} | {r.normalised:.4f} | {r.top1:.3f}"
        lines.append(f"| {r.kind} | {r.guide} | {cells} | {ratio} |")
    return "\n".join(lines) + "\n"


def folder_markdown(table: pd.DataFrame) -> str:
    """`by_folder` as a Markdown table."""
    lines = [
        "| folder | guide | designs | steps | normalised rank | top-1 | top-5 | / heuristic's (90% CI) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table.itertuples():
        ratio = _ratio_text(r)
        lines.append(
            f"| {r.folder} | {r.guide} | {r.designs} | {r.steps} | {r.normalised:.4f} | {r.top1:.3f} | "
            f"{r.top5:.3f} | {ratio} |"
        )
    return "\n".join(lines) + "\n"


def design_folders(designs_table: Path) -> dict[str, str]:
    """Design id -> timeline folder, from a stage's designs table (``data/gt/designs.parquet``,
    ``data/designs/index.parquet``); empty where the table or its folders are absent."""
    if not designs_table.is_file():
        return {}
    table = pd.read_parquet(designs_table)
    if "folder" not in table:
        return {}
    return dict(zip(table["design_id"], table["folder"].astype(str), strict=True))


LEGEND = (
    "Means over steps with 90% bootstrap intervals over designs; rank / P is the paper's axis and the floor "
    "its best value on these steps; the normalised rank (rank - 1) / (P - 1) is 0 for the GT first and 0.5 "
    "for random (docs/evaluation.md).\n"
)


def markdown(table: pd.DataFrame, ratio: pd.DataFrame | None = None) -> str:
    """The summary as a Markdown table: every metric with its interval per guide, then the
    normalised rank of each guide over the heuristic's when ``ratio`` is given."""
    lines = [
        "| guide | designs | steps (single left out) | rank / P | floor | normalised rank | top-1 | top-5 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table.to_dict(orient="records"):
        if r["steps"] == 0:
            lines.append(f"| {r['guide']} | 0 | 0 ({r['single']}) | | | | | |")
            continue
        cells = [f"{r['rank']:.4f} ({r['ci_low']:.4f} - {r['ci_high']:.4f})", f"{r['floor']:.4f}"]
        cells += [f"{r[m]:.4f} ({r[m + '_ci_low']:.4f} - {r[m + '_ci_high']:.4f})" for m in ("normalised",)]
        cells += [f"{r[m]:.3f} ({r[m + '_ci_low']:.3f} - {r[m + '_ci_high']:.3f})" for m in ("top1", "top5")]
        head = f"| {r['guide']} | {r['designs']} | {r['steps']} ({r['single']}) | "
        lines.append(head + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n\n" + LEGEND
    if ratio is not None and len(ratio):
        text += "\n" + ratio_markdown(ratio)
    return text


def ratio_markdown(ratio: pd.DataFrame) -> str:
    """`ratios` as a Markdown table: each guide's normalised rank over its base's."""
    base = ratio["base"].iloc[0]
    text = f"| guide | normalised rank / {base}'s | 90% CI (paired) |\n|---|---|---|\n"
    return text + "".join(
        f"| {r.guide} | {r.ratio:.3f} | {r.ci_low:.3f} - {r.ci_high:.3f} |\n" for r in ratio.itertuples()
    )


def plot_ranks(table: pd.DataFrame, path: Path) -> Path:
    """Bars per guide with their intervals: rank / P beside its floor, and the normalised rank
    beside random's 0.5."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table = table[table["steps"] > 0]
    fig, axes = plt.subplots(1, 2, figsize=(2.4 * len(table) + 3, 3.2))
    for ax, (metric, low, high, label, line, line_label) in zip(
        axes,
        [
            ("rank", "ci_low", "ci_high", "rank / P (the paper's axis)", "floor", "floor (GT always first)"),
            ("normalised", "normalised_ci_low", "normalised_ci_high", "(rank - 1) / (P - 1)", None, "random"),
        ],
        strict=True,
    ):
        errors = [table[metric] - table[low], table[high] - table[metric]]
        ax.bar(table["guide"], table[metric], yerr=errors, capsize=4, color="C0")
        for x, value in enumerate(table[metric]):
            ax.text(x, value / 2, f"{value:.3f}", ha="center", color="white")
        level = float(table[line].mean()) if line else 0.5
        ax.axhline(level, color="C3", linestyle="--", label=line_label)
        ax.set(ylabel=f"{label}, lower is better", ylim=(0, max(0.7, float(table[high].max()) + 0.05)))
        ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> None:
    import argparse
    import json

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=Path, default=Path("data/labels"))
    parser.add_argument("--graphs", type=Path, default=Path("data/zonegraphs/graphs"))
    parser.add_argument(
        "--split", default="test", help="a labels split, or holdout: the training projects models held out"
    )
    parser.add_argument("--guides", nargs="*", default=["random", "heuristic"])
    parser.add_argument("--model", nargs="*", default=[], help="network checkpoints to rank with")
    parser.add_argument("--limit", type=int, default=None, help="the first N designs (by id) only")
    parser.add_argument(
        "--part", choices=PARTS, default=None, help="one half of the designs by project (default: all)"
    )
    parser.add_argument("--part-seed", type=int, default=0, help="the seed that halves them")
    add_exclude(parser)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--designs-table",
        type=Path,
        default=Path("data/gt/designs.parquet"),
        help="design ids with their timeline folders, for the table by folder (skipped if absent)",
    )
    parser.add_argument(
        "--ranks",
        type=Path,
        default=None,
        help="summarise an earlier run's ranks.parquet (less --exclude, --part) instead of ranking",
    )
    parser.add_argument(
        "--pool",
        nargs="*",
        default=[],
        metavar="NAME=GUIDE,GUIDE",
        help="one more guide, the step-by-step mean of the listed guides (e.g. one recipe's seeds)",
    )
    parser.add_argument(
        "--base",
        default=None,
        help="also every guide's normalised rank over this guide's, paired (e.g. one pooled recipe)",
    )
    parser.add_argument("--out", type=Path, default=Path("eval_out/rank"))
    args = parser.parse_args(argv)
    if args.ranks is not None:
        earlier = pd.read_parquet(args.ranks)
        kept = excluded(sorted(set(earlier["design_id"])), args.exclude)
        ranks = earlier[earlier["design_id"].isin(part_of(kept, args.part, args.part_seed)[: args.limit])]
        print(f"rank: {ranks['design_id'].nunique()} designs of {args.ranks}", flush=True)
    else:
        models = [GuideSpec.parse(f"net={m}").model or "" for m in args.model]
        seen, _ = trained_projects(models)
        split = labels_split(args.split)
        kept = excluded(held_out_labelled(args.labels, split, seen), args.exclude)
        if args.split == HOLDOUT:
            kept = of_projects(kept, holdout_projects(models))
        designs = part_of(kept, args.part, args.part_seed)[: args.limit]
        print(f"rank: {len(designs)} {args.split} designs of no project a model trained on", flush=True)
        guides = make_guides(args.guides, args.model, args.seed)
        ranks = guide_ranks(args.labels, args.graphs, guides, split, designs)
    if ranks.empty:
        raise SystemExit("rank: error: no designs left to rank")
    args.out.mkdir(parents=True, exist_ok=True)
    ranks.to_parquet(args.out / "ranks.parquet", index=False)  # the guides ranked, not the pools
    for spec in args.pool:
        name, _, members = spec.partition("=")
        try:
            ranks = pooled(ranks, members.split(","), name)
        except ValueError as exc:
            raise SystemExit(f"rank: error: --pool {spec}: {exc}") from None
    table = summarise(ranks, seed=args.seed)
    ratio = ratios(ranks, seed=args.seed)
    records = {"guides": table.to_dict(orient="records"), "vs_heuristic": ratio.to_dict(orient="records")}
    text = markdown(table, ratio)
    if args.base is not None:
        against = ratios(ranks, base=args.base, seed=args.seed)
        if against.empty:
            raise SystemExit(
                f"rank: error: --base {args.base}: no such guide, or none other on its designs "
                f"(the ranks are in {args.out / 'ranks.parquet'}: summarise them again with --ranks)"
            )
        records["vs_base"] = against.to_dict(orient="records")
        text += "\n" + ratio_markdown(against)
    folders = design_folders(args.designs_table)
    if folders:
        per = by_folder(ranks, folders, seed=args.seed)
        records["by_folder"] = per.to_dict(orient="records")
        text += "\nBy timeline folder (steps with more than one proposal):\n\n" + folder_markdown(per)
    kinds = by_kind(ranks, seed=args.seed)
    if len(kinds):
        records["by_kind"] = kinds.to_dict(orient="records")
        text += "\nBy kind of step (which proposals complete the target):\n\n" + kind_markdown(kinds)
    (args.out / "rank.json").write_text(json.dumps(records, indent=2))
    (args.out / "rank.md").write_text(text)
    plot_ranks(table, args.out / "rank.png")
    print(text)


if __name__ == "__main__":
    main()

"""The evaluation report: the paper's experiments on a test split (or a folder), one script.

    python -m eval.report [--model PATH ...] [--designs SPLIT|FOLDER] [--budget S] [--out DIR]
                          [--k 1 5 10] [--ablation-designs 100] [--limit N] [--workers 2]
                          [--params params.yaml]  (its ``evaluate`` section sets the defaults)

Run in a pipeline project (the ``evaluate`` DVC stage runs it on the test split), it reports:

- relative GT rank of random, heuristic and each model, with 90% bootstrap intervals over
  designs, overall and by timeline folder (from the ``labels`` stage's rank-only test labels);
- IoU and exact rate vs search time for designs with GT length >= 3, one curve per guide at k 5,
  zone-graph build excluded, each curve ending at the rebuilt B-rep's IoU;
- the search-width ablation: the same curves for each ``--k`` (heuristic and network) on the
  first ``--ablation-designs`` of them;
- per guide, the share of inferred steps equal to a GT step and program length / GT length;
- sequence strips of a few designs every guided search solved: the GT's row, then each guide's;
- the ground-truth stage's coverage table and the zone statistics, when the project has them.

No design of a project a model trained on is scored, for any guide (``eval.heldout``).
Everything goes to ``--out`` (JSON, Markdown, CSV and PNG) and into one MLflow run of the
``evaluation`` experiment, linked to the training run of each model. Searches are resumable.
"""

from __future__ import annotations

import argparse
import json
import shutil
from dataclasses import asdict, dataclass
from pathlib import Path

import pandas as pd

import zonegraph.network
from eval.curves import at_time, curves, plot_curves, time_grid
from eval.dvc_metrics import rounded, write_guides
from eval.heldout import (
    HOLDOUT,
    add_exclude,
    excluded,
    held_out,
    held_out_labelled,
    holdout_projects,
    labels_split,
    of_projects,
    trained_projects,
)
from eval.programs import program_measures
from eval.rank import (
    by_kind,
    design_folders,
    guide_ranks,
    kind_markdown,
    make_guides,
    markdown,
    plot_ranks,
    ranked,
    ratios,
    summarise,
)
from eval.searches import Search, Target, folder_targets, run_searches, split_targets
from eval.strips import pick_designs, write_strips
from zonegraph.configs import Config, ConfigError, InferConfig, load_section

SHIPPED = Path(zonegraph.network.__file__).resolve().parent / "checkpoints" / "scorer.pt"  # no torch import
MARKS = (1.0, 5.0, 20.0)  # seconds at which IoU and exact rate are reported as metrics


@dataclass(frozen=True)
class EvalConfig(Config):
    """The report's settings: its command line's defaults, and the ``evaluate`` section of a
    ``--params`` file (which overrides them; the command line overrides both).

    Args:
        model: network checkpoints to evaluate.
        designs: a split of the project, or a folder of parts.
        budget_s: search seconds per design and guide.
        out: the report's folder.
        k: the search widths of the ablation (heuristic and network); k 5 for every guide.
        ablation_designs: designs of the k ablation.
        min_gt_length: IoU vs time on designs with at least this many GT steps (the paper).
        strips: designs drawn as sequence strips.
        limit: the first N designs only (None: all).
        workers: searches side by side.
        timeout_s: hard stop per search (None: 3 x budget + 60).
        seed: seed of the random guide and the bootstrap.
        project: the pipeline project to read data/ from.
        labels: the labels stage's folder.
        graphs: the zonegraphs stage's graphs.
        metrics: also write one metrics JSON per guide into this folder (the DVC metrics).
        plot_csv: also write mean IoU vs time (k 5) here, wide (the DVC plot).
    """

    model: tuple[str, ...] = ()
    designs: str = "test"
    budget_s: float = 20.0
    out: str = "eval_out"
    k: tuple[int, ...] = (1, 5, 10)
    ablation_designs: int = 100
    min_gt_length: int = 3
    strips: int = 3
    limit: int | None = None
    workers: int = 2
    timeout_s: float | None = None
    seed: int = 0
    project: str = "."
    labels: str = "data/labels"
    graphs: str = "data/zonegraphs/graphs"
    metrics: str | None = None
    plot_csv: str | None = None


@dataclass(frozen=True)
class Guide:
    name: str  # label in tables
    guide: str  # InferConfig.guide
    model: str | None = None


def guides_for(models: list[str]) -> list[Guide]:
    """Random, heuristic and one network guide per model: the shipped checkpoint is
    ``net:shipped``, the first other one ``net`` (``make run``'s own), the rest ``net:<name>``
    (the file's stem, or its folder's name for a ``scorer.pt``)."""
    nets, names = [], set()
    for m in models:
        path = Path(m)
        if path.resolve() == SHIPPED:
            name = "net:shipped"
        elif "net" not in names:
            name = "net"
        else:
            name = f"net:{path.stem if path.stem != 'scorer' else path.parent.name}"
        while name in names:
            name += "'"
        names.add(name)
        nets.append(Guide(name, "net", m))
    return [Guide("random", "random"), Guide("heuristic", "heuristic"), *nets]


def searches_for(
    guides: list[Guide], targets: list[Target], ks: list[int], ablation: int, budget: float, seed: int
) -> list[Search]:
    """k 5 for every guide and target; the other k for heuristic and networks on the first targets."""
    out = []
    for g in guides:
        for k in sorted(set(ks) | {5}):
            if k != 5 and g.guide == "random":
                continue
            chosen = targets if k == 5 else targets[:ablation]
            config = InferConfig(guide=g.guide, budget_s=budget, k=k, seed=seed, model=g.model)
            out += [Search(g.name, config, t) for t in chosen]
    return out


def split_of(args: argparse.Namespace) -> str:
    """The pipeline split ``--designs`` names (`labels_split`)."""
    return labels_split(str(args.designs))


def evaluated(args: argparse.Namespace, design_ids: list[str]) -> list[str]:
    """``design_ids`` of no project a model trained on, less ``--exclude``, and with ``--designs
    holdout`` only those of the projects the models held out."""
    kept = excluded(held_out(design_ids, args.trained), args.exclude)
    return kept if args.held is None else of_projects(kept, args.held)


def rank_section(args: argparse.Namespace, guides: list[Guide], out: Path) -> tuple[pd.DataFrame, str]:
    labels, graphs = Path(args.labels), Path(args.graphs)
    if not (labels / "proposals").is_dir() or Path(args.designs).is_dir():
        return pd.DataFrame(), "No rank-only labels for these designs: the rank needs the labels stage.\n"
    rankers = make_guides(["random", "heuristic"], [g.model for g in guides if g.model], args.seed)
    rankers = {g.name: r for g, r in zip(guides, rankers.values(), strict=True)}
    designs = evaluated(args, held_out_labelled(labels, split_of(args), set()))
    ranks = guide_ranks(labels, graphs, rankers, split_of(args), designs[: args.limit])
    ranks.to_parquet(out / "ranks.parquet", index=False)
    table = summarise(ranks, seed=args.seed)
    ratio = ratios(ranks, seed=args.seed)
    plot_ranks(table, out / "rank.png")
    text = "## Relative GT rank\n\n" + markdown(table, ratio) + "\n![rank](rank.png)\n"
    folders = design_folders(Path(args.project) / "data/designs/index.parquet")
    if folders:
        ranks["folder"] = ranks["design_id"].map(folders).fillna("")
        steps = ranked(ranks)
        for metric, name in (("rank", "rank / P"), ("normalised", "normalised rank"), ("top1", "top-1")):
            per = steps.groupby(["folder", "guide"], sort=True)[metric].mean().unstack("guide")
            text += f"\nBy timeline folder (mean {name}):\n\n" + _frame_md(per[table["guide"]]) + "\n"
    kinds = by_kind(ranks, seed=args.seed)
    if len(kinds):
        text += "\nBy kind of step (which proposals complete the target):\n\n" + kind_markdown(kinds)
    return table.assign(**_ratio_columns(table, ratio)), text


def _ratio_columns(table: pd.DataFrame, ratio: pd.DataFrame) -> dict[str, list[float]]:
    """The paired ratio to the heuristic per row of ``table`` (NaN for the heuristic itself)."""
    by = {r.guide: r for r in ratio.itertuples()}
    nan = float("nan")
    return {
        f"vs_heuristic{suffix}": [getattr(by[g], field) if g in by else nan for g in table["guide"]]
        for suffix, field in (("", "ratio"), ("_ci_low", "ci_low"), ("_ci_high", "ci_high"))
    }


def _frame_md(frame: pd.DataFrame) -> str:
    head = "| " + " | ".join([str(frame.index.name or ""), *map(str, frame.columns)]) + " |"
    lines = [head, "|" + "---|" * (len(frame.columns) + 1)]
    for idx, *values in frame.itertuples():
        cells = [f"{v:.4f}" if isinstance(v, float) else str(v) for v in values]
        lines.append("| " + " | ".join([str(idx), *cells]) + " |")
    return "\n".join(lines) + "\n"


def search_section(
    args: argparse.Namespace, guides: list[Guide], out: Path
) -> tuple[pd.DataFrame, pd.DataFrame, str]:
    targets = (
        folder_targets(args.designs)
        if Path(args.designs).is_dir()
        else split_targets(split_of(args), args.project)
    )
    kept = set(evaluated(args, [t.design_id for t in targets]))
    targets = [
        t
        for t in targets
        if t.design_id in kept and (t.gt_length is None or t.gt_length >= args.min_gt_length)
    ][: args.limit]
    searches = searches_for(guides, targets, args.k, args.ablation_designs, args.budget_s, args.seed)
    print(
        f"report: {len(searches)} searches of {len(targets)} designs, budget {args.budget_s:g} s", flush=True
    )

    def progress(i: int, n: int) -> None:
        if i % 20 == 0 or i == n:
            print(f"  {i}/{n} searches", flush=True)

    results = run_searches(searches, out / "records", args.workers, args.timeout_s, progress)
    grid = time_grid(args.budget_s)
    table = pd.concat(
        [curves(group, grid).assign(k=k) for k, group in results.groupby("k", sort=True)], ignore_index=True
    )
    table.to_csv(out / "curves.csv", index=False)
    main = table[table["k"] == 5]
    plot_curves(main, out / "iou_time.png", f"{len(targets)} designs, GT length >= {args.min_gt_length}, k 5")
    text = (
        f"## IoU vs search time ({len(targets)} designs, GT length >= {args.min_gt_length}, k 5)\n\n"
        + _marks_md(main)
        + "\n![](iou_time.png)\n"
    )
    long = results[(results["k"] == 5) & (results["gt_length"].fillna(0) >= 3)]
    if args.min_gt_length < 3 and long["design_id"].nunique():  # the paper's subset, from the same searches
        subset = curves(long, grid)
        subset.to_csv(out / "curves_gt3.csv", index=False)
        plot_curves(
            subset, out / "iou_time_gt3.png", f"{long['design_id'].nunique()} designs, GT length >= 3, k 5"
        )
        text += (
            f"\n### GT length >= 3 ({long['design_id'].nunique()} of them)\n\n"
            + _marks_md(subset)
            + "\n![](iou_time_gt3.png)\n"
        )
    ablation = table[table["guide"] != "random"].copy()
    if ablation["k"].nunique() > 1:
        first = {t.design_id for t in targets[: args.ablation_designs]}
        chosen = results[(results["k"] == 5) & results["design_id"].isin(first)]
        again = curves(chosen, grid).assign(k=5)
        ablation = pd.concat([ablation[ablation["k"] != 5], again[again["guide"] != "random"]])
        ablation["guide"] = ablation["guide"] + " k" + ablation["k"].astype(str)
        plot_curves(ablation, out / "k_ablation.png", f"search width, {len(first)} designs")
        text += (
            f"\n## Search width (k), {len(first)} designs\n\n"
            + _marks_md(ablation)
            + "\n![](k_ablation.png)\n"
        )
    gt = Path(args.project) / "data/gt/steps.parquet"
    if gt.is_file():
        measures = program_measures(results[results["k"] == 5], pd.read_parquet(gt))
        measures.to_csv(out / "programs.csv", index=False)
        text += "\n## Inferred programs vs the designers'\n\n" + _frame_md(measures.set_index("guide")) + "\n"
    text += strips_section(args, guides, targets, results, out)
    return results, table, text


def strips_section(
    args: argparse.Namespace, guides: list[Guide], targets: list[Target], results: pd.DataFrame, out: Path
) -> str:
    """Side-by-side strips of the GT and each guided search's sequence for a few solved designs."""
    names = [g.name for g in guides if g.guide != "random"]
    jsons = _design_jsons(args, targets)
    chosen = [d for d in pick_designs(results, names) if d in jsons]
    paths = write_strips(chosen, jsons, out / "records", names, out, args.strips)
    if not paths:
        return ""
    rows = ", ".join(["GT", *names])
    return (
        f"\n## Sequences (rows: {rows}; green union, red subtraction, grey the shape before)\n\n"
        + "".join(f"![{p.stem}]({p.name})\n" for p in paths)
    )


def _design_jsons(args: argparse.Namespace, targets: list[Target]) -> dict[str, Path]:
    """Each target's design JSON (its ground-truth sequence), where it has one."""
    index = Path(args.project) / "data/designs/index.parquet"
    jsons = {t.design_id: Path(t.path) for t in targets if t.path.lower().endswith(".json")}
    if index.is_file():
        table = pd.read_parquet(index, columns=["design_id", "path"])
        jsons.update(
            {d: Path(args.project) / p for d, p in zip(table["design_id"], table["path"], strict=True)}
        )
    return jsons


def _marks(table: pd.DataFrame) -> list[float]:
    """The report's time marks within the budget (the budget itself when it is shorter)."""
    budget = float(table["seconds"].max())
    return [m for m in MARKS if m <= budget + 1e-9] or [budget]


def _marks_md(table: pd.DataFrame) -> str:
    rows = []
    marks = _marks(table)
    for guide, group in table.groupby("guide", sort=False):
        cells = []
        for mark in marks:
            at = at_time(group, mark)
            cells.append(f"{at.mean_iou:.3f} / {at.exact_rate:.1%}")
        rows.append(f"| {guide} | " + " | ".join(cells) + " |")
    head = "| guide | " + " | ".join(f"IoU / exact at {m:g} s" for m in marks) + " |"
    return "\n".join([head, "|---|" + "---|" * len(marks), *rows]) + "\n"


_KEYS = {"ci_low": "rank_ci_low", "ci_high": "rank_ci_high"}  # rank / P's interval, as before


def metrics_of(rank: pd.DataFrame, curve_table: pd.DataFrame) -> dict[str, float]:
    metrics = {}
    names = [c for c in rank.columns if c not in ("guide", "designs")]
    for r in rank.to_dict(orient="records"):
        metrics.update({f"{_KEYS.get(n, n)}.{r['guide']}": float(r[n]) for n in names if pd.notna(r[n])})
    main = curve_table[curve_table["k"] == 5] if len(curve_table) else curve_table
    for guide, group in main.groupby("guide", sort=False):
        for mark in _marks(main):
            at = at_time(group, mark)
            metrics[f"iou_at_{mark:g}s.{guide}"] = float(at.mean_iou)
            metrics[f"exact_at_{mark:g}s.{guide}"] = float(at.exact_rate)
    return {k.replace(":", "_"): v for k, v in metrics.items()}


def guide_metrics(rank: pd.DataFrame, curve_table: pd.DataFrame) -> dict[str, dict]:
    """Per guide, the DVC metrics' headline: the designs searched at k 5, the exact rate and mean
    IoU at the end of the budget and rank / P (the full set stays in ``metrics.json``)."""
    by_guide: dict[str, dict] = {}
    main = curve_table[curve_table["k"] == 5] if len(curve_table) else curve_table
    for guide, group in main.groupby("guide", sort=False):
        end = group.loc[group["seconds"].idxmax()]
        by_guide[str(guide)] = {
            "designs": int(end["designs"]),
            "exact": rounded(float(end["exact_rate"])),
            "iou": rounded(float(end["mean_iou"])),
        }
    for r in rank.to_dict(orient="records"):
        if pd.notna(r.get("rank")):
            by_guide.setdefault(str(r["guide"]), {})["rank"] = rounded(float(r["rank"]))
    return by_guide


def extras_section(args: argparse.Namespace, out: Path) -> str:
    """The coverage table and zone statistics the pipeline already made, copied beside the report."""
    project, text = Path(args.project), ""
    for source, name in (
        (project / "data/gt/coverage.md", None),
        (project / "data/plots/coverage.png", "coverage.png"),
    ):
        if source.is_file():
            if name:
                shutil.copy(source, out / name)
                text += f"\n![coverage]({name})\n"
            else:
                text += "\n## Coverage (ground-truth stage)\n\n" + source.read_text()
    for plot in sorted((project / "data/plots/zonegraphs").glob("*.png")):
        shutil.copy(plot, out / f"zones_{plot.name}")
        text += f"\n![zones](zones_{plot.name})\n"
    return text


def _parser() -> argparse.ArgumentParser:
    """The command line; every default is `EvalConfig`'s."""
    d = EvalConfig.defaults()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", nargs="*", default=d["model"], help="network checkpoints to evaluate")
    parser.add_argument(
        "--designs",
        default=d["designs"],
        help=f"a split of the project, {HOLDOUT} (the projects models held out of training), or a folder",
    )
    parser.add_argument(
        "--budget", dest="budget_s", type=float, default=d["budget_s"], help="search seconds per design"
    )
    parser.add_argument("--out", type=Path, default=d["out"])
    parser.add_argument("--k", type=int, nargs="*", default=d["k"])
    parser.add_argument("--ablation-designs", type=int, default=d["ablation_designs"])
    parser.add_argument("--min-gt-length", type=int, default=d["min_gt_length"])
    parser.add_argument("--strips", type=int, default=d["strips"], help="designs drawn as sequence strips")
    parser.add_argument("--limit", type=int, default=d["limit"], help="the first N designs only")
    add_exclude(parser)
    parser.add_argument("--workers", type=int, default=d["workers"])
    parser.add_argument(
        "--timeout",
        dest="timeout_s",
        type=float,
        default=d["timeout_s"],
        help="per search (default 3 x budget + 60)",
    )
    parser.add_argument("--seed", type=int, default=d["seed"])
    parser.add_argument("--project", default=d["project"], help="the pipeline project to read data/ from")
    parser.add_argument("--labels", default=d["labels"])
    parser.add_argument("--graphs", default=d["graphs"])
    parser.add_argument("--no-mlflow", action="store_true")
    parser.add_argument(
        "--metrics", default=d["metrics"], help="also write one metrics JSON per guide into this folder"
    )
    parser.add_argument(
        "--plot-csv", default=d["plot_csv"], help="also write mean IoU vs time (k 5) here, wide"
    )
    parser.add_argument(
        "--params", type=Path, default=None, help="defaults from this file's evaluate section"
    )
    return parser


def main() -> None:
    parser = _parser()
    args = parser.parse_args()
    if args.params is not None:
        try:
            section = load_section(EvalConfig, "evaluate", args.params)
        except ConfigError as exc:
            raise SystemExit(str(exc)) from None
        parser.set_defaults(**asdict(section))
        args = parser.parse_args()
    args.timeout_s = args.timeout_s or 3 * args.budget_s + 60
    for model in args.model:
        if not Path(model).is_file():
            raise SystemExit(f"{model}: error: no such model checkpoint")
    args.out.mkdir(parents=True, exist_ok=True)
    args.trained, silent = trained_projects(args.model)
    for model in silent:
        print(f"report: warning: {model} does not list its training projects; they cannot be held out")
    if args.trained:
        print(f"report: leaving out the designs of the {len(args.trained)} projects the models trained on")
    args.held = holdout_projects(args.model) if args.designs == HOLDOUT else None
    guides = guides_for(args.model)
    rank, rank_text = rank_section(args, guides, args.out)
    results, curve_table, search_text = search_section(args, guides, args.out)
    report = "# Evaluation\n\n" + rank_text + "\n" + search_text + extras_section(args, args.out)
    (args.out / "report.md").write_text(report)
    metrics = metrics_of(rank, curve_table)
    (args.out / "metrics.json").write_text(json.dumps(metrics, indent=2))
    if args.metrics:  # the DVC metrics, one file per guide, outside the stage's output folder
        write_guides(Path(args.metrics), guide_metrics(rank, curve_table))
    if args.plot_csv and len(curve_table):  # one column per guide, for dvc plots
        main_curves = curve_table[curve_table["k"] == 5]
        wide = main_curves.pivot(index="seconds", columns="guide", values="mean_iou").reset_index()
        Path(args.plot_csv).parent.mkdir(parents=True, exist_ok=True)
        wide.rename(columns=lambda c: str(c).replace(":", "_")).to_csv(args.plot_csv, index=False)
    print(report.split("\n## Coverage")[0])
    if not args.no_mlflow:
        params = {k: v for k, v in vars(args).items() if k not in ("no_mlflow", "trained", "held")}
        params["excluded_training_projects"] = len(args.trained)
        from eval.tracking import log_evaluation

        run = log_evaluation(params, metrics, curve_table, args.out, args.model)
        print(f"report: MLflow run {run} (experiment evaluation)")


if __name__ == "__main__":
    main()

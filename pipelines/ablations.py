"""Model ablations: objective, proposal features, fusion, point geometry and rounds, each alone
and combined, ranked on held-out designs.

    python -m pipelines.ablations [--params params.yaml] [--variants base listwise features ...]
                                  [--rounds 0 1 2 3 4] [--designs 300] [--epochs 3]
                                  [--eval-designs 100] [--part tune|report] [--compare CHECKPOINT ...]
                                  [--labels DIR] [--graphs DIR] [--eval-labels DIR --eval-graphs DIR]
                                  [--out data/eval/ablations]

A variant is a ``+``-joined list of changes to the ``train`` section of the params (the ``base``):
``focal`` / ``listwise`` (the objective), ``features`` / ``no_features`` (every proposal feature of
`PROPOSAL_FEATURES`, or none), ``state_features`` (those and the `STATE_FEATURES`), ``late`` /
``early`` (the fusion), ``points`` / ``no_points`` (the zones' point geometry), ``context`` (the
readout reads the state's proposals together), ``cosine`` (the learning rate decayed to 0 over
the run), ``roundsN``, ``hiddenN`` (the width of every layer) and ``teacher`` (the listwise
target shared with ``--teacher``'s scores: a student distilled from a trained checkpoint); e.g.
``listwise+features+early`` or ``listwise+features+no_points+hidden48+teacher``. Without
``--variants`` the runner trains the base, every change alone, and the objective and features
together with each of the others. Each variant is one
training run of ``training.train`` (MLflow experiment ``ablations``) on a seeded sample of
``--designs`` training designs, so variants compare at equal data; a finished variant (its
checkpoint and its config) is reused, so an interrupted ablation resumes. Every variant, random,
the heuristic and the ``--compare`` checkpoints are then ranked on the same test designs, none of
a project any of them trained on (``eval.heldout``), on every scale of ``eval.rank`` with 90%
bootstrap intervals over designs (``--eval-labels``: another run's test split, e.g. labels made
at other code or from another sample). Writes ablations.md / .json / .png and ranks.parquet
to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import re
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from eval.heldout import PARTS, held_out_labelled, part_of, trained_projects
from eval.rank import guide_ranks, make_guides, markdown, plot_ranks, ratios, summarise
from training.train import TrainConfig, train
from zonegraph.sequence.features import PROPOSAL_FEATURES, STATE_FEATURES

from .params import section

CHANGES: dict[str, dict[str, Any]] = {  # a variant's tokens, as overrides of the base
    "focal": {"loss": "focal", "neutral_credit": None},
    "listwise": {"loss": "listwise"},
    "features": {"features": PROPOSAL_FEATURES},
    "state_features": {"features": PROPOSAL_FEATURES + STATE_FEATURES},
    "no_features": {"features": ()},
    "late": {"fusion": "late"},
    "early": {"fusion": "early"},
    "points": {"use_points": True},
    "no_points": {"use_points": False},
    "context": {"context": True},
    "cosine": {"lr_schedule": "cosine"},
}


def variant(base: TrainConfig, spec: str, teacher: tuple[str, ...] = ()) -> TrainConfig:
    """The base with the changes of ``spec`` (``base``, or tokens of `CHANGES`, ``roundsN``,
    ``hiddenN`` and ``teacher`` joined by ``+``); an unknown token exits with one line."""
    config = base
    for token in spec.split("+"):
        if token == "base":
            continue
        rounds, hidden = re.fullmatch(r"rounds(\d+)", token), re.fullmatch(r"hidden(\d+)", token)
        if rounds:
            config = replace(config, rounds=int(rounds.group(1)))
        elif hidden:
            config = replace(config, hidden=int(hidden.group(1)))
        elif token == "teacher":
            if not teacher:
                raise SystemExit(
                    f"ablations: {spec!r} learns from a teacher: name its checkpoint with --teacher"
                )
            config = replace(config, teacher=teacher)
        elif token in CHANGES:
            config = replace(config, **CHANGES[token])
        else:
            raise SystemExit(
                f"ablations: unknown change {token!r} in {spec!r} "
                f"(one of {', '.join(CHANGES)}, roundsN, hiddenN, teacher)"
            )
    return config


def default_specs(base: TrainConfig, rounds: list[int]) -> list[str]:
    """The base, each change alone (the other objective, features, fusion and points; every other
    number of rounds), and the other objective with features beside each of the rest."""
    loss = "listwise" if base.loss == "focal" else "focal"
    features = "no_features" if base.features else "features"
    fusion = "early" if base.fusion == "late" else "late"
    points = "no_points" if base.use_points else "points"
    alone = [loss, features, fusion, points] + [f"rounds{r}" for r in rounds if r != base.rounds]
    pair = f"{loss}+{features}"
    return ["base", *alone, pair, *(f"{pair}+{other}" for other in (fusion, points))]


def variants(base: TrainConfig, rounds: list[int]) -> dict[str, TrainConfig]:
    """One config per rounds ablation: each number of rounds with points, the base rounds without."""
    out = {f"rounds{r}": replace(base, rounds=r, use_points=True) for r in rounds}
    out[f"rounds{base.rounds}_no_points"] = replace(base, use_points=False)
    return out


def train_variant(name: str, config: TrainConfig, out: Path) -> Path:
    """The variant's checkpoint, trained unless a finished run with the same config is there;
    its wall seconds go to ``train_s.json`` beside it."""
    folder = out / name
    config = replace(config, out_dir=str(folder))
    stamp = folder / "config.json"
    wanted = json.dumps(asdict(config), sort_keys=True)
    checkpoint = folder / "scorer.pt"
    if checkpoint.is_file() and stamp.is_file() and same_settings(stamp.read_text(), wanted):
        print(f"ablations: {name}: reusing {checkpoint}", flush=True)
        return checkpoint
    print(f"ablations: {name}: training ({describe(config)})", flush=True)
    t0 = time.perf_counter()
    train(config)
    (folder / "train_s.json").write_text(json.dumps({"wall_s": time.perf_counter() - t0}))
    stamp.write_text(wanted)
    return checkpoint


def same_settings(stamp: str, wanted: str) -> bool:
    """Two variant configs alike but for their folder: a copied or moved ablation reuses its runs.
    A setting added since the stamp was written reads as its default, which that run trained with."""
    defaults = json.loads(json.dumps(asdict(TrainConfig())))
    first, second = {**defaults, **json.loads(stamp)}, json.loads(wanted)
    first.pop("out_dir", None)
    second.pop("out_dir", None)
    return bool(first == second)


def describe(config: TrainConfig) -> str:
    features = f"{len(config.features)} features" if config.features else "no features"
    points = "points" if config.use_points else "no points"
    names = " + ".join(Path(t).name for t in config.teacher)
    taught = f", {config.distill:g} taught by {names}" if config.teacher else ""
    context = ", state context" if config.context else ""
    rate = f", {config.lr_schedule} rate" if config.lr_schedule != "constant" else ""
    return (
        f"{config.loss}, {features}, {config.fusion} fusion, {points}, {config.rounds} rounds, "
        f"hidden {config.hidden}{context}{rate}{taught}"
    )


def trained(name: str, folder: Path) -> dict[str, Any]:
    """What one variant's training cost and reached (its best epoch's validation metrics)."""
    metrics = json.loads((folder / "best.json").read_text()) if (folder / "best.json").is_file() else {}
    cost = json.loads((folder / "train_s.json").read_text()) if (folder / "train_s.json").is_file() else {}
    keys = ("epoch", "val_normalised", "val_rank", "val_top1", "val_steps")
    return {"variant": name, "train_wall_s": cost.get("wall_s"), **{k: metrics.get(k) for k in keys}}


def training_table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| variant | settings | train wall s | best epoch | validation normalised rank | validation steps |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        wall = f"{r['train_wall_s']:.0f}" if r["train_wall_s"] is not None else "(reused)"
        norm = f"{r['val_normalised']:.4f}" if r["val_normalised"] is not None else ""
        lines.append(
            f"| {r['variant']} | {r['settings']} | {wall} | {r['epoch']} | {norm} | {r['val_steps']} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument(
        "--variants", nargs="*", default=None, help="specs such as listwise+features (default: all)"
    )
    parser.add_argument("--rounds", type=int, nargs="*", default=[0, 1, 2, 3, 4])
    parser.add_argument("--designs", type=int, default=300, help="training designs per variant (0: all)")
    parser.add_argument("--epochs", type=int, default=3)
    parser.add_argument("--eval-designs", type=int, default=100)
    parser.add_argument("--part", choices=PARTS, default=None, help="rank on one half of them by project")
    parser.add_argument("--part-seed", type=int, default=0, help="the seed that halves them")
    parser.add_argument(
        "--compare", nargs="*", default=[], help="other checkpoints ranked beside them: PATH[@knob=value,...]"
    )
    parser.add_argument(
        "--teacher", nargs="+", default=[], help="the checkpoints a `teacher` variant learns from"
    )
    parser.add_argument("--labels", default=None, help="the labels folder (default: params)")
    parser.add_argument("--graphs", default=None, help="the zone graphs folder (default: params)")
    parser.add_argument(
        "--eval-labels", default=None, help="rank on these labels' test split (default: --labels)"
    )
    parser.add_argument("--eval-graphs", default=None, help="their zone graphs (default: --graphs)")
    parser.add_argument("--out", type=Path, default=Path("data/eval/ablations"))
    args = parser.parse_args()
    base = replace(
        section(TrainConfig, "train", args.params),
        max_designs=args.designs or None,
        epochs=args.epochs,
        experiment="ablations",
    )
    base = replace(base, **{k: v for k, v in (("labels_dir", args.labels), ("graphs_dir", args.graphs)) if v})
    args.out.mkdir(parents=True, exist_ok=True)
    specs = args.variants or default_specs(base, args.rounds)
    chosen = {spec: variant(base, spec, tuple(args.teacher)) for spec in specs}
    models = [train_variant(name, config, args.out) for name, config in chosen.items()]
    compared = list(args.compare)  # checkpoints, each may carry the guide's knobs (PATH@top_m=8)
    seen, _ = trained_projects([*models, *(c.partition("@")[0] for c in compared)])
    labels, graphs = args.eval_labels or base.labels_dir, args.eval_graphs or base.graphs_dir
    designs = part_of(held_out_labelled(labels, "test", seen), args.part, args.part_seed)[: args.eval_designs]
    guides = make_guides(["random", "heuristic"], [*models, *compared], base.seed)
    ranks = guide_ranks(labels, graphs, guides, "test", designs)
    ranks.to_parquet(args.out / "ranks.parquet", index=False)
    table = summarise(ranks, seed=base.seed)
    ratio = ratios(ranks, seed=base.seed)
    plot_ranks(table, args.out / "ablations.png")
    costs = [{**trained(n, args.out / n), "settings": describe(c)} for n, c in chosen.items()]
    text = (
        f"## Ablations: GT rank on {ranks['design_id'].nunique()} held-out test designs\n\n"
        f"(`{labels}`: the first {len(designs)} by id of no project any network trained on; "
        "the others have no step with a captured GT and another proposal)\n"
        f"Each network trained on {args.designs or 'all'} designs for {args.epochs} epochs "
        f"({base.points_per_zone} points per zone); the base is {describe(base)}.\n\n"
        + markdown(table, ratio)
        + "\n### Training\n\n"
        + training_table(costs)
    )
    (args.out / "ablations.md").write_text(text + "\n![ablations](ablations.png)\n")
    summary = {
        "eval_labels": str(labels),
        "designs": len(designs),
        "epochs": args.epochs,
        "train_designs": args.designs or None,
        "guides": table.to_dict(orient="records"),
        "vs_heuristic": ratio.to_dict(orient="records"),
        "training": costs,
        "configs": {n: {**asdict(c), "features": list(c.features)} for n, c in chosen.items()},
    }
    (args.out / "ablations.json").write_text(json.dumps(summary, indent=2, default=str))
    print(text)


if __name__ == "__main__":
    main()

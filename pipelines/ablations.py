"""Model ablations of the paper: message-passing rounds and point geometry, ranked on held-out designs.

    python -m pipelines.ablations [--params params.yaml] [--rounds 0 1 2 3 4] [--designs 300]
                                  [--epochs 3] [--eval-designs 100] [--out data/eval/ablations]

Each variant is one training run of ``training.train`` with the ``train`` section of the params
and an override (``rounds`` = r, or ``use_points`` = false at the section's rounds; the other
loss, the proposal features switched, and both), tracked in
the MLflow experiment ``ablations``. Each is then scored by relative GT rank on the same test
designs, none of a project any variant trained on (``eval.heldout``). Variants train on a seeded
sample of ``--designs`` training designs: the ablation compares variants at equal data, and on
2 cores the full set is too slow for six runs. A finished variant (its checkpoint and its config)
is reused, so an interrupted ablation resumes. Writes ablations.md / .json / .png to ``--out``.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict, replace
from pathlib import Path

from eval.heldout import held_out_labelled, trained_projects
from eval.rank import guide_ranks, make_guides, markdown, plot_ranks, ratios, summarise
from training.train import TrainConfig, train
from zonegraph.sequence.features import FEATURES

from .params import section


def variants(base: TrainConfig, rounds: list[int]) -> dict[str, TrainConfig]:
    """One config per ablation: each number of rounds with points, the base rounds without."""
    out = {f"rounds{r}": replace(base, rounds=r, use_points=True) for r in rounds}
    out[f"rounds{base.rounds}_no_points"] = replace(base, use_points=False)
    return out


def objective_variants(base: TrainConfig) -> dict[str, TrainConfig]:
    """The learned guide's own ablations (issue 24): the other objective, and the proposal
    features switched off (or on, when the base has none), each alone and both together."""
    other = "listwise" if base.loss == "focal" else "focal"
    features = () if base.features else FEATURES
    flip = "no_features" if base.features else "features"
    return {
        f"loss_{other}": replace(base, loss=other, neutral_credit=None),
        flip: replace(base, features=features),
        f"loss_{other}_{flip}": replace(base, loss=other, neutral_credit=None, features=features),
    }


def train_variant(name: str, config: TrainConfig, out: Path) -> Path:
    """The variant's checkpoint, trained unless a finished run with the same config is there."""
    folder = out / name
    config = replace(config, out_dir=str(folder))
    stamp = folder / "config.json"
    wanted = json.dumps(asdict(config), sort_keys=True)
    checkpoint = folder / "scorer.pt"
    if checkpoint.is_file() and stamp.is_file() and stamp.read_text() == wanted:
        print(f"ablations: {name}: reusing {checkpoint}", flush=True)
        return checkpoint
    print(f"ablations: {name}: training (rounds {config.rounds}, points {config.use_points})", flush=True)
    train(config)
    stamp.write_text(wanted)
    return checkpoint


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="params.yaml")
    parser.add_argument("--rounds", type=int, nargs="*", default=[0, 1, 2, 3, 4])
    parser.add_argument("--designs", type=int, default=300, help="training designs per variant")
    parser.add_argument("--epochs", type=int, default=3)
    parser.add_argument("--eval-designs", type=int, default=100)
    parser.add_argument("--out", type=Path, default=Path("data/eval/ablations"))
    args = parser.parse_args()
    base = replace(
        section(TrainConfig, "train", args.params),
        max_designs=args.designs,
        epochs=args.epochs,
        experiment="ablations",
    )
    args.out.mkdir(parents=True, exist_ok=True)
    chosen = {**variants(base, args.rounds), **objective_variants(base)}
    models = [train_variant(name, config, args.out) for name, config in chosen.items()]
    designs = held_out_labelled(base.labels_dir, "test", trained_projects(models)[0])[: args.eval_designs]
    guides = make_guides(["random", "heuristic"], models, base.seed)
    ranks = guide_ranks(base.labels_dir, base.graphs_dir, guides, "test", designs)
    ranks.to_parquet(args.out / "ranks.parquet", index=False)
    table = summarise(ranks, seed=base.seed)
    plot_ranks(table, args.out / "ablations.png")
    text = (
        f"## Ablations: relative GT rank on {ranks['design_id'].nunique()} held-out test designs\n\n"
        f"(the first {len(designs)} by id; the others have no step with a captured GT and another proposal)\n"
        f"Each network trained on {args.designs} designs for {args.epochs} epochs "
        f"({base.fusion} fusion, {base.points_per_zone} points per zone).\n\n"
        + markdown(table, ratios(ranks, seed=base.seed))
    )
    (args.out / "ablations.md").write_text(text + "\n![ablations](ablations.png)\n")
    (args.out / "ablations.json").write_text(table.to_json(orient="records", indent=2))
    print(text)


if __name__ == "__main__":
    main()

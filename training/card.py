"""The model card of a checkpoint: what it was trained on, how, and how well it ranks.

    python -m training.card models/scorer.pt --out zonegraph/network/checkpoints/MODEL_CARD.md
        [--test-ranks eval_out/rank.json] [--note "free text"] [--top-m M] [--blend B]

Everything is read from the checkpoint (`training.train.save_checkpoint` stores the model
and training configuration, the best epoch's metrics and the provenance: data version, git commit,
MLflow run, design counts), so a card cannot drift from the weights it describes.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import torch

DATA = (
    "Labels of Fusion 360 Gallery reconstruction designs (Willis et al., SIGGRAPH 2021), read as "
    "the build123d scripts of the Fusion360GalleryDataset-build123d corpus, under the Fusion 360 "
    "Gallery Dataset licence: non-commercial research use, with attribution to the Fusion 360 "
    "Gallery Dataset (Willis et al., SIGGRAPH 2021). These weights are derived from it: use them "
    "on the same terms."
)


def architecture(model: dict) -> str:
    """The network in one sentence, from its configuration (paper sec. 4.2 and what differs)."""
    zones = (
        "a PointNet over each zone's surface samples beside its flags"
        if model.get("use_points", True)
        else "each zone's flags (no point encoder)"
    )
    features = model.get("features") or ()
    extra = f", with {len(features)} proposal features beside the pooled graph" if features else ""
    return (
        f"{zones}, {model.get('rounds', 3)} rounds of message passing over zone adjacency "
        f"({model.get('fusion', 'late')} fusion), a max pool and an MLP{extra}."
    )


def card(checkpoint: dict, path: Path, test_ranks: dict | None = None, note: str = "") -> str:
    """Markdown describing ``checkpoint`` (loaded from ``path``)."""
    train, model, metrics = checkpoint["train"], checkpoint["model"], checkpoint["metrics"]
    origin = checkpoint.get("provenance", {})
    lines = [
        f"# Model card: `{path.name}`",
        "",
        "The proposal scorer of the network guide (`zonegraph infer PART --guide net`):",
        architecture(model),
        f"Size: {path.stat().st_size / 1e6:.2f} MB, "
        f"{sum(v.numel() for v in checkpoint['state_dict'].values()):,} parameters.",
        f"The guide runs it folded to numpy as `{path.with_suffix('.npz').name}` where it folds (late "
        f"fusion: `python -m training.fold {path.name}`), with no torch.",
        "",
        "## Data",
        "",
        DATA,
        "",
        f"- labels: `{train['labels_dir']}` (data version `{origin.get('data_version', '?')}`)",
        f"- training designs: {origin.get('train_designs', '?')}, validation designs "
        f"{origin.get('val_designs', '?')} (split by project, seed {train['seed']}); "
        f"training states: {origin.get('train_states', '?')}",
        f"- training projects: {len(origin.get('train_projects', [])) or '?'}, listed in the checkpoint "
        "(`provenance.train_projects`): `eval.report` leaves every design of them out",
        *holdout_line(origin),
        "",
        "## Parameters",
        "",
        "| parameter | value |",
        "|---|---|",
        *[f"| {k} | {v} |" for k, v in {**model, **train}.items() if k not in ("labels_dir", "graphs_dir")],
        "",
        "## Metrics",
        "",
        f"- best epoch {metrics['epoch']}: validation relative GT rank **{metrics['val_rank']:.4f}** "
        f"over {metrics.get('val_steps', '?')} steps, validation {train.get('loss', 'focal')} loss "
        f"{metrics['val_loss']:.4f}",
    ]
    if "val_normalised" in metrics:  # checkpoints trained before the other scales have rank / P only
        lines.append(
            f"- validation normalised GT rank (rank - 1) / (P - 1) **{metrics['val_normalised']:.4f}** "
            f"(0.5 random), rank / P floor {metrics['val_floor']:.4f}, top-1 {metrics['val_top1']:.3f}, "
            f"top-5 {metrics['val_top5']:.3f} (docs/evaluation.md)"
        )
    if test_ranks:
        lines.append(
            "- test split relative GT rank: "
            + ", ".join(f"{k} {v:.4f}" if isinstance(v, float) else f"{k} {v}" for k, v in test_ranks.items())
        )
    if checkpoint.get("search"):
        knobs = ", ".join(f"{k} {v}" for k, v in checkpoint["search"].items())
        lines.append(
            f"- search defaults stored with the weights: {knobs} (top_m: only the heuristic's top M "
            "proposals of a state are scored, the rest keep the heuristic's order below them; margin: "
            "only those within that much of the heuristic's best score, none when one leads alone; defer: "
            "the heuristic's first choice of a state is taken unscored, the network orders the others "
            "when the search backtracks; wake: with defer, the network orders every state of a search "
            "once it has backtracked; calls: the network scores at most that many states of a search, "
            "the rest keep the heuristic's order)"
        )
    lines += [
        "",
        "## Provenance",
        "",
        f"- git commit `{origin.get('git_commit', '?')}`, MLflow run `{origin.get('run_id', '?')}`",
        "- trained by `python -m training.train --params PARAMS` (the `train` section above) after "
        "the `labels` stage; see docs/network.md.",
    ]
    if note:
        lines += ["", note]
    return "\n".join(lines) + "\n"


def holdout_line(origin: dict[str, Any]) -> list[str]:
    """The held-out projects' line, for a checkpoint trained with ``train.holdout_fraction``."""
    held = origin.get("holdout_projects", [])
    if not held:
        return []
    return [
        f"- held out of training and validation: {origin.get('holdout_designs', '?')} designs of "
        f"{len(held)} projects (`provenance.holdout_projects`), for evaluation "
        "(`python -m bench.guide_cost_bench --split holdout`)"
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--test-ranks", type=Path, default=None, help="JSON of guide -> rank")
    parser.add_argument("--note", default="")
    parser.add_argument(
        "--top-m", type=int, default=None, help="store: the guide scores only the heuristic's top M"
    )
    parser.add_argument(
        "--blend", type=float, default=None, help="store: the heuristic's weight in the score"
    )
    parser.add_argument(
        "--margin",
        type=float,
        default=None,
        help="store: score only those within this of the heuristic's best",
    )
    parser.add_argument(
        "--calls", type=int, default=None, help="store: the network scores at most N states of a search"
    )
    switches = {
        "defer": "1 takes the heuristic's first choice unscored, the network orders the others",
        "wake": "1 (with defer) lets the network order every state once the search backtracked",
    }
    for name, text in switches.items():
        parser.add_argument(f"--{name}", type=int, choices=(0, 1), default=None, help=f"store: {text}")
    args = parser.parse_args()
    checkpoint = torch.load(args.checkpoint, map_location="cpu", weights_only=True)
    flags = {name: None if getattr(args, name) is None else bool(getattr(args, name)) for name in switches}
    knobs = (
        ("top_m", args.top_m),
        ("blend", args.blend),
        ("margin", args.margin),
        ("calls", args.calls),
        *flags.items(),
    )
    search = {k: v for k, v in knobs if v is not None}
    if search:  # the guide's defaults (NetworkRanker reads them), kept with the weights they suit
        checkpoint["search"] = {**checkpoint.get("search", {}), **search}
        torch.save(checkpoint, args.checkpoint)
    ranks = json.loads(args.test_ranks.read_text()) if args.test_ranks else None
    args.out.write_text(card(checkpoint, args.checkpoint, ranks, args.note))
    print(f"model card -> {args.out}")


if __name__ == "__main__":
    main()

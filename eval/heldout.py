"""Held-out designs: an evaluation never scores a model on a project it was trained on.

A split is drawn per run over that run's designs, so a model trained on one sample of the corpus
and evaluated on another sample's test split would meet some of its own training projects (on
the 3,100- and 3,600-design runs, 341 of 1,264 test designs). Checkpoints therefore carry the
projects they trained and validated on (``provenance.train_projects``), and the report drops
every design of those projects for every guide, so all guides are compared on the same designs.

Once the test split is used up (every design looked at), a model trained with
``train.holdout_fraction`` keeps a seeded share of the training split's projects out of training
and validation (``provenance.holdout_projects``): `holdout_projects` gives the designs of those
projects as a fresh evaluation set.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pyarrow.dataset as ds

from zonegraph.data.dataset import project_of

PARTS = ("tune", "report")
HOLDOUT = "holdout"  # the designs a model held out of training, where a split is named


def trained_projects(models: Sequence[str | Path]) -> tuple[set[str], list[str]]:
    """The projects any of ``models`` (PyTorch checkpoints or their numpy folds) saw in training,
    and the models that do not say."""
    seen: set[str] = set()
    silent = []
    for model in models:
        projects = _listed(Path(model), "train_projects")
        if projects is None:
            silent.append(str(model))
        else:
            seen.update(projects)
    return seen, silent


def _listed(model: Path, key: str) -> list[str] | None:
    """The projects a checkpoint or its numpy fold lists under ``key`` (``train_projects``,
    ``holdout_projects``), or None where it lists none."""
    if model.suffix == ".npz":
        from zonegraph.network.folded import FoldedScorer

        return list(getattr(FoldedScorer.load(model), key)) or None
    import torch  # only when a PyTorch model is evaluated

    provenance = torch.load(model, map_location="cpu", weights_only=True).get("provenance", {})
    return provenance.get(key)


def holdout_projects(models: Sequence[str | Path]) -> set[str]:
    """The training-split projects that every one of ``models`` held out of its training (a
    checkpoint's ``provenance.holdout_projects``); SystemExit naming a model that holds none out."""
    held: set[str] | None = None
    for model in models:
        projects = _listed(Path(model), "holdout_projects")
        if not projects:
            raise SystemExit(f"{model}: error: trained with no held-out projects (train.holdout_fraction 0)")
        held = set(projects) if held is None else held & set(projects)
    if held is None:
        raise SystemExit("error: held-out designs are a network's: name one (net=CHECKPOINT)")
    return held


def labels_split(split: str) -> str:
    """The pipeline split a named split reads: the held-out designs are of the training split."""
    return "train" if split == HOLDOUT else split


def of_projects(design_ids: Iterable[str], projects: set[str]) -> list[str]:
    """The designs whose project is in ``projects``, in their order (`held_out`'s complement)."""
    return [d for d in design_ids if project_of(d) in projects]


def held_out(design_ids: Iterable[str], projects: set[str]) -> list[str]:
    """The designs whose project is not in ``projects``, in their order."""
    return [d for d in design_ids if project_of(d) not in projects]


def held_out_labelled(labels_dir: str | Path, split: str, projects: set[str]) -> list[str]:
    """The designs of ``split`` with label shards, by id, less those of ``projects``."""
    steps = ds.dataset(Path(labels_dir) / "steps", format="parquet").to_table(columns=["design_id", "split"])
    ids = steps.filter(ds.field("split") == split).column("design_id").to_pylist()
    return held_out(sorted(set(ids)), projects)


def add_exclude(parser: argparse.ArgumentParser) -> None:
    """The ``--exclude`` option `excluded` reads, for every command that draws test designs."""
    parser.add_argument(
        "--exclude", type=Path, default=None, help="a text file of design ids to leave out (one per line)"
    )


def excluded(design_ids: Sequence[str], listing: Path | None) -> list[str]:
    """``design_ids`` less those listed in the text file ``listing`` (one id per line; ``#``
    starts a comment): the designs earlier evaluations looked at, so that a figure can be of
    designs that never steered a choice. ``None``: all of them."""
    if listing is None:
        return list(design_ids)
    if not listing.is_file():
        raise SystemExit(f"{listing}: error: no such list of design ids")
    lines = (line.partition("#")[0].strip() for line in listing.read_text().splitlines())
    listed = {line for line in lines if line}
    return [d for d in design_ids if d not in listed]


def part_of(design_ids: Sequence[str], part: str | None, seed: int) -> list[str]:
    """One of two halves of ``design_ids`` by project, drawn with ``seed``, in their order: knobs
    of a guide are chosen on ``tune`` and reported on ``report``, so the figure is of designs
    that did not steer the choice. ``None``: all of them."""
    if part is None:
        return list(design_ids)
    if part not in PARTS:
        raise ValueError(f"unknown part {part!r} (one of {', '.join(PARTS)})")
    projects = sorted({project_of(d) for d in design_ids})
    order = np.random.default_rng(seed).permutation(len(projects))
    tune = {projects[i] for i in order[: len(projects) // 2]}
    return [d for d in design_ids if (project_of(d) in tune) == (part == "tune")]

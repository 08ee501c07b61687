"""Held-out designs: an evaluation never scores a model on a project it was trained on.

A split is drawn per run over that run's designs, so a model trained on one sample of the corpus
and evaluated on another sample's test split would meet some of its own training projects (on
the 3,100- and 3,600-design runs, 341 of 1,264 test designs). Checkpoints therefore carry the
projects they trained and validated on (``provenance.train_projects``), and the report drops
every design of those projects for every guide, so all guides are compared on the same designs.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import pyarrow.dataset as ds

from zonegraph.data.dataset import project_of


def trained_projects(models: Sequence[str | Path]) -> tuple[set[str], list[str]]:
    """The projects any of ``models`` saw in training, and the models that do not say."""
    import torch  # only when a model is evaluated

    seen: set[str] = set()
    silent = []
    for model in models:
        provenance = torch.load(model, map_location="cpu", weights_only=True).get("provenance", {})
        if "train_projects" in provenance:
            seen.update(provenance["train_projects"])
        else:
            silent.append(str(model))
    return seen, silent


def held_out(design_ids: Iterable[str], projects: set[str]) -> list[str]:
    """The designs whose project is not in ``projects``, in their order."""
    return [d for d in design_ids if project_of(d) not in projects]


def held_out_labelled(labels_dir: str | Path, split: str, projects: set[str]) -> list[str]:
    """The designs of ``split`` with label shards, by id, less those of ``projects``."""
    steps = ds.dataset(Path(labels_dir) / "steps", format="parquet").to_table(columns=["design_id", "split"])
    ids = steps.filter(ds.field("split") == split).column("design_id").to_pylist()
    return held_out(sorted(set(ids)), projects)

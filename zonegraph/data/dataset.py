"""A folder of design JSON files as (design id, path, split) records.

Two layouts are read the same way: the published r1.0.1 reconstruction folder, whose
``train_test.json`` (beside the JSON files or one level up) fixes the split, and any other folder
(generated designs, the shared samples), which gets a seeded random split.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from zonegraph.errors import InputError

SPLIT_FILE = "train_test.json"


@dataclass(frozen=True)
class DesignRecord:
    design_id: str
    path: Path
    split: str  # "train" or "test"


def _split_file(folder: Path) -> Path | None:
    for candidate in (folder / SPLIT_FILE, folder.parent / SPLIT_FILE):
        if candidate.is_file():
            return candidate
    return None


def read_dataset(folder: str | Path, seed: int = 0, test_fraction: float = 0.2) -> list[DesignRecord]:
    """Every design JSON in ``folder``, sorted by id, with its split."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(str(folder), "no such data folder")
    paths = {p.stem: p for p in sorted(folder.glob("*.json")) if p.name != SPLIT_FILE}
    if not paths:
        raise InputError(str(folder), "no design JSON files in folder")
    split_path = _split_file(folder)
    if split_path is not None:
        try:
            split = json.loads(split_path.read_text())
        except json.JSONDecodeError as exc:
            raise InputError(str(split_path), f"invalid JSON ({exc})") from None
        test = set(split.get("test", []))
    else:
        ids = sorted(paths)
        order = np.random.default_rng(seed).permutation(len(ids))
        test = {ids[i] for i in order[: int(round(test_fraction * len(ids)))]}
    return [DesignRecord(i, p, "test" if i in test else "train") for i, p in sorted(paths.items())]

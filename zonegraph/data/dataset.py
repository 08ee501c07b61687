"""A folder of design JSON files as (design id, path, split) records.

Two layouts are read the same way: the published r1.0.1 reconstruction folder, whose
``train_test.json`` (beside the JSON files or one level up) fixes the split, and any other folder
(generated or converted designs, the shared samples), which gets a seeded split by design project:
designs of one project (the first two parts of the id, ``100622_1c7038f5`` for
``100622_1c7038f5_0002``) are near-copies and always land on the same side.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
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
        test = test_ids(list(paths), seed, test_fraction)
    return [DesignRecord(i, p, "test" if i in test else "train") for i, p in sorted(paths.items())]


def project_of(design_id: str) -> str:
    """The design project: the first two parts of a Fusion 360 Gallery id, else the id itself."""
    parts = design_id.split("_")
    return "_".join(parts[:2]) if len(parts) >= 3 else design_id


def test_ids(ids: Sequence[str], seed: int, test_fraction: float) -> set[str]:
    """A seeded test set of whole projects holding about ``test_fraction`` of the projects."""
    projects = sorted({project_of(i) for i in ids})
    order = np.random.default_rng(seed).permutation(len(projects))
    chosen = {projects[k] for k in order[: int(round(test_fraction * len(projects)))]}
    return {i for i in ids if project_of(i) in chosen}


def stratified_sample(groups: Sequence[str], limit: int | None, seed: int) -> list[int]:
    """Indices of a seeded sample of at most ``limit`` items, proportional per group (each group
    keeps at least one item while the limit allows), in their original order."""
    if limit is None or limit >= len(groups):
        return list(range(len(groups)))
    rng = np.random.default_rng(seed)
    by_group: dict[str, list[int]] = {}
    for i, g in enumerate(groups):
        by_group.setdefault(g, []).append(i)
    quota = {g: max(1, int(limit * len(m) / len(groups))) for g, m in sorted(by_group.items())}
    while sum(quota.values()) > limit:  # at least one per group can overshoot a small limit
        largest = max(quota, key=lambda g: quota[g])
        quota[largest] -= 1
    left = limit - sum(quota.values())
    for g in sorted(by_group, key=lambda g: -len(by_group[g]))[:left]:  # rounding remainder
        quota[g] += 1
    chosen = [
        i
        for g, members in sorted(by_group.items())
        for i in rng.choice(members, size=min(quota[g], len(members)), replace=False)
    ]
    return sorted(int(i) for i in chosen)

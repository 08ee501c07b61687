"""Which label shards training reads: those the labels stage lists as ok, and only while intact.

A shard in ``proposals/`` or ``steps/`` is not necessarily current: a design that failed on a later
run, one of an earlier and different run, a file a killed worker left half-written, a file damaged
since. The labels stage's job records (``records/<design_id>.json``, ``pipelines.records``) are its
manifest: an ok record names the design's two shards with their sizes and SHA-1. Training reads a
design's shards only when its record is ok and both match; every other shard is left out with one
warning, so a stray or corrupt file never stops a training (the labels stage recomputes a damaged
design on its next run). A folder without records (shards written by ``zonegraph.jobs.label_and_save``
alone) keeps every pair of shards whose Parquet footers read.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import pyarrow.parquet as pq

from zonegraph.outputs import hash_output

KINDS = ("proposals", "steps")


@dataclass(frozen=True)
class LabelShards:
    """The shards to read, by kind, in design order, and those left out with why."""

    proposals: list[Path]
    steps: list[Path]
    left_out: dict[str, str]  # shard path relative to the labels folder -> reason

    @property
    def design_ids(self) -> list[str]:
        return [p.stem for p in self.steps]

    def of(self, kind: str) -> list[Path]:
        return self.proposals if kind == "proposals" else self.steps


def _readable(path: Path) -> bool:
    try:
        pq.read_metadata(path)
    except (OSError, ValueError):  # pyarrow's ArrowInvalid is a ValueError
        return False
    return True


def _record_problem(root: Path, design_id: str) -> str | None:
    """Why the design's shards are not to be read, by its record, or None."""
    try:
        record = json.loads((root / "records" / f"{design_id}.json").read_text())
    except (OSError, ValueError):
        return "no readable record in records/"
    if not isinstance(record, dict) or record.get("status") != "ok":
        status = record.get("status") if isinstance(record, dict) else None
        return f"its record is not ok ({status})"
    listed = record.get("outputs")
    for kind in KINDS:
        shard = root / kind / f"{design_id}.parquet"
        if not shard.is_file():
            return f"{kind}/{shard.name} is missing"
        if listed is None:  # a record from before output hashes: the footer must read
            if not _readable(shard):
                return f"{kind}/{shard.name} is not a readable Parquet file"
        elif hash_output(shard) not in listed:
            return f"{kind}/{shard.name} differs from its record (size or SHA-1)"
    return None


def label_shards(labels_dir: str | Path) -> LabelShards:
    """The shards of ``labels_dir`` to train on (see the module's docstring); warns once about
    every shard left out."""
    root = Path(labels_dir)
    found = {kind: {p.stem for p in (root / kind).glob("*.parquet")} for kind in KINDS}
    managed = (root / "records").is_dir()
    keep, left_out = [], {}
    for design_id in sorted(found["proposals"] | found["steps"]):
        if managed:
            problem = _record_problem(root, design_id)
        elif design_id not in found["proposals"] or design_id not in found["steps"]:
            problem = "only one of its two shards exists"
        else:
            bad = [k for k in KINDS if not _readable(root / k / f"{design_id}.parquet")]
            problem = f"{bad[0]}/{design_id}.parquet is not a readable Parquet file" if bad else None
        if problem is None:
            keep.append(design_id)
            continue
        for kind in KINDS:
            if design_id in found[kind]:
                left_out[f"{kind}/{design_id}.parquet"] = problem
    if left_out:
        first = next(iter(left_out.items()))
        message = f"{root}: {len(left_out)} label shards left out (first: {first[0]}: {first[1]})"
        warnings.warn(message, stacklevel=1)  # one place: Python shows the same message once
    return LabelShards(
        [root / "proposals" / f"{d}.parquet" for d in keep],
        [root / "steps" / f"{d}.parquet" for d in keep],
        left_out,
    )

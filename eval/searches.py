"""The evaluation's searches: every (guide, k, design) ``infer``, isolated, resumable.

Targets are a split of a pipeline run (the replayed final B-reps with their saved zone graphs, the
ground-truth length from the replay) or a folder of the user's own design JSON / STEP / BREP
files. Each search runs in a killable child under a timeout (``zonegraph.isolation``), several
side by side, and writes one JSON record; a record made with the same settings is reused, so an
interrupted evaluation resumes and a second run does nothing.
"""

from __future__ import annotations

import functools
import hashlib
import json
import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import pandas as pd

import zonegraph
from zonegraph.configs import InferConfig
from zonegraph.isolation import run_isolated
from zonegraph.reconstruction import infer
from zonegraph.status import Status

TARGET_SUFFIXES = (".json", ".step", ".stp", ".brep")


@dataclass(frozen=True)
class Target:
    """One part to reconstruct: its file, the pipeline's saved zone graph if any, its GT length."""

    design_id: str
    path: str
    graph: str | None = None
    gt_length: int | None = None
    folder: str = ""


@dataclass(frozen=True)
class Search:
    """One search of the evaluation: a guide (with its model), a top-k, a target."""

    name: str  # the guide's label in tables: random, heuristic, net, net:<model>
    config: InferConfig
    target: Target

    @property
    def key(self) -> str:
        return f"{self.name.replace(':', '_')}_k{self.config.k}/{self.target.design_id}"

    def fingerprint(self) -> str:
        """The settings, the model's bytes, the target's and its saved graph's bytes and the code
        that searches: a record made of another target, graph or code is searched again. Paths
        are left out, so a moved project resumes."""
        model = Path(self.config.model) if self.config.model else None
        config = {**asdict(self.config), "model": bool(model)}
        target = {
            **asdict(self.target),
            "path": Path(self.target.path).name,
            "graph": bool(self.target.graph),
        }
        h = hashlib.sha1(json.dumps([config, target], sort_keys=True, default=str).encode())
        for path in (model, Path(self.target.path), Path(self.target.graph) if self.target.graph else None):
            if path is not None:
                h.update(_tree_hash(path).encode())
        h.update(_code_hash().encode())
        return h.hexdigest()


def _tree_hash(path: Path, pattern: str = "*") -> str:
    """A file's bytes, or every file of a folder matching ``pattern`` with its relative name;
    the hash of nothing when absent."""
    h = hashlib.sha1()
    files = [path] if path.is_file() else sorted(f for f in path.rglob(pattern) if f.is_file())
    for f in files:
        h.update(str(f.relative_to(path)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()


@functools.cache
def _code_hash() -> str:
    """The source of the package that searches (``zonegraph``), hashed once per process."""
    return _tree_hash(Path(zonegraph.__file__).parent, "*.py")


def split_targets(split: str, root: str | Path = ".") -> list[Target]:
    """The replayed designs of one split of a pipeline run (``data/replay``, ``data/designs``)."""
    root = Path(root)
    manifest = pd.read_parquet(root / "data/replay/manifest.parquet")
    rows = manifest[(manifest["split"] == split) & (manifest["status"] == Status.OK)].sort_values("design_id")
    index = root / "data/designs/index.parquet"
    folders: dict[str, str] = {}
    if index.is_file():
        table = pd.read_parquet(index)
        if "folder" in table:
            folders = dict(zip(table["design_id"], table["folder"].fillna("").astype(str), strict=True))
    return [
        Target(
            r.design_id,
            str(root / r.brep_dir / "final.brep"),
            str(root / "data/zonegraphs/graphs" / r.design_id),
            int(r.steps),
            folders.get(r.design_id, ""),
        )
        for r in rows.itertuples()
    ]


def folder_targets(folder: str | Path) -> list[Target]:
    """Every design JSON, STEP or BREP file of a folder (GT length known for JSON only)."""
    out = []
    for path in sorted(Path(folder).iterdir()):
        if path.suffix.lower() not in TARGET_SUFFIXES or path.name == "train_test.json":
            continue
        length = None
        if path.suffix.lower() == ".json":
            try:
                design = json.loads(path.read_text())
                length = sum(
                    1 for e in design.get("entities", {}).values() if e.get("type") == "ExtrudeFeature"
                )
            except (OSError, json.JSONDecodeError, AttributeError):
                length = None
        out.append(Target(path.stem, str(path), None, length))
    return out


def _search(target: str, graph: str | None, config: InferConfig, out: str) -> dict:
    result = infer(target, out, config, render=False, saved_graph=graph).to_dict()
    result.pop("config")
    return result


def _run_one(search: Search, records: Path, timeout_s: float) -> dict[str, Any]:
    """One search's record: reused when made with the same settings, else searched and written."""
    path = records / f"{search.key}.json"
    fingerprint = search.fingerprint()
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):  # absent, or truncated by a killed run: searched again
        record = None
    if isinstance(record, dict) and record.get("fingerprint") == fingerprint:
        return record
    out = records / "programs" / search.key
    outcome = run_isolated(
        _search, (search.target.path, search.target.graph, search.config, str(out)), timeout_s
    )
    record = {
        "guide": search.name,
        "k": search.config.k,
        "design_id": search.target.design_id,
        "folder": search.target.folder,
        "gt_length": search.target.gt_length,
        "fingerprint": fingerprint,
        "outcome": str(outcome.status),  # the job's; a search's own status comes with its values
        "reason": outcome.reason,
        **(outcome.value if outcome.ok and outcome.value else {}),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(record, default=str))
    tmp.replace(path)
    return record


def run_searches(
    searches: Sequence[Search],
    records: Path,
    workers: int = 2,
    timeout_s: float = 120.0,
    progress: Callable[[int, int], None] | None = None,
) -> pd.DataFrame:
    """Every search (reusing records made with the same settings); one row per search.

    Workers are spawned processes, each forking one isolated child per search: forking from a
    thread of a multi-threaded parent can deadlock the child on a lock another thread held."""
    rows: list[dict[str, Any]] = []
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max(1, workers), mp_context=context) as pool:
        jobs = pool.map(_run_one, searches, [records] * len(searches), [timeout_s] * len(searches))
        for i, row in enumerate(jobs, 1):
            rows.append(row)
            if progress:
                progress(i, len(searches))
    table = pd.DataFrame(rows)
    for column, default in (("exact", False), ("iou_brep", 0.0), ("time_to_best_s", float("nan"))):
        if column not in table:
            table[column] = default
    table["exact"] = table["exact"].fillna(False).astype(bool)
    table["iou_brep"] = table["iou_brep"].fillna(0.0)
    return table

"""Run one job per design on Dask: isolated, under a timeout, resumable, with progress.

Each finished design leaves a small JSON record (status, reason, seconds and the job's values)
named by its design id. A re-run reuses every record whose fingerprint (a hash of the job's
inputs) still matches, so an interrupted stage resumes where it stopped and finished work is never
lost. A failing design is a record with its status, never a failed stage.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from distributed import Client, as_completed
from tqdm import tqdm

from zonegraph.isolation import run_isolated
from zonegraph.status import Status


@dataclass(frozen=True)
class Job:
    key: str  # design id: names the record
    fingerprint: str  # changes whenever the job's result could change
    args: tuple
    cost: float = 0.0  # expected run time, any scale: the costliest jobs start first


PROJECT = Path(__file__).resolve().parents[1]  # dvc.yaml and the code live here, whatever the cwd
CODE_ROOTS = ("zonegraph", "pipelines", "training", "eval")


def _tree_files(path: Path) -> list[Path]:
    """A file, or every file under a folder in a stable order (caches and bytecode left out)."""
    if path.is_file():
        return [path]
    return sorted(
        f
        for f in path.rglob("*")
        if f.is_file() and "__pycache__" not in f.parts and f.suffix not in {".pyc", ".tmp"}
    )


def fingerprint(*parts: Any, files: tuple[str | Path, ...] = ()) -> str:
    """A hash of plain values and of the bytes (and relative names) of files and whole folders."""
    h = hashlib.sha1(json.dumps(parts, sort_keys=True, default=str).encode())
    for f in files:
        root = Path(f)
        for path in _tree_files(root):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def stage_code(stage: str, root: str | Path = PROJECT) -> tuple[str, ...]:
    """The code a stage depends on: its ``dvc.yaml`` deps under the code roots (files or folders).

    ``dvc.yaml`` is the one list of a stage's code: DVC reruns the stage when it changes, and
    :func:`code_fingerprint` hashes the same paths into every record, so that a record made by
    other code is recomputed rather than reused."""
    root = Path(root)
    with open(root / "dvc.yaml") as f:
        deps = yaml.safe_load(f)["stages"][stage].get("deps", [])
    return tuple(str(root / d) for d in deps if Path(d).parts[0] in CODE_ROOTS)


def code_fingerprint(stage: str, root: str | Path = PROJECT) -> str:
    """A hash of all the source a stage's records depend on (see :func:`stage_code`)."""
    return fingerprint(stage, files=stage_code(stage, root))


def _execute(fn: Callable, job: Job, timeout: float | None) -> dict:
    outcome = run_isolated(fn, job.args, timeout)
    record = {
        "design_id": job.key,
        "fingerprint": job.fingerprint,
        "status": str(outcome.status),  # the plain string: records and tables hold no enum objects
        "reason": outcome.reason,
        "seconds": round(outcome.seconds, 4),
    }
    if outcome.ok and outcome.value:
        record.update(outcome.value)
    if outcome.detail:  # a bug: its traceback, for whoever fixes it
        record["traceback"] = outcome.detail
    return record


def _write_atomic(path: Path, record: dict) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(record))
    os.replace(tmp, path)


def _load(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None


def run_jobs(
    fn: Callable, jobs: list[Job], records_dir: Path, client: Client, timeout: float | None, desc: str
) -> list[dict]:
    """Records for all ``jobs`` (in order), computing only those not already done."""
    records_dir.mkdir(parents=True, exist_ok=True)
    done: dict[str, dict] = {}
    todo = []
    for job in jobs:
        rec = _load(records_dir / f"{job.key}.json")
        if rec is not None and rec.get("fingerprint") == job.fingerprint:
            done[job.key] = rec
        else:
            todo.append(job)
    todo.sort(key=lambda job: -job.cost)  # longest first: no big design is left to run alone at the end
    if done:
        print(f"{desc}: {len(done)} of {len(jobs)} designs already done, resuming", flush=True)
    futures = client.map(_execute, [fn] * len(todo), todo, [timeout] * len(todo), pure=False)
    key_of = {f.key: job for f, job in zip(futures, todo, strict=False)}
    with tqdm(total=len(todo), desc=desc, unit="design", mininterval=2.0) as bar:
        for future in as_completed(futures):
            job = key_of[future.key]
            try:
                record = future.result()
            except Exception as exc:  # the worker itself died: record it, keep going
                record = {
                    "design_id": job.key,
                    "fingerprint": job.fingerprint,
                    "status": Status.CRASH.value,
                    "reason": f"{type(exc).__name__}: {exc}",
                    "seconds": 0.0,
                }
            _write_atomic(records_dir / f"{job.key}.json", record)
            done[job.key] = record
            bar.update()
    return [done[j.key] for j in jobs]

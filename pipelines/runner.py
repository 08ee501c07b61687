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
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any, Callable

from distributed import Client, as_completed
from tqdm import tqdm

from zonegraph.isolation import run_isolated


@dataclass(frozen=True)
class Job:
    key: str  # design id: names the record
    fingerprint: str  # changes whenever the job's result could change
    args: tuple
    cost: float = 0.0  # expected run time, any scale: the costliest jobs start first


def fingerprint(*parts: Any, files: tuple[str | Path, ...] = ()) -> str:
    h = hashlib.sha1(json.dumps(parts, sort_keys=True, default=str).encode())
    for f in files:
        h.update(Path(f).read_bytes())
    return h.hexdigest()


def code_fingerprint(*modules: ModuleType) -> str:
    """A hash of the modules' source: records made by other code are recomputed, not reused."""
    return fingerprint(files=tuple(m.__file__ for m in modules))


def _execute(fn: Callable, job: Job, timeout: float | None) -> dict:
    outcome = run_isolated(fn, job.args, timeout)
    record = {"design_id": job.key, "fingerprint": job.fingerprint, "status": outcome.status,
              "reason": outcome.reason, "seconds": round(outcome.seconds, 4)}
    if outcome.ok and outcome.value:
        record.update(outcome.value)
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


def run_jobs(fn: Callable, jobs: list[Job], records_dir: Path, client: Client,
             timeout: float | None, desc: str) -> list[dict]:
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
    key_of = {f.key: job for f, job in zip(futures, todo)}
    with tqdm(total=len(todo), desc=desc, unit="design", mininterval=2.0) as bar:
        for future in as_completed(futures):
            job = key_of[future.key]
            try:
                record = future.result()
            except Exception as exc:  # the worker itself died: record it, keep going
                record = {"design_id": job.key, "fingerprint": job.fingerprint, "status": "crash",
                          "reason": f"{type(exc).__name__}: {exc}", "seconds": 0.0}
            _write_atomic(records_dir / f"{job.key}.json", record)
            done[job.key] = record
            bar.update()
    return [done[j.key] for j in jobs]

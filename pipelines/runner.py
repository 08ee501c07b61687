"""Run one job per design on Dask: isolated, under a timeout, resumable, with progress.

Each finished design leaves a small JSON record (status, reason, seconds and the job's values)
named by its design id. A re-run reuses every record whose fingerprint (a hash of the job's
inputs) still matches and whose output files are intact (``pipelines.records``), so an interrupted
stage resumes where it stopped and finished work is never lost. A failing design is a record with
its status, never a failed stage; a failure the environment caused is tried again on later runs.

Job paths are absolute (``pipelines.paths`` resolves them), so a worker started in any folder of a
machine that shares the file system runs them; a worker that could not fork a child per design
(daemonic) is refused before any job runs.

Each worker imports the modules in `WARM_MODULES` once, before its first job: a design's child is
forked from the worker, so what a job imports on first use (build123d, behind the readers of
shapes) was imported again in every child and thrown away with it. That import, about 2 CPU
seconds, was most of a ground-truth job (0.1 s of work).
"""

from __future__ import annotations

import hashlib
import importlib
import json
import multiprocessing as mp
import os
import shutil
import socket
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
import yaml
from distributed import Client, as_completed
from tqdm import tqdm

from zonegraph.isolation import run_isolated
from zonegraph.lazy import uncollected
from zonegraph.status import Status

from . import records as rec


@dataclass(frozen=True)
class Job:
    key: str  # design id: names the record
    fingerprint: str  # changes whenever the job's result could change
    args: tuple
    cost: float = 0.0  # expected run time, any scale: the costliest jobs start first
    outputs: tuple[str, ...] = ()  # files or folders the job writes (hashed into its record)
    inputs: tuple[str, ...] = ()  # files the job reads, which must exist where it runs
    outputs_optional: bool = False  # an ok job may write nothing (a design that did not convert)


PROJECT = Path(__file__).resolve().parents[1]  # dvc.yaml and the code live here, whatever the cwd
CODE_ROOTS = ("zonegraph", "pipelines", "training", "eval")
# How jobs are run, not what they compute: left out of the records' code fingerprint, so that a
# change to the runner does not recompute finished work (DVC still reruns the stage).
MACHINERY = ("pipelines/runner.py", "pipelines/records.py", "pipelines/cluster.py")


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
    `code_fingerprint` hashes the same paths into every record, so that a record made by
    other code is recomputed rather than reused."""
    root = Path(root)
    with open(root / "dvc.yaml") as f:
        deps = yaml.safe_load(f)["stages"][stage].get("deps", [])
    return tuple(str(root / d) for d in deps if Path(d).parts[0] in CODE_ROOTS)


def code_fingerprint(stage: str, root: str | Path = PROJECT) -> str:
    """A hash of all the source a stage's records depend on (see `stage_code`), less the
    `MACHINERY` that only runs the jobs."""
    machinery = {str(Path(root) / m) for m in MACHINERY}
    return fingerprint(stage, files=tuple(p for p in stage_code(stage, root) if p not in machinery))


def _worker_problem(job: Job) -> str | None:
    """Why this worker cannot run the job at all, or None: the environment's fault, not the design's."""
    if mp.current_process().daemon:
        return f"daemonic worker on {socket.gethostname()} cannot fork a child ({DAEMON_HINT})"
    for path in job.inputs:
        if not Path(path).exists():
            return f"input {path} not found on worker {socket.gethostname()} (cwd {os.getcwd()})"
    return None


def _clear(outputs: Iterable[str]) -> None:
    """Remove a job's outputs: before it runs (nothing stale survives it) and when it failed."""
    for out in outputs:
        path = Path(out)
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)


def _execute(fn: Callable, job: Job, timeout: float | None, memory_mb: int | None = None) -> dict:
    problem = _worker_problem(job)
    record: dict[str, Any] = {
        "design_id": job.key,
        "fingerprint": job.fingerprint,
        "version": rec.RECORD_VERSION,
    }
    if problem:
        return {
            **record,
            "status": Status.WORKER_ERROR.value,
            "reason": problem,
            "seconds": 0.0,
            "outputs": [],
        }
    _clear(job.outputs)
    outcome = run_isolated(fn, job.args, timeout, memory_mb=memory_mb)
    record.update(
        status=str(outcome.status),  # the plain string: records and tables hold no enum objects
        reason=outcome.reason,
        seconds=round(outcome.seconds, 4),
    )
    if outcome.ok and outcome.value:
        record.update(outcome.value)
    if outcome.detail:  # a bug: its traceback, for whoever fixes it
        record["traceback"] = outcome.detail
    if not outcome.ok:
        _clear(job.outputs)
    record["outputs"] = rec.hash_outputs(job.outputs)
    return record


# Imported by each worker before its first job (the kernel's thread-pool guard before build123d).
WARM_MODULES = ("zonegraph.geometry.kernel", "build123d")


def warm_worker(modules: tuple[str, ...] = WARM_MODULES) -> list[str]:
    """Import ``modules`` in this worker (without the cyclic collector, as the CLI imports the
    kernel); returns those it had not imported yet. Each design's child starts with them frozen
    (`zonegraph.isolation`)."""
    new = [m for m in modules if m not in sys.modules]
    with uncollected():
        for module in new:
            importlib.import_module(module)
    return new


DAEMON_HINT = "start workers with DASK_DISTRIBUTED__WORKER__DAEMON=False"


def _daemonic() -> bool:
    return mp.current_process().daemon


def refuse_daemonic_workers(client: Client) -> None:
    """Stop with one line before any job runs when a worker cannot fork (each design needs a child)."""
    daemonic = sorted(addr for addr, flag in client.run(_daemonic).items() if flag)
    if daemonic:
        raise SystemExit(
            f"dask: worker {daemonic[0]} is daemonic and cannot fork a child per design: {DAEMON_HINT} "
            "(or dask worker --no-nanny)"
        )


def _lost(job: Job, exc: BaseException, previous: int) -> dict:
    return {
        "design_id": job.key,
        "fingerprint": job.fingerprint,
        "version": rec.RECORD_VERSION,
        "status": Status.CRASH.value,
        "reason": f"worker lost: {type(exc).__name__}: {exc}",
        "seconds": 0.0,
        "outputs": rec.hash_outputs(job.outputs),
        "attempts": previous + 1,
    }


def _plan(jobs: list[Job], records_dir: Path) -> tuple[dict[str, dict], list[Job], dict[str, int]]:
    """The records to reuse, the jobs to run and how often each was tried before."""
    done: dict[str, dict] = {}
    todo, tried = [], {}
    for job in jobs:
        path = records_dir / f"{job.key}.json"
        old = rec.load(path)
        kept = rec.reuse(old, job.fingerprint, job.outputs, job.outputs_optional)
        if kept is None:
            todo.append(job)
            tried[job.key] = rec.attempts(old, job.fingerprint)
            continue
        if kept is not old:  # a first-format record, now with its output hashes
            rec.write_atomic(path, kept)
        done[job.key] = kept
    return done, todo, tried


def run_jobs(
    fn: Callable,
    jobs: list[Job],
    records_dir: Path,
    client: Client,
    timeout: float | None,
    desc: str,
    memory_mb: int | None = None,
) -> list[dict]:
    """Records for all ``jobs`` (in order), computing only those not already done and intact."""
    records_dir.mkdir(parents=True, exist_ok=True)
    done, todo, tried = _plan(jobs, records_dir)
    todo.sort(key=lambda job: -job.cost)  # longest first: no big design is left to run alone at the end
    if done:
        print(f"{desc}: {len(done)} of {len(jobs)} designs already done, resuming", flush=True)
    if todo:
        refuse_daemonic_workers(client)
        client.run(warm_worker)
    n = len(todo)
    futures = client.map(_execute, [fn] * n, todo, [timeout] * n, [memory_mb] * n, pure=False)
    key_of = {f.key: job for f, job in zip(futures, todo, strict=False)}
    with tqdm(total=n, desc=desc, unit="design", mininterval=2.0) as bar:
        for future in as_completed(futures):
            job = key_of[future.key]
            try:
                record = future.result()
                if rec.is_transient(record["status"]):
                    record["attempts"] = tried[job.key] + 1
            except Exception as exc:  # the worker itself died: record it, keep going
                record = _lost(job, exc, tried[job.key])
            rec.write_atomic(records_dir / f"{job.key}.json", record)
            done[job.key] = record
            bar.update()
    ordered = [done[j.key] for j in jobs]
    _report_retries(desc, ordered)
    return ordered


def _report_retries(desc: str, records: list[dict]) -> None:
    summary = rec.retry_summary(records)
    if summary["environment_failures"]:
        print(
            f"{desc}: {summary['environment_failures']} designs failed for the environment (timeout, crash, "
            f"worker error, memory); {summary['retried_next_run']} will be tried again on the next run "
            f"(at most {rec.MAX_ATTEMPTS} runs each)",
            flush=True,
        )


def records_frame(records: list[dict], columns: Iterable[str] = ()) -> pd.DataFrame:
    """The records as a table without their bookkeeping, with ``columns`` present even when no
    design succeeded (a stage whose designs all failed still writes its metrics)."""
    drop = {"fingerprint", "outputs", "version"}
    table = pd.DataFrame([{k: v for k, v in r.items() if k not in drop} for r in records])
    for column in ("design_id", "status", "reason", "seconds", "attempts", *columns):
        if column not in table:
            table[column] = None
    return table

"""What a stage's record says about the files its job wrote, and when a record may be reused.

A record is the only trace of finished work, so reusing one whose files were altered, truncated or
deleted would carry garbage downstream as if it were current. Each record therefore names its
outputs with every file's size and content hash, and is reused only while all of them are intact.
Outcomes the environment caused (a killed child, a lost worker, a timeout, a missing input on a
worker) say nothing about the design: they are recorded but tried again on later runs, at most
`MAX_ATTEMPTS` times in all, so that a design that always crashes does not cost every run.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from zonegraph.outputs import FileHashes, hash_output
from zonegraph.status import Status

RECORD_VERSION = 2  # records without it predate output hashes (see `reuse`)
MAX_ATTEMPTS = 3  # runs on which an environment failure is tried before it stands as final
TRANSIENT = frozenset({Status.TIMEOUT, Status.CRASH, Status.WORKER_ERROR, Status.OUT_OF_MEMORY})


def hash_outputs(outputs: tuple[str, ...]) -> list[FileHashes]:
    return [hash_output(p) for p in outputs]


def is_transient(status: str) -> bool:
    return status in {s.value for s in TRANSIENT}


def attempts(record: dict | None, fingerprint: str) -> int:
    """How many runs already tried this job on these inputs and failed for the environment."""
    if (
        record is None
        or record.get("fingerprint") != fingerprint
        or not is_transient(record.get("status", ""))
    ):
        return 0
    return int(record.get("attempts", 1))


def reuse(
    record: dict | None, fingerprint: str, outputs: tuple[str, ...], optional: bool = False
) -> dict | None:
    """The record to reuse as it stands, or None to run the job again.

    Only an ok record's outputs are read downstream, so only theirs are checked (a failed job's
    are removed). A record of the first format (no output hashes; the corpus runs before them) is
    trusted on its first reuse when its fingerprint matches and its outputs exist: their hashes
    are taken then and checked on every later run, so finished work survives the format change
    (``optional``: an ok job may have written nothing, as a design that did not convert)."""
    if record is None or record.get("fingerprint") != fingerprint:
        return None
    status = record.get("status", "")
    if is_transient(status) and attempts(record, fingerprint) < MAX_ATTEMPTS:
        return None
    if status != Status.OK:
        return record
    found = hash_outputs(outputs)
    if record.get("version") != RECORD_VERSION:
        if not optional and any(not files for files in found):
            return None  # an ok record whose outputs are gone
        return {**record, "version": RECORD_VERSION, "outputs": found}
    return record if record.get("outputs") == found else None


def load(path: Path) -> dict | None:
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def write_atomic(path: Path, record: dict) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(record))
    os.replace(tmp, path)


def retry_summary(records: list[dict]) -> dict[str, Any]:
    """What a stage's metrics say about environment failures: the limit and who will be retried."""
    transient = [r for r in records if is_transient(r.get("status", ""))]
    return {
        "retry_limit": MAX_ATTEMPTS,
        "environment_failures": len(transient),
        "retried_next_run": sum(int(r.get("attempts", 1)) < MAX_ATTEMPTS for r in transient),
    }

"""Atomic command outputs: a run writes into a scratch folder beside ``--out`` and moves its files
into place only when it succeeded.

Before this, an ``infer`` stopped at its timeout left ``sequence.py``, ``sequence.json`` and
``steps/00.step`` without a ``result.json``, and an earlier run's ``result.json`` in the same folder
stayed as if it were current. Now each completed run lists what it wrote in `LISTING`; the
next run into the same folder first removes exactly those entries (never a file it did not write),
so after a failure the folder holds nothing that looks current, and after a success only the new
run's files.

One run writes into an ``--out`` at a time: a second one finds its lock (``.OUT.lock`` beside it,
an ``flock`` the kernel drops when the holder dies, removed when the run ends) and refuses in one
line, instead of two runs mixing their files. Whoever holds the lock also removes the scratch
folders that killed runs left.

`hash_output` is the one definition of an output's content (each file's size and SHA-1):
the pipeline's records name their outputs with it and training checks label shards against it.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from zonegraph.errors import ZoneGraphError
from zonegraph.isolation import Outcome

LISTING = ".zonegraph-outputs.json"
FileHashes = dict[str, list[Any]]  # file name relative to its output -> [size, sha1]


def run_staged(run: Callable[[Path], Outcome], out: Path) -> Outcome:
    """``run(scratch)`` and, if it succeeded, its files moved into ``out``; if it failed, the
    scratch folder and the outputs of the previous run into ``out`` are removed."""
    out = Path(os.path.abspath(out))
    out.parent.mkdir(parents=True, exist_ok=True)
    with writer_lock(out):
        for stale in out.parent.glob(f".{out.name}.partial-*"):  # of runs that were killed
            shutil.rmtree(stale, ignore_errors=True)
        scratch = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
        try:
            outcome = run(scratch)
            _remove_listed(out)
            if outcome.ok:
                _move_into(scratch, out)
            return outcome
        finally:
            shutil.rmtree(scratch, ignore_errors=True)


@contextmanager
def writer_lock(out: Path) -> Iterator[None]:
    """Hold ``out``'s lock for the block.

    Raises:
        ZoneGraphError: another run holds it (``invalid_input``: the command's input is the folder)."""
    path = out.parent / f".{out.name}.lock"
    while True:
        handle = open(path, "a")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            raise ZoneGraphError(str(out), "another zonegraph run is writing this folder") from None
        if _same_file(handle, path):
            break
        handle.close()  # the holder removed it between our open and our lock: take the new one
    try:
        yield
    finally:
        path.unlink(missing_ok=True)  # nothing of the lock stays beside the user's folder
        handle.close()


def _same_file(handle: IO[str], path: Path) -> bool:
    try:
        return os.fstat(handle.fileno()).st_ino == os.stat(path).st_ino
    except FileNotFoundError:
        return False


def _remove_listed(out: Path) -> None:
    """Remove what the last completed run wrote into ``out``, as its listing names it."""
    listing = out / LISTING
    try:
        names = json.loads(listing.read_text())["names"]
    except (OSError, ValueError, KeyError, TypeError):
        return
    for name in names:
        if isinstance(name, str) and name and Path(name).name == name:  # an entry of out, no path
            _remove(out / name)
    listing.unlink(missing_ok=True)


def _move_into(scratch: Path, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(p.name for p in scratch.iterdir())
    for name in names:
        _remove(out / name)
        os.replace(scratch / name, out / name)
    (out / LISTING).write_text(json.dumps({"names": names}))


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


def write_record(out: Path, name: str, text: str) -> None:
    """Write one file into ``out`` as the whole output of a run (a failed part's ``error.json``),
    listed so that the next run replaces it like any other output."""
    with writer_lock(Path(os.path.abspath(out))):
        _write_record(out, name, text)


def _write_record(out: Path, name: str, text: str) -> None:
    _remove_listed(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / name).write_text(text)
    (out / LISTING).write_text(json.dumps({"names": [name]}))


def _files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    if not path.is_dir():
        return []
    return sorted(f for f in path.rglob("*") if f.is_file() and "__pycache__" not in f.parts)


def hash_output(path: str | Path) -> FileHashes:
    """Every file of an output (one file or a folder) with its size and SHA-1; empty when absent."""
    root = Path(path)
    hashes: FileHashes = {}
    for f in _files(root):
        digest = hashlib.sha1()
        with open(f, "rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
        name = "." if f == root else str(f.relative_to(root))
        hashes[name] = [f.stat().st_size, digest.hexdigest()]
    return hashes

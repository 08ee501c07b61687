"""Many parts in one process: ``zonegraph infer`` and ``zonegraph build`` over files and folders.

The caller imports the geometry kernel once; each part then runs in a forked child
(`zonegraph.isolation.run_isolated`) that inherits those modules, so a part costs its own work
and a fork instead of a fresh interpreter's seconds of imports. One bad part becomes a row with its
status and one-line reason, and the batch goes on. This module itself imports nothing heavy.
"""

from __future__ import annotations

import json
import sys
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from zonegraph.errors import InputError, file_problem
from zonegraph.isolation import Outcome
from zonegraph.outputs import run_staged, write_record
from zonegraph.status import Status

PART_SUFFIXES = (".step", ".stp", ".brep", ".json")


@dataclass(frozen=True)
class Part:
    """One target of a batch and the folder its outputs go to (``--out/<name>``)."""

    name: str
    path: Path


@dataclass(frozen=True)
class Column:
    """A per-part figure of the summary table: its key in the job's row fields, header, format."""

    key: str
    header: str
    spec: str


@dataclass(frozen=True)
class BatchJob:
    """What a batch runs per part and how a result becomes a row.

    ``run`` gets the target and its output folder and returns the isolated outcome; ``describe``
    turns a successful outcome's value into the row's ``status``, its columns' values and
    optionally its ``reason``."""

    command: str
    run: Callable[[Path, Path], Outcome]
    describe: Callable[[Any], dict[str, Any]]
    columns: tuple[Column, ...]


@dataclass
class PartRow:
    """One part's line of the summary table and of ``summary.json``."""

    name: str
    target: str
    status: Status
    ok: bool
    reason: str = ""
    seconds: float = 0.0
    values: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        row = asdict(self)
        return {**{k: v for k, v in row.items() if k != "values"}, **self.values}


def is_batch(targets: Sequence[str]) -> bool:
    """Several targets, or a folder: outputs go to ``--out/<name>``. One file keeps the old layout,
    ``--out`` being its own folder, so single-part scripts see no change."""
    return len(targets) != 1 or Path(targets[0]).is_dir()


def collect_parts(targets: Sequence[str]) -> list[Part]:
    """The parts named on the command line, in order: files as given, a folder as its part files
    (sorted). A missing path or a folder without part files stays, to fail as its own row."""
    paths: list[Path] = []
    for target in map(Path, targets):
        paths.extend(_folder_parts(target) if target.is_dir() else [target])
    return name_parts(paths)


def _folder_parts(folder: Path) -> list[Path]:
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in PART_SUFFIXES)
    return files or [folder]


def name_parts(paths: Sequence[Path]) -> list[Part]:
    """Each part's folder name: its file stem, or its file name where two files share a stem
    (``Couch.json`` and ``Couch.step`` go to ``Couch.json/`` and ``Couch.step/``, so each folder
    says which file it holds); a name still taken (one file named twice) gets ``_2``, ``_3``...
    after its stem: the same names for the same command."""
    stems = Counter(path.stem for path in paths)
    taken: set[str] = set()
    parts = []
    for path in paths:
        suffix = "" if stems[path.stem] == 1 else path.suffix
        name, n = path.stem + suffix, 1
        while name in taken:
            n += 1
            name = f"{path.stem}_{n}{suffix}"
        taken.add(name)
        parts.append(Part(name, path))
    return parts


def unrunnable(path: Path) -> str | None:
    """Why a part cannot start (checked before any kernel import), or None."""
    if path.is_dir():  # a folder stands for its part files: here it had none
        return f"no {', '.join(PART_SUFFIXES)} files in the folder"
    return file_problem(path)


def run_batch(job: BatchJob, parts: Sequence[Part], out: Path) -> list[PartRow]:
    """Run every part under ``out`` with a progress bar on stderr; write ``out/summary.json`` and
    print the summary table. A failed part's folder gets ``error.json`` (status and reason)."""
    from tqdm import tqdm  # here, not at the top: ``zonegraph --help`` need not load it

    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows = []
    with tqdm(parts, desc=job.command, unit="part", file=sys.stderr) as bar:
        for part in bar:
            bar.set_postfix_str(part.name, refresh=True)
            rows.append(_run_part(job, part, out / part.name))
            if not rows[-1].ok:
                bar.write(f"zonegraph: error: {part.path}: {rows[-1].status}: {rows[-1].reason}", sys.stderr)
    total = totals(job, rows, time.perf_counter() - t0)
    summary = {"command": job.command, "parts": [r.to_dict() for r in rows], "totals": total}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(format_table(job, rows, total, out))
    return rows


def _run_part(job: BatchJob, part: Part, out: Path) -> PartRow:
    reason = unrunnable(part.path)
    if reason:
        outcome = Outcome(InputError.status, reason=reason)
    else:
        outcome = run_staged(lambda scratch: job.run(part.path, scratch), out)
    if outcome.ok:
        values = job.describe(outcome.value)
        status = Status(values.pop("status"))
        reason = str(values.pop("reason", ""))  # why a part that ran is not exact, say
        return PartRow(part.name, str(part.path), status, True, reason, round(outcome.seconds, 4), values)
    error = {"target": str(part.path), "status": outcome.status, "reason": outcome.reason}
    if outcome.detail:
        error["traceback"] = outcome.detail
    write_record(out, "error.json", json.dumps(error, indent=1))
    return PartRow(
        part.name, str(part.path), outcome.status, False, outcome.reason, round(outcome.seconds, 4)
    )


def totals(job: BatchJob, rows: Sequence[PartRow], wall_s: float) -> dict[str, Any]:
    """Counts by status, seconds, and each column's mean over the parts that ran."""
    done = [r for r in rows if r.ok]
    means = {
        f"mean_{c.key}": sum(r.values[c.key] for r in done) / len(done) if done else None for c in job.columns
    }
    return {
        "parts": len(rows),
        "ok": len(done),
        "failed": len(rows) - len(done),
        "by_status": dict(Counter(r.status for r in rows)),
        "part_seconds": round(sum(r.seconds for r in rows), 3),
        "wall_seconds": round(wall_s, 3),
        "seconds_per_part": round(wall_s / len(rows), 3) if rows else None,
        **means,
    }


def format_table(job: BatchJob, rows: Sequence[PartRow], total: dict[str, Any], out: Path) -> str:
    """The summary as aligned text: one line per part, then the totals."""
    width = max([4, *(len(r.name) for r in rows)])
    head = f"{'part':<{width}}  {'status':<15}" + "".join(f" {c.header:>10}" for c in job.columns)
    lines = [head + f" {'seconds':>8}  reason"]
    for r in rows:
        cells = "".join(f" {_cell(r.values.get(c.key), c.spec):>10}" for c in job.columns)
        reason = " ".join(r.reason.split())  # one line, whatever the kernel's message held
        lines.append(f"{r.name:<{width}}  {r.status:<15}{cells} {r.seconds:8.2f}  {reason}".rstrip())
    by_status = ", ".join(f"{k} {v}" for k, v in sorted(total["by_status"].items()))
    lines.append(
        f"{total['parts']} parts: {total['ok']} ran, {total['failed']} failed ({by_status}); "
        f"{total['part_seconds']:.1f} s in parts, {total['wall_seconds']:.1f} s wall -> {out}"
    )
    return "\n".join(lines)


def _cell(value: Any, spec: str) -> str:
    return "-" if value is None else format(value, spec)

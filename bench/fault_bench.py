"""Faults injected into a small pipeline project, each trial checked against an uninterrupted run.

    python -m bench.fault_bench [--designs 6] [--trials 200] [--seed 0] [--out bench_out/faults]

A reference run replays ``--designs`` synthetic designs and builds their zone graphs with the
stages' own job bodies and runner (``pipelines.runner.run_jobs`` on the stages' local cluster).
Each trial copies that project, injects one seeded fault and runs both stages again (twice where
the fault is a killed child, as a user would rerun), then compares every design with the reference:

- ``kill_child``: a design's child is killed (SIGKILL) after writing half of its outputs;
- ``truncate`` / ``garble`` / ``delete``: one stored file of one design (the replay's B-reps and
  record, the graph's Parquet tables, ``zones.brep`` and record) cut to a seeded length, 64 bytes
  changed, or removed;
- ``writers``: two runs finishing into the same ``--out`` at once (``zonegraph.outputs``).

Printed: faults by kind, survived (every design as in the reference), records lost (ok in the
reference, not ok now), stale (a reused record whose files differ from the reference's), wrong (an
ok record whose values differ), and for damaged files whether the damage was detected (the design
recomputed). Goal: 0 lost, 0 stale, 0 wrong, every corruption detected.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import threading
from collections import defaultdict
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
from distributed import Client

from pipelines.cluster import dask_client
from pipelines.params import DaskParams
from pipelines.records import hash_output
from pipelines.replay import replay_design
from pipelines.runner import Job, code_fingerprint, fingerprint, run_jobs
from zonegraph.configs import BuildConfig
from zonegraph.data.synthetic import design_seed, generate_design, synthetic_id
from zonegraph.errors import InputError
from zonegraph.isolation import Outcome
from zonegraph.jobs import build_and_save
from zonegraph.outputs import run_staged
from zonegraph.status import Status
from zonegraph.zones.storage import load_zone_graph

CONFIG = BuildConfig(samples=16)
VOLATILE = {
    "seconds",
    "attempts",
    "version",
    "outputs",
    "fingerprint",
    "build_s",
    "replay_seconds",
    "brep_dir",
}
FILE_FAULTS = ("truncate", "garble", "delete")


@dataclass
class Tally:
    faults: int = 0
    survived: int = 0
    lost: int = 0
    stale: int = 0
    wrong: int = 0
    damaged: int = 0
    detected: int = 0
    notes: list[str] = field(default_factory=list)


def _killing(flag: str, fn: Any, *args: Any) -> Any:
    """A job body that, while ``flag`` exists, writes its outputs, cuts one in half and dies."""
    result = fn(*args)
    if os.path.exists(flag):
        os.unlink(flag)
        out = Path(args[1])
        files = sorted(p for p in (out.rglob("*") if out.is_dir() else [out]) if p.is_file())
        if files:
            files[0].write_bytes(files[0].read_bytes()[: files[0].stat().st_size // 2])
        os.kill(os.getpid(), signal.SIGKILL)
    return result


def _jobs(project: Path, designs: list[str], kill: dict[str, str]) -> tuple[list[Job], list[Job]]:
    replay_code, graph_code = code_fingerprint("replay"), code_fingerprint("zonegraphs")
    replays, graphs = [], []
    for d in designs:
        path, breps = str(project / "json" / f"{d}.json"), str(project / "replay" / d)
        flag = kill.get(f"replay/{d}", str(project / "no-flag"))
        args = (flag, replay_design, path, breps)
        replays.append(
            Job(d, fingerprint(replay_code, files=(path,)), args, outputs=(breps,), inputs=(path,))
        )
        brep, graph = f"{breps}/final.brep", str(project / "graphs" / d)
        flag = kill.get(f"graphs/{d}", str(project / "no-flag"))
        fp = fingerprint(graph_code, repr(CONFIG), files=(brep,))
        graphs.append(
            Job(d, fp, (flag, build_and_save, brep, graph, CONFIG), outputs=(graph,), inputs=(brep,))
        )
    return replays, graphs


def run_project(
    project: Path, designs: list[str], client: Client, kill: dict[str, str] | None = None
) -> dict:
    """Both stages on ``project``; the records of each by design, and how many were recomputed."""
    before = {p: p.stat().st_mtime_ns for p in project.glob("records-*/*.json")}
    replays, _ = _jobs(project, designs, kill or {})
    out = {"replay": run_jobs(_killing, replays, project / "records-replay", client, 60, "replay")}
    ok = {r["design_id"] for r in out["replay"] if r["status"] == Status.OK}
    _, graphs = _jobs(project, designs, kill or {})  # fingerprints of the B-reps the replay left
    todo = [j for j in graphs if j.key in ok]
    out["graphs"] = run_jobs(_killing, todo, project / "records-graphs", client, 120, "zonegraphs")
    after = {p: p.stat().st_mtime_ns for p in project.glob("records-*/*.json")}
    out["recomputed"] = sum(before.get(p) != t for p, t in after.items())
    return out


def _values(record: dict) -> dict:
    """A record's values less its bookkeeping and timings."""
    return {k: v for k, v in record.items() if k not in VOLATILE and not k.endswith("_s")}


def compare(project: Path, reference: Path, ref: dict, now: dict) -> tuple[int, int, int]:
    """(lost, stale, wrong) of a trial's final records against the reference run's."""
    lost = stale = wrong = 0
    for stage, folder in (("replay", "replay"), ("graphs", "graphs")):
        mine = {r["design_id"]: r for r in now[stage]}
        for r in ref[stage]:
            m = mine.get(r["design_id"])
            if m is None or m["status"] != Status.OK:
                lost += r["status"] == Status.OK
                continue
            if _values(m) != _values(r):
                wrong += 1
            stale += not _same_files(
                folder, project / folder / r["design_id"], reference / folder / r["design_id"]
            )
    return lost, stale, wrong


def _same_files(stage: str, mine: Path, theirs: Path) -> bool:
    """The same B-rep bytes; for a zone graph the same arrays and metadata (its build timings,
    kept in the metadata, differ from run to run)."""
    if stage != "graphs":
        return hash_output(mine) == hash_output(theirs)
    try:
        a, b = load_zone_graph(mine), load_zone_graph(theirs)
    except InputError:
        return False
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "solids":
            same = len(x or []) == len(y or [])
        elif f.name == "info":
            same = _values(x) == _values(y)
        elif isinstance(x, np.ndarray):
            same = x.shape == y.shape and bool(np.array_equal(x, y, equal_nan=x.dtype.kind == "f"))
        else:
            same = x == y
        if not same:
            return False
    return True


def _damage(path: Path, kind: str, rng: np.random.Generator) -> None:
    data = path.read_bytes()
    if kind == "delete":
        path.unlink()
    elif kind == "truncate":
        path.write_bytes(data[: int(rng.integers(0, max(len(data), 1)))])
    else:
        garbled = bytearray(data)
        n = min(64, len(garbled))
        at = int(rng.integers(0, len(garbled) - n + 1))
        noise = rng.integers(1, 256, n, dtype=np.uint8)
        for i in range(n):
            garbled[at + i] ^= int(noise[i])  # never zero: every byte really changes
        path.write_bytes(bytes(garbled))


def _stored_files(project: Path, design: str) -> list[Path]:
    files = sorted((project / "replay" / design).glob("*.brep")) + sorted(
        (project / "graphs" / design).glob("*")
    )
    return files + [
        project / "records-replay" / f"{design}.json",
        project / "records-graphs" / f"{design}.json",
    ]


def _writers_trial(root: Path, i: int) -> tuple[bool, str]:
    """Two runs into one ``--out`` at once: one refused or both in turn, never a mixed folder."""
    out = root / f"writers-{i}" / "out"
    barrier = threading.Barrier(2)
    results: list[str] = []

    def run(tag: str) -> None:
        def body(scratch: Path) -> Outcome:
            barrier.wait(5)
            for name in ("result.json", "sequence.py", "steps"):
                (scratch / name).write_text(tag)
            return Outcome(Status.OK)

        try:
            run_staged(body, out)
            results.append(tag)
        except Exception as exc:  # noqa: BLE001 - the refusal is the expected outcome of one of them
            results.append(f"refused: {exc}")
            try:
                barrier.wait(5)
            except threading.BrokenBarrierError:
                pass

    threads = [threading.Thread(target=run, args=(t,)) for t in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    tags = {(out / n).read_text() for n in ("result.json", "sequence.py", "steps") if (out / n).exists()}
    return len(tags) == 1, ", ".join(sorted(results))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--designs", type=int, default=6)
    p.add_argument("--trials", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, default=Path("bench_out/faults"))
    args = p.parse_args()
    table = run_bench(args.designs, args.trials, args.seed, args.out.resolve())
    print(format_table(table))


def run_bench(n_designs: int, trials: int, seed: int, root: Path) -> dict[str, Tally]:
    shutil.rmtree(root, ignore_errors=True)
    reference = root / "reference"
    (reference / "json").mkdir(parents=True)
    designs = [synthetic_id(i) for i in range(n_designs)]
    for i, d in enumerate(designs):
        (reference / "json" / f"{d}.json").write_text(json.dumps(generate_design(d, design_seed(2021, i))))
    rng = np.random.default_rng(seed)
    tallies: dict[str, Tally] = defaultdict(Tally)
    with dask_client(DaskParams(n_workers=2)) as client:  # the stages' own local cluster
        ref = run_project(reference, designs, client)
        kinds = ["kill_child", *FILE_FAULTS, "writers"]
        for i in range(trials):
            kind = kinds[int(rng.integers(len(kinds)))]
            tally = tallies[kind]
            tally.faults += 1
            if kind == "writers":
                fine, said = _writers_trial(root, i)
                tally.survived += fine
                tally.wrong += not fine
                if not fine:
                    tally.notes.append(f"trial {i}: mixed folder ({said})")
                continue
            project = root / f"trial-{i}"
            shutil.copytree(reference, project)
            design = designs[int(rng.integers(len(designs)))]
            if kind == "kill_child":
                stage = ("replay", "graphs")[int(rng.integers(2))]
                flag = project / f"kill-{i}"
                flag.touch()
                for folder in ("replay", "graphs"):  # the design is still to be computed
                    (project / f"records-{folder}" / f"{design}.json").unlink(missing_ok=True)
                first = run_project(project, designs, client, {f"{stage}/{design}": str(flag)})
                crashed = any(r["status"] == Status.CRASH for s in ("replay", "graphs") for r in first[s])
                if not crashed:
                    tally.notes.append(f"trial {i}: the child was not killed")
                now = run_project(project, designs, client)
            else:
                files = _stored_files(project, design)
                target = files[int(rng.integers(len(files)))]
                _damage(target, kind, rng)
                now = run_project(project, designs, client)
                tally.damaged += 1
                tally.detected += now["recomputed"] > 0
                if not now["recomputed"]:
                    tally.notes.append(f"trial {i}: {kind} of {target.relative_to(project)} not detected")
            lost, stale, wrong = compare(project, reference, ref, now)
            tally.lost, tally.stale, tally.wrong = tally.lost + lost, tally.stale + stale, tally.wrong + wrong
            tally.survived += not (lost or stale or wrong)
            if lost or stale or wrong:
                tally.notes.append(f"trial {i}: {kind} {design}: lost {lost}, stale {stale}, wrong {wrong}")
            shutil.rmtree(project, ignore_errors=True)
    return dict(tallies)


def format_table(tallies: dict[str, Tally]) -> str:
    lines = [
        "| fault | faults | survived | lost | stale | wrong | corruptions detected |",
        "|---|---|---|---|---|---|---|",
    ]
    total = Tally()
    for kind, t in sorted(tallies.items()):
        detected = f"{t.detected}/{t.damaged}" if t.damaged else "-"
        lines.append(
            f"| {kind} | {t.faults} | {t.survived} | {t.lost} | {t.stale} | {t.wrong} | {detected} |"
        )
        for name in ("faults", "survived", "lost", "stale", "wrong", "damaged", "detected"):
            setattr(total, name, getattr(total, name) + getattr(t, name))
    lines.append(
        f"| all | {total.faults} | {total.survived} | {total.lost} | {total.stale} | {total.wrong} | "
        f"{total.detected}/{total.damaged} |"
    )
    notes = [n for t in tallies.values() for n in t.notes]
    return "\n".join(lines + notes)


if __name__ == "__main__":
    main()

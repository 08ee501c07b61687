"""Faults injected into a small pipeline project, each trial checked against an uninterrupted run.

    python -m bench.fault_bench [--designs 6] [--trials 200] [--seed 0] [--out bench_out/faults]
        [--kinds KIND ...] [--cycle]

A reference run replays ``--designs`` synthetic designs, builds their zone graphs and labels them
with the stages' own job bodies and runner (``pipelines.runner.run_jobs`` on the stages' local
cluster; the labels job maps the ground truth first, as the ground_truth stage does), and converts
a small build123d corpus with the generate stage's job body. Each trial copies that project,
injects one seeded fault and runs the stages again (twice where the fault is a kill or a hostile
script, as a user would rerun), then compares every design with the reference:

- ``kill_child``: a design's child is killed (SIGKILL) after writing half of its outputs;
- ``kill_worker``: the same, but the child kills its Dask worker first (the worker's nanny starts
  a new one and the scheduler reschedules its tasks);
- ``truncate`` / ``garble`` / ``delete``: one stored file of one design (the replay's B-reps, the
  graph's Parquet tables and ``zones.brep``, the label shards, and each stage's record) cut to a
  seeded length, 64 bytes changed, or removed; a damaged label shard must also be left out of
  what training reads (``training.shards``) until the labels stage rewrites it;
- ``writers``: two runs finishing into the same ``--out`` at once (``zonegraph.outputs``);
- ``convert_truncate`` / ``convert_garbage`` / ``convert_loop`` / ``convert_alloc`` /
  ``convert_exit``: a hostile batch beside the corpus's good one (a truncated copy, 64 garbled
  bytes, a model that never returns, one that allocates without bound, one that calls
  ``os._exit``): each of its designs must end as a record with a status and a reason (the expected
  status where the fault decides it), the good designs kept as they were, and a rerun must resume
  (only the environment's failures, which are retried, run again).

Printed: faults by kind, survived (every design as in the reference), records lost (ok in the
reference, not ok now), stale (a reused record whose files differ from the reference's), wrong (an
ok record whose values differ, or a hostile design without the record it should have), and for
damaged files whether the damage was detected (the design recomputed). Goal: 0 lost, 0 stale,
0 wrong, every corruption detected.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import threading
import warnings
from collections import defaultdict
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
from distributed import Client

from pipelines.cluster import dask_client
from pipelines.generate import convert_to_json
from pipelines.params import DaskParams, LabelsParams, ReplayParams, ZoneGraphParams
from pipelines.records import hash_output, is_transient
from pipelines.replay import replay_design
from pipelines.runner import Job, code_fingerprint, fingerprint, run_jobs
from training.shards import label_shards
from zonegraph.configs import BuildConfig
from zonegraph.data.b123d import batch_entries
from zonegraph.data.synthetic import design_seed, generate_design, synthetic_id
from zonegraph.errors import InputError
from zonegraph.isolation import Outcome
from zonegraph.jobs import build_and_save, ground_truth_and_coverage, label_and_save
from zonegraph.outputs import run_staged
from zonegraph.status import Status
from zonegraph.testing.batches import block_model, plate_model
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
CONVERT_FAULTS = ("convert_truncate", "convert_garbage", "convert_loop", "convert_alloc", "convert_exit")
KINDS = ("kill_child", "kill_worker", *FILE_FAULTS, "writers", *CONVERT_FAULTS)
STAGES = ("replay", "graphs", "labels")
# The stages' own defaults (params.yaml's): a limit tighter than the pipeline's would count a slow
# job on a loaded machine (a 414-zone design labels in 70 s beside other work) as a lost record.
STAGE_TIMEOUTS_S = {
    "replay": ReplayParams().timeout_s,
    "graphs": ZoneGraphParams().timeout_s,
    "labels": LabelsParams().timeout_s,
}
CONVERT_TIMEOUT_S = 8.0  # the looping model's timeout (the good ones are reused, never rerun)
CONVERT_MEMORY_MB = 1024  # the allocating model's limit


def good_models(prefix: str) -> str:
    """A batch of two good models, ``model_<prefix>plate`` and ``model_<prefix>block``."""
    return "from build123d import *\n" + plate_model(f"{prefix}plate") + block_model(f"{prefix}block")


HOSTILE_MODELS = {
    "convert_loop": "def model_spins():\n    while True:\n        pass\n",
    "convert_alloc": (
        "def model_grows():\n    hoard = []\n    while True:\n        hoard.append(bytes(64 << 20))\n"
    ),
    "convert_exit": "import os\n\n\ndef model_exits():\n    os._exit(0)\n",
}
EXPECTED = {
    "convert_loop": Status.TIMEOUT,
    "convert_alloc": Status.OUT_OF_MEMORY,
    "convert_exit": Status.CRASH,
}


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


def _killing(flag: str, outputs: tuple[str, ...], fn: Any, *args: Any) -> Any:
    """A job body that, while ``flag`` exists, writes its outputs, cuts one in half and dies;
    when the flag says ``worker`` it kills its Dask worker first (the parent waiting for it)."""
    result = fn(*args)
    if os.path.exists(flag):
        mode = Path(flag).read_text()
        os.unlink(flag)
        files = sorted(
            f for o in map(Path, outputs) for f in (o.rglob("*") if o.is_dir() else [o]) if f.is_file()
        )
        if files:
            files[0].write_bytes(files[0].read_bytes()[: files[0].stat().st_size // 2])
        if mode == "worker":
            os.kill(os.getppid(), signal.SIGKILL)
        os.kill(os.getpid(), signal.SIGKILL)
    return result


def gt_and_labels(brep_dir: str, graph_dir: str, operations: str, design_id: str, out_dir: str) -> dict:
    """The ground_truth stage's job body on the saved graph, then the labels stage's, on a design
    whose ground truth reaches its target (the labels stage's candidates)."""
    gt = ground_truth_and_coverage(brep_dir, graph_dir, operations.split(","), (1,), 0.5, full_graph=False)
    name = "simplified" if "simplified_status" in gt else "full"
    if not gt[f"{name}_reaches_target"]:
        return {"labelled": False}
    rows = [
        {
            "operation": s["operation"],
            "gt_zones": s["gt_zones"],
            "captured": s["captured_l1"],
            "reason": s["reason"],
        }
        for s in gt["steps"]
    ]
    return {"labelled": True, **label_and_save(graph_dir, rows, design_id, "train", out_dir)}


def _job(project: Path, stage: str, design: str, kill: dict[str, str], *parts: Any, **kw: Any) -> Job:
    """A stage's job for one design, its body wrapped in `_killing`."""
    flag = kill.get(f"{stage}/{design}", str(project / "no-flag"))
    fn, args, outputs = kw.pop("body"), kw.pop("args"), kw["outputs"]
    return Job(design, fingerprint(*parts, files=kw["inputs"]), (flag, outputs, fn, *args), **kw)


def _jobs(project: Path, stage: str, designs: list[str], kill: dict[str, str], previous: dict) -> list[Job]:
    code = code_fingerprint({"graphs": "zonegraphs"}.get(stage, stage))
    jobs = []
    for d in designs:
        path, breps = str(project / "json" / f"{d}.json"), str(project / "replay" / d)
        brep, graph = f"{breps}/final.brep", str(project / "graphs" / d)
        if stage == "replay":
            spec = {"body": replay_design, "args": (path, breps), "outputs": (breps,), "inputs": (path,)}
            jobs.append(_job(project, stage, d, kill, code, **spec))
        elif stage == "graphs":
            spec = {
                "body": build_and_save,
                "args": (brep, graph, CONFIG),
                "outputs": (graph,),
                "inputs": (brep,),
            }
            jobs.append(_job(project, stage, d, kill, code, repr(CONFIG), **spec))
        else:
            labels = project / "labels"
            shards = tuple(str(labels / k / f"{d}.parquet") for k in ("proposals", "steps"))
            ops = previous["replay"][d]["operations"]
            args = (breps, graph, ops, d, str(labels))
            spec = {"body": gt_and_labels, "args": args, "outputs": shards, "inputs": (graph,)}
            jobs.append(_job(project, stage, d, kill, code, ops, **spec))
    return jobs


def records_dir(project: Path, stage: str) -> Path:
    return project / "labels" / "records" if stage == "labels" else project / f"records-{stage}"


def _record_files(project: Path) -> list[Path]:
    return [p for s in STAGES for p in records_dir(project, s).glob("*.json")]


def run_project(
    project: Path, designs: list[str], client: Client, kill: dict[str, str] | None = None
) -> dict:
    """The three stages on ``project``, each on the designs the one before left ok; the records
    of each by design, and how many were recomputed."""
    before = {p: p.stat().st_mtime_ns for p in _record_files(project)}
    out: dict[str, Any] = {}
    todo, ok = designs, {}
    for stage, timeout in STAGE_TIMEOUTS_S.items():
        jobs = _jobs(project, stage, todo, kill or {}, ok)
        out[stage] = run_jobs(_killing, jobs, records_dir(project, stage), client, timeout, stage)
        ok[stage] = {r["design_id"]: r for r in out[stage] if r["status"] == Status.OK}
        todo = [d for d in todo if d in ok[stage]]
    after = {p: p.stat().st_mtime_ns for p in _record_files(project)}
    out["recomputed"] = sum(before.get(p) != t for p, t in after.items())
    return out


def _values(record: dict) -> dict:
    """A record's values less its bookkeeping and timings."""
    return {k: v for k, v in record.items() if k not in VOLATILE and not k.endswith("_s")}


def compare(project: Path, reference: Path, ref: dict, now: dict) -> tuple[int, int, int, list[str]]:
    """(lost, stale, wrong) of a trial's final records against the reference run's, and which
    (``stage/design: what``)."""
    lost = stale = wrong = 0
    which: list[str] = []
    for stage in STAGES:
        mine = {r["design_id"]: r for r in now[stage]}
        for r in ref[stage]:
            m = mine.get(r["design_id"])
            where = f"{stage}/{r['design_id']}"
            if m is None or m["status"] != Status.OK:
                lost += r["status"] == Status.OK
                said = f"{m['status']}: {m.get('reason', '')}" if m else "no record"
                which += [f"{where}: lost ({said})"] if r["status"] == Status.OK else []
                continue
            if _values(m) != _values(r):
                wrong += 1
                which.append(f"{where}: wrong")
            if not _same_files(stage, project, reference, r["design_id"]):
                stale += 1
                which.append(f"{where}: stale")
    return lost, stale, wrong, which


def _same_files(stage: str, project: Path, reference: Path, design: str) -> bool:
    """The same B-rep bytes; the same label tables; for a zone graph the same arrays and metadata
    (its build timings, kept in the metadata, differ from run to run)."""
    if stage == "replay":
        return hash_output(project / "replay" / design) == hash_output(reference / "replay" / design)
    if stage == "labels":
        return all(
            _same_table(p / "labels" / k / f"{design}.parquet" for p in (project, reference))
            for k in ("proposals", "steps")
        )
    try:
        a, b = load_zone_graph(project / "graphs" / design), load_zone_graph(reference / "graphs" / design)
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


def _same_table(paths: Any) -> bool:
    mine, theirs = paths
    if not theirs.exists():
        return not mine.exists()
    try:
        a, b = pq.read_table(mine), pq.read_table(theirs)
    except (OSError, ValueError):
        return False
    timings = [c for c in a.column_names if c == "seconds" or c.endswith("_s")]  # differ run to run
    return bool(a.drop_columns(timings).equals(b.drop_columns(timings)))


def _damage(path: Path, kind: str, rng: np.random.Generator) -> None:
    data = path.read_bytes()
    if kind == "delete":
        path.unlink()
    elif kind == "truncate":
        path.write_bytes(data[: int(rng.integers(0, max(len(data), 1)))])
    else:
        path.write_bytes(_garbled(data, rng))


def _garbled(data: bytes, rng: np.random.Generator) -> bytes:
    garbled = bytearray(data)
    n = min(64, len(garbled))
    at = int(rng.integers(0, len(garbled) - n + 1))
    noise = rng.integers(1, 256, n, dtype=np.uint8)
    for i in range(n):
        garbled[at + i] ^= int(noise[i])  # never zero: every byte really changes
    return bytes(garbled)


def _stored_files(project: Path, design: str) -> list[Path]:
    files = sorted((project / "replay" / design).glob("*.brep")) + sorted(
        (project / "graphs" / design).glob("*")
    )
    files += [
        f for k in ("proposals", "steps") if (f := project / "labels" / k / f"{design}.parquet").exists()
    ]
    return files + [records_dir(project, s) / f"{design}.json" for s in STAGES]


def _training_reads_damage(project: Path, target: Path, design: str) -> bool:
    """Whether training would read a label shard that is damaged (before the stage rewrites it)."""
    if target.parent.parent != project / "labels":
        return False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return design in label_shards(project / "labels").design_ids


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


# ---------------------------------------------------------------- convert


def _warm_convert() -> None:
    """build123d imported in the worker, so that each design's child inherits it (the generate
    stage's worker has it after its first design) and the memory limit measures the model alone."""
    import build123d  # noqa: F401


def convert_project(project: Path, client: Client) -> tuple[dict[str, dict], set[str]]:
    """The generate stage's conversion of ``project/corpus``: records by design, and the designs
    recomputed (their record rewritten)."""
    records = project / "convert_records"
    before = {p.stem: p.stat().st_mtime_ns for p in records.glob("*.json")}
    json_dir = project / "json"
    json_dir.mkdir(parents=True, exist_ok=True)
    code = code_fingerprint("generate")
    jobs = []
    for batch in sorted((project / "corpus").rglob("batch_*.py")):
        for e in batch_entries(batch, batch.parent.name):
            out = str(json_dir / f"{e.design_id}.json")
            jobs.append(
                Job(
                    e.design_id,
                    fingerprint(code, CONVERT_TIMEOUT_S, files=(batch,)),
                    (str(batch), e.design_id, out),
                    outputs=(out,),
                    inputs=(str(batch),),
                    outputs_optional=True,
                )
            )
    client.run(_warm_convert)
    done = run_jobs(
        convert_to_json, jobs, records, client, CONVERT_TIMEOUT_S, "convert", memory_mb=CONVERT_MEMORY_MB
    )
    after = {p.stem: p.stat().st_mtime_ns for p in records.glob("*.json")}
    return {r["design_id"]: r for r in done}, {d for d, t in after.items() if before.get(d) != t}


def _status(record: dict) -> str:
    """The design's status as the stage reports it: the converter's, else the child's."""
    if record["status"] != Status.OK:
        return str(record["status"])
    return str(record.get("convert_status") or Status.OK)


def _reason(record: dict) -> str:
    return record.get("convert_reason", "") if record["status"] == Status.OK else record.get("reason", "")


def _hostile_batch(kind: str, rng: np.random.Generator) -> bytes:
    if kind in HOSTILE_MODELS:  # a batch imports build123d (the converter records its extrude)
        return f"from build123d import *\n\n\n{HOSTILE_MODELS[kind]}".encode()
    text = good_models("h_").encode()
    if kind == "convert_truncate":
        return text[: int(rng.integers(0, len(text)))]
    return _garbled(text, rng)


def _convert_trial(
    reference: Path, project: Path, kind: str, client: Client, rng: np.random.Generator, ref: dict
) -> list[str]:
    """A hostile batch beside the good one, converted twice; what went wrong (empty: survived)."""
    shutil.copytree(reference, project)
    (project / "corpus" / "01_2ops" / "batch_002.py").write_bytes(_hostile_batch(kind, rng))
    problems = []
    first, ran = convert_project(project, client)
    hostile = sorted(set(first) - set(ref))
    if ran != set(hostile):
        problems.append(f"the first run recomputed {sorted(ran)}, not just the hostile {hostile}")
    for d in hostile:
        r = first[d]
        status, reason = _status(r), _reason(r)
        if status != Status.OK and not reason:
            problems.append(f"{d}: {status} without a reason")
        if kind in EXPECTED and status != EXPECTED[kind]:
            problems.append(f"{d}: {status} ({reason}), expected {EXPECTED[kind]}")
        if (project / "json" / f"{d}.json").exists() != (status == Status.OK):
            problems.append(
                f"{d}: {status}, and its JSON {'is missing' if status == Status.OK else 'exists'}"
            )
    again, rerun = convert_project(project, client)
    retried = {d for d in hostile if is_transient(first[d]["status"])}
    if rerun != retried:
        problems.append(f"the rerun recomputed {sorted(rerun)}, expected the retried {sorted(retried)}")
    for d, r in ref.items():
        if _values(again[d]) != _values(r):
            problems.append(f"{d}: its record changed")
        if hash_output(project / "json" / f"{d}.json") != hash_output(reference / "json" / f"{d}.json"):
            problems.append(f"{d}: its JSON changed")
    shutil.rmtree(project, ignore_errors=True)
    return problems


def _convert_reference(root: Path, client: Client) -> tuple[Path, dict]:
    reference = root / "convert-reference"
    folder = reference / "corpus" / "01_2ops"
    folder.mkdir(parents=True)
    (folder / "batch_001.py").write_text(good_models(""))
    ref, _ = convert_project(reference, client)
    bad = {d: _reason(r) for d, r in ref.items() if _status(r) != Status.OK}
    if bad:
        raise SystemExit(f"fault_bench: the good corpus did not convert: {bad}")
    return reference, ref


# ---------------------------------------------------------------- the benchmark


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--designs", type=int, default=6)
    p.add_argument("--trials", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, default=Path("bench_out/faults"))
    p.add_argument("--kinds", nargs="+", choices=KINDS, default=KINDS, help="the faults to draw from")
    p.add_argument("--cycle", action="store_true", help="each kind in turn instead of drawn")
    args = p.parse_args()
    table = run_bench(args.designs, args.trials, args.seed, args.out.resolve(), tuple(args.kinds), args.cycle)
    print(format_table(table))
    write_results(table, args.out / "results.json")


def write_results(tallies: dict[str, Tally], path: Path) -> None:
    """The tallies by kind, for ``python -m bench.figures fault`` (the docs' table)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({kind: asdict(t) for kind, t in sorted(tallies.items())}, indent=1) + "\n")


def _kill_trial(
    project: Path,
    designs: list[str],
    client: Client,
    kind: str,
    design: str,
    rng: np.random.Generator,
    i: int,
) -> tuple[dict, list[str]]:
    """A child (or its worker) killed while it writes a design's outputs, then a rerun."""
    stage = STAGES[int(rng.integers(len(STAGES)))]
    flag = project / f"kill-{i}"
    flag.write_text("worker" if kind == "kill_worker" else "child")
    for s in STAGES:  # the design is still to be computed
        (records_dir(project, s) / f"{design}.json").unlink(missing_ok=True)
    workers = set(client.scheduler_info()["workers"])
    first = run_project(project, designs, client, {f"{stage}/{design}": str(flag)})
    notes = []
    if flag.exists():
        notes.append(f"trial {i}: {stage}/{design} was not run with the kill flag")
    elif kind == "kill_child" and not any(r["status"] == Status.CRASH for s in STAGES for r in first[s]):
        notes.append(f"trial {i}: the child was not killed")
    elif kind == "kill_worker" and set(client.scheduler_info()["workers"]) >= workers:
        notes.append(f"trial {i}: the worker was not killed")
    return run_project(project, designs, client), notes


def run_bench(
    n_designs: int,
    trials: int,
    seed: int,
    root: Path,
    kinds: tuple[str, ...] = KINDS,
    cycle: bool = False,
) -> dict[str, Tally]:
    """``trials`` faults on ``n_designs`` designs, each of a kind drawn from ``kinds`` (seeded), or
    with ``cycle`` each kind in turn (a slice that shows every kind once)."""
    shutil.rmtree(root, ignore_errors=True)
    reference = root / "reference"
    (reference / "json").mkdir(parents=True)
    designs = [synthetic_id(i) for i in range(n_designs)]
    for i, d in enumerate(designs):
        (reference / "json" / f"{d}.json").write_text(json.dumps(generate_design(d, design_seed(2021, i))))
    rng = np.random.default_rng(seed)
    tallies: dict[str, Tally] = defaultdict(Tally)
    convert_ref: tuple[Path, dict] | None = None
    with dask_client(DaskParams(n_workers=2)) as client:  # the stages' own local cluster
        ref = run_project(reference, designs, client)
        for i in range(trials):
            drawn = int(rng.integers(len(kinds)))
            kind = kinds[i % len(kinds) if cycle else drawn]
            tally = tallies[kind]
            tally.faults += 1
            project = root / f"trial-{i}"
            if kind == "writers":
                fine, said = _writers_trial(root, i)
                tally.survived += fine
                tally.wrong += not fine
                if not fine:
                    tally.notes.append(f"trial {i}: mixed folder ({said})")
                continue
            if kind in CONVERT_FAULTS:
                convert_ref = convert_ref or _convert_reference(root, client)
                problems = _convert_trial(convert_ref[0], project, kind, client, rng, convert_ref[1])
                tally.survived += not problems
                tally.wrong += bool(problems)
                tally.notes += [f"trial {i}: {kind}: {p}" for p in problems]
                continue
            shutil.copytree(reference, project)
            design = designs[int(rng.integers(len(designs)))]
            notes: list[str] = []
            if kind == "kill_child":  # a fault not injected is not survived
                now, notes = _kill_trial(project, designs, client, kind, design, rng, i)
            elif kind == "kill_worker":  # a cluster of its own: a second kill on one cluster left no worker
                with dask_client(DaskParams(n_workers=2)) as fresh:
                    now, notes = _kill_trial(project, designs, fresh, kind, design, rng, i)
            else:
                files = _stored_files(project, design)
                target = files[int(rng.integers(len(files)))]
                _damage(target, kind, rng)
                if _training_reads_damage(project, target, design):
                    tally.wrong += 1
                    tally.notes.append(
                        f"trial {i}: training would read the damaged {target.relative_to(project)}"
                    )
                now = run_project(project, designs, client)
                tally.damaged += 1
                tally.detected += now["recomputed"] > 0
                if not now["recomputed"]:
                    tally.notes.append(f"trial {i}: {kind} of {target.relative_to(project)} not detected")
            tally.notes += notes
            lost, stale, wrong, which = compare(project, reference, ref, now)
            tally.lost, tally.stale, tally.wrong = tally.lost + lost, tally.stale + stale, tally.wrong + wrong
            tally.survived += not (lost or stale or wrong or notes)
            if lost or stale or wrong:
                tally.notes.append(f"trial {i}: {kind} {design}: {', '.join(which)}")
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

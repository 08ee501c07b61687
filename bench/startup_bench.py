"""Whole-process cost of one ``zonegraph build`` (and ``infer``) per part, beside the original.

    python -m bench.startup_bench [--designs data/designs/json] [--per-folder 3] [--seed 7]
                                  [--exclude FILE] [--budget 1] [--guide heuristic] [--no-infer]
                                  [--original DIR] [--freecad-python PY] [--original-deps DIR]
                                  [--timeout 600] [--server] [--out bench_out/startup]

The parts: ``--per-folder`` designs of each timeline folder of the build123d corpus (``../shared``),
drawn with ``--seed`` from those whose converted JSON is in ``--designs`` and whose id is not in
``--exclude`` (one id a line; a validation sample must never steer tuning), plus the Couch sample.
Each is replayed once to ``PART.step`` (centimetres declared), the input both sides read.

Each part then runs as its own process, as a user's single call does: ``python -m zonegraph
build PART.step`` (and ``infer PART.step --budget B --guide G``), cold (``ZONEGRAPH_NO_SERVER``),
measured by ``os.wait4``: CPU seconds (user + sys of the process and every child it reaped, so a
loaded machine does not inflate them), wall seconds and peak resident memory (the largest of the
process and its children). With ``--server`` a ``zonegraph server`` is started once (its start
measured apart) and each command runs again handed to it (the ``warm`` columns): the calling
process's CPU plus the call's child in the server, as the server reports its last call (its peak
resident memory counts the pages it shares with the server). The original
implementation (brownvc/zone-graphs on FreeCAD) runs the same way when ``--original`` names its
checkout and FreeCAD's Python module imports under ``--freecad-python`` (Debian's
``freecad-python3`` package, for the system's ``/usr/bin/python3``): one process that reads the STEP
file and partitions it with its ``SpaceSplitter``; otherwise that column is skipped with the reason.
The original imports trimesh, which Debian does not package: ``--original-deps`` names a folder put
on that interpreter's path (one holding a link to any trimesh will do). A process still running
after ``--timeout`` seconds is killed and its row says so (rc -9). Prints one row per part and
the medians; writes ``results.json`` and ``results.md``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from bench.corpus import CORPUS, require_corpus, write_results
from zonegraph.testing import SAMPLES

ROOT = Path(__file__).resolve().parents[1]
COUCH = "Couch.json"
FREECAD_PATHS = ("/usr/lib/freecad-python3/lib", "/usr/lib/freecad/lib")  # Debian's packages
# The original's zone-graph build on one STEP file, run by FreeCAD's Python in the checkout's src/.
ORIGINAL_DRIVER = """
import sys
sys.path[:0] = [{src!r}, *{paths!r}]
import FreeCAD  # before Part: FreeCAD 0.20's Part module crashes when imported first
import Part
from utils.space_splitter import SpaceSplitter
shape = Part.read({step!r})
print("zones", len(SpaceSplitter(shape).get_zone_solids()))
"""


@dataclass(frozen=True)
class Run:
    """One process: its exit status, CPU seconds (user + sys, children included), wall seconds and
    peak resident memory in MB."""

    rc: int
    cpu_s: float
    wall_s: float
    peak_mb: float
    tail: str = ""


def measure(cmd: list[str], cwd: Path, env: dict[str, str] | None = None, timeout: float = 600) -> Run:
    """``cmd`` as a child process, measured by ``wait4`` (its own and its reaped children's use),
    killed after ``timeout`` seconds (a partition that runs for hours must not stall the table)."""
    with tempfile.TemporaryFile() as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT)
        killer = threading.Timer(timeout, proc.kill)
        killer.start()
        _, status, use = os.wait4(proc.pid, 0)
        killer.cancel()
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        tail = out.read().decode(errors="replace").strip().splitlines()[-1:] or [""]
    return Run(proc.returncode, use.ru_utime + use.ru_stime, wall, use.ru_maxrss / 1024, tail[0][:200])


def draw_parts(designs: Path, per_folder: int, seed: int, exclude: set[str]) -> list[tuple[str, Path]]:
    """``(folder, design JSON)`` of ``per_folder`` converted designs per timeline folder, seeded."""
    from zonegraph.data.b123d import list_corpus

    by_folder: dict[str, list[str]] = {}
    for entry in list_corpus(CORPUS):
        if entry.design_id not in exclude and (designs / f"{entry.design_id}.json").is_file():
            by_folder.setdefault(entry.folder, []).append(entry.design_id)
    rng = random.Random(seed)
    parts = []
    for folder in sorted(by_folder):
        ids = sorted(by_folder[folder])
        parts += [(folder, designs / f"{i}.json") for i in rng.sample(ids, min(per_folder, len(ids)))]
    return parts + [("sample", SAMPLES / COUCH)]


def to_step(design: Path, folder: Path) -> Path:
    """The design's final shape as ``folder/<id>.step`` (the input both implementations read),
    replayed by ``zonegraph replay`` in its own process: a parent that had imported build123d would
    pass its peak memory on to every measured child (Linux keeps the high-water mark across exec)."""
    out = folder / f"{design.stem}_replay"
    cmd = [sys.executable, "-m", "zonegraph.cli", "replay", str(design), "--out", str(out)]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run(cmd, cwd=ROOT, env=env, check=True, capture_output=True)
    return (out / "final.step").rename(folder / f"{design.stem}.step")


def original_paths(args: argparse.Namespace) -> list[str]:
    """What the original's interpreter needs on its path besides the checkout's ``src``."""
    return [*FREECAD_PATHS, *([str(args.original_deps)] if args.original_deps else [])]


def original_problem(original: Path | None, python: str, paths: list[str]) -> str | None:
    """Why the original implementation cannot run here, or None."""
    if original is None:
        return "no --original checkout of brownvc/zone-graphs given"
    if not (original / "src" / "utils" / "space_splitter.py").is_file():
        return f"{original} is not a brownvc/zone-graphs checkout (no src/utils/space_splitter.py)"
    probe = f"import sys; sys.path[:0] = {paths!r}; import FreeCAD, Part, trimesh"
    try:
        proc = subprocess.run([python, "-c", probe], capture_output=True, text=True)
    except OSError as exc:
        return f"{python} cannot run: {exc.strerror}"
    if proc.returncode:
        last = (proc.stderr.strip().splitlines() or [f"exit {proc.returncode}"])[-1]
        return f"FreeCAD's Part or trimesh does not import under {python} ({last})"
    return None


@dataclass(frozen=True)
class Warm:
    """A running ``zonegraph server`` (its folder and socket) that warm calls are handed to."""

    folder: Path
    socket: str

    def env(self) -> dict[str, str]:
        return {**os.environ, "PYTHONPATH": str(ROOT), "ZONEGRAPH_SERVER_DIR": str(self.folder)}


def start_server(work: Path) -> tuple[Warm, dict]:
    """A server in a private folder of ``work``; its start measured: the starting command's own
    process, and the server's CPU and memory once it answers."""
    folder = work / "servers"
    cmd = [sys.executable, "-m", "zonegraph.cli", "server", "start", "--json"]
    with tempfile.TemporaryFile() as out:
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, env=Warm(folder, "").env(), stdout=out, check=True)
        wall = time.perf_counter() - t0
        out.seek(0)
        state = json.loads(out.read())
    start = {"wall_s": wall, "server_cpu_s": state["cpu_s"], "server_mb": state["peak_mb"]}
    return Warm(folder, state["socket"]), start


def measure_warm(cmd: list[str], warm: Warm, timeout: float) -> Run:
    """``cmd`` handed to the server: the calling process (``measure``) plus the call's child in
    the server (its CPU and peak resident memory, as the server's status reports its last call)."""
    from zonegraph.handoff import ask

    caller = measure(cmd, ROOT, warm.env(), timeout)
    state = ask("status", warm.socket)
    call = (state or {}).get("last_call") or {"cpu_s": math.nan, "peak_mb": math.nan}
    peak = max(caller.peak_mb, call["peak_mb"])
    return Run(caller.rc, caller.cpu_s + call["cpu_s"], caller.wall_s, peak, caller.tail)


def _warm_out(cmd: list[str]) -> list[str]:
    """``cmd`` writing to its own ``--out`` folder (``<out>_warm``)."""
    at = cmd.index("--out") + 1
    return [*cmd[:at], f"{cmd[at]}_warm", *cmd[at + 1 :]]


def run_part(step: Path, work: Path, args: argparse.Namespace, original_ok: bool, warm: Warm | None) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "ZONEGRAPH_NO_SERVER": "1"}
    cli = [sys.executable, "-m", "zonegraph"]  # as the console script
    row: dict = {"part": step.stem, "step_bytes": step.stat().st_size}
    runs = {"build": cli + ["build", str(step), "--out", str(work / f"{step.stem}_build")]}
    if not args.no_infer:
        budget = ["--budget", str(args.budget), "--guide", args.guide]
        runs["infer"] = cli + ["infer", str(step), "--out", str(work / f"{step.stem}_infer"), *budget]
    if warm is not None:
        runs |= {f"{name} warm": _warm_out(cmd) for name, cmd in list(runs.items())}
    if original_ok:
        src = args.original / "src"
        code = ORIGINAL_DRIVER.format(src=str(src), paths=original_paths(args), step=str(step))
        runs["original"] = [args.freecad_python, "-c", code]
    for name, cmd in runs.items():
        original = name == "original"
        if name.endswith(" warm") and warm is not None:
            run = measure_warm(cmd, warm, args.timeout)
        else:
            run = measure(cmd, src if original else ROOT, None if original else env, args.timeout)
        row[name] = asdict(run)
        print(
            f"  {step.stem} {name}: rc {run.rc}, cpu {run.cpu_s:.2f} s, wall {run.wall_s:.2f} s, "
            f"{run.peak_mb:.0f} MB  {run.tail}",
            flush=True,
        )
    return row


def table(rows: list[dict], columns: list[str], skipped: str | None) -> str:
    head = "| part | " + " | ".join(f"{c} CPU s | {c} wall s | {c} MB" for c in columns) + " |"
    lines = [head, "|" + "---|" * (1 + 3 * len(columns))]
    for r in rows:
        cells = []
        for c in columns:
            run = r[c]
            ok = "" if run["rc"] == 0 else f" (rc {run['rc']})"
            cells += [f"{run['cpu_s']:.2f}{ok}", f"{run['wall_s']:.2f}", f"{run['peak_mb']:.0f}"]
        lines.append(f"| {r['part']} | " + " | ".join(cells) + " |")
    medians = []
    for c in columns:
        for key, fmt in (("cpu_s", ".2f"), ("wall_s", ".2f"), ("peak_mb", ".0f")):
            medians.append(format(statistics.median(r[c][key] for r in rows), fmt))
    lines.append(f"| **median of {len(rows)}** | " + " | ".join(medians) + " |")
    done = ", ".join(f"{c} {sum(r[c]['rc'] == 0 for r in rows)}" for c in columns)
    lines.append(f"\nprocesses that exited 0, of {len(rows)}: {done}")
    small = min(rows, key=lambda r: r["step_bytes"])["build"]
    smallest = min(rows, key=lambda r: r["step_bytes"])["part"]
    lines.append(
        f"\nsmallest part ({smallest}, by STEP size): build wall {small['wall_s']:.2f} s, "
        f"CPU {small['cpu_s']:.2f} s, {small['peak_mb']:.0f} MB"
    )
    if skipped:
        lines.append(f"\noriginal implementation skipped: {skipped}")
    for ours in ("build", "build warm"):
        if "original" in columns and ours in columns:
            worse = [r["part"] for r in rows if r[ours]["cpu_s"] > r["original"]["cpu_s"]]
            ratios = [r[ours]["cpu_s"] / r["original"]["cpu_s"] for r in rows]
            lines.append(
                f"\n{ours}: CPU / the original's, median {statistics.median(ratios):.2f} "
                f"({min(ratios):.2f}-{max(ratios):.2f}); parts above the original's: {worse or 'none'}"
            )
    return "\n".join(lines)


def prepare(args: argparse.Namespace, work: Path) -> list[tuple[str, Path]]:
    """The drawn parts' STEP files in ``work``, made by this script in another process: listing the
    corpus imports build123d, and Linux hands a parent's peak memory to every child it starts."""
    draw = ["--designs", str(args.designs), "--per-folder", str(args.per_folder), "--seed", str(args.seed)]
    draw += ["--exclude", str(args.exclude)] if args.exclude else []
    cmd = [sys.executable, "-m", "bench.startup_bench", "--prepare", str(work), *draw]
    subprocess.run(cmd, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, check=True)
    return [(folder, Path(step)) for folder, step in json.loads((work / "parts.json").read_text())]


def _prepare_here(args: argparse.Namespace) -> None:
    require_corpus(CORPUS)
    exclude = set(args.exclude.read_text().split()) if args.exclude else set()
    parts = draw_parts(args.designs, args.per_folder, args.seed, exclude)
    steps = [(folder, str(to_step(design, args.prepare))) for folder, design in parts]
    (args.prepare / "parts.json").write_text(json.dumps(steps))


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--designs", type=Path, default=ROOT / "data" / "designs" / "json")
    p.add_argument("--per-folder", type=int, default=3)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--exclude", type=Path, default=None, help="ids never drawn, one a line")
    p.add_argument("--budget", type=float, default=1.0, help="infer's search seconds")
    p.add_argument("--guide", default="heuristic", help="infer's guide (net: the shipped network)")
    p.add_argument("--no-infer", action="store_true")
    p.add_argument("--original", type=Path, default=None, help="a brownvc/zone-graphs checkout")
    p.add_argument("--freecad-python", default="/usr/bin/python3", help="the Python that imports FreeCAD")
    p.add_argument("--original-deps", type=Path, default=None, help="a folder holding trimesh for it")
    p.add_argument("--timeout", type=float, default=600, help="seconds before a process is killed")
    p.add_argument("--server", action="store_true", help="also each call handed to a zonegraph server")
    p.add_argument("--out", type=Path, default=ROOT / "bench_out" / "startup")
    p.add_argument("--prepare", type=Path, default=None, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.prepare:
        return _prepare_here(args)
    skipped = original_problem(args.original, args.freecad_python, original_paths(args))
    columns = ["build"] + ([] if args.no_infer else ["infer"]) + ([] if skipped else ["original"])
    if args.server:
        columns[1 if args.no_infer else 2 : 0] = [f"{c} warm" for c in columns if c in ("build", "infer")]
    rows, started = [], None
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        parts = prepare(args, work)
        print(f"{len(parts)} parts; columns {columns}; original skipped: {skipped or 'no'}")
        print(f"this process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB peak")
        warm, started = start_server(work) if args.server else (None, None)
        if started:
            print(f"server started: {started}")
        try:
            for folder, step in parts:
                rows.append({"folder": folder, **run_part(step, work, args, skipped is None, warm)})
        finally:
            if warm is not None:
                from zonegraph.handoff import ask

                ask("stop", warm.socket)
    text = table(rows, columns, skipped)
    if started:
        text += (
            f"\n\nthe server's start, once: {started['wall_s']:.2f} s wall, {started['server_cpu_s']:.2f} "
            f"CPU s and {started['server_mb']:.0f} MB in the server"
        )
    write_results(rows, text, args.out)
    if started:
        (args.out / "server_start.json").write_text(json.dumps(started))


if __name__ == "__main__":
    main()

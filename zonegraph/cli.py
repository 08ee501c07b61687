"""The ``zonegraph`` command line.

User errors (a missing or corrupt file, an unsupported feature) print one line naming the file and
the reason and exit with status 2; anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import sys
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from zonegraph.configs import GUIDES, MODELLESS_GUIDES, BuildConfig, InferConfig
from zonegraph.errors import ZoneGraphError
from zonegraph.status import plural
from zonegraph.verified import REPLAY_RTOL

if TYPE_CHECKING:  # imported where used, so that ``zonegraph --help`` loads nothing it need not
    from zonegraph.batch import BatchJob
    from zonegraph.isolation import Outcome
    from zonegraph.reconstruction import InferResult

EXIT_USER_ERROR = 2
EXIT_BUG = 1
MANY = "or a folder of them; several make a batch"
PER_PART = "; for a batch, the parent of one folder per part and summary.json"


def _cmd_replay(args: argparse.Namespace) -> int:
    from zonegraph.errors import InputError, file_problem
    from zonegraph.isolation import Outcome

    problem = file_problem(Path(args.design))  # before the kernel is imported
    if problem:
        return _fail(args.design, Outcome(InputError.status, reason=problem))
    from zonegraph.isolation import run_isolated
    from zonegraph.jobs import replay_and_save
    from zonegraph.outputs import run_staged

    out = Path(args.out)
    tolerance = None if args.no_check else args.tolerance

    def run(scratch: Path) -> Outcome:
        return run_isolated(
            replay_and_save, (args.design, scratch, tolerance), timeout=args.timeout, memory_mb=args.memory
        )

    outcome = run_staged(run, out)
    if not outcome.ok:
        return _fail(args.design, outcome)
    summary = outcome.value
    print(
        f"{summary['id']}: {plural(len(summary['steps']), 'extrude')}, "
        f"{plural(summary['body_count'], 'body', 'bodies')}, "
        f"{summary['face_count']} faces, volume {summary['volume']:.6g} cm^3 -> {out}"
    )
    check = summary.get("check")
    if check:
        print(
            f"  vs the file's properties: volume rel. error {check['volume_rel_error']:.1e}, "
            f"area rel. error {check['area_rel_error']:.1e}"
        )
    return 0


def _fail(target: str | Path, outcome: Outcome) -> int:
    """A failed part's message: one line and exit 2 for the input's fault; a bug's traceback and
    exit 1, as a bug is ours to fix, not the user's."""
    from zonegraph.status import Status

    if outcome.status == Status.BUG:
        message = f"zonegraph: internal error on {target} (a bug: please report it)"
        print(f"{outcome.detail}{message}", file=sys.stderr)
        return EXIT_BUG
    print(f"zonegraph: error: {target}: {outcome.status}: {outcome.reason}", file=sys.stderr)
    return EXIT_USER_ERROR


def _batch(job: Callable[[], BatchJob], args: argparse.Namespace) -> int | None:
    """Several targets, or a folder: each part under ``--out/<name>``, and the exit status (2 if
    any part failed, after all of them ran). One target file: None, for `_single`."""
    from zonegraph.batch import collect_parts, is_batch, run_batch

    if not is_batch(args.targets):
        return None
    from zonegraph.status import Status

    rows = run_batch(_load(job, args), collect_parts(args.targets), Path(args.out))
    if any(r.status == Status.BUG for r in rows):
        return EXIT_BUG
    return EXIT_USER_ERROR if any(not r.ok for r in rows) else 0


def _load(job: Callable[[], BatchJob], args: argparse.Namespace) -> BatchJob:
    """``job()``, which imports the geometry kernel, without the cyclic collector; then, in the
    command's own process, the imported objects are frozen out of later collections, so that the
    forked children that do the work neither walk them again nor copy their pages by touching
    their collector headers."""
    from zonegraph.lazy import uncollected

    with uncollected():
        loaded = job()
    if args.own_process:
        gc.freeze()
    return loaded


def _single(job: Callable[[], BatchJob], args: argparse.Namespace) -> Outcome:
    """The one target's outcome, ``--out`` being its folder. ``job`` imports the geometry kernel,
    so it is called only once the target exists: a missing file costs no import."""
    from zonegraph.batch import unrunnable
    from zonegraph.errors import InputError
    from zonegraph.isolation import Outcome
    from zonegraph.outputs import run_staged

    target = Path(args.targets[0])
    reason = unrunnable(target)
    if reason:
        return Outcome(InputError.status, reason=reason)
    run = _load(job, args).run
    return run_staged(lambda scratch: run(target, scratch), Path(args.out))


def _build_job(config: BuildConfig, timeout: float, memory_mb: int | None) -> BatchJob:
    """``build_and_save`` in a killable child per part, under ``memory_mb`` more MiB."""
    from zonegraph.batch import BatchJob, Column
    from zonegraph.build_job import build_and_save
    from zonegraph.isolation import run_isolated

    def run(target: Path, out: Path) -> Outcome:
        args = (str(target), str(out), config, True)
        return run_isolated(build_and_save, args, timeout=timeout, memory_mb=memory_mb)

    def values(s: dict[str, Any]) -> dict[str, Any]:
        return {"status": s["status"], "zones": s["zones"]}

    return BatchJob("build", run, values, (Column("zones", "zones", "d"),))


def _cmd_build(args: argparse.Namespace) -> int:
    config = BuildConfig(simplify=not args.no_simplify, samples=args.samples, seed=args.seed)
    job = partial(_build_job, config, args.timeout, args.memory)
    status = _batch(job, args)
    if status is not None:
        return status
    outcome, target = _single(job, args), args.targets[0]
    if not outcome.ok:
        return _fail(target, outcome)
    s = outcome.value
    print(
        f"{Path(target).name}: status {s['status']}, {s['zones']} zones ({s['inside_zones']} inside), "
        f"{s['faces']} faces, {s['edges']} edges, {s['surfaces']} surfaces "
        f"from {s['target_faces']} target faces"
        f"{'' if s['simplified'] else ' (not simplified)'}"
    )
    laps = ", ".join(f"{k[:-2]} {v:.3f}" for k, v in s.items() if k.endswith("_s") and k != "build_s")
    print(f"  built in {s['build_s']:.3f} s ({laps}) -> {args.out}")
    return 0


def _guide_error(config: InferConfig) -> str | None:
    """Why the guide or its model cannot be used, checked before the kernel is imported."""
    from zonegraph.plugins import guide_problem, model_problem

    problem = guide_problem(config.guide)
    if problem is not None:
        return problem
    if config.model is not None and config.guide in MODELLESS_GUIDES:
        return f"--model {config.model}: the {config.guide} guide uses no model (only --guide net does)"
    if config.model is not None and not Path(config.model).is_file():
        return f"{config.model}: no such model checkpoint"
    if config.model is not None and str(config.model).endswith(".npz"):
        return _folded_problem(Path(config.model))
    return None if config.model is None else model_problem(str(config.model))


def _folded_problem(path: Path) -> str | None:
    """Why a folded checkpoint cannot be read, from its header (its weights are read in search)."""
    from zonegraph.network.folded import FoldedScorer

    try:
        FoldedScorer.header(path)
    except ValueError as e:
        return str(e)
    return None


def _infer_job(config: InferConfig, timeout: float, memory_mb: int | None) -> BatchJob:
    """``infer`` in a killable child per part; a shipped or plugin guide's package (torch) is
    imported here too, so that a batch's children inherit it instead of importing it each."""
    from zonegraph.batch import BatchJob, Column
    from zonegraph.isolation import run_isolated
    from zonegraph.plugins import guide_factory
    from zonegraph.reconstruction import infer

    guide_factory(config.guide)

    def run(target: Path, out: Path) -> Outcome:
        return run_isolated(infer, (str(target), str(out), config), timeout=timeout, memory_mb=memory_mb)

    def values(r: InferResult) -> dict[str, Any]:
        return {
            "status": r.status,
            "steps": r.steps,
            "zones": r.zones,
            "iou_brep": r.iou_brep,
            "reason": r.reason,
        }

    columns = (
        Column("steps", "steps", "d"),
        Column("zones", "zones", "d"),
        Column("iou_brep", "B-rep IoU", ".6f"),
    )
    return BatchJob("infer", run, values, columns)


def _cmd_infer(args: argparse.Namespace) -> int:
    config = InferConfig.from_mapping(vars(args))
    error = _guide_error(config)
    if error:
        print(f"zonegraph: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    timeout = args.timeout or 3 * args.budget_s + 300  # the build and the export are not budgeted
    job = partial(_infer_job, config, timeout, args.memory)
    status = _batch(job, args)
    if status is not None:
        return status
    outcome, target = _single(job, args), args.targets[0]
    if not outcome.ok:
        return _fail(target, outcome)
    r = outcome.value
    print(infer_summary(Path(target).name, r, args.out))
    return 0


def infer_summary(name: str, r: InferResult, out: str | Path) -> str:
    """The lines ``infer`` prints for one part: the outcome, the reason when not exact, the times."""
    steps = f"{plural(r.steps, 'step')} ({', '.join(r.operations)})" if r.steps else "no step"
    lines = [f"{name}: {r.status}, {steps}, B-rep IoU {r.iou_brep:.6f}, zone IoU {r.iou_zone:.6f}"]
    if r.reason:
        lines.append(f"  why: {r.reason}")
    lines.append(
        f"  {r.zones} zones, build {r.build_s:.2f} s, search {r.search_s:.2f} s "
        f"(best after {r.time_to_best_s:.2f} s, {plural(r.expansions, 'expansion')}), "
        f"rebuild {r.rebuild_s:.2f} s, verify {r.verify_s:.2f} s -> {out}"
    )
    return "\n".join(lines)


def _cmd_convert(args: argparse.Namespace) -> int:
    """Every design of the batches in a killable child under ``--timeout``; the JSON of each design
    converted ``ok`` and ``summary.json`` (a row per design) moved into ``--out`` together at the
    end. Exit 2 when nothing converted, 1 when a design met a bug of ours (its traceback shown)."""
    from zonegraph.isolation import Outcome
    from zonegraph.outputs import run_staged, write_record
    from zonegraph.status import Status

    batches = _convert_batches(Path(args.source))
    import build123d  # noqa: F401 - imported once here, inherited by every design's child

    from zonegraph.data.b123d import install_ocp_shims

    install_ocp_shims()
    rows: list[dict[str, Any]] = []

    def run(scratch: Path) -> Outcome:
        rows.extend(_convert_into(batches, scratch, args.timeout, args.memory))
        summary = _convert_summary(rows)
        (scratch / "summary.json").write_text(summary)
        converted = any(row["status"] == Status.OK for row in rows)
        return Outcome(Status.OK if converted else Status.NOTHING_CONVERTED, summary)

    out = Path(args.out)
    outcome = run_staged(run, out)
    if not outcome.ok:  # the failed rows still say why, as a failed part's error.json does
        write_record(out, "summary.json", outcome.value)
    counts = json.loads(outcome.value)["counts"]
    if not rows:
        print(f"zonegraph: error: {args.source}: no def model_*() function in its batches", file=sys.stderr)
    for row in rows:
        if row.get("traceback"):
            print(row["traceback"], file=sys.stderr, end="")
    print(f"converted {counts.get('ok', 0)} of {len(rows)} designs -> {out} (by status {counts})")
    if counts.get(Status.BUG.value):
        print("zonegraph: internal error while converting (a bug: please report it)", file=sys.stderr)
        return EXIT_BUG
    return 0 if outcome.ok else EXIT_USER_ERROR


def _convert_batches(source: Path) -> list[Path]:
    """The batch files of ``source`` (a file or a folder searched recursively)."""
    if source.is_dir():
        batches = sorted(source.rglob("batch_*.py"))
    elif source.is_file():
        batches = [source]
    else:
        raise ZoneGraphError(str(source), "no such batch file or folder")
    if not batches:
        raise ZoneGraphError(str(source), "no batch_*.py files in the folder")
    return batches


def _convert_into(
    batches: list[Path], out: Path, timeout: float, memory_mb: int | None = None
) -> list[dict[str, Any]]:
    """A row per design, each converted in its own child (the batch is listed without running it,
    so a model's ``os._exit`` or endless loop stops only that design); its JSON written when ok."""
    from zonegraph.data.b123d import batch_entries
    from zonegraph.jobs import convert_isolated
    from zonegraph.status import Status

    rows: list[dict[str, Any]] = []
    for batch in batches:
        entries = batch_entries(batch, batch.parent.name)
        ok = 0
        for e in entries:
            r = convert_isolated(batch, e.design_id, e.fusion_volume, e.fusion_area, timeout, memory_mb)
            if r.ok and r.design_json is not None:
                (out / f"{r.design_id}.json").write_text(json.dumps(r.design_json))
                ok += 1
            row = {
                "batch": str(batch),
                "design_id": r.design_id,
                "folder": r.folder,
                "status": str(r.status),
                "reason": r.reason,
                "steps": r.steps,
                "seconds": round(r.seconds, 4),
                "fusion_volume_rel_error": r.fusion_volume_rel_error,
                "fusion_area_rel_error": r.fusion_area_rel_error,
            }
            if r.status == Status.BUG:
                row["traceback"] = r.notes[0] if r.notes else ""
            elif not r.ok:
                print(f"zonegraph: {batch}: {r.design_id}: {r.status}: {r.reason}", file=sys.stderr)
            rows.append(row)
        print(f"{batch.parent.name}/{batch.name}: {ok}/{len(entries)} converted", flush=True)
    return rows


def _convert_summary(rows: list[dict[str, Any]]) -> str:
    counts: dict[str, int] = {}
    for row in rows:
        counts[row["status"]] = counts.get(row["status"], 0) + 1
    return json.dumps({"counts": counts, "designs": rows}, indent=1)


DESCRIPTION = (
    "Recover editable sketch + extrude programs (build123d scripts and Fusion 360 Gallery JSON) "
    "from B-rep solids with zone graphs."
)
EPILOG = """examples:
  zonegraph infer part.step --out out/            # out/sequence.py, sequence.json, result.json
  zonegraph infer parts/ extra.step --out out/ --budget 5   # a batch: out/<name>/, summary.json
  zonegraph build part.step --out graph/          # the zone graph: Parquet, zones.brep, zones.ply
  zonegraph replay design.json --out replay/      # a Fusion 360 Gallery design rebuilt as STEP
  zonegraph convert corpus/01_2ops --out json/    # build123d corpus batches to design JSON
  zonegraph server start                          # later calls skip the start-up (server stop)

A batch names each part's folder by its file stem, or by its file name where two files share a
stem (Couch.json and Couch.step go to Couch.json/ and Couch.step/).
"""


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Defaults shown after each option's help (not where there is none to show: a flag, or a
    default the help explains itself), and the epilog's examples kept as written."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if action.default is None or action.default is False or "default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def build_parser() -> argparse.ArgumentParser:
    from zonegraph import __version__

    parser = argparse.ArgumentParser(
        prog="zonegraph", description=DESCRIPTION, epilog=EPILOG, formatter_class=_HelpFormatter
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="{infer,build,replay,convert,server}")
    _add_infer(sub)
    _add_build(sub)
    _add_replay(sub)
    _add_convert(sub)
    _add_server(sub)
    return parser


def _command(sub: Any, name: str, help: str) -> argparse.ArgumentParser:
    parser: argparse.ArgumentParser = sub.add_parser(
        name, help=help, description=help[:1].upper() + help[1:] + ".", formatter_class=_HelpFormatter
    )
    return parser


def _add_infer(sub: Any) -> None:
    d = InferConfig.defaults()
    p = _command(sub, "infer", "infer an editable sketch + extrude program that rebuilds a part")
    p.add_argument(
        "targets",
        nargs="+",
        metavar="target",
        help=f"PART.step, PART.brep, DESIGN.json (its final shape) {MANY}",
    )
    p.add_argument(
        "--out", required=True, help=f"output folder (result.json, sequence.py/.json/.png, steps/){PER_PART}"
    )
    p.add_argument(
        "--guide",
        default=d["guide"],
        metavar="{" + ",".join(GUIDES) + "}",
        help="proposal ranking (net: the network, with the train extra; or a ranker plugin's name)",
    )
    p.add_argument(
        "--model", default=None, help="the net guide's checkpoint (default: the shipped one; net only)"
    )
    p.add_argument(
        "--budget",
        dest="budget_s",
        type=float,
        default=d["budget_s"],
        help="search seconds (zone graph build excluded)",
    )
    p.add_argument("--k", type=int, default=d["k"], help="proposals kept per state (top-k)")
    p.add_argument("--k-decay", type=float, default=d["k_decay"], help="k decrease per depth level")
    p.add_argument("--max-depth", type=int, default=d["max_depth"], help="longest program searched")
    p.add_argument("--seed", type=int, default=d["seed"], help="seed of the random guide")
    p.add_argument(
        "--level", type=int, default=d["level"], help="proposal level (subsets of sketch components)"
    )
    p.add_argument(
        "--expansions",
        dest="max_expansions",
        type=int,
        default=None,
        help="states expanded per graph searched at most (a bound the same on any machine)",
    )
    p.add_argument(
        "--timeout",
        type=float,
        default=None,
        help="hard stop per part in seconds (default: 3 x budget + 300)",
    )
    _add_memory(p)
    p.set_defaults(func=_cmd_infer)


def _add_build(sub: Any) -> None:
    b = BuildConfig.defaults()
    p = _command(sub, "build", "build the zone graph of STEP/BREP parts or design JSON files")
    p.add_argument("targets", nargs="+", metavar="target", help=f"PART.step, PART.brep, DESIGN.json {MANY}")
    p.add_argument(
        "--out", required=True, help=f"output folder (Parquet tables, zones.brep, zones.ply){PER_PART}"
    )
    p.add_argument("--no-simplify", action="store_true", help="extend face-loop walls as full planes")
    p.add_argument("--samples", type=int, default=b["samples"], help="surface samples per zone")
    p.add_argument("--seed", type=int, default=b["seed"], help="seed of the surface samples")
    p.add_argument("--timeout", type=float, default=600.0, help="seconds before a build is stopped")
    _add_memory(p)
    p.set_defaults(func=_cmd_build)


def _add_replay(sub: Any) -> None:
    p = _command(sub, "replay", "replay a Fusion 360 Gallery design JSON with build123d")
    p.add_argument("design", help="design JSON file")
    p.add_argument("--out", required=True, help="output folder (final.step, steps/, summary.json)")
    p.add_argument("--timeout", type=float, default=600.0, help="seconds before the replay is stopped")
    p.add_argument(
        "--tolerance",
        type=float,
        default=REPLAY_RTOL,
        help="largest relative volume and area error against the file's properties (else exit 2)",
    )
    p.add_argument("--no-check", action="store_true", help="keep the result whatever the file's properties")
    _add_memory(p)
    p.set_defaults(func=_cmd_replay)


def _add_convert(sub: Any) -> None:
    p = _command(sub, "convert", "convert build123d corpus batches to verified design JSON")
    p.add_argument("source", help="a batch_NNN.py file or a folder of them (searched recursively)")
    p.add_argument("--out", required=True, help="output folder (one JSON per design, summary.json)")
    p.add_argument(
        "--timeout", type=float, default=120.0, help="seconds per design (each runs in its own process)"
    )
    _add_memory(p)
    p.set_defaults(func=_cmd_convert)


def _add_server(sub: Any) -> None:
    p = _command(sub, "server", "keep the geometry kernel loaded between calls (start, stop, status)")
    p.add_argument("action", choices=("start", "stop", "status"))
    p.add_argument(
        "--idle", type=float, default=15.0, help="minutes without a call after which the server stops"
    )
    p.add_argument("--json", action="store_true", help="print the server's status as JSON")
    p.set_defaults(func=_cmd_server)


def _cmd_server(args: argparse.Namespace) -> int:
    from zonegraph import server

    state: dict[str, Any] | None
    try:
        if args.action == "start":
            state, other = server.start(args.idle * 60), 0
        elif args.action == "stop":
            state, other = server.stop()
        else:
            state, other = server.status(), len(server.others())
    except server.ServerError as exc:
        print(f"zonegraph: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    print(json.dumps(state) if args.json else server.describe(args.action, state, other))
    return 0 if state is not None or args.action != "status" else 1


def _add_memory(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--memory",
        type=int,
        default=None,
        metavar="MIB",
        help="address space each part's child may add, in MiB; past it the part is out_of_memory "
        "(default: $ZONEGRAPH_MEMORY_MB, else no limit)",
    )


# Arguments that must be positive where a command has them (0 or less ran a search of no steps).
POSITIVE = {
    "budget_s": "--budget",
    "max_expansions": "--expansions",
    "timeout": "--timeout",
    "k": "--k",
    "max_depth": "--max-depth",
    "tolerance": "--tolerance",
    "memory": "--memory",
    "idle": "--idle",
}


def argument_error(args: argparse.Namespace) -> str | None:
    """What is wrong with the arguments, checked before any geometry is read, or None."""
    for name, flag in POSITIVE.items():
        value = getattr(args, name, None)
        if value is not None and not (math.isfinite(value) and value > 0):
            return f"{flag} {value}: must be a positive number"
    if getattr(args, "samples", 0) < 0 or getattr(args, "level", 1) < 1:
        return "--samples must be 0 or more and --level 1 or more"
    return out_error(Path(args.out)) if hasattr(args, "out") else None


def out_error(out: Path) -> str | None:
    """Why ``out`` cannot be the output folder (it is a file, or nothing can be created there)."""
    if out.exists():
        return None if out.is_dir() else f"--out {out}: exists and is not a folder"
    parent = next((p for p in out.absolute().parents if p.exists()), None)
    if parent is None or not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        return f"--out {out}: cannot be created ({parent} is not a writable folder)"
    return None


def main(argv: Sequence[str] | None = None, own_process: bool | None = None) -> int:
    """Run a command; ``argv`` None means this process is the command (the console script).
    ``own_process`` (default: ``argv`` is None): the process ends with the command, so its
    objects need not stay collectable (a warm server's child passes its own ``argv``)."""
    args = build_parser().parse_args(argv)
    args.own_process = argv is None if own_process is None else own_process
    func: Callable[[argparse.Namespace], int] = args.func
    error = argument_error(args)
    if error:
        print(f"zonegraph: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    try:
        return func(args)
    except ZoneGraphError as exc:
        print(f"zonegraph: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    finally:
        if args.own_process:
            _skip_final_collection()


def _skip_final_collection() -> None:
    """Freeze every object before the interpreter exits: its last collections would walk the
    kernel's millions of objects only to free memory the exit frees anyway (measured on ``zonegraph
    infer`` of a one-extrude part: 4.3 s -> 3.4 s). Not done for in-process callers, whose garbage
    must stay collectable."""
    gc.freeze()


if __name__ == "__main__":
    sys.exit(main())

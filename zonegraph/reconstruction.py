"""``zonegraph infer``: a target file in, a verified editable program out.

The simplified zone graph is searched first (fewer zones, faster); if it yields no exact program,
the unsimplified graph gets the rest of the budget (face-loop strips can leave zones that no prism
fills, as on slanted walls), unless simplification found no face loop and the two graphs are one.
The best program found is rebuilt from its sketches and measured against the target with B-rep
Booleans, whether or not it is exact, and written out whenever it has a step: a partial program is
still a start for the user. A result that is not exact carries a ``reason``
(`zonegraph.sequence.diagnosis`): the target faces no extrusion can make, whether the zone
graph can hold the target at all, and how each search ended. A search that found no step writes no
program files (an empty script would look like an answer); its ``reason`` says so first.
The budget bounds the search alone, each graph's proposal generator set-up included; building the
graphs, rebuilding, diagnosing and verifying are timed apart.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from build123d import Part, Shape, Solid, Unit

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.configs import InferConfig
from zonegraph.data.design import parse_design
from zonegraph.data.replay import replay
from zonegraph.data.targets import load_target, target_region
from zonegraph.export.verify import Export, run_script, verified_export
from zonegraph.export.writers import write_outputs
from zonegraph.geometry.occ import self_intersects
from zonegraph.sequence.best_first import SearchConfig, SearchResult, search
from zonegraph.sequence.deadline import Deadline
from zonegraph.sequence.diagnosis import Diagnosis, diagnose
from zonegraph.sequence.program import (
    AGREE_TOL,
    ProgramStep,
    RebuildError,
    build_program,
    execute,
    measured,
)
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.sequence.rankers import make_ranker
from zonegraph.status import Status, plural
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.model import ZoneGraph, ZoneGraphBuildError
from zonegraph.zones.storage import load_zone_graph

EXACT_IOU = 0.9999
FIRST_SHARE = 0.5  # of the budget, for the simplified graph
# Seconds for the diagnosis's sweeps of every face over every plane pair (outside the budget, as the
# rebuild is); the fillet-box test part's 297 zones take 0.1 s.
DIAGNOSIS_S = 5.0
ENDINGS = {
    "exhausted": "exhausted its space",
    "budget": "ran out of budget",
    "expansions": "reached its expansion limit",
    "exact": "found an exact canvas",
}


@dataclass
class Reconstruction:
    """The best search over a target's zone graphs, before rebuilding it as real geometry."""

    graph: ZoneGraph  # the graph the best result was found on
    generator: ProposalGenerator
    result: SearchResult
    build_s: float  # zone-graph build seconds (both graphs)
    search_s: float  # search seconds (both graphs, generator set-up included)
    solids: list[Solid]  # the target, in the input's units
    trace: list[tuple[float, float]] = field(default_factory=list)  # anytime (search s, best zone IoU)
    searches: list[str] = field(default_factory=list)  # how each graph's search ended, in words

    @property
    def time_to_best_s(self) -> float:
        """Search seconds until the returned program was found, over both graphs."""
        return self.trace[-1][0] if self.trace else 0.0


@dataclass
class InferResult:
    """What ``zonegraph infer`` found: the metrics of ``result.json`` and the program itself.

    The program is kept as the texts written to ``sequence.py`` and ``sequence.json`` (verified by
    ``script_iou`` and ``json_iou``), so that a result crosses a process boundary as plain data;
    `to_part` runs the script. A result of no step has no program: those methods raise.

    Example (a part whose program is exact rebuilds to the target's volume)::

        result = zg.infer("part.step", "out/")
        part = result.to_part()        # a build123d Part, in the input's units and position
        text = result.to_script()      # sequence.py
        design = result.to_json()      # sequence.json (Fusion 360 Gallery format)
    """

    status: Status  # exact, partial or rebuild_failed
    exact: bool  # rebuilt with B-rep IoU >= EXACT_IOU (a zone sliver short of the target can be)
    iou_zone: float
    iou_brep: float
    steps: int
    time_to_best_s: float  # search seconds to the returned program (both graphs)
    build_s: float
    search_s: float  # both graphs, generator set-up included: what the budget bounds
    zones: int
    simplified: bool
    expansions: int
    script_snapped: bool = False  # sequence.py carries snapped numbers (it rebuilt as well)
    json_snapped: bool = False  # sequence.json carries snapped numbers (it rebuilt as well)
    snapped_numbers: int = 0  # numbers written shorter than the raw program's
    script_iou: float = 0.0  # B-rep IoU of the written sequence.py, run as written
    json_iou: float = 0.0  # B-rep IoU of the written sequence.json, replayed by our reader
    export_error: str = ""  # why a written file did not rebuild
    measured_by: str = "rebuild"  # what iou_brep measured: the rebuild, or sequence.py / .json
    operations: list[str] = field(default_factory=list)  # union / subtract, in program order
    step_zones: list[list[int]] = field(default_factory=list)  # each step's extrusion zones (its graph)
    rebuild_error: str = ""
    rebuild_s: float = 0.0  # rebuilding the program and its B-rep IoU against the target
    verify_s: float = 0.0  # snapping, checking and writing the script and JSON
    config: dict[str, Any] = field(default_factory=dict)
    trace: list[tuple[float, float]] = field(default_factory=list)  # anytime (search s, best zone IoU)
    reason: str = ""  # why the result is not exact ("" when it is)
    diagnosis: dict[str, Any] = field(default_factory=dict)  # the reason's figures (a Diagnosis)
    diagnose_s: float = 0.0
    files: list[str] = field(default_factory=list)  # the program files written (none for no step)
    script: str = field(default="", repr=False)  # sequence.py's text, not in result.json
    design: str = field(default="", repr=False)  # sequence.json's text, not in result.json

    def to_dict(self) -> dict[str, Any]:
        """Plain data (the status as its string), for ``result.json`` and the pipeline's tables:
        the metrics, not the program texts (they are the files beside it)."""
        data = {**asdict(self), "status": self.status.value}
        del data["script"], data["design"]
        return data

    def to_script(self) -> str:
        """The editable build123d script (``sequence.py``).

        Raises:
            ValueError: the search found no step, so there is no program.
        """
        return self._program(self.script)

    def to_json(self) -> str:
        """The program in Fusion 360 Gallery format (``sequence.json``), as ``zonegraph replay``
        reads it.

        Raises:
            ValueError: the search found no step, so there is no program.
        """
        return self._program(self.design)

    def to_part(self) -> Part:
        """The program's shape as a build123d ``Part``, by running the written script.

        Raises:
            ValueError: the search found no step, so there is no program.
        """
        shape = run_script(self.to_script())
        return shape if isinstance(shape, Part) else Part(shape.wrapped)

    def _program(self, text: str) -> str:
        if not text:
            raise ValueError(f"no program was found: {self.reason or self.rebuild_error}")
        return text


def input_unit(path: Path) -> Unit:
    """What the target's numbers mean: design JSON is in cm; STEP is read in mm (BREP has no unit)."""
    return Unit.CM if path.suffix.lower() == ".json" else Unit.MM


def _graph(
    solids: list[Solid], simplify: bool, source: str, saved: Path | None, samples: int = 0
) -> tuple[ZoneGraph, float]:
    """The zone graph and its build seconds; a graph saved by the pipeline is reused.

    ``samples``: surface samples per zone, for a ranker that reads zone geometry (the network)."""
    if saved is not None and (saved / "zones.parquet").is_file():
        graph = load_zone_graph(saved)
        usable = graph.zone_points.shape[1] >= samples
        if graph.info.get("simplified") == simplify and graph.solids is not None and usable:
            return graph, float(graph.info["build_s"])
    t0 = time.perf_counter()
    graph = build_zone_graph(solids, simplify=simplify, samples=samples, source=source)
    return graph, time.perf_counter() - t0


def budget_share(graph: ZoneGraph, simplified: bool) -> float:
    """The share of the remaining budget a graph's search gets: half for a simplified graph with a
    face loop (the full graph may still need the rest), else all of it (a simplified graph with no
    face loop is the full graph, which is then skipped: its half used to go unspent)."""
    return FIRST_SHARE if simplified and bool(graph.surface_strip.any()) else 1.0


def reconstruct(
    target_path: str | Path, config: InferConfig = InferConfig(), saved_graph: str | Path | None = None
) -> Reconstruction:
    """Search the simplified, then (if needed) the full zone graph of a target file.

    Args:
        target_path: a STEP, BREP or design JSON file.
        config: search settings.
        saved_graph: a folder holding this target's saved zone graph, reused instead of rebuilt.

    Returns:
        The best search (zone IoU, then fewest steps) and the graph it ran on.

    Raises:
        InputError: the file cannot be read as solids.
        ZoneGraphBuildError: no zone graph could be built.
    """
    solids = load_target(target_path)
    ranker = make_ranker(config.guide, config.seed, config.model)
    saved = Path(saved_graph) if saved_graph else None
    best: tuple[ZoneGraph, ProposalGenerator, SearchResult] | None = None
    build_s, search_s = 0.0, 0.0
    trace: list[tuple[float, float]] = []
    searches: list[str] = []
    error: ZoneGraphBuildError | None = None
    for simplify in (True, False):
        try:
            graph, seconds = _graph(solids, simplify, str(target_path), saved, getattr(ranker, "samples", 0))
        except ZoneGraphBuildError as exc:
            error = exc
            continue
        build_s += seconds
        share = (config.budget_s - search_s) * budget_share(graph, simplify)
        deadline, start = Deadline.after(share), time.perf_counter()  # set-up counts against it
        gen = ProposalGenerator(graph, level=config.level)
        setup = time.perf_counter() - start
        settings = {**asdict(config), "budget_s": share - setup}
        result = search(graph, ranker, SearchConfig.from_mapping(settings), gen, deadline)
        if best is None or (result.iou, -len(result.steps)) > (best[2].iou, -len(best[2].steps)):
            trace += _improvements(result, search_s + setup, best[2].iou if best else -1.0)
            best = (graph, gen, result)
        search_s += setup + result.seconds
        searches.append(_ending(result, simplify))
        if result.exact or not graph.surface_strip.any():  # no face loop: the full graph is the same
            break
    if best is None:
        assert error is not None
        raise error
    return Reconstruction(
        *best, build_s=build_s, search_s=search_s, solids=solids, trace=trace, searches=searches
    )


def _ending(result: SearchResult, simplified: bool) -> str:
    graph = "simplified" if simplified else "full"
    return (
        f"{ENDINGS[result.ended]} on the {graph} graph after {plural(result.expansions, 'expansion')} "
        f"({result.seconds:.2f} s)"
    )


def _improvements(result: SearchResult, offset: float, above: float) -> list[tuple[float, float]]:
    """A better graph's anytime trace on the clock of the whole search: the points that beat
    ``above`` (the best IoU of the graphs searched before it), else its best alone (an equal IoU
    in fewer steps)."""
    points = [(offset + t, iou) for t, iou in result.trace if iou > above]
    return points or [(offset + result.time_to_best_s, result.iou)]


def _export_fields(export: Export | None) -> dict[str, Any]:
    """result.json's account of the written files (none written: nothing snapped, IoU 0)."""
    if export is None:
        return {}
    return {
        "script_snapped": export.snapped,
        "json_snapped": export.design_snapped,
        "snapped_numbers": export.snapped_numbers,
        "script_iou": export.check.script_iou,
        "json_iou": export.check.json_iou,
        "export_error": export.check.error,
    }


def _by_files(export: Export, part: Shape, iou: float, name: str) -> tuple[Shape, float, str]:
    """The program's part, its B-rep IoU and what measured it, where the rebuild falls short of
    the zones: the written file that rebuilds the program best, when it measures higher.

    The files are the same program built another way, from its written numbers, whose corners
    each loop's edges share. A diagnosis part's zone-exact 14-step program rebuilt from its
    partition faces to 1.0008 of the target's volume (its last union, of a part whose
    tolerances had grown to 1.3e-3, failed in the Booleans and in the cells alike), while its
    script rebuilt it to 0.99999993 (96186_05427635_0000)."""
    script, design = export.check.script_iou, export.check.json_iou
    if max(script, design) <= iou:
        return part, iou, "rebuild"
    try:
        if script >= design:
            return run_script(export.script), script, "sequence.py"
        return replay(parse_design(json.loads(export.design), name)).shape, design, "sequence.json"
    except Exception:  # OCP's exceptions share no base class; verification ran it once already
        return part, iou, "rebuild"


def _disagreement(rebuilt: Shape | None, target: Shape, iou: float) -> str:
    """Why a program exact on zones is not exact as a B-rep, for ``result.json``: the rebuild or
    the Booleans measuring it failed (a zone-exact program's prisms are the target's zones), or
    the target itself is a shape no Boolean handles."""
    volume = rebuilt.volume / target.volume if rebuilt is not None and target.volume else 0.0
    cause = (
        "the target's own faces cross each other (OpenCASCADE's Boolean check), so no Boolean "
        "with it can be trusted"
        if self_intersects(target.wrapped)
        else "an OpenCASCADE Boolean of the rebuild or of the IoU failed"
    )
    return f"exact on zones but rebuilt to B-rep IoU {iou:.6g} (volume {volume:.6g} of the target's): {cause}"


def _why_not_exact(
    rec: Reconstruction, target: Shape, program: list[ProgramStep], rebuild_error: str
) -> dict[str, Any]:
    """The ``reason`` and ``diagnosis`` fields of a result that is not exact."""
    diagnosis = diagnose(target.wrapped, rec.generator, rec.searches, DIAGNOSIS_S)
    lead = [rebuild_error] if rebuild_error else []
    if not program and not rebuild_error:
        lead.append("no step found, so no program was written")
    return {"reason": "; ".join([*lead, diagnosis.reason()]), "diagnosis": asdict(diagnosis)}


def _exact_fields() -> dict[str, Any]:
    """An exact result's ``reason`` and ``diagnosis``: empty, but with every key, so that a table
    of exact results alone still has a ``diagnosis`` Parquet can write (a struct of no field fails)."""
    return {"reason": "", "diagnosis": asdict(Diagnosis())}


def _files(out: Path, states: list, render: bool) -> list[str]:
    """The program files written into ``out``, relative to it."""
    names = ["sequence.py", "sequence.json"]
    if render:
        names += [f"steps/{i:02d}.step" for i, state in enumerate(states) if state is not None]
        names.append("sequence.png")
    return names


def infer(
    target_path: str | Path,
    out: str | Path,
    config: InferConfig = InferConfig(),
    render: bool = True,
    saved_graph: str | Path | None = None,
) -> InferResult:
    """Reconstruct, rebuild, verify and export a target; writes ``result.json`` and the program.

    Args:
        target_path: a STEP, BREP or design JSON file.
        out: output folder (result.json, sequence.py/.json, and when ``render`` steps/ and a PNG).
            The script and JSON carry snapped numbers when they rebuild the part as well as the
            raw ones (`zonegraph.export.verify.verified_export`).
        config: search settings.
        render: write the per-step STEP files and the PNG (the pipeline's bulk runs skip them).
        saved_graph: a folder holding this target's zone graph, reused instead of rebuilt.

    Returns:
        The result, also written to ``out/result.json``; when not exact, its ``reason`` says why.
            A search that found no step writes no program files (its reason says so).

    Raises:
        InputError, ZoneGraphBuildError: as `reconstruct`.
    """
    path, out_dir = Path(target_path), Path(out)
    rec = reconstruct(path, config, saved_graph)
    target = target_region(rec.solids)
    program: list[ProgramStep] = []
    states: list = []
    rebuild_error, iou = "", 0.0
    started = time.perf_counter()
    try:
        program = build_program(rec.graph, rec.result.steps, rec.generator)
        states = execute(program)
        if states and states[-1] is not None:
            states[-1], iou = measured(program, states[-1], target, rec.result.iou)
    except RebuildError as exc:
        rebuild_error = str(exc)
    rebuild_s = time.perf_counter() - started
    export: Export | None = None
    measured_by = "rebuild"
    if states:
        unit = input_unit(path)
        export = verified_export(program, path.stem, unit, target, iou, EXACT_IOU)
        if states[-1] is not None and iou < rec.result.iou - AGREE_TOL:
            states[-1], iou, measured_by = _by_files(export, states[-1], iou, path.stem)
        write_outputs(export.script, export.design, program, states, out_dir, unit, render)
    if not rebuild_error and rec.result.exact and iou < EXACT_IOU:
        rebuild_error = _disagreement(states[-1] if states else None, target, iou)
    verify_s = time.perf_counter() - started - rebuild_s
    exact = bool(iou >= EXACT_IOU)  # the rebuilt B-rep decides, not the zones it was found on
    started = time.perf_counter()
    why = _exact_fields() if exact else _why_not_exact(rec, target, program, rebuild_error)
    result = InferResult(
        status=Status.REBUILD_FAILED if rebuild_error else Status.EXACT if exact else Status.PARTIAL,
        exact=exact,
        iou_zone=rec.result.iou,
        iou_brep=iou,
        measured_by=measured_by,
        steps=len(program),
        time_to_best_s=rec.time_to_best_s,
        build_s=rec.build_s,
        search_s=rec.search_s,
        zones=rec.graph.n_zones,
        simplified=bool(rec.graph.info["simplified"]),
        expansions=rec.result.expansions,
        **_export_fields(export),
        operations=[s.op.name.lower() for s in program],
        step_zones=[[int(z) for z in np.flatnonzero(p.zones)] for p in rec.result.steps],
        rebuild_error=rebuild_error,
        rebuild_s=rebuild_s,
        verify_s=verify_s,
        config=asdict(config),
        trace=rec.trace,
        **why,
        diagnose_s=time.perf_counter() - started,
        files=_files(out_dir, states, render) if export else [],
        script=export.script if export else "",
        design=export.design if export else "",
    )
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "result.json").write_text(json.dumps(result.to_dict(), indent=2))
    return result

"""``zonegraph infer``: a target file in, a verified editable program out.

The simplified zone graph is searched first (fewer zones, faster); if it yields no exact program,
the unsimplified graph gets the rest of the budget (face-loop strips can leave zones that no prism
fills, as on slanted walls), unless simplification found no face loop and the two graphs are one.
The best program found is rebuilt from its sketches and measured against the target with B-rep
Booleans, whether or not it is exact.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from build123d import Unit

from zonegraph.export.writers import write_outputs
from zonegraph.zones.build import build_zone_graph
from zonegraph.sequence.program import RebuildError, brep_iou, build_program, execute
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.data.replay import as_shape
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.rankers import make_ranker
from zonegraph.data.targets import load_target
from zonegraph.zones.model import ZoneGraph, ZoneGraphBuildError
from zonegraph.zones.storage import load_zone_graph

EXACT_IOU = 0.9999
FIRST_SHARE = 0.5  # of the budget, for the simplified graph


@dataclass(frozen=True)
class InferConfig:
    guide: str = "heuristic"
    budget_s: float = 10.0
    k: int = 5
    k_decay: float = 0.0
    max_depth: int = 20
    seed: int = 0
    level: int = 1  # proposal level: sketches of 1..level and N-level..N components


def input_unit(path: Path) -> Unit:
    """What the target's numbers mean: design JSON is in cm; STEP is read in mm (BREP has no unit)."""
    return Unit.CM if path.suffix.lower() == ".json" else Unit.MM


def _graph(solids, simplify: bool, source: str, saved: Path | None) -> tuple[ZoneGraph, float]:
    """The zone graph and its build seconds; a graph saved by the pipeline is reused."""
    if saved is not None and (saved / "zones.parquet").is_file():
        graph = load_zone_graph(saved)
        if graph.info.get("simplified") == simplify and graph.solids is not None:
            return graph, float(graph.info["build_s"])
    t0 = time.perf_counter()
    graph = build_zone_graph(solids, simplify=simplify, samples=0, source=source)
    return graph, time.perf_counter() - t0


def reconstruct(target_path: str | Path, config: InferConfig = InferConfig(), saved_graph: str | None = None):
    """Search the zone graphs of a target; returns (graph, generator, result, build_s, search_s, solids)."""
    solids = load_target(target_path)
    ranker = make_ranker(config.guide, config.seed)
    best, build_s, search_s, error = None, 0.0, 0.0, None
    for simplify in (True, False):
        try:
            graph, seconds = _graph(solids, simplify, str(target_path), Path(saved_graph) if saved_graph else None)
        except ZoneGraphBuildError as exc:
            error = exc
            continue
        build_s += seconds
        left = config.budget_s - search_s
        budget = left * FIRST_SHARE if simplify else left
        gen = ProposalGenerator(graph, level=config.level)
        result = search(graph, ranker, SearchConfig(config.k, config.k_decay, config.max_depth, budget), gen)
        search_s += result.seconds
        if best is None or (result.iou, -len(result.steps)) > (best[2].iou, -len(best[2].steps)):
            best = (graph, gen, result)
        if result.exact or not graph.surface_strip.any():  # no face loop: the full graph is the same
            break
    if best is None:
        raise error
    return (*best, build_s, search_s, solids)


def infer(target_path: str, out: str, config: InferConfig = InferConfig(), render: bool = True,
          saved_graph: str | None = None) -> dict:
    """Reconstruct, rebuild, verify and export; returns the contents of result.json.

    ``render=False`` skips the per-step STEP files and the PNG (the pipeline's bulk runs);
    ``saved_graph`` is a folder holding this target's zone graph, reused instead of rebuilt."""
    path, out_dir = Path(target_path), Path(out)
    graph, gen, result, build_s, search_s, solids = reconstruct(path, config, saved_graph)
    program = build_program(graph, result.steps, gen)
    states, rebuild_error, iou = [], "", 0.0
    try:
        states = execute(program)
        iou = brep_iou(states[-1] if states else None, as_shape(solids))
    except RebuildError as exc:
        rebuild_error = str(exc)
    if states:
        write_outputs(program, states, out_dir, path.stem, input_unit(path), render)
    status = "rebuild_failed" if rebuild_error else "exact" if result.exact and iou >= EXACT_IOU else "partial"
    summary = {
        "status": status, "rebuild_error": rebuild_error,
        "exact": bool(result.exact and iou >= EXACT_IOU), "iou_zone": result.iou, "iou_brep": iou,
        "steps": len(program), "time_to_best_s": result.time_to_best_s, "build_s": build_s, "search_s": search_s,
        "zones": graph.n_zones, "simplified": graph.info["simplified"], "expansions": result.expansions,
        "operations": [s.op.name.lower() for s in program], "config": asdict(config),
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "result.json").write_text(json.dumps(summary, indent=2))
    return summary

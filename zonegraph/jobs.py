"""Job bodies shared by the CLI and the pipeline; each runs in an isolated child process and
returns only small plain data (the geometry goes to files).

The design replay and the corpus converter need build123d, which a zone-graph build does not, so
their modules are imported by the jobs that use them: ``zonegraph build PART.step`` stays on OCP.
The build's own job lives in `zonegraph.build_job` (named here too), as this module's other
jobs import the search and the labels, which a build does not need.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow.parquet as pq

from zonegraph.build_job import build_and_save as build_and_save  # the pipeline's name for it
from zonegraph.errors import ReplayMismatchError
from zonegraph.geometry.shapes import read_shape, read_solids, write_step
from zonegraph.isolation import run_isolated
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.ground_truth import ground_truth, search_op
from zonegraph.sequence.labels import GTOperation, label_design, label_tables
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.status import Status
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.model import ZoneGraph, ZoneGraphBuildError
from zonegraph.zones.storage import load_zone_graph

if TYPE_CHECKING:
    from zonegraph.data.b123d import ConvertedDesign


def replay_and_save(design_path: str, out: Path, tolerance: float | None = None) -> dict[str, Any]:
    """Replay a design and write final.step, steps/ and summary.json (run in a killable child).

    Raises:
        ReplayMismatchError: ``tolerance`` given and the result disagrees with the file's own
            properties beyond it (nothing is written).
    """
    from zonegraph.data.design import load_design
    from zonegraph.data.replay import replay

    design = load_design(design_path)
    result = replay(design)
    problem = None if tolerance is None else result.disagreement(tolerance)
    if problem:
        raise ReplayMismatchError(design_path, None, problem)
    write_step(result.shape, out / "final.step")
    summary = result.summary()
    for i, step in enumerate(result.steps):
        name = f"steps/{i:02d}.step"
        write_step(step.shape, out / name)
        write_step(step.tool, out / f"steps/{i:02d}_tool.step")
        summary["steps"][i]["step_file"] = name
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    return {"id": design.id, **summary}


def ground_truth_and_coverage(
    brep_dir: str,
    graph_dir: str,
    operations: list[str],
    levels: tuple[int, ...] = (1, 3),
    budget_s: float = 2.0,
    full_graph: bool = True,
) -> dict[str, Any]:
    """A design's ground truth on its saved (simplified) zone graph, and on the full graph.

    Args:
        brep_dir: the replay stage's folder: ``final.brep`` and ``NN_tool.brep`` (design units).
        graph_dir: the zonegraphs stage's saved graph of ``final.brep``.
        operations: Fusion's operation of each extrude, in timeline order.
        levels: proposal levels at which capture is tested.
        budget_s: heuristic search seconds for a graph whose GT is not captured at level 1
            (does another sequence reach the target?).
        full_graph: also build the unsimplified graph when simplification changed it.

    Returns:
        Plain data: ``steps`` (one dict per GT step and graph) and per-graph design fields.
    """
    tools = [read_shape(Path(brep_dir) / f"{i:02d}_tool.brep").wrapped for i in range(len(operations))]
    graph = load_zone_graph(graph_dir)
    out: dict[str, Any] = {"steps": []}
    variants: list[tuple[str, ZoneGraph]] = [
        ("simplified" if graph.info.get("simplified") else "full", graph)
    ]
    if full_graph and graph.info.get("simplified"):
        if graph.surface_strip.any():
            solids = read_solids(Path(brep_dir) / "final.brep")
            try:
                variants.append(
                    ("full", build_zone_graph(solids, simplify=False, samples=0, source=brep_dir))
                )
            except ZoneGraphBuildError as exc:
                out["full_status"], out["full_reason"] = exc.status, exc.reason
        else:  # no face loop: the full graph is this graph
            variants.append(("full", graph))
    for name, g in variants:
        gt = ground_truth(g, tools, operations, levels)
        exact = None
        if not gt.captured(1):
            result = search(g, HeuristicRanker(), SearchConfig(budget_s=budget_s))
            exact = result.exact
        out[f"{name}_status"] = Status.OK
        out[f"{name}_zones"] = g.n_zones
        out[f"{name}_reaches_target"] = gt.reaches_target
        for level in levels:
            out[f"{name}_captured_l{level}"] = gt.captured(level)
        out[f"{name}_search_exact"] = exact
        out[f"{name}_reason"] = gt.reason or next((s.reason for s in gt.steps if s.reason), "")
        for s in gt.steps:
            out["steps"].append(
                {
                    "graph": name,
                    "step": s.index,
                    "operation": s.operation,
                    "gt_zones": np.flatnonzero(s.zones).astype(int).tolist(),
                    "mapping_error": s.mapping_error,
                    "mapped": s.mapped,
                    **{f"captured_l{k}": v for k, v in s.captured.items()},
                    **{f"effect_captured_l{k}": v for k, v in s.effect_captured.items()},
                    **{f"proposals_l{k}": v for k, v in s.proposals.items()},
                    "reason": s.reason,
                }
            )
    return out


def label_and_save(
    graph_dir: str,
    gt_steps: list[dict[str, Any]],
    design_id: str,
    split: str,
    out_dir: str,
    seed: int = 0,
    level: int = 1,
    multiplier: float = 1.0,
    slack: int = 2,
) -> dict[str, Any]:
    """Ternary labels of one design, written as its two Parquet shards; returns the counts.

    Args:
        graph_dir: the saved zone graph the ground truth was mapped onto.
        gt_steps: the ground-truth stage's rows of that graph, in step order: ``operation``,
            ``gt_zones`` (zone ids), ``captured`` (at ``level``) and ``reason``.
        out_dir: receives ``proposals/<design_id>.parquet`` and ``steps/<design_id>.parquet``.
    """
    graph = load_zone_graph(graph_dir)
    gt = []
    for row in gt_steps:
        zones = np.zeros(graph.n_zones, bool)
        zones[np.asarray(row["gt_zones"], dtype=int)] = True
        gt.append(
            GTOperation(
                zones, search_op(row["operation"]), bool(row["captured"]), row["operation"], row["reason"]
            )
        )
    steps = label_design(graph, gt, design_id, seed=seed, level=level, multiplier=multiplier, slack=slack)
    proposals, step_rows = label_tables(steps, gt, design_id, split)
    for name, table in (("proposals", proposals), ("steps", step_rows)):
        folder = Path(out_dir) / name
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{design_id}.parquet.tmp"  # hidden: pyarrow.dataset never reads it
        pq.write_table(table, tmp)
        tmp.replace(folder / f"{design_id}.parquet")
    labels = np.asarray(proposals.column("label").to_pylist(), dtype=int)
    return {
        "steps": len(steps),
        "labelled_steps": sum(any(x.is_gt for x in st.proposals) for st in steps),
        "proposals": len(labels),
        "positives": int((labels == 1).sum()),
        "negatives": int((labels == -1).sum()),
        "neutrals": int((labels == 0).sum()),
        "completions": int(sum(proposals.column("completions").to_pylist())),
        "zones": graph.n_zones,
    }


def convert_isolated(
    batch_path: str | Path,
    design_id: str,
    fusion_volume: float | None = None,
    fusion_area: float | None = None,
    timeout: float = 120.0,
    memory_mb: int | None = None,
) -> ConvertedDesign:
    """`convert_design` in a forked child killed after ``timeout`` seconds and allowed
    ``memory_mb`` more MiB: the design's endless C call, ``os._exit``, segfault or unbounded
    allocation becomes a ``timeout``, ``crash`` or ``out_of_memory`` row, and a bug of ours a
    ``bug`` row (its traceback the first of its ``notes``)."""
    from zonegraph.data.b123d import ConvertedDesign, convert_design

    args = (str(batch_path), design_id, fusion_volume, fusion_area)
    outcome = run_isolated(convert_design, args, timeout=timeout, memory_mb=memory_mb)
    if outcome.ok:
        converted: ConvertedDesign = outcome.value
        return converted
    path = Path(batch_path)
    notes = [outcome.detail] if outcome.detail else []
    return ConvertedDesign(
        design_id,
        path.parent.name,
        None,
        Status(outcome.status),
        outcome.reason,
        seconds=outcome.seconds,
        notes=notes,
    )


def convert_batch(batch_path: str | Path, timeout: float = 120.0) -> list[ConvertedDesign]:
    """Convert every model of a batch, in file order, each in its own killable child."""
    from zonegraph.data.b123d import batch_entries

    path = Path(batch_path)
    return [
        convert_isolated(path, e.design_id, e.fusion_volume, e.fusion_area, timeout)
        for e in batch_entries(path, path.parent.name)
    ]

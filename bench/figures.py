"""Figures for the documentation, written from the benchmarks' own results.

    python -m bench.figures corpus NAME RESULTS.json --command "python -m bench.corpus_bench ..." \
        [--commit SHA] [--out docs/figures]
    python -m bench.figures fusion-diff NAME RESULTS.json --command "..." [--commit SHA]
    python -m bench.figures conversion NAME data/details/conversion.json --command "..."
    python -m bench.figures coverage NAME data/gt/designs.parquet --command "dvc repro ground_truth"
    python -m bench.figures fuzz NAME DIR/rows.json --command "python -m bench.fuzz_bench ..."
    python -m bench.figures verify NAME DIR/results.json --command "python -m bench.verify_bench ..."
    python -m bench.figures fault NAME DIR/results.json --command "python -m bench.fault_bench ..."
    python -m bench.figures build|search|replay NAME DIR/results.json --command "python -m bench..."
    python -m bench.figures guide-cost NAME DIR/guide_cost.json --command "python -m bench.guide_cost..."
    python -m bench.figures report NAME REPORT_DIR --command "python -m eval.report ..."
    python -m bench.figures rank NAME DIR/rank.json --command "python -m eval.rank ..."

A results page never carries a number typed by hand: a benchmark's ``results.json`` (its per-design
rows, or its summary) is reduced here to a small figure file, ``docs/figures/NAME.json``, holding
the figure with the command and the commit that measured it, and the site's hook
(``docs/hooks/figures.py``) renders ``<!-- figure: ... -->`` markers in the pages from those files.
Re-running a benchmark and this command is how a page's numbers change.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
from collections import Counter
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from bench.guide_cost_bench import summary
from eval.coverage import CATEGORIES, LABELS, coverage_table
from eval.curves import at_time
from zonegraph.status import Status

FIGURES = Path("docs/figures")
EXACT_IOU = 0.9999
SEARCHED = (Status.EXACT, Status.PARTIAL, Status.REBUILD_FAILED)
# "zonegraph: error: PATH: STATUS: reason", convert's "PATH: DESIGN: STATUS: reason"
USER_ERROR = re.compile(r"error: \S+: (?:\S+: )?([a-z_]+): ")


def _group(rows: list[dict]) -> dict:
    """Counts of one folder's rows: drawn, converted, zone graph built and searched, exact."""
    converted = [r for r in rows if not str(r.get("status", "")).startswith("convert_")]
    searched = [r for r in converted if r.get("status") in SEARCHED]
    return {
        "drawn": len(rows),
        "converted": len(converted),
        "zone_graph": len(searched),
        "exact": sum(bool(r.get("exact")) for r in searched),
        "mean_iou_brep": round(float(np.mean([r.get("iou_brep", 0.0) for r in searched])), 4)
        if searched
        else None,
    }


def corpus_figure(rows: list[dict]) -> dict:
    """The corpus benchmark's figure: counts by folder and overall, the largest search wall past
    its budget, and the zone-exact programs whose B-rep, JSON or script is not exact."""
    folders = sorted({r["folder"] for r in rows})
    timed = [r for r in rows if "search_s" in r and r.get("config")]
    overrun = max((r["search_s"] / r["config"]["budget_s"] - 1 for r in timed), default=None)
    zone_exact = [r for r in rows if r.get("iou_zone", 0.0) >= EXACT_IOU]
    lost = [
        r["design_id"]
        for r in zone_exact
        if min(r.get("iou_brep", 0.0), r.get("json_iou", 0.0), r.get("script_iou", 0.0)) < EXACT_IOU
    ]
    return {
        "folders": {f: _group([r for r in rows if r["folder"] == f]) for f in folders},
        "all": _group(rows),
        "largest_overrun": None if overrun is None else round(overrun, 4),
        "zone_exact": len(zone_exact),
        "zone_exact_files_not_exact": lost,
    }


def conversion_figure(details: dict) -> dict:
    """The corpus conversion by folder and its failures by status, from the generate stage's
    ``data/details/conversion.json`` (or a metrics file of before, which held the same keys)."""
    by_folder = {
        f: {"designs": g["designs"], "converted": g["converted"]} for f, g in details["by_folder"].items()
    }
    return {
        "by_folder": by_folder,
        "designs": sum(g["designs"] for g in by_folder.values()),
        "converted": sum(g["converted"] for g in by_folder.values()),
        "failed_by_status": {k: v for k, v in details["by_status"].items() if k != Status.OK},
    }


def coverage_figure(designs: pd.DataFrame) -> dict:
    """The coverage categories by timeline folder of every variant (graph, proposal level) that
    the ``ground_truth`` stage measured, from its ``data/gt/designs.parquet``; a variant the stage
    left out (``full_graph: false``) has no status and no table."""
    variants = {}
    for graph in ("simplified", "full"):
        measured = f"{graph}_status" in designs and designs[f"{graph}_status"].notna().any()
        for level in (1, 3):
            if not measured or f"{graph}_captured_l{level}" not in designs:
                continue
            table = coverage_table(designs, graph, level)
            folders = [f for f in table.columns if f != "all"]
            variants[f"{graph} graph, level {level}"] = {
                c: {f: int(table.loc[c, f]) for f in folders} for c in CATEGORIES
            }
    return {"variants": variants, "labels": LABELS, "designs": len(designs)}


def fuzz_figure(rows: list[dict]) -> dict:
    """The fuzz benchmark's outcomes by command, the user errors by status and the slowest input,
    from its ``rows.json``."""
    from zonegraph.testing.fuzz import OUTCOMES  # needs hypothesis: only for this figure

    commands = sorted({r["command"] for r in rows})
    outcomes = list(OUTCOMES)  # every class, a violation that did not happen as 0
    statuses: dict[str, int] = {}
    for r in rows:
        if r["outcome"] == "user_error":
            found = USER_ERROR.search(str(r.get("detail", "")))
            key = found.group(1) if found else "other"
            statuses[key] = statuses.get(key, 0) + 1
    return {
        "inputs": len(rows),
        "by_outcome": {
            o: {c: sum(r["outcome"] == o and r["command"] == c for r in rows) for c in commands}
            for o in outcomes
        },
        "user_errors_by_status": dict(sorted(statuses.items(), key=lambda kv: -kv[1])),
        "slowest_s": round(max((float(r["seconds"]) for r in rows), default=0.0), 2),
    }


def verify_figure(rows: list[dict]) -> dict:
    """The verify benchmark's sample: conversions by status, replay exit codes, the differences
    from Fusion by decade and every converted design above ``THRESHOLD``, from its results.json."""
    from bench.verify_bench import THRESHOLD, decade

    ok = [r for r in rows if r["status"] == Status.OK]
    above = [
        r
        for r in ok
        if max(r["fusion_volume_rel_difference"] or 0, r["fusion_area_rel_difference"] or 0) > THRESHOLD
    ]
    return {
        "designs": len(rows),
        "convert": dict(Counter(r["status"] for r in rows)),
        "converted": len(ok),
        "replay_exits": {str(k): v for k, v in Counter(r.get("replay_exit") for r in ok).items()},
        "volume_decades": dict(Counter(decade(r["fusion_volume_rel_difference"]) for r in ok)),
        "area_decades": dict(Counter(decade(r["fusion_area_rel_difference"]) for r in ok)),
        "threshold": THRESHOLD,
        "above": [
            {k: r.get(k) for k in ("design_id", "batch", "replay_exit")}
            | {"volume": r["fusion_volume_rel_difference"], "area": r["fusion_area_rel_difference"]}
            for r in sorted(above, key=lambda r: -(r["fusion_volume_rel_difference"] or 0))
        ],
    }


def _spread(values: list[float], scale: float = 1.0, digits: int = 4) -> dict | None:
    """Median, 90th percentile and maximum of ``values`` times ``scale`` (None when empty)."""
    if not values:
        return None
    a = scale * np.asarray(values, float)
    figures = (np.median(a), np.percentile(a, 90), a.max())
    return {k: round(float(v), digits) for k, v in zip(("median", "p90", "max"), figures, strict=True)}


def build_figure(rows: list[dict]) -> dict:
    """The zone-graph build benchmark by design set and graph: built of drawn, build seconds and
    zone counts, and every failure with its status."""
    groups = {}
    for name in sorted({r["set"] for r in rows}):
        for simplified in (True, False):
            group = [r for r in rows if r["set"] == name and r["simplified"] == simplified]
            built = [r for r in group if r["status"] == Status.OK]
            groups[f"{name}, {'simplified' if simplified else 'full'}"] = {
                "designs": len(group),
                "built": len(built),
                "build_s": _spread([r["build_s"] for r in built]),
                "zones": _spread([r["zones"] for r in built], digits=0),
                "failed": {r["design"]: r["status"] for r in group if r["status"] != Status.OK},
            }
    return {"groups": groups}


def search_figure(rows: list[dict]) -> dict:
    """The search benchmark by design set: exact of searched (and of drawn), proposals per state,
    milliseconds per expansion, seconds to exact and the designs not exact."""
    sets = {}
    for name in sorted({r["set"] for r in rows}):
        drawn = [r for r in rows if r["set"] == name]
        searched = [r for r in drawn if "skipped" not in r]
        exact = [r for r in searched if r["exact"]]
        slowest = max(searched, key=lambda r: max(r["expansion_s"] or [0.0]), default=None)
        sets[name] = {
            "drawn": len(drawn),
            "searched": len(searched),
            "exact": len(exact),
            "expansions": sum(len(r["expansion_s"]) for r in searched),
            "proposals_per_state": _spread([n for r in searched for n in r["proposals_per_state"]], digits=0),
            "ms_per_expansion": _spread([t for r in searched for t in r["expansion_s"]], 1e3, 2),
            "s_to_exact": _spread([r["time_to_best_s"] for r in exact]),
            "not_exact": sorted(r["design"] for r in searched if not r["exact"]),
            "slowest_expansion": None
            if slowest is None
            else {"design": slowest["design"], "zones": slowest["zones"]},
            "budget_s": searched[0]["budget_s"] if searched else None,
            "guide": searched[0]["guide"] if searched else None,
        }
    return {"sets": sets}


def replay_figure(rows: list[dict]) -> dict:
    """The replay benchmark by design set: milliseconds per design and per extrude step."""
    sets = {}
    for name in sorted({r["set"] for r in rows}):
        group = [r for r in rows if r["set"] == name]
        slowest = max(group, key=lambda r: r["seconds"])
        sets[name] = {
            "designs": len(group),
            "steps": sum(len(r["step_s"]) for r in group),
            "ms_per_design": _spread([r["seconds"] for r in group], 1e3, 2),
            "ms_per_step": _spread([t for r in group for t in r["step_s"]], 1e3, 2),
            "slowest": {"design": slowest["design"], "steps": len(slowest["step_s"])},
        }
    return {"sets": sets}


TALLY = ("faults", "survived", "lost", "stale", "wrong", "damaged", "detected")


def fault_figure(tallies: dict[str, dict]) -> dict:
    """The fault benchmark's tallies by kind and over all kinds (its notes name each failed
    trial)."""
    by_kind = {k: {n: int(t[n]) for n in TALLY} for k, t in sorted(tallies.items())}
    return {
        "by_kind": by_kind,
        "all": {n: sum(t[n] for t in by_kind.values()) for n in TALLY},
        "notes": [n for t in tallies.values() for n in t.get("notes", [])],
    }


def _median_ratio(times: pd.DataFrame, guide: str, reference: str, seed: int = 0) -> dict:
    """Median time to exact of ``guide`` over ``reference``'s on the designs both solved, with a
    seeded 90% bootstrap interval over those designs."""
    pair = times[[guide, reference]].dropna().to_numpy()
    if len(pair) == 0:
        return {"designs": 0, "ratio": None, "ci": None}

    def ratio(rows: np.ndarray) -> float:
        ref = float(np.median(rows[:, 1]))
        return float(np.median(rows[:, 0])) / ref if ref > 0 else float("nan")

    draws = np.random.default_rng(seed).integers(0, len(pair), (2000, len(pair)))
    boot = np.array([ratio(pair[d]) for d in draws])
    low, high = np.nanpercentile(boot, [5, 95])
    interval = [round(float(low), 3), round(float(high), 3)]
    return {"designs": len(pair), "ratio": round(ratio(pair), 3), "ci": interval}


def _rounded(value: float | None, digits: int) -> float | None:
    return None if value is None or pd.isna(value) else round(float(value), digits)


def guide_cost_figure(results: dict, reference: str = "heuristic") -> dict:
    """The guide cost benchmark by budget and guide: its own summary (exact, all designs and
    GT >= 3; medians on the designs every guide solved) and each guide's median time to exact
    over the reference's on the designs both solved."""
    rows = pd.DataFrame(results["rows"])
    budgets: dict[str, dict] = {}
    for r in summary(rows).to_dict(orient="records"):
        at = rows[rows["budget"] == r["budget_s"]]
        times = at.pivot(index="design_id", columns="guide", values="time_to_exact_s")
        entry = budgets.setdefault(f"{r['budget_s']:g}", {"common": int(r["common"]), "guides": {}})
        entry["guides"][str(r["guide"])] = {
            "exact": int(r["exact"]),
            "designs": int(r["designs"]),
            "exact_gt3": int(r["exact_gt3"]),
            "designs_gt3": int(r["designs_gt3"]),
            "mean_iou": _rounded(r["mean_iou"], 4),
            "mean_iou_gt3": _rounded(r["mean_iou_gt3"], 4),
            "median_time_to_exact_s": _rounded(r["median_time_to_exact_s"], 5),
            "median_expansions": _rounded(r["median_expansions"], 1),
            "time_ratio": None if r["guide"] == reference else _median_ratio(times, r["guide"], reference),
        }
    return {"reference": reference, "budgets": budgets}


REPORT_TIMES = (0.5, 1.0, 5.0, 20.0)  # the search seconds the evaluation's figure reads its curves at


def _curve_points(curves: pd.DataFrame) -> dict:
    """Per guide: designs, and mean IoU and exact rate at each of REPORT_TIMES, read as the
    report reads them (`eval.curves.at_time`)."""
    out = {}
    for guide, group in curves.groupby("guide", sort=False):
        points = {}
        for t in REPORT_TIMES:
            at = at_time(group, t)
            iou, exact = round(float(at["mean_iou"]), 4), round(float(at["exact_rate"]), 4)
            points[f"{t:g}"] = {"iou": iou, "exact": exact}
        out[str(guide)] = {"designs": int(group["designs"].iloc[0]), "at": points}
    return out


def report_figure(folder: Path) -> dict:
    """The evaluation report's IoU and exact rate vs search time (``eval.report``'s
    ``curves.csv`` and ``curves_gt3.csv``), per guide at REPORT_TIMES."""
    figure = {"all": _curve_points(pd.read_csv(folder / "curves.csv"))}
    if (folder / "curves_gt3.csv").is_file():
        figure["gt3"] = _curve_points(pd.read_csv(folder / "curves_gt3.csv"))
    return figure


RANK_METRICS = ("rank", "floor", "normalised", "top1", "top5")


def _ratios(rows: list[dict]) -> dict:
    """`eval.rank.ratios` rows by guide: the ratio and its paired interval."""
    return {
        str(r["guide"]): {
            "ratio": _rounded(r["ratio"], 3),
            "ci": [_rounded(r["ci_low"], 3), _rounded(r["ci_high"], 3)],
        }
        for r in rows
    }


def rank_figure(results: dict) -> dict:
    """The GT rank per guide (``eval.rank``'s ``rank.json``): designs, ranked and single steps,
    every scale with its 90% interval, and each guide's normalised rank over the heuristic's (and
    over ``--base``'s); by timeline folder and by kind of step where the results have them."""
    guides = {}
    for r in results["guides"]:
        entry = {"designs": int(r["designs"]), "steps": int(r["steps"]), "single": int(r["single"])}
        for metric in RANK_METRICS:
            prefix = "" if metric == "rank" else f"{metric}_"
            entry[metric] = _rounded(r.get(metric), 4)
            if metric != "floor":
                entry[f"{metric}_ci"] = [
                    _rounded(r.get(f"{prefix}ci_low"), 4),
                    _rounded(r.get(f"{prefix}ci_high"), 4),
                ]
        guides[str(r["guide"])] = entry
    figure = {"guides": guides, "vs_heuristic": _ratios(results.get("vs_heuristic", []))}
    if results.get("vs_base"):
        base = str(results["vs_base"][0]["base"])
        figure["vs_base"] = {"base": base, "ratios": _ratios(results["vs_base"])}
    if results.get("by_folder"):
        figure["by_folder"] = [
            {
                "folder": str(r["folder"]),
                "guide": str(r["guide"]),
                "designs": int(r["designs"]),
                "steps": int(r["steps"]),
                **{m: _rounded(r[m], 4) for m in ("normalised", "top1", "top5")},
                "vs_heuristic": _rounded(r["vs_heuristic"], 3),
                "ci": [_rounded(r["ci_low"], 3), _rounded(r["ci_high"], 3)],
            }
            for r in results["by_folder"]
        ]
    if results.get("by_kind"):
        figure["by_kind"] = [
            {
                "kind": str(r["kind"]),
                "guide": str(r["guide"]),
                "steps": int(r["steps"]),
                "share": _rounded(r["share"], 3),
                "normalised": _rounded(r["normalised"], 4),
                "top1": _rounded(r["top1"], 3),
                "vs_heuristic": _rounded(r["vs_heuristic"], 3),
                "ci": [_rounded(r["ci_low"], 3), _rounded(r["ci_high"], 3)],
            }
            for r in results["by_kind"]
        ]
    return figure


def _stage(table: pd.DataFrame, status: str, seconds: str) -> dict:
    """Designs by status and the job seconds of one stage's table (its sum and median)."""
    counts = table[status].fillna("not run").astype(str).value_counts()
    done = table[seconds].dropna()
    return {
        "designs": len(table),
        "statuses": {str(k): int(v) for k, v in counts.items()},
        "job_seconds": round(float(done.sum()), 1),
        "median_seconds": _rounded(done.median(), 3) if len(done) else None,
    }


def pipeline_run_figure(project: Path) -> dict:
    """A pipeline run's stages from what they wrote (``data/``, ``models/``): designs by status and
    job seconds per stage, the labels' counts and the training's best epoch. Walls are not among
    the stages' outputs (a resumed stage's pieces run sessions apart)."""
    data = project / "data"
    stages = {
        "generate": _stage(pd.read_parquet(data / "designs/conversion.parquet"), "status", "seconds"),
        "replay": _stage(pd.read_parquet(data / "replay/manifest.parquet"), "status", "seconds"),
        "zonegraphs": _stage(pd.read_parquet(data / "zonegraphs/manifest.parquet"), "status", "job_seconds"),
    }
    gt = pd.read_parquet(data / "gt/designs.parquet")
    stages["ground_truth"] = _stage(gt[gt["gt_seconds"].notna()], "simplified_status", "gt_seconds")
    labels = json.loads((data / "details/labels.json").read_text())
    for key, name in (("rank_only", "labels (rank-only)"), ("", "labels (with completions)")):
        part = labels.get(key, {}) if key else labels
        if part.get("designs"):
            stages[name] = {
                "designs": int(part["designs"]),
                "statuses": {str(k): int(v) for k, v in part["by_status"].items()},
                "job_seconds": round(float(part["seconds"]), 1),
                "median_seconds": part.get("seconds_per_design_median"),
                "steps": int(part["steps"]),
                "labelled_steps": int(part["labelled_steps"]),
                "proposals": int(part["proposals"]),
            }
    best = project / "models/best.json"
    train = json.loads(best.read_text()) if best.is_file() else None
    if train is not None:
        train = {k: train[k] for k in ("epoch", "val_normalised", "val_rank", "run_id") if k in train}
    return {"stages": stages, "train": train}


HEAVY_FIELDS = ("folder", "zones", "build_s", "expansion_s", "first_proposals", "ground_truth_s", "labels_s")


def heavy_figure(rows: list[dict]) -> dict:
    """The heavy-part benchmark by design: zones, each stage's CPU seconds (absent where the
    design ran out of time first), its status and its whole time."""
    return {
        "designs": {
            r["design_id"]: {
                **{k: r[k] for k in HEAVY_FIELDS if k in r},
                "status": r["status"],
                "seconds": r["seconds"],
            }
            for r in rows
        }
    }


EXPANSION_FIELDS = ("zones", "first_expansion_cpu_s", "search_cpu_s", "exact", "expansions")


def expansion_figure(rows: list[dict]) -> dict:
    """The expansion benchmark: the spread of first-expansion and search CPU seconds, and each
    graph's own figures (to set two checkouts' runs side by side)."""
    return {
        "graphs": len(rows),
        "exact": sum(r["exact"] for r in rows),
        "first_expansion_cpu_s": _spread([r["first_expansion_cpu_s"] for r in rows]),
        "search_cpu_s": _spread([r["search_cpu_s"] for r in rows]),
        "first_expansion_total_s": round(sum(r["first_expansion_cpu_s"] for r in rows), 3),
        "search_total_s": round(sum(r["search_cpu_s"] for r in rows), 3),
        "designs": {r["design_id"]: {k: r[k] for k in EXPANSION_FIELDS} for r in rows},
    }


FOLDED_FIELDS = ("zones", "states", "network", "features", "heuristic")


def folded_figure(rows: list[dict]) -> dict:
    """The folded-scorer benchmark: milliseconds per scored state of each graph (to set two
    checkouts' runs side by side)."""
    return {"designs": {r["design_id"]: {k: r[k] for k in FOLDED_FIELDS} for r in rows}}


def startup_figure(results: Path) -> dict:
    """The start-up benchmark by part: each process's CPU, wall and peak memory per column (ours
    cold, ours handed to a server, the original), and the server's own start where it ran."""
    rows = json.loads(results.read_text())
    start = results.parent / "server_start.json"
    columns = [c for c in rows[0] if isinstance(rows[0][c], dict)] if rows else []
    parts = {
        r["part"]: {"folder": r["folder"], "step_bytes": r["step_bytes"], **{c: r[c] for c in columns}}
        for r in rows
    }
    return {
        "columns": columns,
        "parts": parts,
        "server_start": json.loads(start.read_text()) if start.is_file() else None,
    }


def cover_figure(results: Path) -> dict:
    """The cover benchmark's counts (``tally.json`` beside its ``results.json``)."""
    return json.loads((results.parent / "tally.json").read_text())


FIGURES_OF = {
    "build": build_figure,
    "search": search_figure,
    "replay": replay_figure,
    "fault": fault_figure,
    "corpus": corpus_figure,
    "conversion": conversion_figure,
    "coverage": coverage_figure,
    "fuzz": fuzz_figure,
    "verify": verify_figure,
    "guide-cost": guide_cost_figure,
    "rank": rank_figure,
    "heavy": heavy_figure,
    "expansion": expansion_figure,
    "folded": folded_figure,
}


def head_commit() -> str:
    out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return out.stdout.strip() or "unknown"


def write_figure(
    kind: str, name: str, figure: dict, command: str, commit: str, measured: str, out: Path
) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.json"
    record = {
        "kind": kind,
        "name": name,
        "command": command,
        "commit": commit,
        "measured": measured,
        "figure": figure,
    }
    path.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n")
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "kind", choices=[*FIGURES_OF, "fusion-diff", "report", "pipeline-run", "startup", "cover"]
    )
    ap.add_argument("name", help="the figure's file name under --out, without .json")
    ap.add_argument("results", type=Path, help="the benchmark's results.json (a project, for pipeline-run)")
    ap.add_argument("--command", required=True, help="the command that wrote RESULTS")
    ap.add_argument("--commit", default=None, help="the commit it measured (default: HEAD)")
    ap.add_argument("--measured", default=date.today().isoformat(), help="the day it ran (default: today)")
    ap.add_argument("--out", type=Path, default=FIGURES)
    args = ap.parse_args()
    if args.kind == "report":
        figure = report_figure(args.results)
    elif args.kind == "pipeline-run":
        figure = pipeline_run_figure(args.results)
    elif args.kind == "startup":
        figure = startup_figure(args.results)
    elif args.kind == "cover":
        figure = cover_figure(args.results)
    else:
        coverage = args.kind == "coverage"
        data = pd.read_parquet(args.results) if coverage else json.loads(args.results.read_text())
        figure = FIGURES_OF[args.kind](data) if args.kind in FIGURES_OF else data
    commit = args.commit or head_commit()
    path = write_figure(args.kind, args.name, figure, args.command, commit, args.measured, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()

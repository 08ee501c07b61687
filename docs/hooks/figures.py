"""MkDocs hook: results tables rendered from the figure files the benchmarks wrote.

A page writes ``<!-- figure: KIND NAME ... -->`` where a table belongs; the hook replaces it with
the table drawn from ``docs/figures/NAME.json`` (written by ``python -m bench.figures``), each
table followed by the command and commit that measured it. An unknown kind or a missing figure
file stops the build, so ``mkdocs build --strict`` in ``make test`` fails rather than publishing a
stale or invented number. ``<!-- typed: COMMIT -->`` marks a number typed from a command's output
before its results file was kept, with the commit that added it.
"""

from __future__ import annotations

import json
import math
import re
import statistics
from collections.abc import Callable
from pathlib import Path

FIGURES = Path(__file__).resolve().parents[1] / "figures"
MARKER = re.compile(r"<!--\s*figure:\s*([\w-]+)((?:\s+[\w.-]+)+)\s*-->")
# A number typed from a command's output whose results file is not kept any more: the page names
# the command beside it, the marker the commit that added it (never a new figure made up for it).
TYPED = re.compile(r"<!--\s*typed:\s*([0-9a-f]{7,40})\s*-->")


def _load(name: str) -> dict:
    path = FIGURES / f"{name}.json"
    if not path.is_file():
        raise ValueError(f"figure file {path} does not exist (write it with python -m bench.figures)")
    return json.loads(path.read_text())


def _rate(n: int, d: int) -> str:
    return f"{n}/{d} ({n / d:.1%})" if d else "-"


def _sources(records: list[dict]) -> str:
    return "\n".join(f"- {r['name']}: `{r['command']}` at {r['commit']} ({r['measured']})" for r in records)


def _row(label: str, cells: list[str]) -> str:
    return f"| {label} | " + " | ".join(cells) + " |"


def corpus_exact(records: list[dict]) -> str:
    """Exact designs by timeline folder, one column per run, rates of the designs that converted."""
    folders = sorted({f for r in records for f in r["figure"]["folders"]})
    figures = [r["figure"] for r in records]
    lines = [_row("folder", [r["name"] for r in records]), "|---" * (len(records) + 1) + "|"]
    for f in folders:
        groups = [x["folders"].get(f) for x in figures]
        lines.append(
            _row(f, [_rate(g["exact"], g["converted"]) if g and g["converted"] else "(none)" for g in groups])
        )
    alls = [x["all"] for x in figures]
    lines += [
        _row("**all, of converted**", [f"**{_rate(a['exact'], a['converted'])}**" for a in alls]),
        _row("all, of drawn", [_rate(a["exact"], a["drawn"]) for a in alls]),
        _row("zone graph built, of converted", [_rate(a["zone_graph"], a["converted"]) for a in alls]),
        _row(
            "largest search wall past budget",
            ["-" if x["largest_overrun"] is None else f"{x['largest_overrun']:+.1%}" for x in figures],
        ),
        _row(
            "zone-exact programs not exact as B-rep, JSON or script",
            [f"{len(x['zone_exact_files_not_exact'])} of {x['zone_exact']}" for x in figures],
        ),
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def fusion_diff(records: list[dict]) -> str:
    """Our replay against Fusion's published figures, by decade, and later-stage failure rates."""
    (r,) = records
    f = r["figure"]
    keys = sorted(
        set(f["volume_decades"]) | set(f["area_decades"]),
        key=lambda k: -99 if k.startswith("<") else (99 if k == "-" else int(k[2:])),
    )
    lines = [
        f"{f['designs']} designs, {f['converted']} converted; {f['above']} of the converted differ "
        "from Fusion by more than 1e-6 in volume or area.",
        "",
        "| relative difference, our replay vs Fusion | volume | area |",
        "|---|---|---|",
        *(f"| {k} | {f['volume_decades'].get(k, 0)} | {f['area_decades'].get(k, 0)} |" for k in keys),
        "",
        "| later stage | group | designs | failed | rate |",
        "|---|---|---|---|---|",
        *(
            f"| {x['stage']} | {x['group']} | {x['designs']} | {x['failed']} | "
            f"{'-' if x['rate'] is None else format(x['rate'], '.1%')} |"
            for x in f["failure_rates"]
        ),
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def conversion(records: list[dict]) -> str:
    """The corpus conversion by timeline folder, with the failures by status."""
    (r,) = records
    f = r["figure"]
    failed = ", ".join(f"`{k}` {v}" for k, v in sorted(f["failed_by_status"].items(), key=lambda kv: -kv[1]))
    lines = [
        f"**{_rate(f['converted'], f['designs'])} designs converted and verified.**",
        "",
        "| folder | designs | converted | rate |",
        "|---|---|---|---|",
        *(
            f"| {k} | {g['designs']:,} | {g['converted']:,} | {g['converted'] / g['designs']:.2%} |"
            for k, g in sorted(f["by_folder"].items())
        ),
        "",
        f"Failures by status: {failed or 'none'}.",
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def coverage(records: list[dict]) -> str:
    """The coverage categories of every measured variant: share of all designs, then of each
    timeline folder, with the counts of designs per folder as the last row."""
    (r,) = records
    f = r["figure"]
    out = []
    for name, table in f["variants"].items():
        folders = sorted({k for counts in table.values() for k in counts})
        totals = {k: sum(counts.get(k, 0) for counts in table.values()) for k in folders}
        n = sum(totals.values())
        out += [f"**{name}**", "", _row("category", ["all", *folders]), "|---" * (len(folders) + 2) + "|"]
        for category, counts in table.items():
            total = sum(counts.values())
            cells = [f"{counts.get(k, 0) / totals[k]:.0%}" if totals[k] else "-" for k in folders]
            out.append(_row(f["labels"][category], [f"{total:,} ({total / n:.1%})" if n else "-", *cells]))
        out += [_row("designs", [f"{n:,}", *(f"{totals[k]:,}" for k in folders)]), ""]
    return "\n".join(out) + "\nMeasured by:\n\n" + _sources(records)


def _outcome_order(outcome: str) -> tuple[int, str]:
    """The contract's outcomes first, then the violations (a figure file sorts its keys)."""
    kept = ("success", "user_error", "timeout")
    return (kept.index(outcome) if outcome in kept else len(kept), outcome)


def fuzz(records: list[dict]) -> str:
    """The fuzz benchmark's outcomes by command, one column per command."""
    (r,) = records
    f = r["figure"]
    commands = sorted({c for counts in f["by_outcome"].values() for c in counts})
    lines = [
        "| outcome | inputs | " + " | ".join(commands) + " |",
        "|---|---:|" + "---:|" * len(commands),
        *(
            f"| {o} | {sum(counts.values())} | " + " | ".join(str(counts.get(c, 0)) for c in commands) + " |"
            for o, counts in sorted(f["by_outcome"].items(), key=lambda kv: _outcome_order(kv[0]))
        ),
        "",
        f"{f['inputs']} inputs; user errors by status: "
        + ", ".join(f"`{k}` {v}" for k, v in f["user_errors_by_status"].items())
        + f"; the slowest input took {f['slowest_s']} s.",
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def _decade_key(k: str) -> int:
    return -99 if k.startswith("<") else (99 if k == "-" else int(k[2:]))


def verify(records: list[dict]) -> str:
    """The verify benchmark's sample: our replay against Fusion by decade, the designs above the
    threshold listed."""
    (r,) = records
    f = r["figure"]
    keys = sorted(set(f["volume_decades"]) | set(f["area_decades"]), key=_decade_key)
    lines = [
        f"{f['designs']} designs, convert: {f['convert']}; `zonegraph replay` (defaults) on the "
        f"{f['converted']} converted: exit codes {f['replay_exits']}.",
        "",
        "| relative difference, our replay vs Fusion | volume | area |",
        "|---|---|---|",
        *(f"| {k} | {f['volume_decades'].get(k, 0)} | {f['area_decades'].get(k, 0)} |" for k in keys),
        "",
        f"{len(f['above'])} of {f['converted']} converted designs differ from Fusion by more than "
        f"{f['threshold']:g}:",
        "",
        *(
            f"- `{a['design_id']}` ({a['batch']}): volume {a['volume']:.1e}, area {a['area']:.1e}, "
            f"replay exit {a['replay_exit']}"
            for a in f["above"]
        ),
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def fault(records: list[dict]) -> str:
    """The fault benchmark: faults by kind, survived, records lost, stale or wrong, and the
    corruptions detected among the stored files damaged."""
    (r,) = records
    f = r["figure"]

    def row(kind: str, t: dict) -> str:
        detected = f"{t['detected']}/{t['damaged']}" if t["damaged"] else "-"
        cells = [str(t[n]) for n in ("faults", "survived", "lost", "stale", "wrong")]
        return f"| {kind} | " + " | ".join(cells) + f" | {detected} |"

    lines = [
        "| fault | faults | survived | lost | stale | wrong | corruptions detected |",
        "|---|---:|---:|---:|---:|---:|---:|",
        *(row(k, t) for k, t in f["by_kind"].items()),
        row("all", f["all"]),
    ]
    if f["notes"]:
        lines += ["", "Trials not survived:", "", *(f"- {n}" for n in f["notes"])]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def _three(spread: dict | None, digits: int = 3) -> str:
    """``median / p90 / max`` of a figure's spread (``-`` when nothing was measured)."""
    if spread is None:
        return "-"
    return " / ".join(f"{spread[k]:,.{digits}f}" for k in ("median", "p90", "max"))


def build(records: list[dict]) -> str:
    """Zone-graph builds by design set and graph: built of drawn, seconds, zones, failures."""
    (r,) = records
    groups = r["figure"]["groups"]
    lines = [
        "| designs | built | build s median / p90 / max | zones median / p90 / max |",
        "|---|---|---|---|",
        *(
            f"| {name} | {_rate(g['built'], g['designs'])} | {_three(g['build_s'])} | "
            f"{_three(g['zones'], 0)} |"
            for name, g in groups.items()
        ),
    ]
    failed = [f"`{d}` ({name}: {status})" for name, g in groups.items() for d, status in g["failed"].items()]
    if failed:
        lines += ["", "Not built: " + ", ".join(failed) + "."]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def search(records: list[dict]) -> str:
    """Searches by design set: exact, proposals per state, milliseconds per expansion, seconds to
    exact, with the designs not exact."""
    (r,) = records
    sets = r["figure"]["sets"]
    lines = [
        "| designs | exact, of searched | proposals per state | ms per expansion | s to exact |",
        "|---|---|---|---|---|",
        *(
            f"| {name} ({g['searched']} of {g['drawn']} searched, {g['guide']}, {g['budget_s']:g} s) | "
            f"{_rate(g['exact'], g['searched'])} | {_three(g['proposals_per_state'], 0)} | "
            f"{_three(g['ms_per_expansion'], 2)} | {_three(g['s_to_exact'])} |"
            for name, g in sets.items()
        ),
        "",
        "Each cell is median / p90 / max. "
        + " ".join(
            f"Not exact in {name}: {', '.join(f'`{d}`' for d in g['not_exact']) or 'none'}."
            for name, g in sets.items()
        ),
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def replay(records: list[dict]) -> str:
    """Replays by design set: milliseconds per design and per extrude step, the slowest design."""
    (r,) = records
    sets = r["figure"]["sets"]
    lines = [
        "| designs | steps | ms per design median / p90 / max | ms per step median / p90 / max | slowest |",
        "|---|---|---|---|---|",
        *(
            f"| {name} ({g['designs']}) | {g['steps']} | {_three(g['ms_per_design'], 1)} | "
            f"{_three(g['ms_per_step'], 1)} | `{g['slowest']['design']}` ({g['slowest']['steps']} steps) |"
            for name, g in sets.items()
        ),
    ]
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def guide_cost(records: list[dict]) -> str:
    """Searches by guide at equal budgets: exact, and the time to exact against the reference's."""
    lines = [
        "| run | budget s | guide | exact | exact, GT >= 3 | mean IoU (all / GT >= 3) | "
        "median s to exact (all solve) | median expansions | median time / reference's (90% CI, designs) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        figure = r["figure"]
        for budget, at in figure["budgets"].items():
            for guide, g in at["guides"].items():
                ratio, versus = g["time_ratio"], "-"
                if ratio and ratio["ratio"] is not None:
                    low, high = ratio["ci"]
                    versus = f"{ratio['ratio']:.2f} ({low:.2f} - {high:.2f}, {ratio['designs']})"
                median = "-" if g["median_time_to_exact_s"] is None else f"{g['median_time_to_exact_s']:.4f}"
                expansions = "-" if g["median_expansions"] is None else f"{g['median_expansions']:g}"
                lines.append(
                    f"| {r['name']} | {budget} | {guide} | {_rate(g['exact'], g['designs'])} | "
                    f"{_rate(g['exact_gt3'], g['designs_gt3'])} | {_ious(g)} | {median} | {expansions} | "
                    f"{versus} |"
                )
    reference = ", ".join(sorted({r["figure"]["reference"] for r in records}))
    note = (
        f"\n\nThe last column: the guide's median time to exact over the {reference}'s, on the designs "
        "both solved at that budget. Medians of time and expansions: over the designs every guide of "
        "the run solved. Mean IoU: the zone IoU of each search's best canvas at that budget."
    )
    return "\n".join(lines) + note + "\n\nMeasured by:\n\n" + _sources(records)


def _ious(guide: dict) -> str:
    """Mean zone IoU of all designs and of GT >= 3 (figures measured before it carry none)."""
    if guide.get("mean_iou") is None:
        return "-"
    long = guide.get("mean_iou_gt3")
    return f"{guide['mean_iou']:.3f} / " + ("-" if long is None else f"{long:.3f}")


def report(records: list[dict]) -> str:
    """IoU and exact rate vs search time per guide, all designs and GT length >= 3."""
    (r,) = records
    lines = []
    for part, title in (("all", "designs searched"), ("gt3", "GT length >= 3")):
        guides = r["figure"].get(part)
        if not guides:
            continue
        times = sorted({t for g in guides.values() for t in g["at"]}, key=float)
        lines += [
            f"| guide ({title}) | designs | " + " | ".join(f"IoU / exact at {t} s" for t in times) + " |",
            "|---|---|" + "---|" * len(times),
        ]
        for name, g in guides.items():
            at = g["at"]
            cells = [f"{at[t]['iou']:.3f} / {at[t]['exact']:.1%}" if t in at else "-" for t in times]
            lines.append(f"| {name} | {g['designs']} | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines) + "\nMeasured by:\n\n" + _sources(records)


def rank(records: list[dict]) -> str:
    """The GT's rank per guide on every scale (means over steps, 90% intervals over designs), then
    each guide's normalised rank over the heuristic's (paired interval)."""
    lines = [
        "| run | guide | designs | steps (single left out) | rank / P | floor | normalised rank | "
        "top-1 | top-5 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]

    def cell(g: dict, metric: str, digits: int) -> str:
        low, high = g[f"{metric}_ci"]
        return f"{g[metric]:.{digits}f} ({low:.{digits}f} - {high:.{digits}f})"

    ratios, against = [], []
    for r in records:
        for name, g in r["figure"]["guides"].items():
            scales = [cell(g, "rank", 4), f"{g['floor']:.4f}", cell(g, "normalised", 4)]
            scales += [cell(g, "top1", 3), cell(g, "top5", 3)]
            head = f"| {r['name']} | {name} | {g['designs']} | {g['steps']} ({g['single']}) | "
            lines.append(head + " | ".join(scales) + " |")
        ratios += _ratio_rows(r["name"], r["figure"]["vs_heuristic"])
        if "vs_base" in r["figure"]:
            base = r["figure"]["vs_base"]
            against += _ratio_rows(r["name"], base["ratios"], base["base"])
    text = "\n".join(lines)
    if ratios:
        text += (
            "\n\n| run | guide | normalised rank / heuristic's | 90% CI (paired) |\n|---|---|---|---|\n"
            + "\n".join(ratios)
        )
    if against:
        text += (
            "\n\n| run | guide | base | normalised rank / base's | 90% CI (paired) |\n|---|---|---|---|---|\n"
            + "\n".join(against)
        )
    folders = [_folder_rows(r) for r in records if r["figure"].get("by_folder")]
    if folders:
        text += (
            "\n\nBy timeline folder (steps with more than one proposal):\n\n| run | folder | guide | designs "
            "| steps | normalised rank | top-1 | top-5 | / heuristic's (90% CI) |\n"
            "|---|---|---|---|---|---|---|---|---|\n" + "\n".join(row for rows in folders for row in rows)
        )
    kinds = [_kind_rows(r) for r in records if r["figure"].get("by_kind")]
    if kinds:
        text += (
            "\n\nBy kind of step (gt_completes: the GT completes the target; other_completes: another "
            "proposal does and the GT does not; none_completes: none does):\n\n| run | step | guide | steps "
            "| share of its sum | normalised rank | top-1 | / heuristic's (90% CI) |\n"
            "|---|---|---|---|---|---|---|---|\n" + "\n".join(row for rows in kinds for row in rows)
        )
    return text + "\n\nMeasured by:\n\n" + _sources(records)


def _ratio_rows(run: str, ratios: dict, base: str | None = None) -> list[str]:
    """One table row per guide: its ratio to the base (the heuristic unless named) and interval."""
    rows = []
    for name, v in ratios.items():
        interval = f"{v['ci'][0]:.3f} - {v['ci'][1]:.3f}"
        cells = [run, name, *([base] if base else []), f"{v['ratio']:.3f}", interval]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


def _ratio_cell(value: float | None, low: float | None, high: float | None) -> str:
    """A ratio with its interval, or "-" where it has none (the heuristic itself, or a base that
    ranks every GT first)."""
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:.3f}" + ("" if low is None else f" ({low:.3f} - {high:.3f})")


def _kind_rows(record: dict) -> list[str]:
    rows = []
    for k in record["figure"]["by_kind"]:
        cells = [record["name"], k["kind"], k["guide"], str(k["steps"]), f"{k['share']:.3f}"]
        cells += [f"{k['normalised']:.4f}", f"{k['top1']:.3f}", _ratio_cell(k["vs_heuristic"], *k["ci"])]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


def _folder_rows(record: dict) -> list[str]:
    rows = []
    for f in record["figure"]["by_folder"]:
        ratio = _ratio_cell(f["vs_heuristic"], *f["ci"])
        cells = [record["name"], f["folder"], f["guide"], str(f["designs"]), str(f["steps"])]
        cells += [f"{f['normalised']:.4f}", f"{f['top1']:.3f}", f"{f['top5']:.3f}", ratio]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


HEAVY_COLUMNS = (("zones", 0), ("build_s", 1), ("expansion_s", 2), ("first_proposals", 0), ("labels_s", 1))


def heavy(records: list[dict]) -> str:
    """The heaviest parts, one figure per checkout (oldest first): zones and each stage's CPU
    seconds as ``before → after``; a stage the design did not reach in its time says so."""

    def cell(d: dict | None, key: str, digits: int = 1) -> str:
        if d is None:
            return "-"
        if key in d:
            return f"{d[key]:,.{digits}f}" if isinstance(d[key], float) else f"{d[key]:,}"
        return f"> {d['seconds']:,.0f} ({d['status']})" if d["status"] != "ok" else "-"

    designs = list(dict.fromkeys(name for r in records for name in r["figure"]["designs"]))
    lines = [
        "| design | folder | zones | build CPU s | first expansion CPU s | first proposals | labels CPU s |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in designs:
        runs = [r["figure"]["designs"].get(name) for r in records]
        folder = next(d["folder"] for d in runs if d is not None)
        cells = [" → ".join(cell(d, key, digits) for d in runs) for key, digits in HEAVY_COLUMNS]
        lines.append(_row(f"{name}", [folder, *cells]))
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def expansion(records: list[dict]) -> str:
    """Runs of the expansion benchmark side by side (oldest first): the CPU seconds' spread per run,
    then the ten graphs of the costliest first expansions in the first run as ``before → after``."""

    def spread(s: dict) -> str:
        return f"{s['median']:.4f} / {s['p90']:.4f} / {s['max']:.3f}"

    lines = [
        "| run | graphs | exact | first expansion CPU s: median / p90 / max (total) "
        "| search CPU s: median / p90 / max (total) |",
        "|---|---|---|---|---|",
    ]
    for r in records:
        f = r["figure"]
        first = f"{spread(f['first_expansion_cpu_s'])} ({f['first_expansion_total_s']:.2f})"
        searched = f"{spread(f['search_cpu_s'])} ({f['search_total_s']:.2f})"
        lines.append(_row(r["name"], [str(f["graphs"]), str(f["exact"]), first, searched]))
    designs = records[0]["figure"]["designs"]
    costliest = sorted(designs, key=lambda d: -designs[d]["first_expansion_cpu_s"])[:10]
    lines += [
        "",
        "| design | zones | first expansion CPU s | search CPU s | exact | expansions |",
        "|---|---|---|---|---|---|",
    ]
    for name in costliest:
        runs = [r["figure"]["designs"].get(name) for r in records]
        cells = [" → ".join(_value(d, key) for d in runs) for key in EXPANSION_KEYS]
        lines.append(_row(name, [str(designs[name]["zones"]), *cells]))
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


EXPANSION_KEYS = ("first_expansion_cpu_s", "search_cpu_s", "exact", "expansions")


def folded(records: list[dict]) -> str:
    """Runs of the folded-scorer benchmark side by side (oldest first): per graph, by zone count,
    the network's milliseconds per scored state in each run (``before → after``), and the last
    run's features, heuristic and ratio."""
    last = records[-1]["figure"]["designs"]
    lines = [
        "| design | zones | states | network ms per state | features ms | heuristic ms "
        "| network / heuristic |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in sorted(last, key=lambda d: last[d]["zones"]):
        d = last[name]
        runs = [r["figure"]["designs"].get(name) for r in records]
        network = " → ".join("-" if r is None else f"{r['network']:.2f}" for r in runs)
        cells = [str(d["zones"]), str(d["states"]), network, f"{d['features']:.2f}", f"{d['heuristic']:.2f}"]
        lines.append(_row(name, [*cells, f"{d['network'] / d['heuristic']:.1f}x"]))
    return "\n".join(lines) + "\n\nMeasured by:\n\n" + _sources(records)


def _value(figures: dict | None, key: str) -> str:
    """One design's figure in a run, "-" where the run did not measure the design."""
    if figures is None:
        return "-"
    value = figures[key]
    return f"{value:.3f}" if isinstance(value, float) else str(value)


STAGE_ORDER = (
    "generate",
    "replay",
    "zonegraphs",
    "ground_truth",
    "labels (rank-only)",
    "labels (with completions)",
)


def pipeline_run(records: list[dict]) -> str:
    """A pipeline run's stages: designs, job seconds (sum and median per design) and designs by
    status, as the stages wrote them; the labels' counts and the training's best epoch below."""
    (r,) = records
    stages, lines = (
        r["figure"]["stages"],
        ["| stage | designs | job seconds (median) | by status |", "|---|---|---|---|"],
    )
    for name in [n for n in STAGE_ORDER if n in stages]:
        st = stages[name]
        median = "" if st["median_seconds"] is None else f" ({st['median_seconds']:.3f})"
        statuses = ", ".join(f"{k} {v:,}" for k, v in sorted(st["statuses"].items(), key=lambda kv: -kv[1]))
        lines.append(f"| {name} | {st['designs']:,} | {st['job_seconds']:,.0f}{median} | {statuses} |")
    notes = [
        f"- {name}: {st['steps']:,} GT steps, {st['labelled_steps']:,} labelled, "
        f"{st['proposals']:,} proposals"
        for name, st in stages.items()
        if "steps" in st
    ]
    train = r["figure"].get("train")
    if train:
        notes.append(
            f"- train: best epoch {train['epoch']}, validation normalised rank "
            f"{train['val_normalised']:.4f}, MLflow run `{train['run_id']}`"
        )
    return "\n".join(lines) + "\n\n" + "\n".join(notes) + "\n\nMeasured by:\n\n" + _sources(records)


def startup(records: list[dict]) -> str:
    """One ``zonegraph build`` per part as its own process, cold and handed to a server, beside
    the original's: CPU seconds, wall seconds and peak memory, the medians, and how ours compare."""
    (r,) = records
    f = r["figure"]
    columns, parts = f["columns"], f["parts"]
    head = " | ".join(f"{c} CPU s | {c} wall s | {c} MB" for c in columns)
    lines = [f"| part (folder) | {head} |", "|---|" + "---|" * (3 * len(columns))]

    def cells(run: dict) -> list[str]:
        failed = "" if run["rc"] == 0 else f" (exit {run['rc']})"
        return [f"{run['cpu_s']:.2f}{failed}", f"{run['wall_s']:.2f}", f"{run['peak_mb']:.0f}"]

    for name, part in parts.items():
        lines.append(_row(f"{name} ({part['folder']})", [x for c in columns for x in cells(part[c])]))
    medians = [
        format(statistics.median([p[c][key] for p in parts.values()]), fmt)
        for c in columns
        for key, fmt in (("cpu_s", ".2f"), ("wall_s", ".2f"), ("peak_mb", ".0f"))
    ]
    lines.append(_row(f"**median of {len(parts)}**", [f"**{m}**" for m in medians]))
    exits = {c: sum(p[c]["rc"] == 0 for p in parts.values()) for c in columns}
    notes = [f"- {c}: {n} of {len(parts)} exited 0" for c, n in exits.items()]
    for ours in [c for c in columns if c != "original" and "original" in columns]:
        ratios = [p[ours]["cpu_s"] / p["original"]["cpu_s"] for p in parts.values()]
        above, spread = sum(x > 1 for x in ratios), f"{min(ratios):.2f}-{max(ratios):.2f}"
        notes.append(
            f"- {ours} CPU / the original's: median {statistics.median(ratios):.2f} ({spread}), "
            f"above the original's on {above} of {len(ratios)} parts"
        )
    smallest = min(parts, key=lambda n: parts[n]["step_bytes"])
    notes.append(
        f"- smallest part by STEP size, {smallest}: "
        + ", ".join(f"{c} {parts[smallest][c]['wall_s']:.2f} s wall" for c in columns)
    )
    start = f.get("server_start")
    if start:
        notes.append(
            f"- the server's start, once: {start['wall_s']:.2f} s wall, {start['server_cpu_s']:.2f} CPU s "
            f"and {start['server_mb']:.0f} MB resident in the server"
        )
    return "\n".join(lines) + "\n\n" + "\n".join(notes) + "\n\nMeasured by:\n\n" + _sources(records)


def _named(items: list[str]) -> str:
    return f" ({', '.join(items)})" if items else ""


def cover(records: list[dict]) -> str:
    """The fuse ladder's rungs by box cover and checks, and what the cover screen decided, one
    sample per figure."""
    lines = ["| sample | designs | covered: checks pass / refuse | uncovered: checks pass / refuse |"]
    lines.append("|---|---|---|---|")
    notes = []
    for r in records:
        f = r["figure"]
        agree = f["agree"]
        cells = [f"{agree[c]['pass']} / {agree[c]['refuse']}" for c in ("covered", "uncovered")]
        lines.append(_row(r["name"], [str(f["designs"] - sum(f["not_measured"].values())), *cells]))
        notes.append(
            f"- {r['name']}: a graph other than the first that passes the checks: "
            f"{len(f['other_graph'])}; the kept fuse uncovered (the later fuses paid first): "
            f"{len(f['kept_uncovered'])}{_named(f['kept_uncovered'])}; refused fuses set aside "
            f"before their zones were meshed: {f['skipped']}; not measured: {f['not_measured'] or 0}"
        )
    return "\n".join(lines) + "\n\n" + "\n".join(notes) + "\n\nMeasured by:\n\n" + _sources(records)


RENDERERS: dict[str, Callable[[list[dict]], str]] = {
    "build": build,
    "search": search,
    "replay": replay,
    "fault": fault,
    "verify": verify,
    "corpus-exact": corpus_exact,
    "fusion-diff": fusion_diff,
    "conversion": conversion,
    "coverage": coverage,
    "fuzz": fuzz,
    "guide-cost": guide_cost,
    "report": report,
    "rank": rank,
    "heavy": heavy,
    "expansion": expansion,
    "folded": folded,
    "pipeline-run": pipeline_run,
    "startup": startup,
    "cover": cover,
}


def render(markdown: str) -> str:
    def table(match: re.Match) -> str:
        kind, names = match.group(1), match.group(2).split()
        if kind not in RENDERERS:
            raise ValueError(f"unknown figure kind {kind!r} (known: {', '.join(RENDERERS)})")
        return RENDERERS[kind]([_load(n) for n in names])

    def typed(match: re.Match) -> str:
        return (
            f"*Typed from the output of the command above when {match.group(1)} added it; "
            "its results file is not kept, so a re-run does not update it.*"
        )

    return TYPED.sub(typed, MARKER.sub(table, markdown))


def on_page_markdown(markdown: str, **_: object) -> str:
    return render(markdown)

"""Coverage: which designs can be reconstructed, and why not (the paper's supplement taxonomy).

Every design of a run falls in exactly one category, decided in pipeline order: the conversion,
the replay and the zone graph must succeed; then its ground truth (GT) is either captured step by
step, or the heuristic search still finds an exact program (with the GT representable on zones
or not), or the design is not reconstructed. The table is computed for each variant the
``ground_truth`` stage measured: the simplified or full zone graph, at proposal level 1 or 3
(search outcomes come from level 1).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

from pathlib import Path  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from zonegraph.status import Status  # noqa: E402

CATEGORIES = (
    "gt_captured",  # reconstructable with the GT sequence
    "other_sequence",  # GT representable on zones, not captured; search finds an exact program
    "reachable_without_gt",  # GT not representable on zones; search reaches the target anyway
    "not_reconstructed",  # GT not captured and the search found no exact program
    "zone_graph_failed",
    "unsupported",
    "conversion_or_replay_failed",
    "timeout_or_crash",
)
LABELS = {
    "gt_captured": "reconstructable with the GT sequence",
    "other_sequence": "GT not captured, search finds another exact program",
    "reachable_without_gt": "GT not representable on zones, target reachable",
    "not_reconstructed": "not reconstructed (search budget spent or space exhausted)",
    "zone_graph_failed": "zone graph failure",
    "unsupported": "unsupported operation",
    "conversion_or_replay_failed": "conversion or replay failure",
    "timeout_or_crash": "timeout or crash",
}
COLOURS = dict(zip(CATEGORIES, plt.get_cmap("tab10").colors, strict=False))
FAILED = {
    Status.TIMEOUT: "timeout_or_crash",
    Status.CRASH: "timeout_or_crash",
    Status.UNSUPPORTED: "unsupported",
}
GONE = (Status.TIMEOUT, Status.CRASH)  # the job never finished


def _true(value: object) -> bool:
    """True only for a real true value: a missing cell reads back as NaN, and bool(NaN) is True."""
    return isinstance(value, (bool, np.bool_)) and bool(value)


def category(row: pd.Series, graph: str, level: int) -> str:
    """The coverage category of one design row of ``designs.parquet`` for a graph and level."""
    for stage_status in ("convert_status", "replay_status"):
        status = row.get(stage_status)
        if isinstance(status, str) and status != Status.OK:
            return FAILED.get(status, "conversion_or_replay_failed")
    status = row.get("graph_status")
    if status in GONE:
        return "timeout_or_crash"
    if status != Status.OK:
        return "zone_graph_failed"
    gt_status = row.get(f"{graph}_status")
    if gt_status in GONE:
        return "timeout_or_crash"
    if gt_status != Status.OK:
        return "zone_graph_failed"
    if _true(row.get(f"{graph}_captured_l{level}")):
        return "gt_captured"
    if _true(row.get(f"{graph}_search_exact")):
        return "other_sequence" if _true(row.get(f"{graph}_reaches_target")) else "reachable_without_gt"
    if "intersect" in str(row.get("operations", "")).split(","):
        return "unsupported"  # an intersect step has no extrusion proposal
    return "not_reconstructed"


def coverage_table(designs: pd.DataFrame, graph: str = "simplified", level: int = 1) -> pd.DataFrame:
    """Counts and shares of each category, overall and per timeline folder (columns)."""
    cats = designs.apply(category, axis=1, graph=graph, level=level)
    table = pd.crosstab(cats, designs["folder"]).reindex(CATEGORIES, fill_value=0)
    table["all"] = table.sum(axis=1)
    return table


def to_markdown(tables: dict[str, pd.DataFrame]) -> str:
    """One Markdown table per variant: category rows, share of all designs, counts per folder."""
    out = []
    for name, table in tables.items():
        total = table.sum(axis=0)
        folders = [c for c in table.columns if c != "all"]
        out.append(f"### {name}\n")
        out.append("| category | all | " + " | ".join(folders) + " |")
        out.append("|---|---|" + "---|" * len(folders))
        for cat in table.index:
            share = table.loc[cat, "all"] / total["all"] if total["all"] else 0.0
            cells = [f"{table.loc[cat, f] / total[f]:.0%}" if total[f] else "-" for f in folders]
            out.append(
                f"| {LABELS[cat]} | {table.loc[cat, 'all']} ({share:.1%}) | " + " | ".join(cells) + " |"
            )
        out.append(f"| designs | {total['all']} | " + " | ".join(str(total[f]) for f in folders) + " |\n")
    return "\n".join(out)


def plot_coverage(table: pd.DataFrame, path: Path, title: str) -> Path:
    """Stacked bars of category shares per timeline folder."""
    folders = [c for c in table.columns if c != "all"] + ["all"]
    shares = table[folders] / np.maximum(table[folders].sum(axis=0), 1)
    fig, ax = plt.subplots(figsize=(1.1 * len(folders) + 4.5, 4.2))
    bottom = np.zeros(len(folders))
    for cat in table.index:
        ax.bar(folders, shares.loc[cat], bottom=bottom, color=COLOURS[cat], label=LABELS[cat])
        bottom += shares.loc[cat].to_numpy()
    ax.set_ylabel("share of designs")
    ax.set_title(title)
    ax.tick_params(axis="x", rotation=30)
    ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

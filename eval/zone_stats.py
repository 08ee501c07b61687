"""Zone graph statistics (paper fig. 4): zone count vs face count, build time vs zone count, and
how many graphs were built, by status and (with the designs' index) by timeline folder.

python -m eval.zone_stats MANIFEST --out DIR [--index data/designs/index.parquet]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from zonegraph.status import Status  # noqa: E402


def plot_zone_stats(manifest: pd.DataFrame, out: Path, index: pd.DataFrame | None = None) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    ok = manifest[manifest["status"] == Status.OK]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    axes[0].scatter(ok["faces_in"], ok["zones"], s=8, alpha=0.6)
    axes[0].set(xlabel="B-rep face count", ylabel="zone count", yscale="log", title="Zones vs faces")
    axes[1].scatter(ok["zones"], ok["build_s"], s=8, alpha=0.6, color="tab:orange")
    axes[1].set(
        xlabel="zone count",
        ylabel="build time (s)",
        xscale="log",
        yscale="log",
        title="Zone graph build time vs zones",
    )
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{len(ok)} zone graphs ({'simplified' if ok['simplified'].all() else 'not simplified'})")
    fig.tight_layout()
    fig.savefig(out / "zone_stats.png", dpi=120)
    plt.close(fig)
    stats = {
        "designs": int(len(manifest)),
        "ok": int(len(ok)),
        "zones": _describe(ok["zones"]),
        "faces_in": _describe(ok["faces_in"]),
        "build_s": _describe(ok["build_s"]),
        "slowest": ok.nlargest(5, "build_s")[["design_id", "zones", "build_s"]].to_dict("records"),
        "statuses": {str(k): int(v) for k, v in manifest["status"].value_counts().items()},
    }
    if index is not None:
        stats["by_folder"] = built_by_folder(manifest, index)
    (out / "zone_stats.json").write_text(json.dumps(stats, indent=2))
    return stats


def built_by_folder(manifest: pd.DataFrame, index: pd.DataFrame) -> dict[str, dict]:
    """Per timeline folder (and ``all``): designs in the manifest, graphs built, and their share;
    the denominator is every design that reached the zone-graph stage (converted and replayed)."""
    rows = manifest.merge(index[["design_id", "folder"]], on="design_id", how="left")
    rows["folder"] = rows["folder"].fillna("unknown")
    out = {}
    for folder, group in [*sorted(rows.groupby("folder")), ("all", rows)]:
        built = int((group["status"] == Status.OK).sum())
        out[str(folder)] = {"designs": int(len(group)), "built": built, "share": built / max(len(group), 1)}
    return out


def _describe(values: pd.Series) -> dict:
    v = values.to_numpy(float)
    if not len(v):
        return {}
    return {
        "median": float(np.median(v)),
        "p90": float(np.percentile(v, 90)),
        "max": float(v.max()),
        "mean": float(v.mean()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest", help="the zonegraphs stage's manifest.parquet")
    parser.add_argument("--out", required=True, help="the folder for the plots and stats")
    parser.add_argument("--index", help="the designs' index.parquet: graphs built per timeline folder")
    args = parser.parse_args()
    index = pd.read_parquet(args.index) if args.index else None
    stats = plot_zone_stats(pd.read_parquet(args.manifest), Path(args.out), index)
    print(
        f"zone stats: {stats['ok']} graphs, zones {stats['zones']}, build_s {stats['build_s']} -> {args.out}"
    )


if __name__ == "__main__":
    main()

"""Issue 29: every design ``convert`` calls ok replays with ``zonegraph replay``'s default check, and
how far our replay is from Fusion's published figures.

    python -m bench.verify_bench [--per-folder 25] [--seed 29] [--corpus ../shared/data/fusion360_b123d]
                                 [--out bench_out/verify]

A seeded sample with the same number of designs from every timeline folder (``bench.corpus_bench``'s
``sample``). Each design is converted in its own killable child, as ``zonegraph convert`` does
(`zonegraph.jobs.convert_isolated`), and each converted JSON goes through ``zonegraph replay``
with its defaults (the command's own code, in this process: ``zonegraph.cli.main``), which exits 0
only when the replay reproduces the file's ``properties`` (`zonegraph.verified`). Prints the
exit codes and the replay-vs-Fusion table (relative volume and area differences: how many above
1e-6, by decade); writes ``results.json`` (a row per design) and ``results.md`` under ``--out``.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from collections import Counter
from pathlib import Path

from bench.corpus import CORPUS, require_corpus, write_results
from bench.corpus_bench import sample
from zonegraph.cli import main as zonegraph
from zonegraph.jobs import convert_isolated

THRESHOLD = 1e-6


def decade(x: float | None) -> str:
    """The decade of a relative difference, as a table row key (None: not measured)."""
    if x is None:
        return "-"
    if x <= 1e-12:
        return "<= 1e-12"
    return f"1e{math.floor(math.log10(x)):d}"


def decade_rows(volume: Counter, area: Counter) -> list[str]:
    """Table rows, smallest decade first: how many designs differ by that much in volume, area."""
    keys = sorted(set(volume) | set(area), key=lambda k: -99 if k.startswith("<") else int(k[2:]))
    return [f"| {k} | {volume.get(k, 0)} | {area.get(k, 0)} |" for k in keys]


def run(corpus: Path, per_folder: int, seed: int, work: Path) -> list[dict]:
    rows = []
    entries = sample(corpus, per_folder, seed)
    for i, e in enumerate(entries, 1):
        r = convert_isolated(e.batch, e.design_id, e.fusion_volume, e.fusion_area, timeout=120)
        row = {
            "design_id": e.design_id,
            "folder": e.folder,
            "batch": str(Path(e.batch).relative_to(corpus)),
            "status": str(r.status),
            "reason": r.reason,
            "fusion_volume_rel_difference": r.fusion_volume_rel_error,
            "fusion_area_rel_difference": r.fusion_area_rel_error,
        }
        if r.ok and r.design_json is not None:
            path = work / f"{e.design_id}.json"
            path.write_text(json.dumps(r.design_json))
            row["replay_exit"] = zonegraph(["replay", str(path), "--out", str(work / e.design_id)])
        rows.append(row)
        if i % 10 == 0 or i == len(entries):
            print(f"  {i}/{len(entries)} designs", flush=True)
    return rows


def summarise(rows: list[dict]) -> str:
    ok = [r for r in rows if r["status"] == "ok"]
    exits = Counter(r["replay_exit"] for r in ok)
    lines = [
        f"{len(rows)} designs, convert: {dict(Counter(r['status'] for r in rows))}",
        f"`zonegraph replay` (defaults) on the {len(ok)} converted ok: exit codes {dict(exits)}",
        "",
        "| relative difference, our replay vs Fusion | volume | area |",
        "|---|---|---|",
    ]
    vol = Counter(decade(r["fusion_volume_rel_difference"]) for r in ok)
    area = Counter(decade(r["fusion_area_rel_difference"]) for r in ok)
    lines += decade_rows(vol, area)
    above = [
        r
        for r in ok
        if max(r["fusion_volume_rel_difference"] or 0, r["fusion_area_rel_difference"] or 0) > THRESHOLD
    ]
    lines += [
        "",
        f"{len(above)} of {len(ok)} converted designs differ from Fusion by more than {THRESHOLD:g}:",
    ]
    for r in sorted(above, key=lambda r: -(r["fusion_volume_rel_difference"] or 0)):
        lines.append(
            f"- {r['design_id']} ({r['batch']}): volume {r['fusion_volume_rel_difference']:.1e}, "
            f"area {r['fusion_area_rel_difference']:.1e}, replay exit {r['replay_exit']}"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=CORPUS)
    parser.add_argument("--per-folder", type=int, default=25)
    parser.add_argument("--seed", type=int, default=29)
    parser.add_argument("--out", type=Path, default=Path("bench_out/verify"))
    args = parser.parse_args()
    require_corpus(args.corpus)
    with tempfile.TemporaryDirectory() as work:
        rows = run(args.corpus, args.per_folder, args.seed, Path(work))
    write_results(rows, summarise(rows), args.out)


if __name__ == "__main__":
    main()

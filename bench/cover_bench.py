"""Does a fuse's box cover predict its checks? Every rung of the fuse ladder, on corpus designs.

    python -m bench.cover_bench [--per-folder 25] [--seed 12] [--fresh-from 0 2023] [--folders 04 05]
                                [--workers 2] [--timeout 600] [--corpus ../shared/...] [--out DIR]

The zone-graph build sets a general fuse aside when its split box faces do not cover the box's
area (``zonegraph.zones.build._checked_partition``), and checks it in full only after the later
fuzzy values. That may cost time, never a graph: this benchmark shows it. For a seeded sample of
designs (``bench.corpus_bench.sample``), each face-loop rule the build would try and each of the
ladder's general fuses (the fuzzy values, then the anchored fuse) is run on its own: its cover and
whether its graph passes every check. Printed: how cover and checks agree; the designs where the
build now keeps another rung than the first one that passes (must be none); where the kept fuse
was uncovered (the build paid for the other fuses first); and where an uncovered fuse that the
checks refuse was skipped before its zones were meshed. Writes ``results.json`` (one row per
design, one entry per rung), ``results.md`` and the counts (``tally.json``, which ``bench.figures
cover`` reads) under ``--out``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from collections import Counter
from pathlib import Path

from bench.corpus import CORPUS, replayed, require_corpus, run_designs, write_results
from bench.corpus_bench import sample
from zonegraph.data.b123d import CorpusEntry
from zonegraph.isolation import run_isolated

COVERS = ("covered", "uncovered")


def _rungs(entry: CorpusEntry, work: str) -> dict:
    """Cover and check outcome of every general fuse on the ladder, per face-loop rule."""
    from zonegraph.geometry.normalize import Normalization
    from zonegraph.zones import build as zb
    from zonegraph.zones.model import ZoneGraphBuildError

    replay, row = replayed(entry.batch, entry.design_id, work)
    if replay is None:
        return row
    target = zb._target_shape(replay.shape, entry.design_id)
    norm = Normalization.of(target)
    target_n = norm.apply(target)
    box, solids = zb.bounds(target_n), zb.sub_shapes(target_n, zb.TopAbs_SOLID)
    region = zb._Region(solids)
    rungs = []
    for rule, surfaces, _ in zb._extensions(target_n, box, list(zb.LOOP_RULES)):
        for method in [m for m in zb._ladder(zb.FUZZY_LADDER) if m[0] != "volumes"]:
            rung = {"rule": rule.value if rule else None, "method": list(method)}
            try:
                split = zb._split(box, surfaces, method, entry.design_id)
                rung["cover"] = zb._box_cover(split)
                graph = zb._partition(norm, box, region, solids, surfaces, split, 0, 0, zb._Timer())
                graph.check(entry.design_id)
                rung["checks"] = "ok"
            except ZoneGraphBuildError as exc:
                rung["checks"] = exc.status.value
            rungs.append(rung)
    return {"status": "ok", "rungs": rungs}


def _job(args: tuple[CorpusEntry, float, str]) -> dict:
    entry, timeout, work = args
    outcome = run_isolated(_rungs, (entry, work), timeout=timeout)
    row = {"design_id": entry.design_id, "folder": entry.folder}
    row.update(outcome.value if outcome.ok else {"status": outcome.status, "reason": outcome.reason})
    return row


def decisions(rungs: list[dict], rtol: float) -> dict:
    """The rung the build keeps before and with the cover screen (indices into ``rungs`` of one
    rule), and what the screen did. The order is ``zones.build._checked_partition``'s: covered
    fuses in ladder order, then the uncovered ones, then the other methods."""
    ok = [r["checks"] == "ok" for r in rungs]
    covered = [abs(r.get("cover", 0.0) - 1) <= rtol for r in rungs]
    fuses = [i for i, r in enumerate(rungs) if r["method"][0] == "fuse"]
    rest = [i for i in range(len(rungs)) if i not in fuses]
    order = [i for i in fuses if covered[i]] + [i for i in fuses if not covered[i]] + rest
    first = next((i for i, good in enumerate(ok) if good), None)
    kept = next((i for i in order if ok[i]), None)
    return {
        "same": first == kept,
        "kept_uncovered": kept is not None and kept in fuses and not covered[kept],
        "skipped": kept is not None and sum(not covered[i] and not ok[i] for i in fuses if i < kept),
    }


def tally(rows: list[dict], rtol: float) -> dict:
    """How cover and checks agree over every measured rung, and the build's decisions per rule."""
    agree = {cover: {"pass": 0, "refuse": 0} for cover in COVERS}
    other, kept_uncovered, skipped = [], [], 0
    for row in rows:
        for rule in dict.fromkeys(r["rule"] for r in row.get("rungs", [])):
            rungs = [r for r in row["rungs"] if r["rule"] == rule]
            for r in rungs:
                cover = COVERS[abs(r.get("cover", 0.0) - 1) > rtol]
                agree[cover]["pass" if r["checks"] == "ok" else "refuse"] += 1
            d = decisions(rungs, rtol)
            other += [] if d["same"] else [f"{row['design_id']} ({rule})"]
            kept_uncovered += [f"{row['design_id']} ({rule})"] if d["kept_uncovered"] else []
            skipped += d["skipped"]
    return {
        "designs": len(rows),
        "not_measured": dict(Counter(row["status"] for row in rows if row["status"] != "ok")),
        "rtol": rtol,
        "agree": agree,
        "other_graph": other,
        "kept_uncovered": kept_uncovered,
        "skipped": skipped,
    }


def summarise(t: dict) -> str:
    return "\n".join(
        [
            f"{t['designs']} designs ({sum(t['not_measured'].values())} not measured: {t['not_measured']})",
            "",
            "| fuse | checks pass | checks refuse |",
            "|---|---|---|",
            *(f"| {c} | {t['agree'][c]['pass']} | {t['agree'][c]['refuse']} |" for c in COVERS),
            "",
            f"a graph other than the first that passes: {len(t['other_graph'])} {t['other_graph']}",
            f"kept fuse uncovered (later fuses paid first): {len(t['kept_uncovered'])} {t['kept_uncovered']}",
            f"refused fuses skipped before meshing: {t['skipped']}",
        ]
    )


def main() -> None:
    from zonegraph.zones.build import BOX_AREA_RTOL

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-folder", type=int, default=25)
    parser.add_argument("--seed", type=int, default=12)
    parser.add_argument("--fresh-from", type=int, nargs="*", default=[0, 2023])
    parser.add_argument("--folders", nargs="*", default=[])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per design")
    parser.add_argument("--corpus", type=Path, default=CORPUS)
    parser.add_argument("--out", type=Path, default=Path("bench_out/cover"))
    args = parser.parse_args()
    require_corpus(args.corpus)
    entries = sample(
        args.corpus, args.per_folder, args.seed, fresh_from=args.fresh_from, folders=args.folders
    )
    with tempfile.TemporaryDirectory() as work:
        rows = run_designs(_job, [(e, args.timeout, work) for e in entries], args.workers)
    counts = tally(rows, BOX_AREA_RTOL)
    write_results(rows, summarise(counts), args.out)
    (args.out / "tally.json").write_text(json.dumps(counts, indent=1))


if __name__ == "__main__":
    main()

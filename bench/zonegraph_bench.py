"""Zone graph build time, zone count and face count on the real samples and synthetic designs,
simplified and not.

    python -m bench.zonegraph_bench [--synthetic N] [--workers 2] [--timeout 120] [--out DIR]

Each design is built in its own process under a timeout (one core each; ``--workers`` run side
by side). Prints medians, the slowest designs and every failure with its status and reason, and
writes a row per design and graph to ``--out/results.json`` (``python -m bench.figures build``
draws the documentation's table from it).
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.data.synthetic import synthetic_design
from zonegraph.isolation import Outcome, run_isolated
from zonegraph.testing import SAMPLES
from zonegraph.zones.build import build_zone_graph


def _build(source: str, simplify: bool) -> dict:
    if source.startswith("synthetic:"):
        i = int(source.split(":")[1])
        design = synthetic_design(i)
    else:
        design = load_design(source)
    return build_zone_graph(
        list(replay(design).bodies), simplify=simplify, samples=512, source=source
    ).summary()


def _job(args: tuple[str, bool, float]) -> tuple[str, bool, Outcome]:
    source, simplify, timeout = args
    return source, simplify, run_isolated(_build, (source, simplify), timeout)


def report(name: str, results: list[tuple[str, bool, Outcome]]) -> None:
    for simplify in (True, False):
        rows = [(s, o) for s, simp, o in results if simp == simplify]
        ok = [(s, o.value) for s, o in rows if o.ok]
        label = f"{name}, {'simplified' if simplify else 'not simplified'}"
        if not ok:
            print(f"\n{label}: no graph built")
            continue
        build = np.array([v["build_s"] for _, v in ok])
        zones = np.array([v["zones"] for _, v in ok])
        faces = np.array([v["target_faces"] for _, v in ok])
        print(f"\n{label}: {len(ok)}/{len(rows)} ok")
        print(
            f"  build s   median {np.median(build):.3f}  p90 {np.percentile(build, 90):.3f}  "
            f"max {build.max():.2f}"
        )
        print(
            f"  zones     median {np.median(zones):.0f}  p90 {np.percentile(zones, 90):.0f}  "
            f"max {zones.max()}"
        )
        print(f"  faces     median {np.median(faces):.0f}  max {faces.max()}")
        slow = sorted(ok, key=lambda r: -r[1]["build_s"])[:3]
        print(
            "  slowest: "
            + ", ".join(f"{Path(s).stem} ({v['zones']} zones, {v['build_s']:.2f} s)" for s, v in slow)
        )
        for s, o in rows:
            if not o.ok:
                print(f"  FAILED {Path(s).stem}: {o.status}: {o.reason}")


def rows(name: str, results: list[tuple[str, bool, Outcome]]) -> list[dict]:
    """One results row per design and graph: its set, status, and build figures when built."""
    out = []
    for source, simplify, o in results:
        row = {"set": name, "design": Path(source).stem, "simplified": simplify, "status": o.status}
        if o.ok:
            row |= {
                "build_s": o.value["build_s"],
                "zones": o.value["zones"],
                "faces": o.value["target_faces"],
            }
        else:
            row["reason"] = o.reason
        out.append(row)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=300)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--out", type=Path, default=Path("bench_out/zonegraph"))
    args = parser.parse_args()
    samples = [str(p) for p in sorted(SAMPLES.glob("*.json"))] if SAMPLES.is_dir() else []
    synthetic = [f"synthetic:{i}" for i in range(args.synthetic)]
    written: list[dict] = []
    with ProcessPoolExecutor(args.workers) as pool:
        for name, sources in (("samples", samples), ("synthetic", synthetic)):
            jobs = [(s, simp, args.timeout) for s in sources for simp in (True, False)]
            results = list(pool.map(_job, jobs, chunksize=2))
            report(name, results)
            written += rows(name, results)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(written, indent=1))
    print(f"\nwrote {args.out / 'results.json'}")


if __name__ == "__main__":
    main()

"""Replay time per design and per step on the real samples and on synthetic designs.

    python -m bench.replay_bench [--synthetic N] [--seed S] [--out DIR]

Prints timing tables and the synthetic set's statistics beside the published r1.0.1 figures, and
writes a row per design (its seconds and its steps' seconds) to ``--out/results.json`` (``python
-m bench.figures replay`` draws the documentation's table from it). Single process, one core: the
figures are per-core costs.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from zonegraph.data.design import Design, load_design
from zonegraph.data.replay import replay
from zonegraph.data.stats import design_statistics, format_comparison
from zonegraph.data.synthetic import synthetic_design
from zonegraph.testing import SAMPLES


def time_replays(designs: list[Design]) -> list[dict]:
    """A row per design: its replay's seconds and each extrude step's."""
    rows = []
    for d in designs:
        t0 = time.perf_counter()
        result = replay(d)
        seconds = time.perf_counter() - t0
        rows.append({"design": d.id, "seconds": seconds, "step_s": [s.seconds for s in result.steps]})
    return rows


def report(name: str, designs: list[Design]) -> list[dict]:
    timed = [r | {"set": name} for r in time_replays(designs)]
    per_design = np.array([r["seconds"] for r in timed])
    per_step = np.array([s for r in timed for s in r["step_s"]])
    rows = sorted(((r["seconds"], r["design"], len(r["step_s"])) for r in timed), reverse=True)
    ms = lambda a, q: 1e3 * float(np.percentile(a, q))  # noqa: E731
    print(f"\n{name}: {len(designs)} designs, {len(per_step)} extrude steps")
    print(
        f"  per design  median {ms(per_design, 50):7.1f} ms   p90 {ms(per_design, 90):7.1f} ms   "
        f"max {1e3 * per_design.max():7.1f} ms   total {per_design.sum():.2f} s"
    )
    print(
        f"  per step    median {ms(per_step, 50):7.1f} ms   p90 {ms(per_step, 90):7.1f} ms   "
        f"max {1e3 * per_step.max():7.1f} ms"
    )
    print("  slowest: " + ", ".join(f"{i} ({n} steps, {1e3 * s:.0f} ms)" for s, i, n in rows[:3]))
    return timed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=300, help="number of synthetic designs")
    parser.add_argument("--seed", type=int, default=2021)
    parser.add_argument("--out", type=Path, default=Path("bench_out/replay"))
    args = parser.parse_args()
    rows = []
    if SAMPLES.is_dir():
        replay(load_design(next(SAMPLES.glob("*.json"))))  # warm-up: first OCP calls load libraries
        rows += report("samples", [load_design(p) for p in sorted(SAMPLES.glob("*.json"))])
    else:
        print(f"real samples not found at {SAMPLES}: skipped")
    t0 = time.perf_counter()
    synthetic = [synthetic_design(i, args.seed) for i in range(args.synthetic)]
    print(f"\ngenerated {len(synthetic)} synthetic designs in {time.perf_counter() - t0:.1f} s")
    rows += report("synthetic", synthetic)
    print("\n" + format_comparison(design_statistics(synthetic)))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(rows, indent=1))
    print(f"\nwrote {args.out / 'results.json'}")


if __name__ == "__main__":
    main()

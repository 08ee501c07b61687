"""Replay time per design and per step on the real samples and on synthetic designs.

    python -m bench.replay_bench [--synthetic N] [--seed S]

Prints timing tables and the synthetic set's statistics beside the published r1.0.1 figures.
Single process, one core: the figures are per-core costs.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from zonegraph.data.design import Design, load_design
from zonegraph.data.replay import replay
from zonegraph.data.stats import design_statistics, format_comparison
from zonegraph.data.synthetic import synthetic_design
from zonegraph.testing import SAMPLES


def time_replays(designs: list[Design]) -> tuple[np.ndarray, np.ndarray, list[tuple[float, str, int]]]:
    per_design, per_step, rows = [], [], []
    for d in designs:
        t0 = time.perf_counter()
        result = replay(d)
        seconds = time.perf_counter() - t0
        per_design.append(seconds)
        per_step.extend(s.seconds for s in result.steps)
        rows.append((seconds, d.id, len(result.steps)))
    return np.array(per_design), np.array(per_step), sorted(rows, reverse=True)


def report(name: str, designs: list[Design]) -> None:
    per_design, per_step, rows = time_replays(designs)
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=300, help="number of synthetic designs")
    parser.add_argument("--seed", type=int, default=2021)
    args = parser.parse_args()
    if SAMPLES.is_dir():
        replay(load_design(next(SAMPLES.glob("*.json"))))  # warm-up: first OCP calls load libraries
        report("real samples", [load_design(p) for p in sorted(SAMPLES.glob("*.json"))])
    else:
        print(f"real samples not found at {SAMPLES}: skipped")
    t0 = time.perf_counter()
    synthetic = [synthetic_design(i, args.seed) for i in range(args.synthetic)]
    print(f"\ngenerated {len(synthetic)} synthetic designs in {time.perf_counter() - t0:.1f} s")
    report("synthetic", synthetic)
    print("\n" + format_comparison(design_statistics(synthetic)))


if __name__ == "__main__":
    main()

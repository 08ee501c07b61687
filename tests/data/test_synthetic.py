"""Synthetic designs: reproducible, valid Fusion JSON that our replay reads back exactly."""

from __future__ import annotations

import json
from multiprocessing import get_context

from zonegraph.data.design import parse_design
from zonegraph.data.replay import replay
from zonegraph.data.stats import design_statistics
from zonegraph.data.synthetic import generate_design

COUNT = 500  # the bar: 500 designs replay with no failure
SEED = 7


def check_design(i: int) -> tuple[str, str]:
    """Generate, round-trip through JSON text, replay; returns (design id, problem or '')."""
    design_id = f"t{i:04d}"
    data = json.loads(json.dumps(generate_design(design_id, SEED * 100_000 + i)))
    try:
        result = replay(parse_design(data, design_id))
    except Exception as exc:  # report every failure, not just the first
        return design_id, f"{type(exc).__name__}: {exc}"
    props = result.design.properties
    problems = []
    if len(result.bodies) != 1 or not result.bodies[0].is_valid:
        problems.append(f"{len(result.bodies)} bodies")
    if abs(result.volume - props.volume) > 1e-9 * props.volume or result.face_count != props.face_count:
        problems.append("properties differ")
    volumes = [0.0] + [s.volume for s in result.steps]
    if any(abs(b - a) <= 1e-3 * max(a, b) for a, b in zip(volumes, volumes[1:], strict=False)):
        problems.append("a step leaves the shape unchanged")
    for s in result.steps:
        if (s.body_count, s.face_count) != (s.extrude.labels.body_count, s.extrude.labels.face_count):
            problems.append(f"labels differ at {s.extrude.name}")
    return design_id, "; ".join(problems)


def test_generation_is_reproducible():
    assert generate_design("a", 11) == generate_design("a", 11)
    assert generate_design("a", 11) != generate_design("a", 12)


def test_500_designs_replay_without_failure():
    with get_context("spawn").Pool(2) as pool:  # fork after Dask threads can deadlock
        results = pool.map(check_design, range(COUNT), chunksize=10)
    failures = [f"{d}: {p}" for d, p in results if p]
    assert not failures, "\n".join(failures)


def test_statistics_resemble_the_published_data_set():
    designs = [parse_design(generate_design(f"s{i}", i), f"s{i}") for i in range(200)]
    stats = design_statistics(designs)
    assert 0.4 < stats["share_single_extrude"] < 0.7
    assert 3.5 < stats["sequence_length_mean"] < 6.0
    assert max(stats["extrude_count_histogram"]) >= 6
    assert stats["operations"]["cut"] > 0 and stats["operations"]["join"] > 0
    assert {"one_side", "symmetric"} <= set(stats["extents"])
    assert {"Line", "Arc", "Circle"} <= set(stats["curves"])

"""Exact replay of the real Fusion 360 Gallery samples against their own published labels."""

from __future__ import annotations

import pytest

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.geometry.shapes import read_solids, symmetric_difference_volume
from zonegraph.testing import requires_samples, sample_paths

RTOL = 1e-6


@requires_samples
@pytest.mark.parametrize("path", sample_paths(), ids=lambda p: p.stem)
def test_sample_replays_exactly(path):
    design = load_design(path)
    result = replay(design)
    props = design.properties
    assert abs(result.volume - props.volume) <= RTOL * props.volume
    assert abs(result.area - props.area) <= RTOL * props.area
    assert len(result.bodies) == props.body_count
    assert result.face_count == props.face_count
    for step in result.steps:
        labels = step.extrude.labels
        if labels is None:  # the early-format file has no per-step labels
            continue
        assert (step.body_count, step.face_count) == (labels.body_count, labels.face_count), step.extrude.name
    assert all(b.is_valid for b in result.bodies)


@requires_samples
def test_all_22_samples_present():
    assert len(sample_paths()) == 22


def test_couch_matches_fusion_step(samples_dir):
    result = replay(load_design(samples_dir / "Couch.json"))
    fusion = read_solids(samples_dir / "Couch.step")
    assert len(fusion) == 1
    reference = fusion[0].scale(0.1)  # Fusion's STEP is in millimetres, the JSON in centimetres
    assert abs(reference.volume - result.volume) <= 1e-6 * result.volume
    assert symmetric_difference_volume(reference, result.shape) <= 1e-6 * result.volume

"""Sequence strips drawn from real designs: the replayed timeline, one panel per extrude."""

from __future__ import annotations

import pytest

from eval.strips import design_strip
from zonegraph.export.render import render_strips
from zonegraph.testing import requires_samples


@requires_samples
def test_a_design_strip_shows_each_step_on_the_shape_before_it(samples_dir, tmp_path):
    steps = design_strip(samples_dir / "Couch.json")  # a box, then a cut
    assert [s.subtract for s in steps] == [False, True]
    assert steps[0].before is None and steps[1].before is not None
    assert steps[1].before.volume == pytest.approx(steps[0].tool.volume, rel=1e-6)
    path = render_strips({"GT": steps, "again": steps[:1]}, tmp_path / "strip.png")
    assert path.stat().st_size > 5000

"""A fast slice of the fault benchmark: every fault kind survived once, every corruption detected."""

from __future__ import annotations

import pytest

from bench.fault_bench import KINDS, run_bench

pytestmark = pytest.mark.slow  # a local cluster, two conversions and a few dozen stage reruns


def test_a_slice_of_faults_is_survived(tmp_path):
    tallies = run_bench(n_designs=2, trials=len(KINDS), seed=1, root=tmp_path / "faults", cycle=True)
    assert sorted(tallies) == sorted(KINDS)
    for kind, t in tallies.items():
        assert (t.lost, t.stale, t.wrong) == (0, 0, 0), (kind, t.notes)
        assert t.survived == t.faults == 1 and t.detected == t.damaged, (kind, t.notes)

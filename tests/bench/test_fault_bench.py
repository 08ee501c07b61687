"""A fast slice of the fault benchmark: every fault kind survived, every corruption detected."""

from __future__ import annotations

import pytest

from bench.fault_bench import run_bench

pytestmark = pytest.mark.slow  # a local cluster and a dozen stage reruns (about a minute of CPU)


def test_a_slice_of_faults_is_survived(tmp_path):
    tallies = run_bench(n_designs=2, trials=10, seed=1, root=tmp_path / "faults")
    assert sum(t.faults for t in tallies.values()) == 10
    for kind, t in tallies.items():
        assert (t.lost, t.stale, t.wrong) == (0, 0, 0), (kind, t.notes)
        assert t.survived == t.faults and t.detected == t.damaged, (kind, t.notes)

"""Jobs in forked children on real geometry: the kernel's thread pool does not hang them."""

from __future__ import annotations

import subprocess
import sys

from zonegraph.data.replay import replay
from zonegraph.data.synthetic import synthetic_design
from zonegraph.geometry.kernel import fork_safe
from zonegraph.isolation import run_isolated
from zonegraph.status import Status


def _replayed_volume(index: int) -> float:
    return sum(b.volume for b in replay(synthetic_design(index)).bodies)


def test_a_child_forked_after_parallel_booleans_runs_its_own():
    """synth_00002's replay (build123d Booleans, run in parallel) hung in every forked child once
    its parent had replayed it: the child waited for a pool thread it did not inherit."""
    volume = _replayed_volume(2)
    outcome = run_isolated(_replayed_volume, (2,), timeout=60)
    assert fork_safe()
    assert outcome.status == Status.OK and outcome.value == volume and outcome.seconds < 60


def test_a_pool_started_before_the_package_is_named_once_forked():
    code = (
        "import warnings\n"
        "from build123d import Box, Cylinder\n"
        "for r in range(20): Box(10, 10, 10) - Cylinder(2 + r / 100, 20)\n"
        "from zonegraph.isolation import run_isolated\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        "    first, second = run_isolated(abs, (-2,)), run_isolated(abs, (-3,))\n"
        "print(first.value, second.value, [str(w.message) for w in caught])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("2 3 [") and out.stdout.count("thread pool started before zonegraph") == 1

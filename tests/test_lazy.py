import gc
import subprocess
import sys

from zonegraph.lazy import uncollected


def test_uncollected_runs_its_block_without_the_collector_and_restores_its_state():
    was = gc.isenabled()
    try:
        for before in (True, False):
            (gc.enable if before else gc.disable)()
            with uncollected():
                assert not gc.isenabled()
            assert gc.isenabled() is before
        gc.enable()
        try:
            with uncollected():
                raise KeyError
        except KeyError:
            pass
        assert gc.isenabled()
    finally:
        (gc.enable if was else gc.disable)()


def test_a_lazy_name_imports_the_kernel_with_no_full_collection():
    """The kernel's import makes ~184,000 objects; a collector left on walks them in full
    collections during it (the CPU this saves is measured in docs/results/benchmarks.md)."""
    code = (
        "import gc, zonegraph\n"
        "full = gc.get_stats()[2]['collections']\n"
        "zonegraph.build_zone_graph\n"
        "import sys; assert 'OCP' in sys.modules\n"
        "print(gc.get_stats()[2]['collections'] - full, gc.isenabled())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["0", "True"]

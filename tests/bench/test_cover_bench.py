"""The cover benchmark: the build's decisions replayed from each rung's cover and checks, its
counts and their table; and one real corpus design measured end to end."""

import importlib.util
import json
from pathlib import Path

from bench.cover_bench import decisions, summarise, tally
from bench.figures import cover_figure
from zonegraph.testing import requires_corpus

ROOT = Path(__file__).resolve().parents[2]
RTOL = 1e-6


def _rung(method: str, fuzzy: float, cover: float, checks: str = "ok") -> dict:
    return {"rule": "strict", "method": [method, fuzzy], "cover": cover, "checks": checks}


def test_an_uncovered_refused_fuse_is_skipped_and_the_same_graph_kept():
    """23325_292b3294_0000's ladder: 1e-6 and 1e-5 uncovered and refused, 1e-7 covered."""
    rungs = [
        _rung("fuse", 1e-6, 0.999996, "fuse_failed"),
        _rung("fuse", 1e-5, 0.999995, "fuse_failed"),
        _rung("fuse", 1e-7, 1.0),
        _rung("anchored", 1e-6, 1.0),
    ]
    assert decisions(rungs, RTOL) == {"same": True, "kept_uncovered": False, "skipped": 2}


def test_an_uncovered_fuse_the_checks_pass_is_kept_after_the_others():
    rungs = [_rung("fuse", v, 0.9999957) for v in (1e-6, 1e-5, 1e-7)] + [_rung("anchored", 1e-6, 1.0)]
    assert decisions(rungs, RTOL) == {"same": True, "kept_uncovered": True, "skipped": 0}


def test_a_covered_later_fuse_would_replace_an_uncovered_first_one():
    """The case the benchmark exists to count: a rung the checks pass, passed over."""
    rungs = [_rung("fuse", 1e-6, 0.99999), _rung("fuse", 1e-5, 1.0), _rung("fuse", 1e-7, 1.0)]
    assert not decisions(rungs, RTOL)["same"]


def test_the_counts_render_as_a_figure(tmp_path):
    rows = [
        {
            "design_id": "a",
            "folder": "08",
            "status": "ok",
            "rungs": [_rung("fuse", 1e-6, 0.99, "fuse_failed")],
        },
        {"design_id": "b", "folder": "01", "status": "timeout"},
    ]
    counts = tally(rows, RTOL)
    assert counts["agree"]["uncovered"] == {"pass": 0, "refuse": 1} and counts["not_measured"] == {
        "timeout": 1
    }
    assert "| uncovered | 0 | 1 |" in summarise(counts)
    (tmp_path / "tally.json").write_text(json.dumps(counts))
    record = {"name": "s", "command": "c", "commit": "abc1234", "measured": "today"}
    record["figure"] = cover_figure(tmp_path / "results.json")
    spec = importlib.util.spec_from_file_location("figures_hook", ROOT / "docs/hooks/figures.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    assert "| s | 1 | 0 / 0 | 0 / 1 |" in hook.cover([record])


@requires_corpus
def test_a_corpus_design_s_rungs_are_measured(tmp_path):
    from bench.cover_bench import _rungs
    from zonegraph.data.b123d import list_corpus
    from zonegraph.testing import CORPUS

    entry = next(e for e in list_corpus(CORPUS) if e.design_id == "33625_c9ff9be8_0008")
    row = _rungs(entry, str(tmp_path))
    fuses = [r for r in row["rungs"] if r["method"][0] == "fuse"]
    assert len(fuses) == 3 and all(abs(r["cover"] - 0.9999957) < 1e-7 and r["checks"] == "ok" for r in fuses)

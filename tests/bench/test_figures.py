"""Results pages draw their tables from the committed figure files, never from typed numbers."""

import importlib.util
import json
import re
from pathlib import Path

import pandas as pd
import pytest

from bench.fault_bench import Tally, write_results
from bench.figures import (
    conversion_figure,
    corpus_figure,
    coverage_figure,
    expansion_figure,
    fault_figure,
    folded_figure,
    fuzz_figure,
    guide_cost_figure,
    heavy_figure,
    pipeline_run_figure,
    rank_figure,
    report_figure,
    startup_figure,
)

ROOT = Path(__file__).resolve().parents[2]


def _hook():
    spec = importlib.util.spec_from_file_location("figures_hook", ROOT / "docs/hooks/figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_corpus_figure_counts_converted_searched_and_exact_designs():
    rows = [
        {
            "design_id": "a",
            "folder": "01",
            "status": "exact",
            "exact": True,
            "iou_zone": 1.0,
            "iou_brep": 1.0,
            "json_iou": 1.0,
            "script_iou": 1.0,
            "search_s": 1.0,
            "config": {"budget_s": 20},
        },
        {
            "design_id": "b",
            "folder": "01",
            "status": "rebuild_failed",
            "exact": False,
            "iou_zone": 1.0,
            "iou_brep": 0.5,
            "search_s": 22.0,
            "config": {"budget_s": 20},
        },
        {"design_id": "c", "folder": "02", "status": "convert_mismatch"},
        {"design_id": "d", "folder": "02", "status": "fuse_failed"},
    ]
    f = corpus_figure(rows)
    assert f["all"] == {"drawn": 4, "converted": 3, "zone_graph": 2, "exact": 1, "mean_iou_brep": 0.75}
    assert f["folders"]["02"]["converted"] == 1 and f["folders"]["02"]["exact"] == 0
    assert f["largest_overrun"] == pytest.approx(0.1)
    assert f["zone_exact"] == 2 and f["zone_exact_files_not_exact"] == ["b"]


def test_every_figure_marker_in_the_docs_renders_from_a_committed_file():
    hook = _hook()
    pages = [p for p in (ROOT / "docs").rglob("*.md") if "<!-- figure:" in p.read_text()]
    assert pages, "no page draws a figure"
    for page in pages:
        out = hook.render(page.read_text())
        assert "<!-- figure:" not in out and "Measured by:" in out, page


def test_a_missing_figure_file_stops_the_build():
    with pytest.raises(ValueError, match="does not exist"):
        _hook().render("<!-- figure: corpus-exact no-such-run -->")
    name = next((ROOT / "docs/figures").glob("*.json")).stem
    assert json.loads((ROOT / "docs/figures" / f"{name}.json").read_text())["command"]


def test_conversion_and_fuzz_figures_count_from_the_stage_and_bench_outputs():
    details = {
        "by_status": {"ok": 3, "model_raised": 1},
        "by_folder": {"01": {"designs": 2, "converted": 2}, "02": {"designs": 2, "converted": 1}},
    }
    f = conversion_figure(details)
    assert (f["designs"], f["converted"], f["failed_by_status"]) == (4, 3, {"model_raised": 1})
    rows = [
        {"command": "build", "outcome": "success", "seconds": 0.5, "detail": ""},
        {
            "command": "infer",
            "outcome": "user_error",
            "seconds": 1.25,
            "detail": "zonegraph: error: /x.json: invalid_design: bad",
        },
        {
            "command": "infer",
            "outcome": "user_error",
            "seconds": 0.1,
            "detail": "zonegraph: error: /y.step: invalid_input: empty",
        },
    ]
    z = fuzz_figure(rows)
    assert z["by_outcome"]["user_error"] == {"build": 0, "infer": 2} and z["slowest_s"] == 1.25
    assert z["user_errors_by_status"] == {"invalid_design": 1, "invalid_input": 1}
    hook = _hook()
    record = {"name": "n", "command": "c", "commit": "abc1234", "measured": "today"}
    assert "| user_error | 2 | 0 | 2 |" in hook.fuzz([{**record, "figure": z}])
    assert "**3/4 (75.0%)" in hook.conversion([{**record, "figure": f}])


def test_the_fault_figure_totals_the_benchs_tallies_and_names_failed_trials(tmp_path):
    tallies = {
        "truncate": Tally(faults=3, survived=3, damaged=3, detected=3),
        "kill_child": Tally(faults=2, survived=1, wrong=1, notes=["trial 4: a record differs"]),
    }
    write_results(tallies, tmp_path / "results.json")
    f = fault_figure(json.loads((tmp_path / "results.json").read_text()))
    assert f["all"]["faults"] == 5 and f["all"]["survived"] == 4 and f["all"]["detected"] == 3
    record = {"name": "n", "command": "c", "commit": "abc1234", "measured": "today", "figure": f}
    table = _hook().fault([record])
    assert "| all | 5 | 4 | 0 | 0 | 1 | 3/3 |" in table and "| kill_child | 2 | 1 | 0 | 0 | 1 | - |" in table
    assert "- trial 4: a record differs" in table


TYPED_MARKER = re.compile(r"<!--\s*typed:")
NUMBER_CELL = re.compile(r"[*]*[\d.,]+%?[*]*(\s.*)?")
SEPARATOR_ROW = re.compile(r"\|(\s*:?-+:?\s*\|)+")


def _numeric_tables(text: str) -> list[tuple[str, str]]:
    """Each Markdown table of ``text`` with a number in its body, with the block that follows it."""
    blocks = text.split("\n\n")
    tables = []
    for i, block in enumerate(blocks):
        rows = [line.strip() for line in block.split("\n") if line.strip().startswith("|")]
        if len(rows) < 2 or not SEPARATOR_ROW.fullmatch(rows[1]):
            continue
        cells = [c.strip() for row in rows[2:] for c in row.strip("|").split("|")]
        if any(NUMBER_CELL.fullmatch(c) for c in cells):
            tables.append((block, blocks[i + 1] if i + 1 < len(blocks) else ""))
    return tables


def test_the_table_finder_sees_a_numeric_table_and_nothing_else():
    words = "Text | with a bar.\n\n| page | what |\n|---|---|\n| a | b |"
    numbers = "Note:\n| n | s |\n|---:|---|\n| 3 | 1.5 s |"
    (table, after), *rest = _numeric_tables(f"{words}\n\n{numbers}\n\n<!-- typed: abc1234 -->")
    assert not rest and table.startswith("Note:") and after == "<!-- typed: abc1234 -->"


def test_results_pages_draw_every_table_from_a_figure():
    """A results page holds no number typed by hand: every table is a ``<!-- figure: -->`` marker
    that the hook draws from ``docs/figures/``; a number typed before its results file was kept is
    history, in the changelog."""
    pages = sorted((ROOT / "docs/results").glob("*.md"))
    assert pages
    for page in pages:
        text = page.read_text()
        assert not TYPED_MARKER.search(text), f"{page.name}: a typed number belongs in docs/CHANGELOG.md"
        tables = _numeric_tables(text)
        assert not tables, f"{page.name}: a table typed by hand, not a figure: {tables[0][0][:80]}"


def test_the_front_pages_quote_no_typed_number():
    """The README's and the site's headline tables are drawn by ``python -m bench.readme``."""
    for page in (ROOT / "README.md", ROOT / "docs/index.md"):
        assert not TYPED_MARKER.search(page.read_text()), f"{page.name} quotes a typed number"


def test_the_changelog_keeps_the_commit_that_added_each_typed_table():
    """History keeps a table typed from a command's output with the commit that added it, which
    the hook renders as a note under the table."""
    hook = _hook()
    assert "when 92348d7 added it" in hook.render("<!-- typed: 92348d7 -->")
    tables = _numeric_tables((ROOT / "docs/CHANGELOG.md").read_text())
    assert tables
    for table, after in tables:
        assert hook.TYPED.fullmatch(after.strip()), (
            f"CHANGELOG.md: a typed table without the commit that added it: {table[:80]}"
        )


def test_build_search_and_replay_figures_come_from_the_benches_rows():
    """The three timing benches on synthetic designs: their rows, reduced and rendered."""
    from bench import replay_bench, search_bench, zonegraph_bench
    from bench.figures import build_figure, replay_figure, search_figure
    from zonegraph.data.synthetic import synthetic_design

    designs = [synthetic_design(i) for i in range(3)]
    jobs = [(f"synthetic:{i}", simplify, 60.0) for i in range(3) for simplify in (True, False)]
    built = build_figure(zonegraph_bench.rows("synthetic", [zonegraph_bench._job(j) for j in jobs]))
    searched = search_figure(search_bench.run("synthetic", designs, 2.0, "heuristic", 2000))
    replayed = replay_figure(replay_bench.report("synthetic", designs))
    group = built["groups"]["synthetic, simplified"]
    assert group["designs"] == 3 and group["built"] + len(group["failed"]) == 3
    s = searched["sets"]["synthetic"]
    assert s["drawn"] == 3 and s["exact"] + len(s["not_exact"]) == s["searched"]
    assert s["expansions"] >= s["searched"] and s["ms_per_expansion"]["max"] > 0
    r = replayed["sets"]["synthetic"]
    assert r["designs"] == 3 and r["steps"] >= 3 and r["ms_per_step"]["median"] <= r["ms_per_step"]["max"]
    hook = _hook()
    record = {"name": "n", "command": "c", "commit": "abc1234", "measured": "today"}
    assert f"| synthetic, simplified | {group['built']}/3 (" in hook.build([{**record, "figure": built}])
    assert "| synthetic (3 of 3 searched, heuristic, 2 s) |" in hook.search([{**record, "figure": searched}])
    assert f"| synthetic (3) | {r['steps']} |" in hook.replay([{**record, "figure": replayed}])


def test_the_coverage_figure_counts_each_measured_variant_by_folder():
    ok = {"convert_status": "ok", "replay_status": "ok", "graph_status": "ok", "simplified_status": "ok"}
    rows = [
        {**ok, "folder": "01", "simplified_captured_l1": True, "operations": "new_body"},
        {
            **ok,
            "folder": "01",
            "simplified_captured_l1": False,
            "simplified_search_exact": True,
            "simplified_reaches_target": True,
            "operations": "new_body,cut",
        },
        {
            **ok,
            "folder": "02",
            "graph_status": "fuse_failed",
            "simplified_status": None,
            "operations": "new_body",
        },
    ]
    designs = pd.DataFrame(rows).assign(full_status=None, full_captured_l1=None)
    f = coverage_figure(designs)
    assert list(f["variants"]) == ["simplified graph, level 1"] and f["designs"] == 3
    table = f["variants"]["simplified graph, level 1"]
    assert table["gt_captured"] == {"01": 1, "02": 0} and table["other_sequence"] == {"01": 1, "02": 0}
    assert table["zone_graph_failed"] == {"01": 0, "02": 1}
    record = {"name": "n", "command": "c", "commit": "abc1234", "measured": "today", "figure": f}
    text = _hook().coverage([record])
    assert "| reconstructable with the GT sequence | 1 (33.3%) | 50% | 0% |" in text
    assert "| designs | 3 | 2 | 1 |" in text


def test_the_guide_cost_figure_compares_each_guide_on_the_designs_both_solved():
    def row(design, guide, exact, seconds, steps=1):
        return {
            "design_id": design,
            "gt_steps": steps,
            "guide": guide,
            "budget": 1.0,
            "exact": exact,
            "time_to_exact_s": seconds if exact else None,
            "search_cpu_s": 0.01,
            "expansions": 2,
            "iou": 1.0 if exact else 0.5,
        }

    rows = [
        row("a", "heuristic", True, 0.002),
        row("a", "net", True, 0.001),
        row("b", "heuristic", True, 0.004, steps=3),
        row("b", "net", True, 0.004, steps=3),
        row("c", "heuristic", False, None, steps=3),
        row("c", "net", True, 0.5, steps=3),  # net alone: outside both the common medians and the ratio
    ]
    figure = guide_cost_figure({"rows": rows})
    at = figure["budgets"]["1"]
    assert at["common"] == 2
    net, heuristic = at["guides"]["net"], at["guides"]["heuristic"]
    assert (net["exact"], net["exact_gt3"], net["designs_gt3"]) == (3, 2, 2)
    assert (heuristic["mean_iou"], heuristic["mean_iou_gt3"], net["mean_iou"]) == (0.8333, 0.75, 1.0)
    assert heuristic["exact"] == 2 and heuristic["time_ratio"] is None
    assert net["median_time_to_exact_s"] == 0.0025 and heuristic["median_time_to_exact_s"] == 0.003
    assert net["time_ratio"]["designs"] == 2 and net["time_ratio"]["ratio"] == round(0.0025 / 0.003, 3)
    low, high = net["time_ratio"]["ci"]
    assert low <= net["time_ratio"]["ratio"] <= high
    record = {"name": "run", "command": "python -m bench.guide_cost_bench", "commit": "abc1234"}
    table = _hook().guide_cost([record | {"measured": "2026-12-05", "figure": figure}])
    assert "| run | 1 | net | 3/3 (100.0%) | 2/2 (100.0%) | 1.000 / 1.000 | 0.0025 | 2 | 0.83 (" in table


def test_the_report_figure_reads_each_curve_at_the_last_point_before_each_time(tmp_path):
    rows = [
        ("heuristic", 0.001, 0.0, 0.0),
        ("heuristic", 0.4, 0.9, 0.5),
        ("heuristic", 0.9, 1.0, 1.0),
        ("net", 0.001, 0.0, 0.0),
        ("net", 3.0, 0.8, 0.5),
    ]
    curves = pd.DataFrame(rows, columns=["guide", "seconds", "mean_iou", "exact_rate"]).assign(designs=2)
    curves.to_csv(tmp_path / "curves.csv", index=False)
    figure = report_figure(tmp_path)
    heuristic, net = figure["all"]["heuristic"]["at"], figure["all"]["net"]["at"]
    assert heuristic["0.5"] == {"iou": 0.9, "exact": 0.5} and heuristic["1"]["exact"] == 1.0
    assert net["1"] == {"iou": 0.0, "exact": 0.0} and net["5"]["exact"] == 0.5 and "gt3" not in figure
    record = {"name": "r", "command": "python -m eval.report", "commit": "abc1234", "measured": "2026-12-05"}
    table = _hook().report([record | {"figure": figure}])
    assert "| heuristic | 2 | 0.900 / 50.0% | 1.000 / 100.0% | 1.000 / 100.0% | 1.000 / 100.0% |" in table


def test_the_rank_figure_keeps_every_scale_with_its_interval_and_the_ratio():
    results = {
        "guides": [
            {
                "guide": "heuristic",
                "designs": 10,
                "steps": 30,
                "single": 4,
                "rank": 0.24,
                "ci_low": 0.22,
                "ci_high": 0.26,
                "floor": 0.17,
                "normalised": 0.072,
                "normalised_ci_low": 0.06,
                "normalised_ci_high": 0.084,
                "top1": 0.6,
                "top1_ci_low": 0.5,
                "top1_ci_high": 0.7,
                "top5": 0.8,
                "top5_ci_low": 0.75,
                "top5_ci_high": 0.85,
            },
        ],
        "vs_heuristic": [
            {"guide": "net", "base": "heuristic", "ratio": 0.5491, "ci_low": 0.473, "ci_high": 0.625}
        ],
    }
    figure = rank_figure(results)
    heuristic = figure["guides"]["heuristic"]
    assert heuristic["normalised"] == 0.072 and heuristic["normalised_ci"] == [0.06, 0.084]
    assert heuristic["rank_ci"] == [0.22, 0.26] and "floor_ci" not in heuristic
    assert figure["vs_heuristic"]["net"] == {"ratio": 0.549, "ci": [0.473, 0.625]}
    record = {"name": "run", "command": "python -m eval.rank", "commit": "abc1234", "measured": "2026-12-06"}
    table = _hook().rank([record | {"figure": figure}])
    assert (
        "| run | heuristic | 10 | 30 (4) | 0.2400 (0.2200 - 0.2600) | 0.1700 | 0.0720 (0.0600 - 0.0840) |"
        in table
    )
    assert "| run | net | 0.549 | 0.473 - 0.625 |" in table and "By timeline folder" not in table
    folder = {"folder": "08_21plus", "guide": "net", "designs": 3, "steps": 9, "normalised": 0.03551}
    folder |= {"top1": 0.7, "top5": 1.0, "vs_heuristic": 0.2577, "ci_low": 0.1, "ci_high": 0.45}
    first = {**folder, "folder": "01_2ops", "vs_heuristic": float("nan"), "ci_low": float("nan")}
    random = {**first, "guide": "random", "vs_heuristic": float("inf"), "ci_high": float("nan")}
    figure = rank_figure(results | {"by_folder": [first, random, folder]})
    assert figure["by_folder"][2]["vs_heuristic"] == 0.258 and figure["by_folder"][0]["vs_heuristic"] is None
    table = _hook().rank([record | {"figure": figure}])
    assert "| run | 08_21plus | net | 3 | 9 | 0.0355 | 0.700 | 1.000 | 0.258 (0.100 - 0.450) |" in table
    assert "| run | 01_2ops | net | 3 | 9 | 0.0355 | 0.700 | 1.000 | - |" in table
    assert "| run | 01_2ops | random | 3 | 9 | 0.0355 | 0.700 | 1.000 | - |" in table
    assert "By kind of step" not in table
    kind = {"kind": "other_completes", "guide": "net", "steps": 141, "share": 0.3431, "normalised": 0.36279}
    kind |= {"top1": 0.004, "vs_heuristic": 0.9046, "ci_low": 0.851, "ci_high": 0.953}
    itself = {**kind, "guide": "heuristic", "vs_heuristic": float("nan"), "ci_low": float("nan")}
    figure = rank_figure(results | {"by_kind": [itself, kind]})
    assert figure["by_kind"][1]["share"] == 0.343 and figure["by_kind"][0]["vs_heuristic"] is None
    table = _hook().rank([record | {"figure": figure}])
    assert "| run | other_completes | net | 141 | 0.343 | 0.3628 | 0.004 | 0.905 (0.851 - 0.953) |" in table
    assert "| run | other_completes | heuristic | 141 | 0.343 | 0.3628 | 0.004 | - |" in table
    assert "base's" not in table
    pooled = {"guide": "cosine", "base": "constant", "ratio": 0.9124, "ci_low": 0.87, "ci_high": 0.951}
    figure = rank_figure(results | {"vs_base": [pooled]})
    ratio = {"ratio": 0.912, "ci": [0.87, 0.951]}
    assert figure["vs_base"] == {"base": "constant", "ratios": {"cosine": ratio}}
    table = _hook().rank([record | {"figure": figure}])
    assert "| run | cosine | constant | 0.912 | 0.870 - 0.951 |" in table


def test_the_heavy_figure_shows_each_stage_before_and_after_and_what_ran_out_of_time():
    """Two checkouts' runs of bench.heavy_bench side by side; a stage the design never reached
    (it timed out during the labels) reads as more than its whole time, not as a number."""
    base = {"design_id": "d1", "folder": "08_21plus", "zones": 627, "build_s": 13.7, "expansion_s": 0.27}
    before = [base | {"first_proposals": 280, "labels_s": 169.1, "status": "ok", "seconds": 190.0}]
    after = [base | {"build_s": 15.0, "first_proposals": 579, "status": "timeout", "seconds": 1800.0}]
    records = [
        {"name": n, "command": "python -m bench.heavy_bench", "commit": c, "measured": "2026-12-06"}
        | {"figure": heavy_figure(rows)}
        for n, c, rows in (("heavy-before", "9491b5a", before), ("heavy-after", "5fcbc01", after))
    ]
    assert records[1]["figure"]["designs"]["d1"]["status"] == "timeout"
    table = _hook().heavy(records)
    row = next(line for line in table.splitlines() if line.startswith("| d1 |"))
    assert "13.7 → 15.0" in row and "280 → 579" in row and "169.1 → > 1,800 (timeout)" in row


def test_a_pipeline_run_figure_reads_each_stage_from_what_it_wrote(tmp_path):
    """Designs by status and job seconds per stage from the stages' own tables; a design the
    ground truth never reached (no seconds) is not one of its designs."""
    data = tmp_path / "data"
    for folder in ("designs", "replay", "zonegraphs", "gt", "details"):
        (data / folder).mkdir(parents=True)
    pd.DataFrame({"status": ["ok", "ok", "mismatch"], "seconds": [1.0, 3.0, 0.5]}).to_parquet(
        data / "designs/conversion.parquet"
    )
    pd.DataFrame({"status": ["ok", "ok"], "seconds": [0.2, 0.4]}).to_parquet(data / "replay/manifest.parquet")
    graphs = pd.DataFrame({"status": ["ok", "timeout"], "job_seconds": [0.1, 300.0]})
    graphs.to_parquet(data / "zonegraphs/manifest.parquet")
    gt = pd.DataFrame({"simplified_status": ["ok", None, None], "gt_seconds": [0.1, None, None]})
    gt.to_parquet(data / "gt/designs.parquet")
    rank_only = {"designs": 1, "by_status": {"ok": 1}, "seconds": 0.09, "seconds_per_design_median": 0.09}
    rank_only |= {"steps": 2, "labelled_steps": 1, "proposals": 7}
    (data / "details/labels.json").write_text(json.dumps({"designs": 0, "rank_only": rank_only}))
    figure = pipeline_run_figure(tmp_path)
    stages = figure["stages"]
    assert stages["generate"] == {
        "designs": 3,
        "statuses": {"ok": 2, "mismatch": 1},
        "job_seconds": 4.5,
        "median_seconds": 1.0,
    }
    assert stages["zonegraphs"]["statuses"] == {"ok": 1, "timeout": 1}
    assert stages["ground_truth"]["designs"] == 1
    assert "labels (with completions)" not in stages and figure["train"] is None
    record = {"name": "run", "command": "dvc repro", "commit": "abc1234", "measured": "2026-12-06"}
    table = _hook().pipeline_run([record | {"figure": figure}])
    assert "| generate | 3 | 4 (1.000) | ok 2, mismatch 1 |" in table
    assert "- labels (rank-only): 2 GT steps, 1 labelled, 7 proposals" in table


def test_a_startup_figure_compares_cold_and_warm_calls_with_the_original(tmp_path):
    """Per part the three processes' CPU, wall and memory; the ratios to the original count a
    part above it, and a killed original keeps its exit status in the table."""

    def run(cpu: float, rc: int = 0) -> dict:
        return {"rc": rc, "cpu_s": cpu, "wall_s": cpu + 0.01, "peak_mb": 300.0, "tail": ""}

    rows = [
        {"folder": "01", "part": "small", "step_bytes": 10, "build": run(1.4), "build warm": run(0.2)}
        | {"original": run(0.4)},
        {"folder": "08", "part": "heavy", "step_bytes": 90, "build": run(17.0), "build warm": run(16.0)}
        | {"original": run(9.0)},
        {"folder": "03", "part": "hung", "step_bytes": 50, "build": run(9.5), "build warm": run(8.9)}
        | {"original": run(300.0, rc=-9)},
    ]
    (tmp_path / "results.json").write_text(json.dumps(rows))
    start = {"wall_s": 3.5, "server_cpu_s": 3.4, "server_mb": 480}
    (tmp_path / "server_start.json").write_text(json.dumps(start))
    figure = startup_figure(tmp_path / "results.json")
    assert figure["columns"] == ["build", "build warm", "original"]
    record = {"name": "s", "command": "python -m bench.startup_bench --server", "commit": "abc1234"}
    table = _hook().startup([record | {"measured": "2026-12-06", "figure": figure}])
    assert "| hung (03) | 9.50 | 9.51 | 300 | 8.90 | 8.91 | 300 | 300.00 (exit -9) | 300.01 | 300 |" in table
    ratios = "median 0.50 (0.03-1.78), above the original's on 1 of 3"
    assert f"- build warm CPU / the original's: {ratios}" in table
    assert "- original: 2 of 3 exited 0" in table and "smallest part by STEP size, small" in table
    assert "the server's start, once: 3.50 s wall, 3.40 CPU s and 480 MB" in table


def test_the_expansion_figure_sets_two_runs_side_by_side():
    """Two checkouts' runs of bench.expansion_bench: the spread per run, and the costliest first
    expansions of the first run as before → after ("-" where the second run lacks the graph)."""
    rows = [
        {"design_id": "big", "zones": 1544, "first_expansion_cpu_s": 1.08, "search_cpu_s": 1.4}
        | {"exact": True, "expansions": 10},
        {"design_id": "small", "zones": 6, "first_expansion_cpu_s": 0.002, "search_cpu_s": 0.002}
        | {"exact": True, "expansions": 1},
    ]
    after = [rows[0] | {"first_expansion_cpu_s": 0.32, "search_cpu_s": 0.65}]
    records = [
        {"name": n, "command": "python -m bench.expansion_bench", "commit": c, "measured": "2026-12-07"}
        | {"figure": expansion_figure(r)}
        for n, c, r in (("before", "f8a76ed", rows), ("after", "7ce69a5", after))
    ]
    assert records[0]["figure"]["first_expansion_total_s"] == 1.082
    table = _hook().expansion(records)
    assert "| before | 2 | 2 | 0.5410 / 0.9722 / 1.080 (1.08) |" in table
    assert "| big | 1544 | 1.080 → 0.320 | 1.400 → 0.650 | True → True | 10 → 10 |" in table
    assert "| small | 6 | 0.002 → - |" in table


def test_the_folded_figure_sets_two_runs_side_by_side_by_zone_count():
    """Two checkouts' runs of bench.folded_bench: each graph's network milliseconds per state as
    before → after ("-" where the first run lacks the graph), sorted by zones."""
    rows = [
        {"design_id": "big", "zones": 2989, "states": 40, "network": 20.46}
        | {"features": 0.18, "heuristic": 0.2},
        {"design_id": "small", "zones": 12, "states": 40, "network": 0.24}
        | {"features": 0.09, "heuristic": 0.02},
    ]
    after = [rows[0] | {"network": 11.45}, rows[1] | {"network": 0.21}, rows[1] | {"design_id": "new"}]
    records = [
        {"name": n, "command": "python -m bench.folded_bench", "commit": c, "measured": "2026-12-07"}
        | {"figure": folded_figure(r)}
        for n, c, r in (("before", "2ab9fcf", rows[:2]), ("after", "b732bd3", after))
    ]
    table = _hook().folded(records)
    lines = table.splitlines()
    assert lines[2].startswith("| small | 12 | 40 | 0.24 → 0.21 | 0.09 | 0.02 | 10.5x |")
    assert "| new | 12 | 40 | - → 0.24 |" in table
    assert lines[4] == "| big | 2989 | 40 | 20.46 → 11.45 | 0.18 | 0.20 | 57.2x |"

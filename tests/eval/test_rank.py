"""Relative GT rank from label shards, on a real sample labelled rank-only."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from eval.rank import bootstrap_mean, guide_ranks, make_guides, rank_states, summarise
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.jobs import label_and_save
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.testing import gt_rows, requires_samples
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph


@pytest.fixture(scope="module")
def labelled(samples_dir, tmp_path_factory):
    """Couch: rank-only labels (multiplier 0: every proposal, the GT flagged) and its graph."""
    root = tmp_path_factory.mktemp("rank")
    r = replay(load_design(samples_dir / "Couch.json"))
    graph = build_zone_graph(list(r.bodies), samples=0)
    gt = ground_truth(
        graph, [s.tool.wrapped for s in r.steps], [s["operation"] for s in r.summary()["steps"]]
    )
    save_zone_graph(graph, root / "graphs" / "couch")
    label_and_save(
        str(root / "graphs" / "couch"), gt_rows(gt.steps), "couch", "test", str(root / "labels"), multiplier=0
    )
    return root / "labels", root / "graphs", graph


@requires_samples
def test_states_rebuild_the_proposals_the_heuristic_ranks(labelled):
    labels, graphs, graph = labelled
    [(loaded, states)] = list(rank_states(labels, graphs, "test"))
    assert loaded.n_zones == graph.n_zones and states
    for state in states:
        assert state.is_gt.sum() == 1 and len(state.proposals) == len(state.is_gt) >= 2
        assert all(p.zones.shape == (graph.n_zones,) and p.zones.any() for p in state.proposals)
        gt = state.proposals[int(np.flatnonzero(state.is_gt)[0])]
        assert not np.array_equal(gt.apply(state.canvas), state.canvas)  # the GT changes the canvas
    assert list(rank_states(labels, graphs, "train")) == []  # a split filter, not a label filter


@requires_samples
def test_a_step_knows_whether_its_gt_or_another_proposal_completes_the_target(labelled):
    labels, graphs, graph = labelled
    [(_, states)] = list(rank_states(labels, graphs, "test"))
    last = states[-1]
    gt = last.proposals[int(np.flatnonzero(last.is_gt)[0])]
    assert np.array_equal(gt.apply(last.canvas), graph.zone_inside) and last.kind == "gt_completes"
    first = states[0]  # Couch takes several steps: its first completes nothing
    assert len(states) > 1 and first.kind == "none_completes"
    finishing = [p for p in last.proposals if np.array_equal(p.apply(last.canvas), graph.zone_inside)]
    others = [p for p in last.proposals if not np.array_equal(p.apply(last.canvas), graph.zone_inside)]
    assert others, "a completing step with nothing else to rank"
    is_gt = np.arange(len(finishing) + 1) == len(finishing)  # the GT a proposal that does not finish
    swapped = replace(last, proposals=[*finishing, others[0]], is_gt=is_gt)
    assert swapped.kind == "other_completes"


@requires_samples
def test_ranks_per_guide_are_fractions_and_the_heuristic_matches_a_direct_call(labelled):
    labels, graphs, _ = labelled
    ranks = guide_ranks(labels, graphs, make_guides(["heuristic", "random"], seed=3), "test")
    assert set(ranks["guide"]) == {"heuristic", "random"}
    assert ((ranks["rank"] > 0) & (ranks["rank"] <= 1)).all()
    assert (ranks["rank"] >= 1 / ranks["proposals"]).all()
    [(graph, states)] = list(rank_states(labels, graphs, "test"))
    scores = HeuristicRanker().score(graph, states[0].canvas, states[0].proposals)
    gt = scores[states[0].is_gt][0]
    expected = (1 + (scores > gt).sum() + 0.5 * ((scores == gt).sum() - 1)) / len(scores)
    assert ranks[ranks.guide == "heuristic"]["rank"].iloc[0] == pytest.approx(expected)
    again = guide_ranks(labels, graphs, make_guides(["random"], seed=3), "test")
    assert again["rank"].tolist() == ranks[ranks.guide == "random"]["rank"].tolist()  # seeded


def test_bootstrap_resamples_designs_and_brackets_the_mean():
    rng = np.random.default_rng(0)
    ranks = pd.DataFrame(
        {"guide": "g", "design_id": np.repeat([f"d{i}" for i in range(40)], 3), "rank": rng.random(120)}
    )
    mean, low, high = bootstrap_mean(ranks, seed=1)
    assert low < mean < high and mean == pytest.approx(ranks["rank"].mean())
    assert bootstrap_mean(ranks, seed=1) == (mean, low, high)
    one = pd.DataFrame({"guide": "g", "design_id": "d", "rank": [0.2, 0.4]})
    assert bootstrap_mean(one) == pytest.approx((0.3, 0.3, 0.3))  # one design: no spread
    table = summarise(ranks)
    assert table.loc[0, "designs"] == 40 and table.loc[0, "steps"] == 120


def test_every_scale_of_a_rank_and_its_hit_rates():
    from zonegraph.sequence.rankers import gt_place

    first = gt_place(np.array([0.9, 0.1, 0.2, 0.3]), np.array([True, False, False, False]))
    assert (first.relative, first.normalised, first.floor, first.hit(1)) == (0.25, 0.0, 0.25, 1.0)
    last = gt_place(np.array([0.0, 0.1, 0.2, 0.3]), np.array([True, False, False, False]))
    assert (last.relative, last.normalised, last.hit(1), last.hit(5)) == (1.0, 1.0, 0.0, 1.0)
    tied = gt_place(np.zeros(5), np.array([False, False, True, False, False]))  # all tied: random
    assert tied.normalised == 0.5 and tied.hit(1) == pytest.approx(0.2) and tied.hit(5) == 1.0
    assert np.isnan(gt_place(np.zeros(1), np.array([True])).normalised)


@requires_samples
def test_the_summary_counts_single_proposal_steps_and_pairs_ratios(labelled):
    from eval.rank import markdown, ratios

    labels, graphs, _ = labelled
    ranks = guide_ranks(labels, graphs, make_guides(["heuristic", "random"], seed=3), "test")
    table = summarise(ranks, seed=1).set_index("guide")
    assert (table["steps"] + table["single"] == ranks.groupby("guide").size()).all()
    for guide in ("heuristic", "random"):
        row = table.loc[guide]
        assert row["floor"] <= row["rank"] and 0 <= row["normalised"] <= 1 and row["top1"] <= row["top5"]
        assert row["normalised_ci_low"] <= row["normalised"] <= row["normalised_ci_high"]
    ratio = ratios(ranks, seed=1)
    [(guide, value)] = ratio[["guide", "ratio"]].itertuples(index=False)
    assert guide == "random"
    assert value == pytest.approx(table.loc["random", "normalised"] / table.loc["heuristic", "normalised"])
    assert "normalised rank" in markdown(summarise(ranks), ratio)


def test_ranks_by_folder_pair_each_folders_designs_alone():
    from eval.rank import by_folder, folder_markdown, ratios

    rows = []
    for design, heuristic, net in [("a", 0.0, 0.0), ("b", 0.4, 0.1), ("c", 0.2, 0.2)]:
        for guide, value in (("heuristic", heuristic), ("net", net)):
            rows.append({"guide": guide, "design_id": design, "step": 0, "proposals": 5, "normalised": value})
            rows.append({"guide": guide, "design_id": design, "step": 1, "proposals": 1, "normalised": 0.0})
    ranks = pd.DataFrame(rows).assign(top1=lambda f: f["normalised"] == 0, top5=True)
    table = by_folder(ranks, {"a": "01", "b": "02", "c": "02"}, seed=2).set_index(["folder", "guide"])
    assert table.loc[("02", "net"), "steps"] == 2 and table.loc[("02", "net"), "designs"] == 2
    assert table.loc[("02", "net"), "normalised"] == pytest.approx(0.15)
    expected = ratios(ranks[ranks["design_id"] != "a"], seed=2).set_index("guide").loc["net"]
    assert table.loc[("02", "net"), "vs_heuristic"] == pytest.approx(0.5) == pytest.approx(expected["ratio"])
    assert table.loc[("02", "net"), "ci_low"] == expected["ci_low"]
    assert np.isnan(table.loc[("01", "net"), "vs_heuristic"])  # the heuristic ranks folder 01's GT first
    assert np.isnan(table.loc[("02", "heuristic"), "vs_heuristic"])
    text = folder_markdown(by_folder(ranks, {"a": "01", "b": "02", "c": "02"}))
    assert "| 02 | net | 2 | 2 | 0.1500 | 0.000 | 1.000 | 0.500 (" in text
    assert "| 01 | net | 1 | 1 | 0.0000 |" in text


def test_ranks_by_kind_of_step_split_each_guides_sum_and_pair_within_a_kind():
    from eval.rank import by_kind, kind_markdown, ratios

    rows = []
    for design, kind, heuristic, net in [
        ("a", "gt_completes", 0.1, 0.0),
        ("b", "other_completes", 0.6, 0.5),
        ("c", "none_completes", 0.4, 0.1),
        ("d", "none_completes", 0.2, 0.1),
    ]:
        for guide, value in (("heuristic", heuristic), ("net", net)):
            at = {"guide": guide, "design_id": design, "kind": kind}
            rows.append({**at, "step": 0, "proposals": 5, "normalised": value})
            rows.append({**at, "step": 1, "proposals": 1, "normalised": 0.0})
    ranks = pd.DataFrame(rows).assign(top1=lambda f: f["normalised"] == 0, top5=True)
    table = by_kind(ranks, seed=2).set_index(["kind", "guide"])
    assert table.loc[("other_completes", "net"), "share"] == pytest.approx(0.5 / 0.7)
    assert table.loc[("none_completes", "net"), "steps"] == 2  # single-proposal steps left out
    assert table.groupby("guide")["share"].sum().tolist() == pytest.approx([1.0, 1.0])
    expected = ratios(ranks[ranks["kind"] == "none_completes"], seed=2).set_index("guide").loc["net"]
    assert table.loc[("none_completes", "net"), "vs_heuristic"] == pytest.approx(1 / 3) == expected["ratio"]
    assert "| other_completes | net | 1 | 0.714 | 0.5000 | 0.000 | 0.833 (" in kind_markdown(by_kind(ranks))
    assert by_kind(ranks.drop(columns="kind")).empty  # ranks written before steps had a kind


def test_a_recipe_pooled_over_its_seeds_is_their_step_by_step_mean_and_pairs_like_a_guide(tmp_path):
    from eval.rank import main, pooled, ratios

    rows = []
    for design, heuristic, seed0, seed1 in [("a", 0.4, 0.0, 0.2), ("b", 0.2, 0.3, 0.1), ("c", 0.6, 0.2, 0.2)]:
        for guide, value in (("heuristic", heuristic), ("s0", seed0), ("s1", seed1)):
            rows.append({"guide": guide, "design_id": design, "step": 0, "proposals": 5, "normalised": value})
    ranks = pd.DataFrame(rows).assign(top1=lambda f: f["normalised"] == 0, top5=True, floor=0.2)
    ranks["rank"] = 0.2 + 0.8 * ranks["normalised"]
    both = pooled(ranks, ["s0", "s1"], "recipe")
    recipe = both[both["guide"] == "recipe"].set_index("design_id")
    assert recipe["normalised"].to_dict() == pytest.approx({"a": 0.1, "b": 0.2, "c": 0.2})
    assert recipe.loc["a", "top1"] == 0.5  # hit rates pool to the members' share
    assert len(both) == len(ranks) + 3 and set(both.columns) == set(ranks.columns)
    paired = ratios(both, seed=3).set_index("guide")
    assert paired.loc["recipe", "ratio"] == pytest.approx(0.5 / 1.2)
    assert paired.loc["recipe", "ci_low"] <= paired.loc["recipe", "ratio"] <= paired.loc["recipe", "ci_high"]
    with pytest.raises(ValueError, match="different steps"):
        pooled(ranks[~((ranks["guide"] == "s1") & (ranks["design_id"] == "c"))], ["s0", "s1"], "recipe")
    with pytest.raises(ValueError, match="no ranks of s2"):
        pooled(ranks, ["s0", "s2"], "recipe")
    ranks.to_parquet(tmp_path / "ranks.parquet")
    out = tmp_path / "out"
    earlier = ["--ranks", str(tmp_path / "ranks.parquet"), "--designs-table", str(tmp_path / "none")]
    main([*earlier, "--pool", "recipe=s0,s1", "--base", "recipe", "--out", str(out)])
    assert "| recipe |" in (out / "rank.md").read_text()
    against = json.loads((out / "rank.json").read_text())["vs_base"]
    assert {r["guide"]: r["base"] for r in against} == {"heuristic": "recipe", "s0": "recipe", "s1": "recipe"}
    assert "| s0 | " in (out / "rank.md").read_text().split("normalised rank / recipe's")[1]
    stored = set(pd.read_parquet(out / "ranks.parquet")["guide"])
    assert stored == {"heuristic", "s0", "s1"}  # the guides ranked; a pool is derived from them
    with pytest.raises(SystemExit, match="--pool recipe=s0,s9: no ranks of s9"):
        main([*earlier, "--pool", "recipe=s0,s9", "--out", str(out)])
    with pytest.raises(SystemExit, match="--base s7: no such guide"):
        main([*earlier, "--base", "s7", "--out", str(out)])


def test_an_earlier_runs_ranks_are_summarised_again_without_the_listed_designs(tmp_path):
    import json

    from eval.rank import main

    rows = [
        {"guide": guide, "design_id": design, "step": 0, "proposals": 4, "normalised": value}
        for design, heuristic, net in [("1_a_0000", 0.4, 0.1), ("2_b_0000", 0.2, 0.2), ("3_c_0000", 0.3, 0.0)]
        for guide, value in (("heuristic", heuristic), ("net", net))
    ]
    ranks = pd.DataFrame(rows).assign(rank=0.5, floor=0.25, top1=False, top5=True, above=1, ties=0)
    ranks.to_parquet(tmp_path / "ranks.parquet")
    (tmp_path / "seen.txt").write_text("3_c_0000\n")
    out, earlier = tmp_path / "again", str(tmp_path / "ranks.parquet")
    main(["--ranks", earlier, "--exclude", str(tmp_path / "seen.txt"), "--out", str(out)])
    result = json.loads((out / "rank.json").read_text())
    assert {g["guide"]: g["designs"] for g in result["guides"]} == {"heuristic": 2, "net": 2}
    assert result["vs_heuristic"][0]["ratio"] == pytest.approx(0.15 / 0.3)
    (tmp_path / "all.txt").write_text("1_a_0000\n2_b_0000\n3_c_0000\n")
    with pytest.raises(SystemExit, match="no designs left to rank"):
        main(["--ranks", earlier, "--exclude", str(tmp_path / "all.txt")])

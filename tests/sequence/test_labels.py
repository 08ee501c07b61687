"""Ternary labels by random completions, on hand-built parts whose answers are known and on real
samples (invariants, determinism, the Parquet tables)."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest
from build123d import Box, Cylinder, Pos

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.jobs import label_and_save
from zonegraph.sequence import labels, proposals
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.sequence.labels import (
    NEGATIVE,
    NEUTRAL,
    POSITIVE,
    PROPOSAL_SCHEMA,
    STEP_SCHEMA,
    GTOperation,
    LabelledStep,
    label_design,
    label_tables,
)
from zonegraph.testing import gt_rows, requires_samples
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph

PLATE = Box(4, 4, 1)
HOLE_A, HOLE_B = Pos(-1, 0, 0) * Cylinder(0.5, 1), Pos(1, 0, 0) * Cylinder(0.5, 1)


def _labelled(part, tools, operations, **kwargs):
    graph = build_zone_graph(part, samples=0, simplify=False)
    gt = ground_truth(graph, [t.wrapped for t in tools], operations)
    assert gt.reaches_target, gt.reason
    ops = [GTOperation(s.zones, s.op, s.captured[1], s.operation, s.reason) for s in gt.steps]
    return graph, ops, label_design(graph, ops, "part", **kwargs)


def _others(step: LabelledStep):
    return [x for x in step.proposals if not x.is_gt]


def _check_invariants(graph, steps: list[LabelledStep]) -> None:
    for step in steps:
        if not step.proposals:
            assert step.reason
            continue
        assert sum(x.label == POSITIVE for x in step.proposals) == sum(x.is_gt for x in step.proposals) == 1
        others = _others(step)
        if others:
            assert any(x.label == NEGATIVE for x in others)
            assert all(0.0 <= x.p <= 1.0 and x.completions >= 1 for x in others)
            assert all(x.label == NEGATIVE for x in others if x.p == 0)
        for x in step.proposals:
            assert x.proposal.zones.shape == (graph.n_zones,) and x.proposal.zones.any()


def test_plate_with_two_holes_alternative_order_is_neutral_and_a_wrong_cut_negative():
    # GT: plate, cut hole A, cut hole B. With no slack, at the first cut only proposals that can
    # finish in the two remaining steps have p > 0: cutting B first (the other order) can, cutting
    # the plate's web away cannot.
    graph, ops, steps = _labelled(
        PLATE - HOLE_A - HOLE_B, [PLATE, HOLE_A, HOLE_B], ["new_body", "cut", "cut"], slack=0, multiplier=10
    )
    _check_invariants(graph, steps)
    cut = steps[1]
    by_zones = {frozenset(np.flatnonzero(x.proposal.zones)): x for x in cut.proposals}
    hole_b = frozenset(np.flatnonzero(ops[2].zones))
    web = frozenset(np.flatnonzero(graph.zone_inside))
    assert by_zones[frozenset(np.flatnonzero(ops[1].zones))].label == POSITIVE
    assert by_zones[hole_b].label == NEUTRAL and by_zones[hole_b].p > 0
    assert by_zones[hole_b | frozenset(np.flatnonzero(ops[1].zones))].p == 1.0  # both holes at once
    assert by_zones[web].label == NEGATIVE and by_zones[web].p == 0.0


def test_every_dead_end_is_negative():
    # Plate with one hole, at the cut, with no slack: the other proposal removes the plate's web,
    # its inverse (adding the web back) is banned, and the plate extruded again from a side face
    # (a prism across the hole's wall) needs a step more than the design has: no completion.
    graph, _, steps = _labelled(PLATE - HOLE_A, [PLATE, HOLE_A], ["new_body", "cut"], slack=0, multiplier=20)
    _check_invariants(graph, steps)
    others = _others(steps[1])
    assert others and all(x.p == 0.0 and x.label == NEGATIVE for x in others)


def test_when_every_proposal_can_finish_exactly_one_is_negative():
    # At the last cut of the two-hole plate every alternative can still reach the target.
    graph, _, steps = _labelled(
        PLATE - HOLE_A - HOLE_B, [PLATE, HOLE_A, HOLE_B], ["new_body", "cut", "cut"], multiplier=20
    )
    others = _others(steps[2])
    assert len(others) >= 2 and all(x.p > 0 for x in others)
    negatives = [x for x in others if x.label == NEGATIVE]
    assert len(negatives) == 1 and negatives[0].p == min(x.p for x in others)
    assert all(x.label == NEUTRAL for x in others if x is not negatives[0])


def test_uncaptured_step_has_a_reason_and_no_labels():
    graph, ops, _ = _labelled(PLATE - HOLE_A, [PLATE, HOLE_A], ["new_body", "cut"])
    ops[1] = GTOperation(ops[1].zones, ops[1].op, False, "cut", "no proposal has the GT extrusion")
    steps = label_design(graph, ops, "part")
    assert steps[0].proposals and not steps[1].proposals
    assert steps[1].reason == "no proposal has the GT extrusion"


def test_seeded_labels_are_identical_and_seeds_differ():
    parts = (PLATE - HOLE_A - HOLE_B, [PLATE, HOLE_A, HOLE_B], ["new_body", "cut", "cut"])
    runs = [_labelled(*parts, seed=seed) for seed in (0, 0, 1)]
    tables = [label_tables(steps, ops, "d", "train")[0] for _, ops, steps in runs]
    assert tables[0].equals(tables[1])
    assert not tables[0].column("p").equals(tables[2].column("p"))  # the seed is used


@requires_samples
@pytest.mark.parametrize("name", ["Couch.json", "Pattern4-SteppedStartEndFace_17dd857d_0000.json"])
def test_real_samples_keep_the_invariants_and_write_readable_shards(samples_dir, tmp_path, name):
    r = replay(load_design(samples_dir / name))
    graph = build_zone_graph(list(r.bodies), samples=0)
    operations = [s["operation"] for s in r.summary()["steps"]]
    gt = ground_truth(graph, [s.tool.wrapped for s in r.steps], operations)
    save_zone_graph(graph, tmp_path / "graph")
    rows = gt_rows(gt.steps)
    counts = label_and_save(str(tmp_path / "graph"), rows, "sample", "train", str(tmp_path / "labels"))
    proposals = pq.read_table(tmp_path / "labels" / "proposals" / "sample.parquet")
    steps = pq.read_table(tmp_path / "labels" / "steps" / "sample.parquet")
    assert proposals.schema.equals(PROPOSAL_SCHEMA) and steps.schema.equals(STEP_SCHEMA)
    assert counts["positives"] == sum(s.captured[1] for s in gt.steps) == counts["labelled_steps"] > 0
    table = proposals.to_pandas()
    assert set(table["label"]) <= {-1, 0, 1} and (table["label"] == 1).eq(table["is_gt"]).all()
    for _, step in table.groupby("step"):
        assert (step["label"] == 1).sum() == 1
        assert len(step) == 1 or (step["label"] == -1).sum() >= 1
    zones = [z for zs in table["zones"] for z in zs]
    assert min(zones) >= 0 and max(zones) < graph.n_zones
    again = label_and_save(str(tmp_path / "graph"), rows, "sample", "train", str(tmp_path / "again"))
    assert again == counts
    assert pq.read_table(tmp_path / "again" / "proposals" / "sample.parquet").equals(proposals)


def test_proposal_features_are_the_heuristic_terms_and_the_geometry_the_search_sees():
    from zonegraph.sequence.features import FEATURES, PROPOSAL_FEATURES, proposal_features
    from zonegraph.sequence.rankers import HeuristicRanker

    graph, ops, steps = _labelled(PLATE - HOLE_A, [PLATE, HOLE_A], ["new_body", "cut"], multiplier=0)
    column = {name: i for i, name in enumerate(FEATURES)}
    for step in steps:
        props = [x.proposal for x in step.proposals]
        feats = step.features
        assert feats.shape == (len(props), len(FEATURES)) and np.isfinite(feats).all()
        np.testing.assert_array_equal(feats, proposal_features(graph, step.canvas, props, step.step))
        heuristic = HeuristicRanker().score(graph, step.canvas, props)
        np.testing.assert_allclose(
            feats[:, column["agree_after"]], np.floor(heuristic * graph.n_zones) / graph.n_zones, atol=1e-6
        )
        assert (feats[:, column["step"]] == step.step).all()
        assert (feats[:, column["union"]] == [float(p.op.name == "UNION") for p in props]).all()
        gt = feats[[x.is_gt for x in step.proposals]][0]
        assert (
            gt[column["iou_gain"]] > 0 and gt[column["start_on_target"]] == gt[column["end_on_target"]] == 1
        )
        # the plate is 1 thick in a box of unit diagonal: every plate-high extrusion has one depth
        assert gt[column["depth"]] > 0 and gt[column["sketch_area"]] > 0 and gt[column["sketch_faces"]] >= 1
        # how far behind the state's best: 0 for the best, the heuristic's order for the others
        agree_gap = feats[:, column["agree_gap"]]
        assert agree_gap.min() == 0 and (agree_gap >= 0).all()
        np.testing.assert_allclose(
            agree_gap, feats[:, column["agree_after"]].max() - feats[:, column["agree_after"]]
        )
        assert feats[np.argmax(heuristic), column["iou_gap"]] == 0
    first, second = steps[0].features, steps[1].features
    assert (first[:, column["missing"]] == 1).all() and (second[:, column["missing"]] == 0).all()
    table, _ = label_tables(steps, ops, "part", "train")
    # the stored columns; the state's own are derived from them whenever a state is read
    assert [f"feat_{n}" for n in PROPOSAL_FEATURES] == table.column_names[-len(PROPOSAL_FEATURES) :]


@requires_samples
def test_labels_do_not_depend_on_what_the_memos_keep(samples_dir, monkeypatch):
    """The generator's and the completions' memos only save work: with room for one entry each
    (every other group, component, sweep and canvas computed again) the labels are the same."""
    r = replay(load_design(samples_dir / "Couch.json"))
    graph = build_zone_graph(list(r.bodies), samples=0)
    operations = [s["operation"] for s in r.summary()["steps"]]
    gt = ground_truth(graph, [s.tool.wrapped for s in r.steps], operations)
    ops = [GTOperation(s.zones, s.op, s.captured[1], s.operation, s.reason) for s in gt.steps]
    kept = label_tables(label_design(graph, ops, "couch"), ops, "couch", "train")[0]
    monkeypatch.setattr(proposals, "MEMO_BYTES", dict.fromkeys(proposals.MEMO_BYTES, 0))
    monkeypatch.setattr(labels, "CANVAS_MEMO_BYTES", 0)
    forgotten = label_tables(label_design(graph, ops, "couch"), ops, "couch", "train")[0]
    assert kept.num_rows > 10 and kept.equals(forgotten)

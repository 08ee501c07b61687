"""bench.copies_bench on the labels of a real sample, as the labels stage writes them."""

from __future__ import annotations

import json

import pyarrow.parquet as pq
import pytest

from bench.copies_bench import main, training_states
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.jobs import label_and_save
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.testing import gt_rows, requires_samples
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph

SAMPLE = "Z0HexagonCutJoin_RootComponent"


@requires_samples
def test_copies_are_proposals_kept_times_zones_and_a_bound_cuts_the_largest(samples_dir, tmp_path):
    r = replay(load_design(samples_dir / f"{SAMPLE}.json"))
    graph = build_zone_graph(list(r.bodies), samples=0)
    save_zone_graph(graph, tmp_path / "graphs" / SAMPLE)
    operations = [s["operation"] for s in r.summary()["steps"]]
    gt = ground_truth(graph, [s.tool.wrapped for s in r.steps], operations)
    labels, graphs = tmp_path / "labels", tmp_path / "graphs"
    label_and_save(str(graphs / SAMPLE), gt_rows(gt.steps), SAMPLE, "train", str(labels))
    states = training_states(labels, graphs, "train")
    steps = pq.read_table(labels / "proposals" / f"{SAMPLE}.parquet").to_pandas()
    assert len(states) == steps.groupby("step").ngroups and set(states["zones"]) == {graph.n_zones}
    assert states["proposals"].tolist() == steps.groupby("step").size().tolist()
    largest = int(states["proposals"].max())
    assert largest > 2, "the sample must have a state the bound can cut"
    bound = 2 * graph.n_zones  # two copies of the graph: the positive and one other
    out = tmp_path / "out"
    read = ["--labels", str(labels), "--graphs", str(graphs), "--out", str(out)]
    main([*read, "--max-proposals", "32", "--max-nodes", str(bound)])
    result = json.loads((out / "results.json").read_text())[0]
    assert result["copies"] == sum(min(p, 32) for p in states["proposals"]) * graph.n_zones
    assert result["largest"] == min(largest, 32) * graph.n_zones
    cut = result["cuts"][0]
    assert cut["states"] == int((states["proposals"] > 2).sum())
    assert cut["largest_after"] == bound
    assert cut["copies_after"] == sum(min(p, 2) for p in states["proposals"]) * graph.n_zones
    with pytest.raises(SystemExit, match="no labelled states of the test split"):
        main([*read, "--split", "test"])

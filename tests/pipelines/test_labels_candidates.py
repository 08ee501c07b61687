"""Which designs the labels stage labels: GT replayed to the target, on either graph."""

from __future__ import annotations

import pandas as pd

from pipelines.labels import candidates
from zonegraph.status import Status


def test_candidates_read_the_full_graph_only_where_the_ground_truth_stage_built_it():
    designs = pd.DataFrame(
        {
            "design_id": ["a", "b", "c"],
            "split": ["test", "test", "train"],
            "folder": ["01_2ops"] * 3,
            "simplified_status": [Status.OK.value, "timeout", Status.OK.value],
            "simplified_reaches_target": [True, None, True],
        }
    )
    assert candidates(designs, ["test"], None, 0)["design_id"].tolist() == ["a"]  # full_graph: false
    designs["full_reaches_target"] = [False, True, True]
    assert candidates(designs, ["test"], None, 0)["design_id"].tolist() == ["a", "b"]

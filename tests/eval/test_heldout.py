"""Held-out designs: the projects a model trained on, from either file, and halves by project."""

from __future__ import annotations

import subprocess
import sys

import pytest

from eval.heldout import HOLDOUT, part_of, trained_projects
from zonegraph.network.checkpoint import SHIPPED
from zonegraph.network.folded import SHIPPED_FOLDED


def test_the_shipped_fold_names_the_projects_its_checkpoint_trained_on():
    from_pt, silent_pt = trained_projects([SHIPPED])
    from_npz, silent_npz = trained_projects([SHIPPED_FOLDED])
    assert len(from_pt) > 1000 and from_npz == from_pt and silent_pt == silent_npz == []


def test_two_parts_split_designs_by_project_and_keep_their_order():
    ids = [f"{p}_{h}_{i:04d}" for p in range(100, 140) for h in ("aa", "bb") for i in range(2)]
    tune, report = part_of(ids, "tune", 3), part_of(ids, "report", 3)
    assert sorted(tune + report) == sorted(ids) and tune == sorted(tune) and report == sorted(report)
    assert not {d.rsplit("_", 1)[0] for d in tune} & {d.rsplit("_", 1)[0] for d in report}  # projects
    assert part_of(ids, "tune", 3) == tune != part_of(ids, "tune", 4) and part_of(ids, None, 3) == ids
    with pytest.raises(ValueError, match="unknown part"):
        part_of(ids, "test", 0)


def test_listed_designs_are_left_out_and_a_missing_list_is_one_line(tmp_path):
    from eval.heldout import excluded

    listing = tmp_path / "seen.txt"
    listing.write_text("# looked at before\n10_a_0000\n  30_c_0001  # a comment\n\n")
    assert excluded(["10_a_0000", "20_b_0000", "30_c_0001"], listing) == ["20_b_0000"]
    assert excluded(["10_a_0000"], None) == ["10_a_0000"]
    with pytest.raises(SystemExit, match="missing.txt: error: no such list of design ids"):
        excluded(["10_a_0000"], tmp_path / "missing.txt")


def test_a_report_on_held_out_designs_keeps_those_projects_and_needs_a_model_that_held_some_out(tmp_path):
    from argparse import Namespace

    from eval.report import evaluated, split_of

    ids = ["1_a_0000", "1_a_0001", "2_b_0000", "3_c_0000", "4_d_0000"]
    args = Namespace(designs=HOLDOUT, trained={"1_a"}, exclude=None, held={"1_a", "2_b", "3_c"})
    assert split_of(args) == "train" and evaluated(args, ids) == ["2_b_0000", "3_c_0000"]
    split = Namespace(designs="test", trained={"1_a"}, exclude=None, held=None)
    assert evaluated(split, ids) == ids[2:]
    shipped = str(SHIPPED_FOLDED)  # trained on the whole training split
    command = ["-m", "eval.report", "--designs", HOLDOUT, "--model", shipped, "--out", str(tmp_path)]
    done = subprocess.run(
        [sys.executable, *command],
        capture_output=True,
        text=True,
    )
    assert done.returncode != 0 and "Traceback" not in done.stderr
    assert done.stderr.strip().endswith("trained with no held-out projects (train.holdout_fraction 0)")

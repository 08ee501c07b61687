"""Design folders as (id, path, split) records: r1.0.1 split files and seeded splits."""

from __future__ import annotations

import json

import pytest

from zonegraph.data.dataset import read_dataset
from zonegraph.errors import InputError


def make_folder(tmp_path, n):
    folder = tmp_path / "reconstruction"
    folder.mkdir()
    for i in range(n):
        (folder / f"d{i:02d}.json").write_text("{}")
    return folder


def test_official_split_file_one_level_up(tmp_path):
    folder = make_folder(tmp_path, 4)
    (tmp_path / "train_test.json").write_text(json.dumps({"train": ["d00", "d01", "d02"], "test": ["d03"]}))
    records = read_dataset(folder)
    assert [(r.design_id, r.split) for r in records] == [
        ("d00", "train"),
        ("d01", "train"),
        ("d02", "train"),
        ("d03", "test"),
    ]


def test_seeded_split_is_reproducible(tmp_path):
    folder = make_folder(tmp_path, 20)
    a = read_dataset(folder, seed=3, test_fraction=0.25)
    assert a == read_dataset(folder, seed=3, test_fraction=0.25)
    assert sum(r.split == "test" for r in a) == 5
    assert a != read_dataset(folder, seed=4, test_fraction=0.25)


def test_samples_folder(samples_dir):
    records = read_dataset(samples_dir)
    assert len(records) == 22 and {r.split for r in records} == {"train", "test"}


def test_missing_or_empty_folder(tmp_path):
    with pytest.raises(InputError, match="no such data folder"):
        read_dataset(tmp_path / "nope")
    with pytest.raises(InputError, match="no design JSON"):
        read_dataset(tmp_path)
